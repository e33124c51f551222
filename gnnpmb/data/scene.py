"""One scene as the rest of the code sees it, independent of where it came from (real nuScenes or the demo)."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from gnnpmb.types import Boxes

if TYPE_CHECKING:
    from gnnpmb.data.demo import ClutterHotspot


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
    gt_num_pts: (N,) LiDAR + radar points in each GT box (the devkit's eval drops boxes with 0);
    gt_num_radar_pts: (N,) the radar points among them (None: not known, e.g. the demo, which has no radar).
    """

    index: int
    sample_token: str
    timestamp_us: int
    ego_pose: Pose
    lidar_calib: Pose
    lidar_path: Path
    gt: Boxes
    gt_num_pts: np.ndarray
    gt_num_radar_pts: np.ndarray | None = None


@dataclass(frozen=True, slots=True)
class SceneData:
    """name (e.g. "scene-0103"), token, description, the dataset it came from and its keyframes in time order.

    synthetic: true for the built-in demo dataset (its descriptions say so too); clutter_hotspots: where the
    scene's simulated detector places extra false positives (only the demo's scenes have them).
    """

    name: str
    token: str
    description: str
    dataroot: Path
    version: str
    synthetic: bool
    keyframes: tuple[Keyframe, ...]
    clutter_hotspots: tuple[ClutterHotspot, ...] = ()

    @property
    def ground_z_m(self) -> float:
        """Height of the ground along the scene (global z, metres): the median ego-pose height, as the nuScenes
        ego frame's origin is on the ground."""
        return float(np.median([k.ego_pose.translation_m[2] for k in self.keyframes]))

    @property
    def sample_tokens(self) -> tuple[str, ...]:
        return tuple(k.sample_token for k in self.keyframes)

    def no_ground_truth(self) -> str | None:
        """Why no failure can be found in this scene (it has no annotation of a tracked class, e.g. a dataset whose
        ``sample_annotation`` table is empty, as v1.0-test's), or None when it has ground truth."""
        if any(len(k.gt) for k in self.keyframes):
            return None
        return (
            f"{self.name} has no ground-truth boxes (no annotation of a tracked class in "
            f"{self.version}/sample_annotation.json, as in a test split): no failure can be found or scored"
        )
