"""The heading and size measurement model (``gnnpmb.box_likelihood``) and its place in the PMB costs."""

import math

import numpy as np

from gnnpmb.box_likelihood import BoxShapeModel, box_log_ratio, heading_log_ratio, size_log_ratio
from gnnpmb.data.boxes3d import quat_wxyz_from_yaw

MODEL = BoxShapeModel(heading_std_rad=0.1, size_log_std=0.1, size_log_spread=0.2, outlier_prob=0.1)


def test_heading_ratio_by_hand():
    """dpsi = 0.1: log[(1 - eps) N(0.1; 0, 2 sigma^2) pi + eps]."""
    got = heading_log_ratio(np.array([0.3]), np.array([0.4]), MODEL)[0, 0]
    var = 2 * 0.1**2
    density = math.exp(-0.5 * 0.1**2 / var) / math.sqrt(2 * math.pi * var)
    assert math.isclose(got, math.log(0.9 * density * math.pi + 0.1), rel_tol=0, abs_tol=1e-12)


def test_heading_is_modulo_a_half_turn_and_bounded_below():
    """A box turned by pi is the same box; a perpendicular one costs at most -log eps (an outlier)."""
    same = heading_log_ratio(np.array([0.2]), np.array([0.2, 0.2 + math.pi, 0.2 - math.pi]), MODEL)
    assert np.allclose(same, same[0, 0], rtol=0, atol=1e-12) and same[0, 0] > 0
    perpendicular = heading_log_ratio(np.array([0.0]), np.array([math.pi / 2]), MODEL)[0, 0]
    assert math.log(0.1) <= perpendicular < math.log(0.1) + 1e-9


def test_size_ratio_by_hand():
    """ds = (log 1.1, 0): log[(1 - eps) N2(ds; 2 s^2) + eps g] - log g, g = N2(ds; 2 s^2 + c^2)."""
    got = size_log_ratio(np.array([[2.0, 4.0]]), np.array([[2.2, 4.0]]), MODEL)[0, 0]
    d2 = math.log(1.1) ** 2

    def n2(var: float) -> float:
        return math.exp(-0.5 * d2 / var) / (2 * math.pi * var)

    same, other = n2(2 * 0.01), n2(2 * 0.01 + 0.04)
    assert math.isclose(got, math.log(0.9 * same + 0.1 * other) - math.log(other), rel_tol=0, abs_tol=1e-12)


def test_switched_off_model_gives_no_ratio_and_shapes_are_tracks_by_detections():
    off = BoxShapeModel(0.0, 0.0, 0.2, 0.1)
    q = quat_wxyz_from_yaw(np.array([0.0, 1.0, 2.0]))
    size = np.tile([2.0, 4.5, 1.6], (3, 1))
    assert box_log_ratio(q[:2], size[:2], q, size, off) is None
    assert box_log_ratio(q[:2], size[:2], q, size, MODEL).shape == (2, 3)
