from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from gnnpmb.eval.failures import short_id
from tests.viz.conftest import N_FRAMES, POINTS_PER_SWEEP, read_sweep
from tests.viz.rrd import at_frame, read_rows
from viz import paths
from viz.scene import log_scene


@pytest.fixture
def scene_rows(saved_stream, tiny_scene) -> dict:
    stream, path = saved_stream
    scene, frames = tiny_scene
    calls = []
    log_scene(stream, scene, frames, points_loader=read_sweep, on_frame=lambda: calls.append(1))
    assert len(calls) == N_FRAMES
    stream.disconnect()
    return read_rows(path)


def test_static_context_and_calibration(scene_rows: dict) -> None:
    assert scene_rows[paths.WORLD][0]["static"]
    assert len(scene_rows[paths.ROOT][0]["AnnotationContext:context"][0]) == 7
    calib = [r for r in scene_rows[paths.LIDAR] if r["static"]]
    assert len(calib) == 1
    np.testing.assert_allclose(calib[0]["Transform3D:translation"], [[0.94, 0.0, 1.84]], rtol=1e-6)
    np.testing.assert_allclose(calib[0]["Transform3D:quaternion"], [[0.0, 0.0, -0.7071068, 0.7071068]], rtol=1e-6)
    assert "scene-test" in scene_rows[paths.SCENE_INFO][0]["TextDocument:text"][0]


def test_ego_pose_and_points_on_both_timelines(scene_rows: dict) -> None:
    ego = [r for r in scene_rows[paths.EGO] if not r["static"]]
    assert [r["frame"] for r in ego] == [0, 1, 2]
    assert [r["Transform3D:translation"][0][0] for r in ego] == [0.0, 2.0, 4.0]
    assert ego[1]["timestamp"] == pd.Timestamp(1_533_151_604_047_590, unit="us")
    pts = [r for r in scene_rows[paths.LIDAR] if not r["static"]]
    assert [r["Points3D:positions.len"] for r in pts] == [POINTS_PER_SWEEP] * N_FRAMES
    assert pts[0]["Points3D:colors.len"] == POINTS_PER_SWEEP


def test_gt_boxes_with_class_ids_and_short_labels(scene_rows: dict) -> None:
    gt = scene_rows[paths.GT]
    first = at_frame(gt, 0)[0]
    assert first["Boxes3D:class_ids"] == [3, 5]
    assert first["Boxes3D:labels"] == ["a1b2c3", "p9"]
    assert at_frame(gt, 2)[0]["Boxes3D:centers"] == []  # no GT in frame 2: the boxes disappear


def test_detections_kept_and_dimmed_suppressed(scene_rows: dict) -> None:
    kept = at_frame(scene_rows[paths.DETECTIONS_KEPT], 1)[0]
    assert kept["Boxes3D:labels"] == ["m0 0.90"] and kept["Boxes3D:class_ids"] == [3]  # m<source index> <score>
    np.testing.assert_allclose(kept["Boxes3D:centers"], [[11.2, 2.1, 1.0]], rtol=1e-6)
    dropped = at_frame(scene_rows[paths.DETECTIONS_SUPPRESSED], 1)[0]
    assert dropped["Boxes3D:labels"] == ["m1 0.50 nms", "m2 0.05 low"]
    assert [c & 0xFF for c in dropped["Boxes3D:colors"]] == [70, 70]


def test_frame_range_logs_only_those_keyframes_and_downsamples_big_sweeps(saved_stream, tiny_scene) -> None:
    stream, path = saved_stream
    scene, frames = tiny_scene
    log_scene(stream, scene, frames[1:3], range(1, 3), points_loader=read_sweep, max_points=100, voxel_m=8.0)
    stream.disconnect()
    rows = read_rows(path)
    assert [r["frame"] for r in rows[paths.EGO]] == [1, 2]
    n = [r["Points3D:positions.len"] for r in rows[paths.LIDAR] if not r["static"]]
    assert all(0 < k < POINTS_PER_SWEEP for k in n)
    assert paths.LIDAR in rows and paths.GT in rows


def test_no_points_loader_means_no_lidar_and_mismatched_frames_are_rejected(saved_stream, tiny_scene) -> None:
    stream, path = saved_stream
    scene, frames = tiny_scene
    with pytest.raises(ValueError, match="2 frames of detections for 3 keyframes"):
        log_scene(stream, scene, frames[:2])
    log_scene(stream, scene, frames)
    stream.disconnect()
    assert all(r["static"] for r in read_rows(path)[paths.LIDAR])


def test_short_id() -> None:
    assert short_id("6dd2cbf4c24b4caeb625035869bca7b5") == "6dd2cb"
    assert short_id("ped-7") == "ped-7"
