"""Geometry of 3D boxes in the nuScenes convention, vectorised over many boxes.

A box is a centre (x, y, z), a size (w, l, h) and a rotation quaternion (w, x, y, z) (``gnnpmb.types.Boxes``).
The box's length runs along its heading (the local x axis), its width along the local y axis, like the
devkit's ``Box.corners``. Detectors and annotations rotate boxes about the vertical axis only, so the geometry
here uses the yaw angle and ignores pitch and roll.

How much two boxes overlap (IoU, GIoU, the NMS's 3D IoU) is ``gnnpmb.box.overlap``.
"""

from __future__ import annotations

import numpy as np


def yaw_from_quat_wxyz(quat_wxyz: np.ndarray) -> np.ndarray:
    """Heading angle (rad, counter-clockwise from the global x axis) of (..., 4) quaternions (w, x, y, z).

    yaw = atan2(2 (w z + x y), 1 - 2 (y^2 + z^2)); a scaled (unnormalised) quaternion gives the same angle.
    """
    q = np.asarray(quat_wxyz, dtype=float)
    w, x, y, z = q[..., 0], q[..., 1], q[..., 2], q[..., 3]
    norm2 = w * w + x * x + y * y + z * z
    return np.arctan2(2.0 * (w * z + x * y), norm2 - 2.0 * (y * y + z * z))


def quat_wxyz_from_yaw(yaw_rad: np.ndarray) -> np.ndarray:
    """(..., 4) unit quaternions (w, x, y, z) of rotations by ``yaw_rad`` about the vertical axis."""
    half = 0.5 * np.asarray(yaw_rad, dtype=float)
    zeros = np.zeros_like(half)
    return np.stack([np.cos(half), zeros, zeros, np.sin(half)], axis=-1)


def bev_corners(xy: np.ndarray, size_wl_m: np.ndarray, yaw_rad: np.ndarray) -> np.ndarray:
    """(N, 4, 2) ground-plane corners, counter-clockwise, of N boxes: centres (N, 2), sizes (w, l) (N, 2)."""
    xy = np.asarray(xy, dtype=float)
    size = np.asarray(size_wl_m, dtype=float)
    yaw = np.asarray(yaw_rad, dtype=float)
    half_w = 0.5 * size[:, 0]
    half_l = 0.5 * size[:, 1]
    # Local corners (along heading, across heading), counter-clockwise: front-left, rear-left, rear-right, ...
    along = np.stack([half_l, -half_l, -half_l, half_l], axis=1)
    across = np.stack([half_w, half_w, -half_w, -half_w], axis=1)
    c, s = np.cos(yaw)[:, None], np.sin(yaw)[:, None]
    x = xy[:, 0:1] + c * along - s * across
    y = xy[:, 1:2] + s * along + c * across
    return np.stack([x, y], axis=-1)


def box_corners_3d(translation_m: np.ndarray, size_wlh_m: np.ndarray, quat_wxyz: np.ndarray) -> np.ndarray:
    """(N, 8, 3) corners of N boxes: 4 bottom corners (counter-clockwise from front-left), then 4 top ones."""
    t = np.asarray(translation_m, dtype=float)
    size = np.asarray(size_wlh_m, dtype=float)
    bev = bev_corners(t[:, :2], size[:, :2], yaw_from_quat_wxyz(quat_wxyz))
    z_bottom = np.repeat((t[:, 2] - 0.5 * size[:, 2])[:, None, None], 4, axis=1)
    z_top = z_bottom + size[:, 2][:, None, None]
    return np.concatenate([np.concatenate([bev, z_bottom], -1), np.concatenate([bev, z_top], -1)], axis=1)
