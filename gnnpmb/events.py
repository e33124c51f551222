"""Introspection events: the contract between trackers and the viewer.

Every tracker emits these, per class and per frame, to an ``EventSink``. The viewer (``viz``) reads only these
events and ``gnnpmb.types``, never a tracker's internals. Events carry ids, indices and arrays, not tracker objects.
Costly payloads (covariances, cost matrices) are built only when ``sink.enabled`` is true, so running without a
sink costs next to nothing.

Array shapes: K tracks (or Bernoullis / Gaussian components), M measurements of the class this frame.
Measurements are named by their *source index* into the frame's full detection list (``FrameDetections.boxes``).
"""

from __future__ import annotations

import enum
import itertools
import math
import operator
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Protocol, runtime_checkable

import numpy as np

from gnnpmb.types import TrackEstimate


class AxisKind(enum.Enum):
    """What a row or column of a cost or marginal matrix stands for."""

    TRACK = "track"  # an existing track / Bernoulli, ref = track id
    MEASUREMENT = "meas"  # a detection, ref = source index
    NEW_TRACK = "new"  # "measurement starts a new track (or is clutter)", ref = source index
    MISSED = "missed"  # "track not detected", ref = track id


@dataclass(frozen=True, slots=True)
class AxisLabel:
    kind: AxisKind
    ref: int

    def __str__(self) -> str:
        return f"{self.kind.value} {self.ref}"


def axis_labels(kind: AxisKind, refs: np.ndarray | Sequence[int]) -> tuple[AxisLabel, ...]:
    """``AxisLabel(kind, r)`` for each of the (N,) refs. Labels come from a cache, one dict per kind read through
    C-level ``map``: building a frozen dataclass (and ``int`` of a numpy scalar) per row and column was the
    largest cost of emitting events (about 4 ms per frame of GNN-PMB's 13 ms with the logger on the centerpoint
    demo), and a Python loop over a cached constructor still cost ~1 µs per label."""
    return tuple(map(_LABELS[kind].__getitem__, np.asarray(refs).tolist()))


class _LabelCache(dict):
    """ref -> ``AxisLabel(kind, ref)`` of one kind, built on first use; emptied when it reaches
    ``_LABEL_CACHE_MAX`` entries (track ids keep growing over a long run)."""

    __slots__ = ("kind",)

    def __init__(self, kind: AxisKind) -> None:
        super().__init__()
        self.kind = kind

    def __missing__(self, ref: int) -> AxisLabel:
        if len(self) >= _LABEL_CACHE_MAX:
            self.clear()
        label = self[ref] = AxisLabel(self.kind, ref)
        return label


_LABEL_CACHE_MAX = 1 << 16
_LABELS = {kind: _LabelCache(kind) for kind in AxisKind}


def label_positions(labels: Sequence[AxisLabel]) -> dict[AxisKind, dict[int, int]]:
    """kind -> (ref -> position in ``labels`` of the last label of that kind and ref): the row or column of a
    cost matrix that a label names. Built run by run of equal kinds with C-level ``map`` and ``zip``: an
    ``AxisKind`` hashes in Python code, so it is hashed once per run, not once per label."""
    out: dict[AxisKind, dict[int, int]] = {}
    refs = list(map(_REF, labels))
    start = 0
    for kind, run in itertools.groupby(map(_KIND, labels)):
        stop = start + len(list(run))
        out.setdefault(kind, {}).update(zip(refs[start:stop], range(start, stop), strict=True))
        start = stop
    return out


_KIND = operator.attrgetter("kind")
_REF = operator.attrgetter("ref")


class PruneReason(enum.Enum):
    LOW_EXISTENCE = "existence below pruning threshold"
    NOT_IN_ANY_HYPOTHESIS = "absent from every kept global hypothesis"
    MERGED = "merged into another component"
    LOW_WEIGHT = "mixture weight below pruning threshold"
    CAPPED = "over the component cap"
    TRACK_LOGIC = "deleted by track logic"
    LOW_SCORE = "track score fell to the deletion threshold"


class Panel(enum.Enum):
    """A tracker-specific viewer panel, named by the event that fills it; each tracker declares the panels it
    contributes (its ``panels``), so the viewer lays them out without knowing tracker names."""

    HYPOTHESES = "hypotheses"  # GlobalHypotheses
    MARGINALS = "marginals"  # Marginals
    CARDINALITY = "cardinality"  # Cardinality
    INTENSITY = "intensity"  # IntensityWeights


