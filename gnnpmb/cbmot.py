"""CBMOT: CenterPoint's greedy tracker with confidence-based score refinement.

Benbarka, Schröder & Zell, "Score refinement for confidence-based 3D multi-object tracking", IROS 2021, its
LiDAR-only configuration (``Results.sh``: ``--score_decay 0.2 --score_update multiplication``; ``tracker.py``):

1. matching as CenterPoint's (``gnnpmb.greedy``): each detection's centre projected back by its own velocity,
   c_j = p_j - v_j dt, against every live track's centre, D[j, k] = || c_j - t_k || (m), a pair allowed iff
   D[j, k] <= d_class (``[classes.<class>] cbmot_distance_m``, the distances CBMOT's code ships); detections
   take their nearest free track one after another in the order of the detection file (``assign.greedy.
   greedy_rows``; detectors, and the simulated ones, list boxes by decreasing score);
2. every frame each track's score s drops by d = 0.2 (``[cbmot] score_decay``); a matched track becomes its
   detection (box, velocity) with score 1 - (1 - max(s - d, 0))(1 - s_det) (eq. 6, ``track_scores``);
3. an unmatched detection starts a track with its own score; an unmatched track keeps s - d, moves by its
   velocity times dt and is not output; it is deleted once s - d <= 0 (``[cbmot] delete_score``) or after 40
   misses in a row (``[cbmot] max_misses``), so a track seen at score 0.9 survives 4 missed frames;
4. output: every detection, with its own box, under its track's id and with its refined score.

Not reproduced: CBMOT clears every track when a frame has no detection of any class (this tracker runs per
class), and its camera fusion (LiDAR detections only here).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from gnnpmb.assign.greedy import greedy_rows
from gnnpmb.config import TrackerConfig
from gnnpmb.detection_fields import DetectionFields
from gnnpmb.events import (
    CostScale,
    EventSink,
    Pruned,
    PruneReason,
    ScoreOnHit,
    ScoreRule,
)
from gnnpmb.greedy import distance_matrix, emit_distance_choices
from gnnpmb.skeleton import ClassFilter, TrackView
from gnnpmb.soa import StructOfArrays
from gnnpmb.track_scores import fuse_confidence, step_down
from gnnpmb.types import IdAllocator, Measurements, TrackEstimate


@dataclass(frozen=True, slots=True)
class CbmotTracks(StructOfArrays):
    """K live tracks: track_id (K,), center_xy (K, 2) m, velocity_mps (K, 2), score (K,) the refined score,
    misses (K,) consecutive missed frames."""

    track_id: np.ndarray
    center_xy: np.ndarray
    velocity_mps: np.ndarray
    score: np.ndarray
    misses: np.ndarray

    @staticmethod
    def empty() -> CbmotTracks:
        return CbmotTracks(
            track_id=np.zeros(0, dtype=np.int64),
            center_xy=np.zeros((0, 2)),
            velocity_mps=np.zeros((0, 2)),
            score=np.zeros(0),
            misses=np.zeros(0, dtype=np.int64),
        )


@dataclass(frozen=True, slots=True)
class CbmotPrior:
    """The K live tracks, their centres coasted by their velocity (K, 2), and the (M, K) distances of this
    frame's back-projected detections to their last centres (``greedy.distance_matrix``, +inf past d_class)."""

    tracks: CbmotTracks
    coasted_xy: np.ndarray
    dist: np.ndarray


