"""The per-class filter skeleton every tracker plugs into: predict -> gate -> emit -> *update* -> extract -> emit.

``ClassFilter.step`` is the only frame loop of the code base. A tracker family subclasses ``ClassFilter`` with
its prior type (the predicted density gated against the frame's measurements) and its posterior type, and writes
the hooks; ``step`` calls them in this order and emits the events every family shares:

1. ``predict(meas, dt_s)``: the motion model applied to the density, birth, and the gate
   d2_kj = (z_j - H m_k)^T S_k^-1 (z_j - H m_k), inside iff d2_kj < G (``gate_tracks``; paper sec. V-B);
2. ``prior_view(prior)``: the predicted tracks and their gate, which ``step`` emits as ``Predicted`` and
   ``Gated`` (``emit_prior``; no ``Gated`` for a family without a Gaussian gate);
3. ``update(prior, meas, sink)``: the family's update rule, the only part that really differs (PMB strategy,
   PHD / CPHD weights, GNN / JPDA association, greedy matching); it emits its own events (cost matrices,
   assignments, births, pruning);
4. ``extract(posterior, sink)``: the estimates of the frame and the threshold they were extracted with;
5. ``posterior_view(posterior)``: the updated tracks, which ``step`` emits as ``Posterior`` with ``Extracted``
   (``emit_posterior``).

``idle()`` lets a filter skip a frame without measurements when that leaves it unchanged (the PHD filters).
Families: ``pmb.core.PmbCore`` (GNN-PMB, PMBM, TO-PMB), ``phd.gmphd.GmPhdTracker`` and ``phd.cphd.CphdTracker``,
``vector.tracks.VectorTracker`` (GNN, JPDA) and ``greedy.GreedyTracker``; ``registry`` only wires names to them.
"""

from __future__ import annotations

from abc import ABC, abstractmethod
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Generic, TypeVar

import numpy as np

from gnnpmb.config import TrackerConfig
from gnnpmb.events import EventSink, Extracted, Gated, Panel, Posterior, Predicted, ScoreRule
from gnnpmb.gating import gate
from gnnpmb.kalman import Innovation, innovation, mahalanobis2
from gnnpmb.types import IdAllocator, Measurements, TrackEstimate

PriorT = TypeVar("PriorT")
PosteriorT = TypeVar("PosteriorT")


@dataclass(frozen=True, slots=True)
class TrackView:
    """K tracks as ``Predicted`` and ``Posterior`` show them: track_id (K,) int64, mean (K, 4) [x, y, vx, vy],
    cov (K, 4, 4), existence (K,) (1 for trackers without one); score (K,) and score_rule: the track scores of a
    tracker that keeps them (``events.ScoreRule``), else None."""

    track_id: np.ndarray
    mean: np.ndarray
    cov: np.ndarray
    existence: np.ndarray
    score: np.ndarray | None = None
    score_rule: ScoreRule | None = None


@dataclass(frozen=True, slots=True)
class Gating:
    """The gate step's result for K tracks and M measurements: inn (K) innovation quantities, d2 (K, M) squared
    Mahalanobis distances, inside (K, M) bool; giou (K, M) the bird's-eye GIoU of the pairs inside the
    Mahalanobis gate (NaN elsewhere) and giou_min when an overlap gate also applied (``Gated``), else None."""

    inn: Innovation
    d2: np.ndarray
    inside: np.ndarray
    giou: np.ndarray | None = None
    giou_min: float | None = None


def gate_tracks(mean: np.ndarray, cov: np.ndarray, R: np.ndarray, z: np.ndarray, gate_chi2: float) -> Gating:
    """Innovations of K tracks ((K, 4) means, (K, 4, 4) covariances) and their gate over measurements z (M, D)."""
    k, m = len(mean), len(z)
    inn = innovation(mean, cov, R)
    d2 = mahalanobis2(inn, z) if k and m else np.zeros((k, m))
    return Gating(inn=inn, d2=d2, inside=gate(d2, gate_chi2))