class TrackLogicAction(enum.Enum):
    TENTATIVE = "tentative"
    CONFIRMED = "confirmed"
    DELETED = "deleted"


@dataclass(frozen=True, slots=True)
class FrameStarted:
    """Emitted by the pipeline before any tracker event of a keyframe."""

    tracker: str
    frame_index: int
    sample_token: str
    timestamp_us: int
    dt_s: float


@dataclass(frozen=True, slots=True)
class MeasurementsReceived:
    """The kept detections of one class that the tracker receives this frame, emitted before its other events.

    meas_indices: (M,) source indices (the ids every other event uses); xyz_m: (M, 3) box centres (global);
    score: (M,) detection scores. The viewer draws association lines to these positions.
    """

    class_name: str
    meas_indices: np.ndarray
    xyz_m: np.ndarray
    score: np.ndarray


@dataclass(frozen=True, slots=True)
class Predicted:
    """Prior of every track after the motion model (Kalman predict, existence times P_S).

    track_ids: (K,); mean: (K, 4) [x, y, vx, vy]; cov: (K, 4, 4); existence: (K,) (1 for trackers without one).
    """

    class_name: str
    track_ids: np.ndarray
    mean: np.ndarray
    cov: np.ndarray
    existence: np.ndarray


@dataclass(frozen=True, slots=True)
class Gated:
    """Ellipsoidal gating: measurement j is in track k's gate iff (z_j - H m_k)^T S_k^-1 (z_j - H m_k) < threshold.

    track_ids: (K,); meas_indices: (M,) source indices; inside: (K, M) bool; center_xy: (K, 2) predicted
    measurement H m_k; innovation_cov: (K, 2, 2) S_k; threshold: squared Mahalanobis gate (chi-square value);
    d2: (K, M) the squared Mahalanobis distances the tracker computed (over its full measurement vector, which can
    hold more than x, y), the NIS every explanation quotes. giou / giou_min: with an overlap gate as well (PMB
    family, ``[pmb] gate_giou_min``), the bird's-eye GIoU (K, M) of every pair inside the Mahalanobis gate (NaN
    elsewhere) and its minimum: inside = (d2 < threshold) & (giou >= giou_min); None without one.
    """

    class_name: str
    track_ids: np.ndarray
    meas_indices: np.ndarray
    inside: np.ndarray
    center_xy: np.ndarray
    innovation_cov: np.ndarray
    threshold: float
    d2: np.ndarray
    giou: np.ndarray | None = None
    giou_min: float | None = None


@dataclass(frozen=True, slots=True)
class PairTerms:
    """What one (detection j, track k) assignment cost is made of, in nats (``CostTerms``).

    existence: the track's predicted existence r_k; p_detect: the P_D its miss hypothesis used; existence_nats:
    log(1 - r_k P_D) - log r_k; score: the detection's score s_j; score_nats: -log s_j (all four None / 0 for a
    tracker without existences or score-based P_D); d2: squared Mahalanobis distance; distance_nats: d2 / 2;
    spread_m: the predicted measurement's spread |S_k|^(1 / 2D) (the geometric mean of its standard deviations,
    metres); spread_nats: (log|S_k| + D log 2 pi) / 2 (with distance_nats, -log N(z_j; H m_k, S_k));
    offset_nats: a constant every pair of the matrix shares, named by offset_text (GNN: detection against clutter);
    box_nats: minus the log-likelihood ratio of the detection's heading and size against the track's last box
    (``gnnpmb.box_likelihood``; 0 for a tracker that measures the centre only).
    """

    existence: float | None
    p_detect: float | None
    existence_nats: float
    score: float | None
    score_nats: float
    d2: float
    distance_nats: float
    spread_m: float
    spread_nats: float
    offset_nats: float = 0.0
    offset_text: str = ""
    box_nats: float = 0.0

    @property
    def total_nats(self) -> float:
        return (
            self.offset_nats
            + self.existence_nats
            + self.score_nats
            + self.distance_nats
            + self.spread_nats
            + self.box_nats
        )

    def existence_for(self, cheaper_by_nats: float) -> float | None:
        """The predicted existence at which this cost would be ``cheaper_by_nats`` lower, all else equal: solves
        log(1 - r P_D) - log r = existence_nats - cheaper_by_nats, i.e. r = 1 / (exp(existence_nats -
        cheaper_by_nats) + P_D); None when no existence <= 1 gets there, or the cost has no existence term."""
        if self.existence is None or self.p_detect is None:
            return None
        target = self.existence_nats - cheaper_by_nats
        if target < math.log1p(-self.p_detect):  # the cost at r = 1
            return None
        return 1.0 / (math.exp(target) + self.p_detect)