class CbmotTracker(ClassFilter[CbmotPrior, tuple[CbmotTracks, Measurements]]):
    """One class's CBMOT (module docstring); the frame loop is ``skeleton.ClassFilter.step``."""

    has_existence = False  # a refined score, not an existence probability
    has_gates = False  # a matching distance, no Gaussian gate

    def __init__(self, class_name: str, config: TrackerConfig, ids: IdAllocator):
        super().__init__(class_name, config, ids)
        self.params = config.cbmot
        self.max_distance_m = self.class_params.cbmot_distance_m
        self.scale = CostScale("distance", "m", 0.3, optimal=False, threshold=self.max_distance_m)
        self.score_rule = ScoreRule(
            ScoreOnHit.FUSED, decay_step=self.params.score_decay, delete_at=self.params.delete_score
        )
        self.tracks = CbmotTracks.empty()

    def predict(self, meas: Measurements, dt_s: float) -> CbmotPrior:
        t = self.tracks
        dist = distance_matrix(meas.z, meas.boxes.velocity_mps, dt_s, t.center_xy, self.max_distance_m)
        return CbmotPrior(t, t.center_xy + t.velocity_mps * dt_s, dist)

    def prior_view(self, prior: CbmotPrior) -> tuple[TrackView, None]:
        return self._view(prior.tracks), None

    def update(self, prior: CbmotPrior, meas: Measurements, sink: EventSink) -> tuple[CbmotTracks, Measurements]:
        """Steps 1-3 of the module docstring; the new tracks' first M are this frame's M detections in order.
        Events: ``CostMatrix``, ``Assignment``, ``Born``, ``Pruned``."""
        m, k = prior.dist.shape
        t = prior.tracks
        pairs = greedy_rows(prior.dist)
        track_of_meas = np.full(m, -1, dtype=np.int64)
        track_of_meas[pairs[:, 0]] = pairs[:, 1]
        matched = np.zeros(k, dtype=bool)
        matched[pairs[:, 1]] = True
        new_j = np.flatnonzero(track_of_meas < 0)
        new_ids = np.array([self.ids.allocate() for _ in new_j], dtype=np.int64)
        ids_of_meas = np.empty(m, dtype=np.int64)
        ids_of_meas[pairs[:, 0]] = t.track_id[pairs[:, 1]]
        ids_of_meas[new_j] = new_ids
        det_score = np.asarray(meas.boxes.score, dtype=float)
        score = det_score.copy()
        score[pairs[:, 0]] = fuse_confidence(
            step_down(t.score[pairs[:, 1]], self.params.score_decay, True), det_score[pairs[:, 0]]
        )
        detected = CbmotTracks(
            ids_of_meas, meas.z.copy(), meas.boxes.velocity_mps.copy(), score, np.zeros(m, dtype=np.int64)
        )
        missed = CbmotTracks(
            t.track_id,
            prior.coasted_xy,
            t.velocity_mps,
            step_down(t.score, self.params.score_decay, False),
            t.misses + 1,
        ).subset(~matched)
        low = missed.score <= self.params.delete_score
        old = missed.misses >= self.params.max_misses
        self.tracks = CbmotTracks.concatenate([detected, missed.subset(~(low | old))])
        if sink.enabled:
            self._emit(prior, meas, track_of_meas, new_j, new_ids, missed.track_id, missed.score, low, old, sink)
        return self.tracks, meas

    def extract(
        self, posterior: tuple[CbmotTracks, Measurements], sink: EventSink
    ) -> tuple[list[TrackEstimate], float]:
        """Every detection with its own box, under its track's id, scored by its track's refined score."""
        tracks, meas = posterior
        m = len(meas)
        det = DetectionFields.from_measurements(meas, np.arange(m))
        state = np.concatenate([tracks.center_xy[:m], tracks.velocity_mps[:m]], axis=1)
        return det.to_estimates(self.class_name, tracks.track_id[:m], state, tracks.score[:m], np.ones(m)), 1.0

    def posterior_view(self, posterior: tuple[CbmotTracks, Measurements]) -> TrackView:
        return self._view(posterior[0])

    def _view(self, t: CbmotTracks) -> TrackView:
        """K tracks as events show them, with the matching disc as covariance (as ``greedy.GreedyTracker``)
        and their refined scores."""
        d2 = self.max_distance_m**2
        cov = np.broadcast_to(np.diag([d2, d2, 1.0, 1.0]), (len(t), 4, 4)).copy()
        mean = np.concatenate([t.center_xy, t.velocity_mps], axis=1)
        return TrackView(t.track_id, mean, cov, np.ones(len(t)), t.score.copy(), self.score_rule)

    def _emit(
        self,
        prior: CbmotPrior,
        meas: Measurements,
        track_of_meas: np.ndarray,
        new_j: np.ndarray,
        new_ids: np.ndarray,
        missed_ids: np.ndarray,
        missed_scores: np.ndarray,
        low: np.ndarray,
        old: np.ndarray,
        sink: EventSink,
    ) -> None:
        """``CostMatrix`` (distances, new-track column = d_class), ``Assignment``, ``Born``, ``Pruned``."""
        description = (
            f"distance (m) from the detection's centre minus velocity x dt to the track's centre; pairs beyond "
            f"{self.max_distance_m:g} m cannot match; detections take their nearest free track in file order; "
            f"new-track column = {self.max_distance_m:g}"
        )
        emit_distance_choices(
            self.class_name,
            prior.dist,
            self.max_distance_m,
            meas,
            prior.tracks.track_id,
            track_of_meas,
            (new_j, new_ids),
            tuple(int(i) for i in missed_ids),
            description,
            self.scale,
            sink,
        )
        for i in np.flatnonzero(low | old).tolist():
            reason = PruneReason.LOW_SCORE if low[i] else PruneReason.TRACK_LOGIC
            sink.emit(Pruned(self.class_name, int(missed_ids[i]), reason, float(missed_scores[i])))