def emit_prior(
    sink: EventSink, class_name: str, t: TrackView, gating: Gating | None, meas_indices: np.ndarray, gate_chi2: float
) -> None:
    """``Predicted`` and ``Gated`` of K predicted tracks (gate ellipses in the BEV plane: the x, y block of S);
    ``Predicted`` only when ``gating`` is None."""
    sink.emit(Predicted(class_name, t.track_id, t.mean, t.cov, t.existence))
    if gating is None:
        return
    sink.emit(
        Gated(
            class_name,
            track_ids=t.track_id,
            meas_indices=np.asarray(meas_indices),
            inside=gating.inside,
            center_xy=gating.inn.z_pred[:, :2],
            innovation_cov=gating.inn.S[:, :2, :2],
            threshold=gate_chi2,
            d2=gating.d2,
            giou=gating.giou,
            giou_min=gating.giou_min,
        )
    )


def emit_posterior(
    sink: EventSink, class_name: str, t: TrackView, estimates: Sequence[TrackEstimate], threshold: float
) -> None:
    """``Posterior`` of the K updated tracks and ``Extracted`` with the estimates and the extraction threshold."""
    sink.emit(Posterior(class_name, t.track_id, t.mean, t.cov, t.existence, t.score, t.score_rule))
    sink.emit(Extracted(class_name, tuple(estimates), threshold))


class ClassFilter(ABC, Generic[PriorT, PosteriorT]):
    """One class's tracker: the frame loop (``step``) and the hooks a family writes (module docstring).

    ``panels``: the tracker-specific viewer panels its events fill. ``has_existence``: False for trackers whose
    tracks have no existence probability (track logic instead; their events carry existence 1), so the viewer
    draws no existence plot for them. ``has_gates``: False for a tracker that matches without a Gaussian gate (no
    ``Gated`` event, so no normalised innovation to plot). ``has_costs``: False for a tracker whose update follows no
    chosen assignment of a cost matrix (JPDA, PHD, CPHD, TO-PMB: soft updates), so no chosen cost to plot.
    ``keeps_detection_box``: an output box has the size, heading and height of the detection that last updated its
    track; False for a tracker that filters the whole box (``gnnpmb.box``), whose box only nears the detection's."""

    panels: tuple[Panel, ...] = ()
    has_existence: bool = True
    has_gates: bool = True
    has_costs: bool = True
    keeps_detection_box: bool = True

    def __init__(self, class_name: str, config: TrackerConfig, ids: IdAllocator):
        self.class_name = class_name
        self.config = config
        self.class_params = config.for_class(class_name)
        self.ids = ids

    def step(self, meas: Measurements, dt_s: float, sink: EventSink) -> list[TrackEstimate]:
        """Process one frame of this class's M measurements; returns the extracted tracks."""
        if not len(meas) and not sink.enabled and self.idle():
            return []
        prior = self.predict(meas, dt_s)
        if sink.enabled:
            t, gating = self.prior_view(prior)
            emit_prior(sink, self.class_name, t, gating, meas.source_index, self.gate_threshold)
        posterior = self.update(prior, meas, sink)
        estimates, threshold = self.extract(posterior, sink)
        if sink.enabled:
            emit_posterior(sink, self.class_name, self.posterior_view(posterior), estimates, threshold)
        return estimates

    @property
    def gate_threshold(self) -> float:
        """The squared Mahalanobis gate ``Gated`` reports (``[models] gate_chi2``; a family with its own gate
        says so)."""
        return self.config.models.gate_chi2

    def idle(self) -> bool:
        """True when a frame without measurements would leave the filter unchanged and extract nothing, so
        ``step`` may skip it (when no sink listens)."""
        return False

    @abstractmethod
    def predict(self, meas: Measurements, dt_s: float) -> PriorT:
        """The prior of this frame: the density predicted over ``dt_s`` seconds, with its births and its gate
        over the M measurements."""

    @abstractmethod
    def prior_view(self, prior: PriorT) -> tuple[TrackView, Gating | None]:
        """The K predicted tracks and their gate over the M measurements, as ``Predicted`` and ``Gated`` show
        them (None: no Gaussian gate, no ``Gated``). Called only when the sink is enabled."""

    @abstractmethod
    def update(self, prior: PriorT, meas: Measurements, sink: EventSink) -> PosteriorT:
        """The family's update rule: the posterior density, kept as the filter's state; emits its own events."""

    @abstractmethod
    def extract(self, posterior: PosteriorT, sink: EventSink) -> tuple[list[TrackEstimate], float]:
        """The estimates of the frame and the threshold they were extracted with (``Extracted.threshold``)."""

    @abstractmethod
    def posterior_view(self, posterior: PosteriorT) -> TrackView:
        """The updated tracks as ``Posterior`` shows them (after ``extract``). Called only when the sink is
        enabled."""