@dataclass(frozen=True, slots=True)
class CostTerms:
    """The track entries of a cost matrix taken apart: C[j, k] = offset_nats + existence_nats[k] + score_nats[j] +
    distance_nats[j, k] + spread_nats[k] + box_nats[j, k] on every gated entry (``PairTerms``).

    PMB family (``gnnpmb.pmb.cost``, García-Fernández et al. 2018, eq. 12-13): existence r (K,), miss_log_lik
    log(1 - r P_D) (K,), score s (M,), offset 0. GNN (``gnnpmb.vector.gnn``): no existence or score (None), the
    offset -log(P_D / ((1 - P_D) kappa)). Both: d2 (K, M) squared Mahalanobis distances, log_det_S (K,), dim D of
    the measurement; track_ids (K,) of the columns; box_nats (K, M): minus the heading and size log-likelihood
    ratio (``gnnpmb.box_likelihood``), None when the tracker measures the centre only. Holds the arrays the
    tracker computed anyway (no copies)."""

    existence: np.ndarray | None
    miss_log_lik: np.ndarray | None
    score: np.ndarray | None
    d2: np.ndarray
    log_det_S: np.ndarray
    dim: int
    offset_nats: float = 0.0
    offset_text: str = ""
    track_ids: np.ndarray | None = None
    box_nats: np.ndarray | None = None

    def column_of(self, track_id: int) -> int | None:
        """The track column of ``track_id``, None if the matrix has no such track (or no ids)."""
        if self.track_ids is None:
            return None
        hit = np.flatnonzero(self.track_ids == track_id)
        return int(hit[0]) if hit.size else None

    def pair(self, j: int, k: int) -> PairTerms:
        """The terms of detection row ``j`` and track column ``k``."""
        r = p_detect = score = None
        existence_nats = score_nats = 0.0
        if self.existence is not None and self.miss_log_lik is not None:
            r, miss = float(self.existence[k]), float(self.miss_log_lik[k])
            p_detect = -math.expm1(miss) / r if r > 0 else 0.0
            existence_nats = miss - math.log(r) if r > 0 else math.inf
        if self.score is not None:
            score = float(self.score[j])
            score_nats = -math.log(score) if score > 0 else math.inf
        d2, log_det_S = float(self.d2[k, j]), float(self.log_det_S[k])
        return PairTerms(
            existence=r,
            p_detect=p_detect,
            existence_nats=existence_nats,
            score=score,
            score_nats=score_nats,
            d2=d2,
            distance_nats=0.5 * d2,
            spread_m=math.exp(log_det_S / (2 * self.dim)),
            spread_nats=0.5 * (log_det_S + self.dim * math.log(2.0 * math.pi)),
            offset_nats=self.offset_nats,
            offset_text=self.offset_text,
            box_nats=0.0 if self.box_nats is None else float(self.box_nats[k, j]),
        )


@dataclass(frozen=True, slots=True)
class CostScale:
    """What the numbers of a ``CostMatrix`` are, so a decision is judged on the tracker's own scale.

    name: what a cost is ("negative log-likelihood ratio", "distance"); unit: "nats", "m", ...; close_call: a
    choice whose margin is below this is a close call (in ``unit``); optimal: the assignment minimises the total
    cost (Hungarian / Murty), so a margin is how much the best total rises without a pair; False for a greedy
    matcher, whose margin is the row's next cheapest entry minus the chosen one. For the model-based baselines
    (``gnnpmb.box``, ``gnnpmb.cbmot``) also threshold: a pair costlier than this is never matched (its entry is
    +inf; every new-track column holds it); similarity: when set (e.g. "GIoU"), cost = 1 - similarity, so a text
    may give the similarity instead (GIoU = 1 - cost). None for the others.
    """

    name: str
    unit: str
    close_call: float
    optimal: bool = True
    threshold: float | None = None
    similarity: str | None = None


NATS = CostScale("negative log-likelihood ratio", "nats", 1.0)
"""The scale of the Bayesian trackers' costs: a margin under 1 nat (a likelihood ratio under e) is a close call."""


