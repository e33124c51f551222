"""AB3DMOT: 3D IoU, Hungarian assignment, the 10-D box Kalman filter, birth and death by hits and misses.

Weng, Wang, Held & Kitani, "3D Multi-Object Tracking: A Baseline and New Evaluation Metrics", IROS 2020, as it
runs on nuScenes in the configuration Probabilistic 3D MOT published for it (Chiu et al. 2020, ``config/
AB3DMOT.yaml``): association by 3D IoU with the Hungarian algorithm over every pair, a pair kept iff IoU >= 0.1
(``[ab3dmot] iou_threshold``); the Kalman filter predicts every frame with AB3DMOT's hand-set covariances
(``NOISE``); a track is output from its 3rd hit on (every track in the first 3 frames) and while missed at most
once, at its prediction, with its last detection's score; it is deleted at its 2nd miss in a row
(``[ab3dmot] min_hits``, ``max_misses``). The frame is ``box.tracker.BoxTracker``'s.
"""

from __future__ import annotations

from gnnpmb.assign.matching import Solver
from gnnpmb.box.cost import OneMinusIou3d
from gnnpmb.box.life import LifeRule
from gnnpmb.box.tracker import BoxTracker, BoxTrackerSpec, Prediction
from gnnpmb.config import BoxNoise, TrackerConfig
from gnnpmb.types import IdAllocator

NOISE = BoxNoise.uniform(r=1.0, q=1.0, q_size=1.0, q_velocity=0.01 / 0.5**2, p_velocity=1e4 / 0.5**2, p_scale=10.0)
"""AB3DMOT's covariances (its ``kalman_filter.py``; Probabilistic 3D MOT's ``BaselineCovariance``): R = I,
Q = I except 0.01 on the velocity, P_0 = 10 I except 10^4 on the velocity. Its velocity is per 0.5 s frame,
hence the 0.5^2 in these (m/s)^2 values."""


def make(class_name: str, config: TrackerConfig, ids: IdAllocator) -> BoxTracker:
    """One class's AB3DMOT (module docstring)."""
    p = config.ab3dmot
    spec = BoxTrackerSpec(
        cost=OneMinusIou3d(p.iou_threshold),
        solver=Solver.HUNGARIAN,
        life=LifeRule(p.min_hits, p.max_misses, p.max_misses - 1),
        prediction=Prediction.EVERY_FRAME,
        noise=NOISE,
    )
    return BoxTracker(class_name, config, ids, spec)
