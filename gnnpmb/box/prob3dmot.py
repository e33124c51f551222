"""Probabilistic 3D MOT: AB3DMOT with the Mahalanobis distance, greedy matching and noise learned per class.

Chiu, Prioletti, Li & Bohg, "Probabilistic 3D Multi-Object Tracking for Autonomous Driving", 2020 (arXiv
2001.05673), sec. IV: the 10-D box Kalman filter with per-class Q, R and P_0 estimated from the training split
(``[box_noise.<class>]``; ``gnnpmb.box.noise``, ``benchmarks/learn_box_noise.py``); association by the
Mahalanobis distance sqrt(nu^T S^-1 nu) of the 7-D box residual (eq. 7), greedy closest pair first, a pair kept
iff the distance is below 11 (``[prob3dmot] distance_threshold``); AB3DMOT's life cycle (3 hits, deleted at the
2nd miss in a row). The frame is ``box.tracker.BoxTracker``'s.

Differences from its code, on purpose: the yaw residual is taken modulo pi (its single +-pi correction leaves
residuals up to 1.5 pi for headings near +-pi); a class with no detection in a frame is still predicted (its
``main.py`` skips the class's tracker for that frame, so its tracks neither age nor move); velocities are in m/s
with the real time between keyframes (its filter counts frames).
"""

from __future__ import annotations

from gnnpmb.assign.matching import Solver
from gnnpmb.box.cost import MahalanobisDistance
from gnnpmb.box.life import LifeRule
from gnnpmb.box.tracker import BoxTracker, BoxTrackerSpec, Prediction
from gnnpmb.config import TrackerConfig
from gnnpmb.types import IdAllocator


def make(class_name: str, config: TrackerConfig, ids: IdAllocator) -> BoxTracker:
    """One class's Probabilistic 3D MOT (module docstring), with the class's ``[box_noise.<class>]``."""
    p = config.prob3dmot
    spec = BoxTrackerSpec(
        cost=MahalanobisDistance(p.distance_threshold),
        solver=Solver.GREEDY,
        life=LifeRule(p.min_hits, p.max_misses, p.max_misses - 1),
        prediction=Prediction.EVERY_FRAME,
        noise=config.box_noise[class_name],
    )
    return BoxTracker(class_name, config, ids, spec)
