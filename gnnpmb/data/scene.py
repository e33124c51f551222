"""One scene as the rest of the code sees it, independent of where it came from (real nuScenes or the demo)."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from gnnpmb.types import Boxes


@dataclass(frozen=True, slots=True)
class Pose:
    """A rigid transform: translation_m (3,) and rotation quat_wxyz (4,) (devkit order)."""

    translation_m: np.ndarray
    quat_wxyz: np.ndarray


@dataclass(frozen=True, slots=True)
class Keyframe:
    """One annotated sample (2 Hz keyframe) of a scene.

    ego_pose: ego vehicle in the global frame at the LiDAR timestamp; lidar_calib: LIDAR_TOP in the ego frame;
    lidar_path: the keyframe's ``.pcd.bin`` (float32 x 5 per point, sensor frame);
    gt: ground-truth boxes of the 7 tracking classes in the global frame (instance_id = instance token, score 1);
    gt_num_pts: (N,) LiDAR + radar points in each GT box (the devkit's eval drops boxes with 0).
    """

    index: int
    sample_token: str
    timestamp_us: int
    ego_pose: Pose
    lidar_calib: Pose
    lidar_path: Path
    gt: Boxes
    gt_num_pts: np.ndarray


@dataclass(frozen=True, slots=True)
class SceneData:
    """name (e.g. "scene-0103"), token, description, the dataset it came from and its keyframes in time order.

    synthetic: true for the built-in demo dataset (its descriptions say so too).
    """

    name: str
    token: str
    description: str
    dataroot: Path
    version: str
    synthetic: bool
    keyframes: tuple[Keyframe, ...]

    @property
    def sample_tokens(self) -> tuple[str, ...]:
        return tuple(k.sample_token for k in self.keyframes)
