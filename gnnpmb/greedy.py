"""Greedy closest-pair tracker: the CenterPoint nuScenes tracking baseline.

Yin, Zhou & Krähenbühl, "Center-based 3D Object Detection and Tracking", CVPR 2021, sec. 4 ("Tracking"), and
their public ``PubTracker``: each detection j is projected back to the previous frame by its own velocity,
``c_j = p_j - v_j dt`` (p_j: BEV centre (2,), v_j: detector velocity (2,)), and compared with the centre t_k of
every live track of the same class:

    D[j, k] = || c_j - t_k ||_2     (metres; +inf when D[j, k] > d_class, the class's distance threshold)

Pairs are then taken greedily by increasing distance (closest pair first; ties by detection, then track index),
each detection and track at most once. A matched track takes the detection's box; an unmatched detection starts a
new track; a track missed ``max_age`` frames in a row is deleted, and while it coasts its centre moves by its
last velocity times dt. Every detection is output, with its own box and score, under its track's id; coasting
tracks are not output. The thresholds d_class are CenterPoint's per-class values (``config.ClassParams``:
``match_distance_m``) and ``max_age`` is ``[greedy] max_age`` (3 in CenterPoint's nuScenes script).

Not a Bayesian filter, but its frame has the shape of ``skeleton.ClassFilter`` and plugs into it like the
filters: predict = each track's coasted centre and each detection's back-projected one, gate = the distance
threshold, update = the greedy matching, extract = every detection. It has no Gaussian gate (no ``Gated`` event)
and no covariance: its ``Predicted`` and ``Posterior`` events carry the matching disc instead
(``GreedyTracker._view``).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from gnnpmb.assign.greedy import greedy_pairs
from gnnpmb.config import TrackerConfig
from gnnpmb.detection_fields import DetectionFields
from gnnpmb.events import (
    Assignment,
    AxisKind,
    Born,
    CostMatrix,
    CostScale,
    EventSink,
    Pruned,
    PruneReason,
    ScoreRule,
    axis_labels,
)
from gnnpmb.skeleton import ClassFilter, TrackView
from gnnpmb.soa import StructOfArrays
from gnnpmb.types import IdAllocator, Measurements, TrackEstimate

COST_DESCRIPTION = "distance (m) from the detection's centre minus velocity x dt; new-track column = threshold"
"""Greedy's costs are metres and its matching is greedy, not optimal: a margin is the detection's next closest
column minus its chosen one, and a close call one under 0.3 m, about the detectors' mean translation error
(mATE 0.29-0.34 m on nuScenes val, docs/demo-data.md "Simulated detectors")."""


@dataclass(frozen=True, slots=True)
class GreedyTracks(StructOfArrays):
    """K live tracks: track_id (K,), center_xy (K, 2) m, velocity_mps (K, 2), score (K,) the track's score (its
    last detection's; CBMOT's refined score), misses (K,) consecutive misses."""

    track_id: np.ndarray
    center_xy: np.ndarray
    velocity_mps: np.ndarray
    score: np.ndarray
    misses: np.ndarray

    @staticmethod
    def empty() -> GreedyTracks:
        return GreedyTracks(
            track_id=np.zeros(0, dtype=np.int64),
            center_xy=np.zeros((0, 2)),
            velocity_mps=np.zeros((0, 2)),
            score=np.zeros(0),
            misses=np.zeros(0, dtype=np.int64),
        )


def distance_matrix(
    det_xy: np.ndarray, det_velocity_mps: np.ndarray, dt_s: float, track_xy: np.ndarray, max_distance_m: float
) -> np.ndarray:
    """(M, K) distances || (p_j - v_j dt) - t_k ||, +inf above ``max_distance_m`` (module docstring)."""
    back = det_xy - det_velocity_mps * dt_s
    dist = np.linalg.norm(back[:, None, :] - track_xy[None, :, :], axis=2)
    return np.where(dist <= max_distance_m, dist, np.inf)


def emit_distance_choices(
    class_name: str,
    dist: np.ndarray,
    max_distance_m: float,
    meas: Measurements,
    track_ids: np.ndarray,
    track_of_meas: np.ndarray,
    born: tuple[np.ndarray, np.ndarray],
    missed_ids: tuple[int, ...],
    description: str,
    scale: CostScale,
    sink: EventSink,
) -> None:
    """The ``CostMatrix`` (M, K + M) of a distance-matching tracker (greedy, CBMOT: the distances, each
    detection's new-track column = ``max_distance_m``), its ``Assignment`` (``track_of_meas`` (M,): the chosen
    track's row index or -1) and the ``Born`` tracks (``born``: the detections' indices and the new ids)."""
    m, k = dist.shape
    full = np.full((m, k + m), np.inf)
    full[:, :k] = dist
    full[np.arange(m), k + np.arange(m)] = max_distance_m
    rows = axis_labels(AxisKind.MEASUREMENT, meas.source_index)
    track_cols = axis_labels(AxisKind.TRACK, track_ids)
    new_cols = axis_labels(AxisKind.NEW_TRACK, meas.source_index)
    sink.emit(CostMatrix(class_name, full, rows, track_cols + new_cols, description=description, scale=scale))
    chosen = track_of_meas.tolist()
    pairs = tuple((rows[j], track_cols[c] if c >= 0 else new_cols[j]) for j, c in enumerate(chosen))
    total = float(sum(full[j, c] if c >= 0 else full[j, k + j] for j, c in enumerate(chosen)))
    sink.emit(Assignment(class_name, pairs, total, missed_ids))
    new_j, new_ids = born
    if len(new_j):
        born_state = np.concatenate([meas.z[new_j], meas.boxes.velocity_mps[new_j]], axis=1)
        sink.emit(Born(class_name, new_ids, meas.source_index[new_j], born_state, np.ones(len(new_j))))


@dataclass(frozen=True, slots=True)
class GreedyPrior:
    """The K live tracks as the last frame left them, their centres coasted to this frame t_k + v_k dt (K, 2),
    and the (M, K) distances of this frame's back-projected detections to them (``distance_matrix``)."""

    tracks: GreedyTracks
    coasted_xy: np.ndarray
    dist: np.ndarray


