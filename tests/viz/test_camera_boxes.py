"""Boxes drawn into the camera images (``viz.camera_boxes``): clipped to the image or left out when mostly outside
it, and words only on the frame's failures, kept apart; read back from a saved recording as the viewer draws
them (``tools.labels``)."""

from __future__ import annotations

from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest
import rerun as rr
import rerun.blueprint as rrb
from PIL import Image
from pyquaternion import Quaternion

from gnnpmb.data.scene import Pose
from gnnpmb.data.sensors import CameraImage, SceneSensors
from gnnpmb.eval.failures import Failure, FailureBox, FailureKind
from tests.viz.rrd import read_rows
from tools.labels import Recording, camera_boxes, overlaps
from viz import paths
from viz.box_projection import CameraFrame, project_boxes
from viz.camera_boxes import (
    CAMERA_VIEW_SCALE,
    MAX_CAMERA_LABELS,
    Box,
    _inside_image,
    failure_boxes,
    log_camera_boxes,
)
from viz.cameras import camera_view, log_cameras
from viz.colors import TEXT_LUMINANCE_MAX, luminance, readable_text
from viz.failure_style import KIND_COLORS
from viz.timeline import PLAIN_CLOCK

WIDTH, HEIGHT = 1600, 900
K = np.array([[1266.0, 0.0, 800.0], [0.0, 1266.0, 450.0], [0.0, 0.0, 1.0]])
CAMERA_IN_EGO = np.array([[0.0, 0.0, 1.0], [-1.0, 0.0, 0.0], [0.0, -1.0, 0.0]])
"""A front camera at the ego origin: its x (right) is the ego's -y, y (down) -z, z (forward) x."""
FRONT = CameraFrame(CAMERA_IN_EGO.T, np.zeros(3), K, WIDTH, HEIGHT)


def _box(x: float, y: float, length: float = 4.5, frame: int = 0, label: str = "") -> Box:
    return Box(frame, (x, y, 0.0), (2.0, length, 1.6), (1.0, 0.0, 0.0, 0.0), (255, 0, 0), label)


def project_box(box: Box, cam: CameraFrame) -> list[np.ndarray]:
    lines = project_boxes(np.array([box.center_m]), np.array([box.size_wlh_m]), np.array([box.quat_wxyz]), [cam])
    return lines.of_box(0)


def _inside(strips: list[np.ndarray]) -> bool:
    pts = np.concatenate(strips)
    return bool(np.all((pts >= -1e-3) & (pts <= np.array([WIDTH, HEIGHT]) + 1e-3)))


def test_a_box_in_view_is_drawn_whole_one_at_the_edge_clipped_one_mostly_outside_left_out() -> None:
    ahead = project_box(_box(20.0, 0.0), FRONT)
    assert ahead and _inside(ahead) and sum(len(s) - 1 for s in ahead) == 12  # the twelve edges
    edge = project_box(_box(10.0, 6.0), FRONT)  # centre at u = 40 px, the near corners past the left edge
    assert edge and _inside(edge) and np.isclose(np.concatenate(edge)[:, 0].min(), 0.0)
    assert project_box(_box(10.0, 9.0), FRONT) == []  # centre left of the image: mostly outside
    assert project_box(_box(-10.0, 0.0), FRONT) == []  # behind the camera
    near = project_box(_box(1.0, 0.0, length=8.0), FRONT)  # reaches behind the camera: cut at the near plane
    assert near and _inside(near)


def test_boxes_projected_together_are_drawn_as_each_alone_in_its_own_camera() -> None:
    turned = Quaternion(axis=(0.0, 0.0, 1.0), angle=0.4)
    side = CameraFrame(turned.rotation_matrix.T @ CAMERA_IN_EGO.T, np.array([3.0, -1.0, 0.5]), K, 1280, 720)
    boxes = [_box(20.0, 0.0), _box(10.0, 6.0), _box(10.0, 9.0), _box(-10.0, 0.0), _box(1.0, 0.0, length=8.0)]
    boxes += [Box(0, (15.0, -2.0, 1.0), (1.0, 3.0, 2.0), tuple(turned.elements), (0, 0, 255))]
    cams = [FRONT, side] * len(boxes)
    boxes = [b for b in boxes for _ in range(2)]
    together = project_boxes(
        np.array([b.center_m for b in boxes]),
        np.array([b.size_wlh_m for b in boxes]),
        np.array([b.quat_wxyz for b in boxes]),
        cams,
    )
    alone = [project_box(b, c) for b, c in zip(boxes, cams, strict=True)]
    assert sum(bool(parts) for parts in alone) >= 6
    for n, parts in enumerate(alone):
        drawn = together.of_box(n)
        assert len(parts) == len(drawn) and all(np.array_equal(x, y) for x, y in zip(parts, drawn, strict=True))


def _failure(kind: FailureKind, frame: int, role: str, object_id: str, x: float, y: float) -> Failure:
    box = FailureBox(role, object_id, (x, y, 0.0), (2.0, 4.5, 1.6), (1.0, 0.0, 0.0, 0.0))
    return Failure(kind, frame, f"sample{frame}", "car", (), (object_id,), (box,))


