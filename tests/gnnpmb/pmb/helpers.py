"""Hand-made measurements and the paper's car model for tracker tests."""

from __future__ import annotations

import numpy as np

from gnnpmb.config import paper_config
from gnnpmb.types import Measurements
from tests.gnnpmb.box.helpers import boxes

CFG = paper_config()  # hand computations use the paper's values (sec. V-B)
P = CFG.models
CAR = CFG.for_class("car")
R = np.diag([CAR.r_x, CAR.r_y])
Q = np.diag([CAR.q_x, CAR.q_y, CAR.q_x, CAR.q_y])


def gauss2(nu: np.ndarray, S: np.ndarray) -> float:
    """The 2-D Gaussian density N(nu; 0, S) of an innovation ``nu`` (2,) with covariance ``S`` (2, 2)."""
    return float(np.exp(-0.5 * nu @ np.linalg.solve(S, nu)) / (2 * np.pi * np.sqrt(np.linalg.det(S))))


def make_measurements(
    xy: list[tuple[float, float]],
    score: float | list[float] = 0.9,
    cls: str = "car",
    velocity: list[tuple[float, float]] | None = None,
) -> Measurements:
    """M car boxes at the given BEV positions (z = 1 m, 2 x 4.5 x 1.6 m, identity rotation; ``boxes``)."""
    return boxes(xy, score, velocity, cls=cls)
