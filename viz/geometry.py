"""Conversions from the devkit's conventions to Rerun's: the project's one quaternion converter and box helpers.

The devkit stores quaternions as (w, x, y, z) and box sizes as (width, length, height) with the length along the
box's x axis; Rerun wants (x, y, z, w) quaternions and full extents along the box's own x, y, z axes.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from gnnpmb.types import Boxes, TrackEstimate


def quat_wxyz_to_xyzw(quat_wxyz: np.ndarray) -> np.ndarray:
    """(..., 4) quaternions (w, x, y, z) -> (..., 4) quaternions (x, y, z, w)."""
    q = np.asarray(quat_wxyz, dtype=np.float64)
    return q[..., [1, 2, 3, 0]]


def size_wlh_to_xyz(size_wlh_m: np.ndarray) -> np.ndarray:
    """(..., 3) devkit sizes (width, length, height) -> (..., 3) extents along the box's (x, y, z)."""
    s = np.asarray(size_wlh_m, dtype=np.float64)
    return s[..., [1, 0, 2]]


@dataclass(frozen=True, slots=True)
class RerunBoxes:
    """Boxes in Rerun's layout: centers_m (N, 3), sizes_xyz_m (N, 3), quat_xyzw (N, 4)."""

    centers_m: np.ndarray
    sizes_xyz_m: np.ndarray
    quat_xyzw: np.ndarray

    def __len__(self) -> int:
        return int(self.centers_m.shape[0])


def rerun_boxes(boxes: Boxes) -> RerunBoxes:
    """The boxes of a ``Boxes`` in Rerun's layout."""
    return RerunBoxes(
        centers_m=np.asarray(boxes.translation_m, dtype=np.float64).reshape(-1, 3),
        sizes_xyz_m=size_wlh_to_xyz(boxes.size_wlh_m).reshape(-1, 3),
        quat_xyzw=quat_wxyz_to_xyzw(boxes.quat_wxyz).reshape(-1, 4),
    )


def estimate_boxes(estimates: Sequence[TrackEstimate]) -> RerunBoxes:
    """The boxes of extracted tracks in Rerun's layout (N = len(estimates))."""
    n = len(estimates)
    return RerunBoxes(
        centers_m=np.array([e.translation_m for e in estimates], dtype=np.float64).reshape(n, 3),
        sizes_xyz_m=size_wlh_to_xyz(np.array([e.size_wlh_m for e in estimates], dtype=np.float64).reshape(n, 3)),
        quat_xyzw=quat_wxyz_to_xyzw(np.array([e.quat_wxyz for e in estimates], dtype=np.float64).reshape(n, 4)),
    )


def lift_xy(xy: np.ndarray, z_m: float | np.ndarray) -> np.ndarray:
    """(..., 2) BEV points -> (..., 3) points at height z_m (a scalar or broadcastable to xy[..., 0])."""
    xy = np.asarray(xy, dtype=np.float64)
    z = np.broadcast_to(np.asarray(z_m, dtype=np.float64), xy.shape[:-1])
    return np.concatenate([xy, z[..., None]], axis=-1)


def footprint_corners_xy(boxes: RerunBoxes, scale: float = 1.0, margin_m: float = 0.0) -> np.ndarray:
    """(4 N, 2) BEV corners of N boxes drawn at ``sizes * scale + margin_m`` (rotated by their quaternions)."""
    from scipy.spatial.transform import Rotation  # here: scipy.spatial costs the main job 0.16 s and 28 MiB

    n = len(boxes)
    if n == 0:
        return np.zeros((0, 2))
    half = 0.5 * (boxes.sizes_xyz_m * scale + margin_m)
    signs = np.array([[1.0, 1.0, 0.0], [1.0, -1.0, 0.0], [-1.0, 1.0, 0.0], [-1.0, -1.0, 0.0]])
    offsets = half[:, None, :] * signs[None, :, :]  # (N, 4, 3) in each box's frame
    rotation = Rotation.from_quat(np.asarray(boxes.quat_xyzw, dtype=np.float64).reshape(n, 4))
    out = np.stack([boxes.centers_m[:, :2] + rotation.apply(offsets[:, k])[:, :2] for k in range(4)], axis=1)
    return out.reshape(-1, 2)
