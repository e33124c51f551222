"""Cameras in a recording: the JPEG bytes as encoded images under the calibrated pinholes, the views that project
the boxes into them, and the focus document's camera line."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import rerun as rr
import rerun.blueprint as rrb

from gnnpmb.data.nuscenes import load_scene, resolve_dataroot
from gnnpmb.data.sensors import CAMERA_ORDER, CameraSighting, SceneSensors, absent_reason, load_scene_sensors
from gnnpmb.focus_cameras import FocusSight
from gnnpmb.types import Boxes, FrameDetections
from tests.viz.rrd import read_rows
from tests.viz.test_blueprint import views
from viz import paths
from viz.blueprint import default_blueprint
from viz.cameras import log_cameras
from viz.focus_summary import camera_lines
from viz.timeline import PLAIN_CLOCK

FRAMES = range(2, 4)


def test_images_are_the_jpeg_files_under_calibrated_pinholes(
    demo_dataroot: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch, saved_stream
) -> None:
    monkeypatch.setenv("GNNPMB_CACHE_DIR", str(tmp_path / "cache"))
    scene = load_scene(resolve_dataroot(demo_dataroot, None), "scene-0103")
    sensors = load_scene_sensors(scene, FRAMES)
    assert absent_reason(sensors, FRAMES) is None
    stream, path = saved_stream
    logged = log_cameras(stream, scene, sensors, FRAMES, PLAIN_CLOCK)
    stream.disconnect()
    rows = read_rows(path)
    files = 0
    for channel in CAMERA_ORDER:
        entity = rows[paths.camera(channel)]
        (pinhole,) = [r for r in entity if r["static"]]
        image = sensors.cameras[FRAMES[0]][CAMERA_ORDER.index(channel)]
        assert np.allclose(np.reshape(pinhole["Pinhole:image_from_camera"], (3, 3)).T, image.intrinsic)
        assert pinhole["Pinhole:resolution"] == [[1600.0, 900.0]]
        blobs = [r for r in entity if r.get("EncodedImage:blob") is not None]
        assert [r["frame"] for r in blobs] == list(FRAMES)
        for r, k in zip(blobs, FRAMES, strict=True):
            want = sensors.cameras[k][CAMERA_ORDER.index(channel)].path.read_bytes()
            assert bytes(r["EncodedImage:blob"][0]) == want and r["EncodedImage:media_type"] == ["image/jpeg"]
            files += len(want)
        assert [r["frame"] for r in entity if r.get("Transform3D:translation") is not None] == list(FRAMES)
    assert logged == files


def test_a_dataset_without_camera_rows_or_files_says_so_in_one_line(tmp_path: Path) -> None:
    assert absent_reason(SceneSensors(cameras=((), ()), sweeps=()), range(2)) == (
        "cameras absent: the dataset has no camera images for this scene"
    )


def test_camera_views_show_their_own_drawn_boxes_and_a_focus_shows_the_camera_that_saw_it() -> None:
    full = [v for v in views(default_blueprint(["gnnpmb", "pmbm"], ["car"], cameras=CAMERA_ORDER))]
    cams = [v for v in full if isinstance(v, rrb.Spatial2DView) and v.origin.startswith(paths.EGO)]
    assert [v.origin for v in cams] == [paths.camera(c) for c in CAMERA_ORDER]
    for v in cams:  # the boxes are drawn under the camera, clipped (viz.camera_boxes); no 3D entity projected
        assert list(v.contents) == ["+ $origin/**"]
    without = views(default_blueprint(["gnnpmb"], ["car"]))
    assert not [v for v in without if isinstance(v, rrb.Spatial2DView) and v.origin.startswith(paths.EGO)]


def test_the_focus_document_names_the_camera_or_says_none_saw_it() -> None:
    seen = FocusSight(7, "bf3d85aa" * 4, (CameraSighting("CAM_FRONT_LEFT", 18.4, (300.0, 500.0), 0.4),))
    (line, _) = camera_lines(seen)
    assert "GT bf3d85 was inside the view of CAM_FRONT_LEFT (18 m away) at frame 7" in line
    (line, _) = camera_lines(FocusSight(7, None, ()))
    assert line == "**Cameras**: The focus place was outside every camera's view at frame 7."
    (line, _) = camera_lines(FocusSight(7, None, seen.seen, track_id=212))
    assert line.startswith("**Cameras**: Track 212 was inside the view of CAM_FRONT_LEFT (18 m away) at frame 7")
    assert camera_lines(None) == []


def test_cameras_log_in_a_few_chunks(demo_dataroot: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    from rerun.chunk import RrdReader

    monkeypatch.setenv("GNNPMB_CACHE_DIR", str(tmp_path / "cache"))
    scene = load_scene(resolve_dataroot(demo_dataroot, None), "scene-0103")
    sensors = load_scene_sensors(scene, FRAMES)
    path = tmp_path / "cams.rrd"
    stream = rr.RecordingStream("gnnpmb-viz-test")
    stream.save(path)
    log_cameras(stream, scene, sensors, FRAMES, PLAIN_CLOCK)
    stream.disconnect()
    chunks = [c for c in RrdReader(path).store().stream() if "CAM_" in c.entity_path]
    assert len(chunks) == 2 * len(CAMERA_ORDER)  # the static pinhole; the poses and images together


def test_sweeps_are_on_their_own_time_only_and_hand_over_with_the_keyframe_cloud(
    swept_dataroot: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch, saved_stream
) -> None:
    from viz.cameras import log_sweeps
    from viz.scene import log_scene
    from viz.timeline import TIMESTAMP

    monkeypatch.setenv("GNNPMB_CACHE_DIR", str(tmp_path / "cache"))
    scene = load_scene(resolve_dataroot(swept_dataroot, None), "scene-0103")
    sensors = load_scene_sensors(scene, range(0, 0))
    frames = range(0, 3)
    stream, path = saved_stream
    none = np.zeros(0, dtype=bool)
    empty = FrameDetections(boxes=Boxes.empty(), kept=none, below_threshold=none, suppressed_by_nms=none)
    log_scene(stream, scene, [empty] * len(frames), frames)
    assert log_sweeps(stream, scene, sensors, frames) == 2
    stream.disconnect()
    rows = read_rows(path)
    sweep_rows = rows[paths.SWEEP_LIDAR]
    points = [r for r in sweep_rows if r.get("Points3D:positions.len")]
    assert len(points) == 2 and all("frame" not in r for r in sweep_rows)
    stamps = [r[TIMESTAMP] for r in points]
    keys = [np.datetime64(scene.keyframes[i].timestamp_us, "us") for i in frames]
    assert keys[0] < stamps[0] < keys[1] < stamps[1] < keys[2]
    cleared = [r[TIMESTAMP] for r in rows[paths.LIDAR] if "Clear:is_recursive" in r]
    assert cleared == stamps and all("frame" not in r for r in rows[paths.LIDAR] if "Clear:is_recursive" in r)