@dataclass(frozen=True, slots=True)
class CostMatrix:
    """An assignment cost matrix with the meaning of every row and column.

    cost: (R, C) float, +inf where an assignment is impossible (outside the gate). For the PMB family rows are
    measurements and columns are [existing tracks | one new-track column per measurement]; entries are negative
    log-likelihood ratios against the track being missed (paper eq. for the PMB update).
    hypothesis: index of the global hypothesis the matrix belongs to (0 for single-hypothesis trackers).
    terms: what the track entries are made of (PMB family, GNN), None where the tracker does not say.
    scale: what the numbers are and when a choice is a close call (``CostScale``).
    """

    class_name: str
    cost: np.ndarray
    rows: tuple[AxisLabel, ...]
    cols: tuple[AxisLabel, ...]
    hypothesis: int = 0
    description: str = "negative log-likelihood ratio"
    terms: CostTerms | None = None
    scale: CostScale = NATS


@dataclass(frozen=True, slots=True)
class Assignment:
    """The chosen association: pairs of (row, col) labels from the cost matrix and the total cost.

    missed_track_ids: tracks associated with no measurement this frame. hypothesis: the ``CostMatrix`` the pairs
    index, by its ``hypothesis`` (PMBM: the prior global hypothesis the best posterior hypothesis came from).
    """

    class_name: str
    pairs: tuple[tuple[AxisLabel, AxisLabel], ...]
    total_cost: float
    missed_track_ids: tuple[int, ...]
    hypothesis: int = 0


@dataclass(frozen=True, slots=True)
class Born:
    """New tracks (Bernoullis) created from measurements.

    track_ids: (B,); meas_indices: (B,) source index of the creating measurement; mean: (B, 4);
    existence: (B,) initial existence probability.
    """

    class_name: str
    track_ids: np.ndarray
    meas_indices: np.ndarray
    mean: np.ndarray
    existence: np.ndarray


class ScoreOnHit(enum.Enum):
    """What a track-score tracker's track takes as its score when a detection updates it (``ScoreRule``)."""

    DETECTION = "the detection's score"
    FUSED = "1 - (1 - track score)(1 - detection score)"  # CBMOT's multiplication update


@dataclass(frozen=True, slots=True)
class ScoreRule:
    """How the scores of a tracker without existence probabilities move (``Posterior.score``; they are its
    tracking scores: confidences, not probabilities that the object exists).

    on_hit: the score a detection gives its track; miss_factor: multiplies a missed track's score every missed
    frame (1: kept; SimpleTrack 0.01); decay_step: subtracted from every track's score each frame before the
    update (0: none; CBMOT 0.2); delete_at: a missed track whose score falls to or below this is deleted (None:
    the score deletes nothing).
    """

    on_hit: ScoreOnHit
    miss_factor: float = 1.0
    decay_step: float = 0.0
    delete_at: float | None = None


@dataclass(frozen=True, slots=True)
class Posterior:
    """Every track after the update: mean (K, 4), cov (K, 4, 4), existence (K,) in [0, 1].

    score: (K,) the track scores of a tracker whose tracks have none of existence (the model-based baselines),
    moved by ``score_rule``; None for the others.
    """

    class_name: str
    track_ids: np.ndarray
    mean: np.ndarray
    cov: np.ndarray
    existence: np.ndarray
    score: np.ndarray | None = None
    score_rule: ScoreRule | None = None


@dataclass(frozen=True, slots=True)
class Pruned:
    """A track or component removed: why, and the existence (or weight; the track score for a tracker whose
    ``Posterior`` carries scores) it last had."""

    class_name: str
    track_id: int
    reason: PruneReason
    last_existence: float


@dataclass(frozen=True, slots=True)
class Extracted:
    """The tracker's output for the frame (state extraction)."""

    class_name: str
    estimates: tuple[TrackEstimate, ...]
    threshold: float


@dataclass(frozen=True, slots=True)
class GlobalHypotheses:
    """PMBM global hypotheses after the update: log_weights (H,) normalised (logsumexp = 0), sorted descending;
    members[h] the track ids present in hypothesis h; local[h] the single-target hypothesis key of each member;
    existence[h] each member's existence probability in hypothesis h; parents (H,): the prior global hypothesis
    each came from (its index in the previous frame's ``GlobalHypotheses`` of the class, which are the prior
    hypotheses of this frame in the same order)."""

    class_name: str
    log_weights: np.ndarray
    members: tuple[tuple[int, ...], ...]
    local: tuple[tuple[int, ...], ...]
    existence: tuple[tuple[float, ...], ...]
    parents: tuple[int, ...]


