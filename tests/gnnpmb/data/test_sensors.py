"""The sensor index: each keyframe's camera images with calibration, the sweeps between keyframes, and which
camera's view holds a point."""

from __future__ import annotations

import os
import shutil
from pathlib import Path

import numpy as np
import pytest

from gnnpmb.data.demo_cameras import CAMERAS, quat_matrix
from gnnpmb.data.nuscenes import load_scene, resolve_dataroot
from gnnpmb.data.scene import SceneData
from gnnpmb.data.sensors import CAMERA_ORDER, _pixel, camera_in_ego, load_scene_sensors, sightings

SCENE = "scene-0103"


@pytest.fixture
def scene(demo_dataroot: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> SceneData:
    """The demo scene in a copy of the dataset (files linked) without the camera images other tests rendered."""
    monkeypatch.setenv("GNNPMB_CACHE_DIR", str(tmp_path / "cache"))
    copy = tmp_path / "demo"
    shutil.copytree(demo_dataroot, copy, ignore=shutil.ignore_patterns("CAM_*"), copy_function=os.symlink)
    return load_scene(resolve_dataroot(copy, None), SCENE)


def test_each_keyframe_has_six_calibrated_images_and_only_asked_ones_are_rendered(scene: SceneData) -> None:
    sensors = load_scene_sensors(scene, range(0, 1))
    assert len(sensors.cameras) == len(scene.keyframes) and sensors.sweeps == ()
    assert sensors.channels == CAMERA_ORDER
    mounts = {c.channel: c for c in CAMERAS}
    for k, images in enumerate(sensors.cameras):
        assert tuple(i.channel for i in images) == CAMERA_ORDER
        for image in images:
            assert image.timestamp_us == scene.keyframes[k].timestamp_us
            assert (image.width_px, image.height_px) == (1600, 900)
            assert np.allclose(image.intrinsic, mounts[image.channel].intrinsic)
    assert sensors.missing_images(range(0, 1)) == []
    assert len(sensors.missing_images(range(1, 2))) == 6  # rendered on first use, keyframe by keyframe


def test_camera_in_the_keyframe_ego_frame_is_its_calibration_when_taken_at_the_keyframe(scene: SceneData) -> None:
    sensors = load_scene_sensors(scene, range(0, 0))
    image = sensors.cameras[3][1]
    rotation, translation = camera_in_ego(image, scene.keyframes[3].ego_pose)
    mount = next(c for c in CAMERAS if c.channel == image.channel)
    assert np.allclose(rotation, quat_matrix(mount.quat_wxyz), atol=1e-9)
    assert np.allclose(translation, mount.translation_m, atol=1e-9)


@pytest.mark.parametrize(
    ("ego_xyz", "seen_by"),
    [((20.0, 0.0, 1.0), "CAM_FRONT"), ((-20.0, 0.0, 1.0), "CAM_BACK"), ((8.0, 10.0, 1.0), "CAM_FRONT_LEFT")],
)
def test_a_point_is_seen_by_the_camera_it_lies_in_front_of(
    scene: SceneData, ego_xyz: tuple[float, float, float], seen_by: str
) -> None:
    sensors = load_scene_sensors(scene, range(0, 0))
    pose = scene.keyframes[0].ego_pose
    point = quat_matrix(pose.quat_wxyz) @ np.array(ego_xyz) + pose.translation_m
    seen = sightings(sensors.cameras[0], point)
    assert seen and seen[0].channel == seen_by
    assert seen[0].distance_m == pytest.approx(np.linalg.norm(np.array(ego_xyz) - [1.5, 0, 1.5]), abs=1.5)
    above = quat_matrix(pose.quat_wxyz) @ np.array([0.0, 0.0, 30.0]) + pose.translation_m
    assert sightings(sensors.cameras[0], above) == ()


def test_a_camera_point_s_pixel_is_the_devkit_s_to_the_bit() -> None:
    from nuscenes.utils.geometry_utils import view_points

    rng = np.random.default_rng(3)
    intrinsic = np.array([[1266.4, 0.0, 816.3], [0.0, 1266.4, 491.5], [0.0, 0.0, 1.0]])
    for point in rng.normal(size=(200, 3)) * [20.0, 5.0, 20.0] + [0.0, 0.0, 21.0]:
        expected = view_points(point.reshape(3, 1), intrinsic, normalize=True)[:2, 0]
        assert np.array_equal(_pixel(point, intrinsic), expected)


def test_sweeps_leave_the_keyframes_and_annotations_as_they_were(swept_dataroot: Path, demo_dataroot: Path) -> None:
    import json

    for path in (swept_dataroot / "samples" / "LIDAR_TOP").iterdir():
        assert path.read_bytes() == (demo_dataroot / "samples" / "LIDAR_TOP" / path.name).read_bytes()
    ours = json.loads((swept_dataroot / "v1.0-mini" / "sample_annotation.json").read_text())
    theirs = {r["token"]: r for r in json.loads((demo_dataroot / "v1.0-mini" / "sample_annotation.json").read_text())}
    assert ours and all(theirs[r["token"]] == r for r in ours)


def test_sweeps_lie_between_keyframes_with_their_own_ego_pose(
    swept_dataroot: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setenv("GNNPMB_CACHE_DIR", str(tmp_path / "cache"))
    scene = load_scene(resolve_dataroot(swept_dataroot, None), SCENE)
    sweeps = load_scene_sensors(scene, range(0, 0)).sweeps
    keys = [k.timestamp_us for k in scene.keyframes]
    assert [s.timestamp_us for s in sweeps] == [t + 250_000 for t in keys[:-1]]
    for k, sweep in enumerate(sweeps):
        before, after = (scene.keyframes[i].ego_pose.translation_m for i in (k, k + 1))
        assert np.allclose(sweep.ego_pose.translation_m, 0.5 * (before + after), atol=0.2)
        assert sweep.lidar_path.is_file() and sweep.sample_token == scene.keyframes[k + 1].sample_token


def test_the_cached_demo_with_sweeps_lives_apart_and_a_bad_setting_is_named(monkeypatch: pytest.MonkeyPatch) -> None:
    from gnnpmb.data.demo import SWEEPS_ENV, demo_cache_dir
    from gnnpmb.errors import DataError

    monkeypatch.setenv(SWEEPS_ENV, "1")
    assert demo_cache_dir().name.endswith("-sweeps")
    monkeypatch.setenv(SWEEPS_ENV, "yes")
    with pytest.raises(DataError, match="GNNPMB_DEMO_SWEEPS='yes' is not valid; set it to 1"):
        demo_cache_dir()