class GreedyTracker(ClassFilter[GreedyPrior, tuple[GreedyTracks, Measurements]]):
    """One class's greedy closest-pair tracker (module docstring); the frame loop is ``skeleton.ClassFilter.step``.
    CBMOT (``gnnpmb.cbmot``) is this tracker with another pairing order and refined scores: the hooks
    ``pairs``, ``hit_scores``, ``missed_scores`` and ``deletions``."""

    has_existence = False  # a track lives until max_age misses
    has_gates = False  # a matching distance, no Gaussian gate
    score_rule: ScoreRule | None = None
    """How the track scores move, for a tracker whose output score is its tracks' (None: the detections')."""

    def __init__(self, class_name: str, config: TrackerConfig, ids: IdAllocator):
        super().__init__(class_name, config, ids)
        self.max_distance_m = self.distance_threshold_m()
        self.max_age = config.greedy.max_age
        self.description = COST_DESCRIPTION
        # the class's distance threshold d_class: an infinite entry is a pair beyond it (there is no gate)
        self.scale = CostScale("distance", "m", 0.3, optimal=False, threshold=self.max_distance_m)
        self.tracks = GreedyTracks.empty()

    def distance_threshold_m(self) -> float:
        """d_class: the largest distance a pair may have."""
        return self.class_params.match_distance_m

    def pairs(self, dist: np.ndarray) -> np.ndarray:
        """(P, 2) the matched (detection, track) index pairs of the (M, K) distances: closest pairs first."""
        return greedy_pairs(dist)

    def hit_scores(self, tracks: GreedyTracks, pairs: np.ndarray, det_score: np.ndarray) -> np.ndarray:
        """(M,) the scores of the tracks the M detections continue or start: each detection's own."""
        return det_score

    def missed_scores(self, tracks: GreedyTracks) -> np.ndarray:
        """(K,) the scores of the K tracks after a missed frame: kept."""
        return tracks.score

    def deletions(self, missed: GreedyTracks) -> list[PruneReason | None]:
        """Why each missed track is deleted, or None where it lives on: ``max_age`` misses."""
        return [PruneReason.TRACK_LOGIC if n >= self.max_age else None for n in missed.misses.tolist()]

    def predict(self, meas: Measurements, dt_s: float) -> GreedyPrior:
        """The distances D[j, k] = || (p_j - v_j dt) - t_k || (+inf above the threshold) and the coasted
        centres t_k + v_k dt of the K tracks (module docstring)."""
        t = self.tracks
        dist = distance_matrix(meas.z, meas.boxes.velocity_mps, dt_s, t.center_xy, self.max_distance_m)
        return GreedyPrior(t, t.center_xy + t.velocity_mps * dt_s, dist)

    def prior_view(self, prior: GreedyPrior) -> tuple[TrackView, None]:
        """The K tracks at their last centres with their matching discs; no Gaussian gate."""
        return self._view(prior.tracks), None

    def update(self, prior: GreedyPrior, meas: Measurements, sink: EventSink) -> tuple[GreedyTracks, Measurements]:
        """The pairs (``pairs``): a matched track takes its detection's centre and velocity, an unmatched
        detection starts a track, an unmatched track coasts and is deleted as ``deletions`` says. Returns the new
        tracks, whose first M are this frame's M detections in order, and those detections.
        Events: ``CostMatrix``, ``Assignment``, ``Born``, ``Pruned``."""
        m, k = prior.dist.shape
        t = prior.tracks
        pairs = self.pairs(prior.dist)
        track_of_meas = np.full(m, -1, dtype=np.int64)
        track_of_meas[pairs[:, 0]] = pairs[:, 1]
        matched = np.zeros(k, dtype=bool)
        matched[pairs[:, 1]] = True
        new_j = np.flatnonzero(track_of_meas < 0)
        new_ids = np.array([self.ids.allocate() for _ in new_j], dtype=np.int64)
        ids_of_meas = np.empty(m, dtype=np.int64)
        ids_of_meas[pairs[:, 0]] = t.track_id[pairs[:, 1]]
        ids_of_meas[new_j] = new_ids
        score = self.hit_scores(t, pairs, np.asarray(meas.boxes.score, dtype=float))
        velocity = meas.boxes.velocity_mps
        detected = GreedyTracks(ids_of_meas, meas.z.copy(), velocity.copy(), score, np.zeros(m, dtype=np.int64))
        coasted = GreedyTracks(t.track_id, prior.coasted_xy, t.velocity_mps, self.missed_scores(t), t.misses + 1)
        missed = coasted.subset(~matched)
        reasons = self.deletions(missed)
        self.tracks = GreedyTracks.concatenate(
            [detected, missed.subset(np.array([r is None for r in reasons], dtype=bool))]
        )
        if sink.enabled:
            self._emit(prior, meas, track_of_meas, (new_j, new_ids), missed, reasons, sink)
        return self.tracks, meas

    def extract(
        self, posterior: tuple[GreedyTracks, Measurements], sink: EventSink
    ) -> tuple[list[TrackEstimate], float]:
        """Every detection with its own box, under its track's id and with its track's score (threshold 1: none
        is withheld)."""
        tracks, meas = posterior
        m = len(meas)
        det = DetectionFields.from_measurements(meas, np.arange(m))
        state = np.concatenate([tracks.center_xy[:m], tracks.velocity_mps[:m]], axis=1)
        return det.to_estimates(self.class_name, tracks.track_id[:m], state, tracks.score[:m], np.ones(m)), 1.0

    def posterior_view(self, posterior: tuple[GreedyTracks, Measurements]) -> TrackView:
        return self._view(posterior[0])

    def _view(self, t: GreedyTracks) -> TrackView:
        """K tracks as events show them: state [x, y, vx, vy] (K, 4), existence 1, and covariance (K, 4, 4)
        diag(d^2, d^2, 1, 1): the greedy tracker has no covariance, so events carry the matching disc of radius
        d = the class threshold (one standard deviation drawn = the disc) and unit velocity; with a
        ``score_rule``, the track scores."""
        d2 = self.max_distance_m**2
        cov = np.broadcast_to(np.diag([d2, d2, 1.0, 1.0]), (len(t), 4, 4)).copy()
        mean = np.concatenate([t.center_xy, t.velocity_mps], axis=1)
        if self.score_rule is None:
            return TrackView(t.track_id, mean, cov, np.ones(len(t)))
        return TrackView(t.track_id, mean, cov, np.ones(len(t)), t.score.copy(), self.score_rule)

    def _emit(
        self,
        prior: GreedyPrior,
        meas: Measurements,
        track_of_meas: np.ndarray,
        born: tuple[np.ndarray, np.ndarray],
        missed: GreedyTracks,
        reasons: list[PruneReason | None],
        sink: EventSink,
    ) -> None:
        """``CostMatrix`` (distances, new-track column = the threshold), ``Assignment``, ``Born``, ``Pruned`` (the
        value: the track's score with a ``score_rule``, else 1)."""
        missed_ids = missed.track_id.tolist()
        emit_distance_choices(
            self.class_name,
            prior.dist,
            self.max_distance_m,
            meas,
            prior.tracks.track_id,
            track_of_meas,
            born,
            tuple(missed_ids),
            self.description,
            self.scale,
            sink,
        )
        values = missed.score.tolist() if self.score_rule is not None else [1.0] * len(missed_ids)
        for track_id, reason, value in zip(missed_ids, reasons, values, strict=True):
            if reason is not None:
                sink.emit(Pruned(self.class_name, int(track_id), reason, float(value)))