@dataclass(frozen=True, slots=True)
class Marginals:
    """Marginal association probabilities (TO-PMB, JPDA): probs (R, C), rows sum to 1 over their columns.

    method: "lbp" (loopy belief propagation), "exact" (enumeration) or similar; iterations used.
    """

    class_name: str
    probs: np.ndarray
    rows: tuple[AxisLabel, ...]
    cols: tuple[AxisLabel, ...]
    method: str
    iterations: int = 0


@dataclass(frozen=True, slots=True)
class Merged:
    """Components merged into one (moment matching): into_id absorbed from_ids with weights (coalescence shows here)."""

    class_name: str
    into_id: int
    from_ids: tuple[int, ...]
    weights: tuple[float, ...]


@dataclass(frozen=True, slots=True)
class Cardinality:
    """CPHD cardinality distribution: pmf[n] = P(n targets), n = 0..len(pmf)-1."""

    class_name: str
    pmf: np.ndarray


@dataclass(frozen=True, slots=True)
class UpdateWeights:
    """How a GM-PHD or CPHD update spread the predicted intensity over the frame's detections (Vo & Ma 2006,
    eq. 23-26), per track label (the components that carry it, summed).

    labels: (K,) track labels of the predicted components (their final track ids this frame; negative for
    provisional labels of components never extracted); meas_indices: (M,) source indices; prior: (K,) predicted
    weight; missed: (K,) weight kept by the missed-detection term; detected: (K, M) weight of the components
    updated with each detection; birth: (M,) weight of each detection's birth component. The update *used*
    detection j for label k in proportion to detected[k, j] / (missed[k] + detected[k].sum()).
    """

    class_name: str
    labels: np.ndarray
    meas_indices: np.ndarray
    prior: np.ndarray
    missed: np.ndarray
    detected: np.ndarray
    birth: np.ndarray


@dataclass(frozen=True, slots=True)
class IntensityWeights:
    """GM-PHD / CPHD intensity: component labels (K,) and weights (K,) after update and pruning."""

    class_name: str
    labels: np.ndarray
    weights: np.ndarray


@dataclass(frozen=True, slots=True)
class TrackLogic:
    """An M/N track-logic transition (GNN, JPDA): hits in the last `window` frames."""

    class_name: str
    track_id: int
    action: TrackLogicAction
    hits: int
    window: int


@dataclass(frozen=True, slots=True)
class BudgetReached:
    """A per-frame budget cut the work of this frame: ``budget`` names it (e.g. "pmbm murty_block_rows"),
    ``limit`` is its value and ``needed`` what the frame would have taken (e.g. rows of the largest block)."""

    class_name: str
    budget: str
    limit: int
    needed: int


Event = (
    FrameStarted
    | MeasurementsReceived
    | Predicted
    | Gated
    | CostMatrix
    | Assignment
    | Born
    | Posterior
    | Pruned
    | Extracted
    | GlobalHypotheses
    | Marginals
    | Merged
    | Cardinality
    | UpdateWeights
    | IntensityWeights
    | TrackLogic
    | BudgetReached
)


@runtime_checkable
class EventSink(Protocol):
    """Receives events. Trackers build costly payloads only when ``enabled`` is true."""

    enabled: bool

    def emit(self, event: Event) -> None: ...


class NullSink:
    """Discards everything; trackers skip building payloads."""

    enabled = False

    def emit(self, event: Event) -> None:
        return None


class ListSink:
    """Keeps every event in order (tests, batch analysis)."""

    enabled = True

    def __init__(self) -> None:
        self.events: list[Event] = []

    def emit(self, event: Event) -> None:
        self.events.append(event)

    def of_type(self, kind: type) -> list:
        return [e for e in self.events if isinstance(e, kind)]


class TeeSink:
    """Forwards every event to several sinks; enabled if any of them is."""

    def __init__(self, *sinks: EventSink) -> None:
        self.sinks = sinks
        self.enabled = any(s.enabled for s in sinks)

    def emit(self, event: Event) -> None:
        for s in self.sinks:
            if s.enabled:
                s.emit(event)
