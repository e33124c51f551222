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

import numpy as np

from gnnpmb.assign.greedy import greedy_rows
from gnnpmb.config import TrackerConfig
from gnnpmb.events import PruneReason, ScoreOnHit, ScoreRule
from gnnpmb.greedy import GreedyTracker, GreedyTracks
from gnnpmb.track_scores import fuse_confidence, step_down
from gnnpmb.types import IdAllocator


class CbmotTracker(GreedyTracker):
    """One class's CBMOT (module docstring): CenterPoint's greedy tracker (``greedy.GreedyTracker``, whose
    tracks and frame it shares) with detections paired in file order and refined scores."""

    def __init__(self, class_name: str, config: TrackerConfig, ids: IdAllocator):
        super().__init__(class_name, config, ids)
        self.params = config.cbmot
        self.score_rule = ScoreRule(
            ScoreOnHit.FUSED, decay_step=self.params.score_decay, delete_at=self.params.delete_score
        )
        self.description = (
            f"distance (m) from the detection's centre minus velocity x dt to the track's centre; pairs beyond "
            f"{self.max_distance_m:g} m cannot match; detections take their nearest free track in file order; "
            f"new-track column = {self.max_distance_m:g}"
        )

    def distance_threshold_m(self) -> float:
        return self.class_params.cbmot_distance_m

    def pairs(self, dist: np.ndarray) -> np.ndarray:
        """Step 1: each detection in file order takes its nearest free track (``greedy_rows``)."""
        return greedy_rows(dist)

    def hit_scores(self, tracks: GreedyTracks, pairs: np.ndarray, det_score: np.ndarray) -> np.ndarray:
        """Step 2: a matched track's score 1 - (1 - max(s - d, 0))(1 - s_det); a new track's, its detection's."""
        score = det_score.copy()
        score[pairs[:, 0]] = fuse_confidence(
            step_down(tracks.score[pairs[:, 1]], self.params.score_decay, True), det_score[pairs[:, 0]]
        )
        return score

    def missed_scores(self, tracks: GreedyTracks) -> np.ndarray:
        """Step 3: s - d."""
        return step_down(tracks.score, self.params.score_decay, False)

    def deletions(self, missed: GreedyTracks) -> list[PruneReason | None]:
        """Step 3: deleted once s - d <= ``delete_score`` (low score) or after ``max_misses`` misses."""
        low = (missed.score <= self.params.delete_score).tolist()
        old = (missed.misses >= self.params.max_misses).tolist()
        return [
            PruneReason.LOW_SCORE if is_low else PruneReason.TRACK_LOGIC if is_old else None
            for is_low, is_old in zip(low, old, strict=True)
        ]