def test_only_the_frames_failures_are_labelled_with_the_run_a_track_belongs_to() -> None:
    a = SimpleNamespace(failures=(_failure(FailureKind.FALSE_TRACK, 0, "false track", "7", 20.0, 0.0),))
    b = SimpleNamespace(failures=(*a.failures, _failure(FailureKind.ID_SWITCH, 1, "new track", "9", 15.0, 2.0)))
    boxes = failure_boxes({"a": a, "b": b}, {0, 1})  # track 7 of a and track 7 of b are two tracks
    assert [(x.frame, x.label) for x in boxes] == [
        (0, "a: false track 7"),
        (0, "b: false track 7"),
        (1, "b: ID switch: new track 9"),
    ]
    assert [x.label for x in failure_boxes({"a": a, "b": b}, {0, 1}, involved={"b": {"9"}})] == [
        "",
        "",
        "b: ID switch: new track 9",
    ]
    missed = _failure(FailureKind.MISS, 2, "missed gt", "4ab7b6aaaa", 20.0, 0.0)
    both = {"a": SimpleNamespace(failures=(missed,)), "b": SimpleNamespace(failures=(missed,))}
    assert [x.label for x in failure_boxes(both, {2})] == ["missed GT 4ab7b6"]  # one object, both runs missed it


@pytest.fixture
def camera_recording(tmp_path: Path, tiny_scene, strict: None) -> Path:
    """The tiny scene's three keyframes seen by one front camera, with a crowd of failures ahead at frame 0 and
    a plain ground-truth box: saved with the camera's view as the blueprint."""
    return _camera_recording(tmp_path, tiny_scene, FailureKind.FALSE_TRACK, "false track")


def _camera_recording(tmp_path: Path, tiny_scene, kind: FailureKind, role: str) -> Path:
    scene, _ = tiny_scene
    jpeg = tmp_path / "front.jpg"
    Image.new("RGB", (WIDTH, HEIGHT), (90, 120, 90)).save(jpeg)
    calib = Pose(np.zeros(3), Quaternion(matrix=CAMERA_IN_EGO).elements)
    images = tuple(
        (CameraImage("CAM_FRONT", jpeg, k.timestamp_us, WIDTH, HEIGHT, K, k.ego_pose, calib),) for k in scene.keyframes
    )
    sensors = SceneSensors(cameras=images, sweeps=())
    crowd = tuple(_failure(kind, 0, role, str(i), 20.0, 0.3 * i) for i in range(8))
    report = SimpleNamespace(failures=crowd)
    layers = {"gt": [_box(12.0, -1.0, frame=f) for f in range(3)], "failures": failure_boxes({"a": report}, {0})}
    path = tmp_path / "cam.rrd"
    stream = rr.RecordingStream("camera-boxes-test")
    stream.set_log_time_enabled(False)
    stream.save(path, default_blueprint=rrb.Blueprint(rrb.Grid(*[camera_view("CAM_FRONT")] * 6, grid_columns=3)))
    frames = range(3)
    log_cameras(stream, scene, sensors, frames, PLAIN_CLOCK)
    log_camera_boxes(stream, scene, sensors, frames, PLAIN_CLOCK, layers)
    stream.disconnect()
    return path


def test_camera_labels_are_the_failures_kept_apart_and_every_line_inside_the_image(camera_recording: Path) -> None:
    rec = Recording(camera_recording)
    view = rec.views[0]
    assert view.camera
    at0 = rec.labels(view, 0)
    assert 1 <= len(at0) <= MAX_CAMERA_LABELS and all(label.text.startswith("false track ") for label in at0)
    assert not overlaps(camera_boxes(rec, view, 0))  # eight failures side by side: the ones that fit
    assert rec.labels(view, 1) == [] and rec.labels(view, 2) == []  # no failure there: no words
    rows = read_rows(camera_recording)
    for layer in ("gt", "failures"):
        strips = [s for r in rows[paths.camera_boxes("CAM_FRONT", layer)] for s in r.get("LineStrips2D:strips") or []]
        assert strips and _inside([np.asarray(s) for s in strips])


def test_a_light_failure_colour_is_darkened_for_its_camera_label_the_box_keeps_it(
    tmp_path: Path, tiny_scene, strict: None
) -> None:
    """Fragmentation orange on the viewer's pale label pill cannot be read (seen on the demo's camera views)."""
    rows = read_rows(_camera_recording(tmp_path, tiny_scene, FailureKind.FRAGMENTATION, "missed gt"))

    def rgb(packed: list[int]) -> set[tuple[int, int, int]]:
        return {((c >> 24) & 0xFF, (c >> 16) & 0xFF, (c >> 8) & 0xFF) for c in packed}

    text = rgb([c for r in rows[paths.camera_labels("CAM_FRONT")] for c in r.get("Points2D:colors") or []])
    boxes = rgb(
        [c for r in rows[paths.camera_boxes("CAM_FRONT", "failures")] for c in r.get("LineStrips2D:colors") or []]
    )
    assert boxes == {KIND_COLORS[FailureKind.FRAGMENTATION]}
    assert text == {readable_text(KIND_COLORS[FailureKind.FRAGMENTATION])}
    assert all(luminance(c) <= TEXT_LUMINANCE_MAX for c in text)


def test_a_label_wider_than_the_image_is_centred_on_it_and_a_narrow_one_kept_inside() -> None:
    """A text wider than the image runs into the margins of a letterboxed view evenly, not off its right edge."""
    from viz.label_size import text_box

    wide = "simpletrack: fragmentation: missed GT bf3d85"
    x0, _, x1, _ = (c / CAMERA_VIEW_SCALE for c in text_box(wide, 0.0, 0.0))
    assert x1 - x0 > 1600.0
    assert _inside_image(wide, 10.0, 300.0, 1600, 900)[0] == 800.0
    narrow = "miss"
    x0, _, x1, _ = (c / CAMERA_VIEW_SCALE for c in text_box(narrow, 0.0, 0.0))
    u, _ = _inside_image(narrow, 1599.0, 300.0, 1600, 900)
    assert u + x1 <= 1600.0 and u + x0 >= 0.0
