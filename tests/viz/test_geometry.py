from __future__ import annotations

import numpy as np

from gnnpmb.types import TrackEstimate
from tests.viz.conftest import make_boxes
from viz.geometry import estimate_boxes, lift_xy, quat_wxyz_to_xyzw, rerun_boxes, size_wlh_to_xyz


def test_quaternion_order() -> None:
    np.testing.assert_array_equal(quat_wxyz_to_xyzw(np.array([1.0, 2.0, 3.0, 4.0])), [2.0, 3.0, 4.0, 1.0])
    q = np.arange(24.0).reshape(2, 3, 4)
    np.testing.assert_array_equal(quat_wxyz_to_xyzw(q)[..., 3], q[..., 0])


def test_devkit_wlh_becomes_extent_along_box_x_y_z() -> None:
    np.testing.assert_array_equal(size_wlh_to_xyz(np.array([[2.0, 4.5, 1.6]])), [[4.5, 2.0, 1.6]])


def test_boxes_and_estimates_agree() -> None:
    boxes = make_boxes([(1.0, 2.0), (3.0, 4.0)], ["car", "bus"], [0.5, 0.6], ["", ""])
    rb = rerun_boxes(boxes)
    estimates = [
        TrackEstimate(i, "car", tuple(boxes.translation_m[i]), tuple(boxes.size_wlh_m[i]), tuple(boxes.quat_wxyz[i]),
                      (0.0, 0.0), 0.5, 1.0)
        for i in range(2)
    ]  # fmt: skip
    eb = estimate_boxes(estimates)
    for a, b in [(rb.centers_m, eb.centers_m), (rb.sizes_xyz_m, eb.sizes_xyz_m), (rb.quat_xyzw, eb.quat_xyzw)]:
        np.testing.assert_array_equal(a, b)
    assert len(estimate_boxes([])) == 0 and estimate_boxes([]).quat_xyzw.shape == (0, 4)


def test_lift_xy_broadcasts_heights() -> None:
    out = lift_xy(np.zeros((2, 5, 2)), np.array([[1.0], [2.0]]))
    assert out.shape == (2, 5, 3)
    np.testing.assert_array_equal(out[:, :, 2], [[1.0] * 5, [2.0] * 5])
