"""SimpleTrack and ImmortalTracker: 3D GIoU, Hungarian assignment, NMS, score decay; tracks that never die.

SimpleTrack (Pang, Li & Wang, "SimpleTrack: Understanding and Rethinking 3D Multi-object Tracking", 2021), its
nuScenes 2 Hz configurations (``configs/nu_configs/velo_giou.yaml`` and ``giou.yaml``): detections are
NMS-filtered (3D IoU 0.1, the pipeline's ``[preprocess] nms_iou_3d``); association by 1 - GIoU_3D with the
Hungarian algorithm over every pair, a pair kept iff GIoU >= -0.5 (``[simpletrack] giou_threshold``); a track
is output at once (min_hits 0) and while missed at most once, at its prediction, its score times 0.01 per missed
frame; it is deleted at its 2nd miss in a row. The motion model (``[simpletrack] detector_velocity``): by
default its "velo" model (a track is its last detection box moved by that detection's velocity; detections are
stepped back by their own velocity to the previous frame to meet the tracks' boxes; chosen on mini_train, see
``config.SimpleTrackParams``), or its 10-D box Kalman filter with hand-set covariances (``NOISE``), predicted
once from the last update over the time since. The two-stage association (``[simpletrack] two_stage``) is off in
both configurations, as in its code.

ImmortalTracker (Wang, Chen, Pang, Wang & Zhang, "Immortal Tracker: Tracklet Never Dies", 2021, its
``configs/nu_configs/immortal.yaml`` and nuScenes result creation): the same tracker whose tracks are never
deleted: an unseen track keeps being predicted and can take a detection again after any gap; it is output while
missed at most once (``[immortal] output_max_misses``).

The frame is ``box.tracker.BoxTracker``'s.
"""

from __future__ import annotations

from gnnpmb.assign.matching import SecondStage, Solver
from gnnpmb.box.cost import OneMinusGiou3d
from gnnpmb.box.life import LifeRule
from gnnpmb.box.tracker import BoxTracker, BoxTrackerSpec, Prediction
from gnnpmb.config import BoxNoise, TrackerConfig
from gnnpmb.types import IdAllocator

NOISE = BoxNoise.uniform(r=1.0, q=1.0, q_size=1.0, q_velocity=1.0, p_velocity=1e4, p_scale=10.0)
"""SimpleTrack's covariances (its ``kalman_filter.py``, covariance "default"): R = I, Q = I, P_0 = 10 I except
10^4 on the velocity (its filter steps by the time lag in seconds, so these are (m/s)^2 as they stand)."""


def _spec(config: TrackerConfig, life: LifeRule) -> BoxTrackerSpec:
    p = config.simpletrack
    second = SecondStage(p.second_stage_score, 1.0 - p.second_stage_giou) if p.two_stage == 1 else None
    return BoxTrackerSpec(
        cost=OneMinusGiou3d(p.giou_threshold),
        solver=Solver.HUNGARIAN,
        life=life,
        prediction=Prediction.DETECTOR_VELOCITY if p.detector_velocity == 1 else Prediction.FROM_LAST_UPDATE,
        noise=NOISE,
        miss_score_factor=p.miss_score_factor,
        first_stage_score=p.first_stage_score,
        second=second,
    )


def make_simpletrack(class_name: str, config: TrackerConfig, ids: IdAllocator) -> BoxTracker:
    """One class's SimpleTrack (module docstring)."""
    p = config.simpletrack
    return BoxTracker(class_name, config, ids, _spec(config, LifeRule(p.min_hits, p.max_misses, p.max_misses - 1)))


def make_immortal(class_name: str, config: TrackerConfig, ids: IdAllocator) -> BoxTracker:
    """One class's ImmortalTracker: SimpleTrack (``[simpletrack]``) whose tracks are never deleted."""
    p = config.immortal
    return BoxTracker(class_name, config, ids, _spec(config, LifeRule(p.min_hits, None, p.output_max_misses)))
