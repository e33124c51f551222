"""The demo's cameras: rows as nuScenes has them, and images whose boxes stand where the devkit projects them."""

from __future__ import annotations

import io
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

from gnnpmb.data import demo_cameras
from gnnpmb.data.demo import DEMO_VERSION, ensure_scene_images, scene_spec

SCENE = "scene-0103"
CHANNELS = {c.channel for c in demo_cameras.CAMERAS}


@pytest.fixture(scope="module")
def nusc(demo_dataroot: Path):
    from nuscenes.nuscenes import NuScenes

    return NuScenes(version=DEMO_VERSION, dataroot=str(demo_dataroot), verbose=False)


def test_every_keyframe_has_the_six_cameras_with_nuscenes_rows(nusc) -> None:
    sensors = {s["channel"]: s for s in nusc.sensor}
    assert {c for c, s in sensors.items() if s["modality"] == "camera"} == CHANNELS
    for sample in nusc.sample:
        assert set(sample["data"]) >= CHANNELS
        for cam in demo_cameras.CAMERAS:
            sd = nusc.get("sample_data", sample["data"][cam.channel])
            assert (sd["fileformat"], sd["width"], sd["height"], sd["is_key_frame"]) == ("jpg", 1600, 900, True)
            assert sd["filename"].startswith(f"samples/{cam.channel}/") and sd["filename"].endswith(".jpg")
            assert sd["timestamp"] == sample["timestamp"]
            calib = nusc.get("calibrated_sensor", sd["calibrated_sensor_token"])
            assert np.allclose(calib["camera_intrinsic"], cam.intrinsic)
            lidar = nusc.get("sample_data", sample["data"]["LIDAR_TOP"])
            pose, lidar_pose = (nusc.get("ego_pose", t) for t in (sd["ego_pose_token"], lidar["ego_pose_token"]))
            assert pose["token"] != lidar_pose["token"] and pose["translation"] == lidar_pose["translation"]


def test_camera_axes_point_where_their_names_say() -> None:
    """The optical axis (camera z) of each camera in the ego frame (x forward, y left): its yaw."""
    yaw = {
        c.channel: np.degrees(np.arctan2(*(demo_cameras.quat_matrix(c.quat_wxyz)[:, 2][[1, 0]])))
        for c in demo_cameras.CAMERAS
    }
    expected = {
        "CAM_FRONT": 0,
        "CAM_FRONT_LEFT": 55,
        "CAM_FRONT_RIGHT": -55,
        "CAM_BACK_LEFT": 110,
        "CAM_BACK_RIGHT": -110,
    }
    for channel, degrees in expected.items():
        assert yaw[channel] == pytest.approx(degrees, abs=5)
    assert abs(yaw["CAM_BACK"]) == pytest.approx(180, abs=5)


def _pixel_rgb(path: Path, uv: np.ndarray) -> np.ndarray:
    image = np.asarray(Image.open(path).convert("RGB"), dtype=float)
    u, v = (int(round(x)) for x in uv)
    return np.median(image[v - 3 : v + 4, u - 3 : u + 4].reshape(-1, 3), axis=0)


def _unhidden_nearest(boxes: list, intrinsic: np.ndarray):
    """The nearest whole box (all corners in the image) whose centre no nearer box's image rectangle covers, and
    its centre's pixel; None if every one is covered."""
    from nuscenes.utils.geometry_utils import view_points

    def rect(box) -> tuple[np.ndarray, float]:
        corners = box.corners()
        uv = view_points(corners, intrinsic, normalize=True)[:2]
        return np.array([uv[0].min(), uv[1].min(), uv[0].max(), uv[1].max()]), float(corners[2].min())

    in_front = [b for b in boxes if b.corners()[2].min() > 0.5]
    for box in sorted(in_front, key=lambda b: np.linalg.norm(b.center)):
        uv = view_points(box.center.reshape(3, 1), intrinsic, normalize=True)[:2, 0]
        if not (0 <= uv[0] < 1600 and 0 <= uv[1] < 900) or box.corners()[2].min() < 1.0:
            continue
        covered = False
        for other in in_front:
            if other is box:
                continue
            (u0, v0, u1, v1), near = rect(other)
            covered |= near < box.center[2] and u0 <= uv[0] <= u1 and v0 <= uv[1] <= v1
        if not covered:
            return box, uv
    return None


def test_the_nearest_box_is_drawn_where_the_devkit_projects_it(nusc, demo_dataroot: Path) -> None:
    """Render one keyframe's cameras; at the devkit's projection (``get_sample_data``, ``view_points``) of the
    nearest box's centre that no nearer box hides, each image shows that box's class colour (shaded: the same hue
    at 55-100 % brightness)."""
    from nuscenes.utils.color_map import get_colormap
    from nuscenes.utils.geometry_utils import BoxVisibility

    k = 14
    ensure_scene_images(demo_dataroot, SCENE, range(k, k + 1))
    scene = next(s for s in nusc.scene if s["name"] == SCENE)
    sample = nusc.get("sample", scene["first_sample_token"])
    for _ in range(k):
        sample = nusc.get("sample", sample["next"])
    colours = get_colormap()
    checked = 0
    for channel in sorted(CHANNELS):
        path, boxes, intrinsic = nusc.get_sample_data(sample["data"][channel], box_vis_level=BoxVisibility.ANY)
        found = _unhidden_nearest(boxes, intrinsic)
        if found is None:
            continue
        box, uv = found
        rgb = _pixel_rgb(Path(path), uv)
        want = np.array(colours[box.name], dtype=float)
        ratio = rgb.sum() / want.sum()
        assert 0.5 <= ratio <= 1.05, (channel, box.name, rgb, want)
        assert np.abs(rgb / ratio - want).max() < 25, (channel, box.name, rgb, want)
        checked += 1
    assert checked >= 3


def test_rendering_is_deterministic_and_small() -> None:
    spec = scene_spec(SCENE)
    view = demo_cameras.WorldView(
        road_origin_m=spec.road_origin_m,
        road_heading_rad=spec.road_heading_rad,
        road_left_m=demo_cameras.ROAD_HALF_WIDTH_M,
        ego_s_m=0.0,
        centre_m=np.array([[spec.road_origin_m[0] + 20.0, spec.road_origin_m[1], 0.8]]),
        size_wlh_m=np.array([[1.9, 4.6, 1.6]]),
        yaw_rad=np.array([0.3]),
        rgb=demo_cameras.category_rgb(["vehicle.car"]),
    )
    camera = demo_cameras.CameraPose.of(demo_cameras.CAMERAS[0], np.array(spec.road_origin_m), 0.0)
    first, again = demo_cameras.render_image(view, camera), demo_cameras.render_image(view, camera)
    assert first == again
    assert first[:2] == b"\xff\xd8" and len(first) < 80_000
    assert Image.open(io.BytesIO(first)).size == (1600, 900)
