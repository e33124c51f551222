"""LiDAR sweep preparation for the viewer: open3d voxel-grid downsampling and intensity colours.

open3d links against libusb; on machines without a system libusb the wheel from ``libusb-package`` is loaded
globally first (``import_open3d``), so ``import open3d`` finds the symbol.
"""

from __future__ import annotations

import ctypes
import functools
from types import ModuleType

import numpy as np

DEFAULT_MAX_POINTS = 40_000
"""Sweeps with more points than this are voxel-downsampled (a nuScenes LIDAR_TOP keyframe has ~35k)."""
DEFAULT_VOXEL_M = 0.2

_DARK = np.array([40.0, 55.0, 80.0])
_BRIGHT = np.array([250.0, 245.0, 210.0])


@functools.cache
def import_open3d() -> ModuleType:
    """``open3d``, after loading libusb from ``libusb-package`` with global symbols (imported once)."""
    import libusb_package

    ctypes.CDLL(str(libusb_package.get_library_path()), mode=ctypes.RTLD_GLOBAL)
    import open3d

    return open3d


def voxel_downsample(points: np.ndarray, voxel_m: float) -> np.ndarray:
    """(N, 4) points [x, y, z, intensity] -> (M, 4): one point per occupied voxel of edge voxel_m, the mean of
    the points in it (position and intensity; the intensity rides along in open3d's colour channel)."""
    if voxel_m <= 0:
        raise ValueError(f"voxel size must be positive, got {voxel_m}")
    o3d = import_open3d()
    cloud = o3d.geometry.PointCloud()
    cloud.points = o3d.utility.Vector3dVector(np.ascontiguousarray(points[:, :3], dtype=np.float64))
    intensity = np.ascontiguousarray(np.repeat(points[:, 3:4].astype(np.float64), 3, axis=1))
    cloud.colors = o3d.utility.Vector3dVector(intensity)
    down = cloud.voxel_down_sample(voxel_m)
    xyz = np.asarray(down.points)
    return np.concatenate([xyz, np.asarray(down.colors)[:, :1]], axis=1).astype(np.float32)


def prepare_sweep(
    points: np.ndarray, max_points: int = DEFAULT_MAX_POINTS, voxel_m: float = DEFAULT_VOXEL_M
) -> np.ndarray:
    """(N, >=4) raw sweep -> (M, 4) float32 [x, y, z, intensity]; voxel-downsampled when N > max_points."""
    pts = np.asarray(points, dtype=np.float32)[:, :4]
    if pts.shape[0] > max_points:
        return voxel_downsample(pts, voxel_m)
    return pts


def intensity_colors(intensity: np.ndarray) -> np.ndarray:
    """(N,) LiDAR intensity (nuScenes: 0..255) -> (N, 3) uint8, dark blue to pale yellow on a sqrt scale."""
    t = np.sqrt(np.clip(np.asarray(intensity, dtype=np.float32) / 255.0, 0.0, 1.0)).astype(np.float64)
    out = np.empty((t.size, 3), dtype=np.uint8)
    for c in range(3):  # channel by channel: numpy's (N, 1) x (3,) broadcast ran 6x slower for the same values
        out[:, c] = _DARK[c] + t * (_BRIGHT[c] - _DARK[c])
    return out
