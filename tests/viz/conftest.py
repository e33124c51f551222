"""Fixtures for the viewer tests: a strict-mode recording saved to a temp file, and a tiny hand-made scene."""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path

import numpy as np
import pytest
import rerun as rr

from gnnpmb.data.scene import Keyframe, Pose, SceneData
from gnnpmb.types import Boxes, FrameDetections

N_FRAMES = 3
POINTS_PER_SWEEP = 500


@pytest.fixture
def strict() -> Iterator[None]:
    """Rerun strict mode (bad arguments raise) for one test, restored afterwards."""
    before = rr.strict_mode()
    rr.set_strict_mode(True)
    yield
    rr.set_strict_mode(before)


@pytest.fixture
def saved_stream(tmp_path: Path, strict: None) -> tuple[rr.RecordingStream, Path]:
    """A fresh recording stream saving to ``tmp_path/test.rrd``; call ``stream.disconnect()`` before reading."""
    path = tmp_path / "test.rrd"
    stream = rr.RecordingStream("gnnpmb-viz-test")
    stream.set_log_time_enabled(False)
    stream.save(path)
    return stream, path


def make_boxes(xy: list[tuple[float, float]], classes: list[str], scores: list[float], ids: list[str]) -> Boxes:
    n = len(xy)
    translation = np.array([[x, y, 1.0] for x, y in xy], dtype=np.float64).reshape(n, 3)
    yaw = np.linspace(0.0, 1.0, n)
    return Boxes(
        translation_m=translation,
        size_wlh_m=np.tile([2.0, 4.5, 1.6], (n, 1)),
        quat_wxyz=np.stack([np.cos(yaw / 2), np.zeros(n), np.zeros(n), np.sin(yaw / 2)], axis=1),
        velocity_mps=np.zeros((n, 2)),
        score=np.array(scores, dtype=np.float64),
        class_name=np.array(classes, dtype=object),
        instance_id=np.array(ids, dtype=object),
    )


@pytest.fixture
def tiny_scene(tmp_path: Path) -> tuple[SceneData, list[FrameDetections]]:
    """3 keyframes 0.5 s apart; the ego drives along x. GT: one car and one pedestrian (none in frame 2).
    Detections per frame: a kept car, a car dropped by NMS and a pedestrian below the score threshold.
    LiDAR sweeps of POINTS_PER_SWEEP points are written as ``.pcd.bin`` (float32 x 5)."""
    rng = np.random.default_rng(0)
    keyframes = []
    frames = []
    for i in range(N_FRAMES):
        sweep = np.concatenate(
            [rng.normal(0.0, 10.0, (POINTS_PER_SWEEP, 3)), rng.uniform(0, 255, (POINTS_PER_SWEEP, 2))], axis=1
        )
        lidar_path = tmp_path / f"sweep_{i}.pcd.bin"
        sweep.astype(np.float32).tofile(lidar_path)
        if i < 2:
            gt = make_boxes([(10.0 + i, 2.0), (5.0, -3.0)], ["car", "pedestrian"], [1.0, 1.0], ["a1b2c3d4e5f6", "p9"])
        else:
            gt = Boxes.empty()
        xy = [(10.2 + i, 2.1), (10.3 + i, 2.0), (5.1, -3.0)]
        dets = make_boxes(xy, ["car", "car", "pedestrian"], [0.9, 0.5, 0.05], ["", "", ""])
        frames.append(
            FrameDetections(
                boxes=dets,
                kept=np.array([True, False, False]),
                below_threshold=np.array([False, False, True]),
                suppressed_by_nms=np.array([False, True, False]),
            )
        )
        keyframes.append(
            Keyframe(
                index=i,
                sample_token=f"sample{i}",
                timestamp_us=1_533_151_603_547_590 + 500_000 * i,
                ego_pose=Pose(np.array([2.0 * i, 0.0, 0.0]), np.array([1.0, 0.0, 0.0, 0.0])),
                lidar_calib=Pose(np.array([0.94, 0.0, 1.84]), np.array([0.7071068, 0.0, 0.0, -0.7071068])),
                lidar_path=lidar_path,
                gt=gt,
                gt_num_pts=np.full(len(gt), 10),
            )
        )
    scene = SceneData(
        name="scene-test",
        token="tok",
        description="hand-made test scene",
        dataroot=tmp_path,
        version="v1.0-mini",
        synthetic=True,
        keyframes=tuple(keyframes),
    )
    return scene, frames


def read_sweep(keyframe: Keyframe) -> np.ndarray:
    """(N, 4) points of a test sweep (the layout of a nuScenes ``.pcd.bin``)."""
    return np.fromfile(keyframe.lidar_path, dtype=np.float32).reshape(-1, 5)[:, :4]
