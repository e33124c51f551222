"""The nuScenes loader on the synthetic demo: where data comes from, scene contents and every user error."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import numpy as np
import pytest

from gnnpmb.data import nuscenes as loader
from gnnpmb.data.demo import DEMO_SCENES, DEMO_VERSION, SYNTHETIC_MARKER
from gnnpmb.data.demo_staged import STAGED_SCENES
from gnnpmb.data.nuscenes import (
    DatasetLocation,
    check_dataroot,
    load_lidar_points,
    load_scene,
    open_nuscenes,
    resolve_dataroot,
    split_scenes,
)
from gnnpmb.errors import DataError, UnknownNameError
from gnnpmb.types import TRACKING_CLASSES


@pytest.fixture(autouse=True)
def _no_env_dataroot(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.delenv(loader.DATAROOT_ENV, raising=False)


@pytest.fixture(scope="module")
def location(demo_dataroot: Path) -> DatasetLocation:
    return check_dataroot(demo_dataroot, None)


@pytest.fixture()
def tables_only(demo_dataroot: Path, tmp_path: Path) -> Path:
    """A dataroot with a copy of the demo's tables (no LiDAR files), to break on purpose."""
    root = tmp_path / "root"
    shutil.copytree(demo_dataroot / DEMO_VERSION, root / DEMO_VERSION)
    return root


def test_explicit_dataroot_wins_over_env(demo_dataroot: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv(loader.DATAROOT_ENV, str(tmp_path / "elsewhere"))
    loc = resolve_dataroot(demo_dataroot, None)
    assert loc == DatasetLocation(dataroot=demo_dataroot.resolve(), version=DEMO_VERSION, synthetic=True)


def test_env_dataroot_used_and_checked(demo_dataroot: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv(loader.DATAROOT_ENV, str(demo_dataroot))
    assert resolve_dataroot(None, DEMO_VERSION).dataroot == demo_dataroot.resolve()
    monkeypatch.setenv(loader.DATAROOT_ENV, str(tmp_path / "missing"))
    with pytest.raises(DataError, match=f"from {loader.DATAROOT_ENV}"):
        resolve_dataroot(None, None)


def test_falls_back_to_the_demo(demo_dataroot: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(loader, "ensure_demo_dataset", lambda needs=(): demo_dataroot)
    loc = resolve_dataroot(None, None)
    assert loc.synthetic and loc.version == DEMO_VERSION and loc.dataroot == demo_dataroot.resolve()
    with pytest.raises(DataError, match="demo dataset only has version v1.0-mini"):
        resolve_dataroot(None, "v1.0-trainval")


def test_real_descriptions_are_not_synthetic(tables_only: Path) -> None:
    scene_path = tables_only / DEMO_VERSION / "scene.json"
    scenes = json.loads(scene_path.read_text())
    scenes[0]["description"] = "Night, rain, parking lot"
    scene_path.write_text(json.dumps(scenes))
    assert not check_dataroot(tables_only, None).synthetic


def test_missing_dataroot(tmp_path: Path) -> None:
    with pytest.raises(DataError, match=r"does not exist; pass --dataroot") as info:
        resolve_dataroot(tmp_path / "nope", None)
    assert "\n" not in str(info.value)


def test_folder_without_version(tmp_path: Path) -> None:
    (tmp_path / "samples").mkdir()
    with pytest.raises(DataError, match=r"is not a nuScenes dataroot: it has no v1.0-\* folder; pass --dataroot"):
        resolve_dataroot(tmp_path, None)
    with pytest.raises(DataError, match=r"no v1.0-mini/ folder \(it has no v1.0-\* folder\)"):
        resolve_dataroot(tmp_path, "v1.0-mini")


def test_version_folder_passed_as_dataroot(tables_only: Path) -> None:
    with pytest.raises(DataError, match=r"it is itself a version folder \(use its parent"):
        resolve_dataroot(tables_only / DEMO_VERSION, None)


def test_several_versions_need_a_choice(tables_only: Path) -> None:
    (tables_only / "v1.0-trainval").mkdir()
    with pytest.raises(DataError, match=r"several nuScenes versions \(v1.0-mini, v1.0-trainval\)"):
        resolve_dataroot(tables_only, None)
    assert resolve_dataroot(tables_only, DEMO_VERSION).version == DEMO_VERSION
    with pytest.raises(DataError, match=r"no v1.0-test/ folder \(found: v1.0-mini, v1.0-trainval\)"):
        resolve_dataroot(tables_only, "v1.0-test")


def test_missing_and_corrupt_tables(tables_only: Path) -> None:
    (tables_only / DEMO_VERSION / "sample_annotation.json").unlink()
    with pytest.raises(DataError, match=r"lacks the table\(s\) sample_annotation.json"):
        resolve_dataroot(tables_only, None)
    (tables_only / DEMO_VERSION / "sample_annotation.json").write_text("[")
    (tables_only / DEMO_VERSION / "scene.json").write_text("{not json")
    with pytest.raises(DataError, match=r"v1.0-mini/scene.json cannot be read \(JSONDecodeError\)"):
        resolve_dataroot(tables_only, None)


def test_open_wraps_devkit_errors(tables_only: Path) -> None:
    (tables_only / DEMO_VERSION / "sample_annotation.json").write_text("[")
    loc = check_dataroot(tables_only, None)
    with pytest.raises(DataError, match=r"is not a nuScenes dataroot: the devkit cannot load v1.0-mini/") as info:
        open_nuscenes(loc)
    assert "\n" not in str(info.value)


def test_open_is_cached(location: DatasetLocation) -> None:
    assert open_nuscenes(location) is open_nuscenes(location)
    assert [s["name"] for s in open_nuscenes(location).scene] == list(DEMO_SCENES + STAGED_SCENES)


def test_unknown_scene_lists_available(location: DatasetLocation) -> None:
    with pytest.raises(
        UnknownNameError, match=r"^unknown scene 'scene-0001'; available: scene-0103, scene-0916, scene-9001$"
    ):
        load_scene(location, "scene-0001")


def test_load_scene(location: DatasetLocation) -> None:
    nusc = open_nuscenes(location)
    scene = load_scene(location, "scene-0916")
    assert scene.name == "scene-0916" and scene.synthetic and scene.description.startswith(SYNTHETIC_MARKER)
    assert scene.version == DEMO_VERSION and scene.dataroot == location.dataroot
    assert len(scene.keyframes) == 40
    assert [k.index for k in scene.keyframes] == list(range(40))
    assert np.all(np.diff([k.timestamp_us for k in scene.keyframes]) == 500_000)
    classes: set[str] = set()
    for keyframe in scene.keyframes:
        sample = nusc.get("sample", keyframe.sample_token)
        sweep = nusc.get("sample_data", sample["data"]["LIDAR_TOP"])
        assert keyframe.lidar_path == location.dataroot / sweep["filename"] and keyframe.lidar_path.is_file()
        pose = nusc.get("ego_pose", sweep["ego_pose_token"])
        assert np.allclose(keyframe.ego_pose.translation_m, pose["translation"])
        assert np.allclose(keyframe.ego_pose.quat_wxyz, pose["rotation"])
        assert np.allclose(keyframe.lidar_calib.translation_m, [0.943713, 0.0, 1.84023])
        gt = keyframe.gt
        n = len(gt)
        assert gt.translation_m.shape == (n, 3) and gt.quat_wxyz.shape == (n, 4) and gt.velocity_mps.shape == (n, 2)
        assert keyframe.gt_num_pts.shape == (n,)
        assert np.all(np.isfinite(gt.velocity_mps)) and np.all(gt.score == 1.0)
        assert set(gt.class_name) <= set(TRACKING_CLASSES)
        classes |= set(gt.class_name)
        anns = {nusc.get("sample_annotation", t)["instance_token"]: t for t in sample["anns"]}
        for i in range(n):
            ann = nusc.get("sample_annotation", anns[gt.instance_id[i]])
            assert np.allclose(gt.translation_m[i], ann["translation"])
            assert np.allclose(gt.size_wlh_m[i], ann["size"])
            assert keyframe.gt_num_pts[i] == ann["num_lidar_pts"] + ann["num_radar_pts"]
            assert np.allclose(gt.velocity_mps[i], np.nan_to_num(nusc.box_velocity(ann["token"])[:2]))
        # barriers and traffic cones are annotated but are not tracking classes
        assert n < len(sample["anns"])
    assert {"bus", "car", "pedestrian", "trailer", "truck", "bicycle", "motorcycle"} <= classes
    moving_bus = scene.keyframes[15].gt.class_name == "bus"
    assert np.linalg.norm(scene.keyframes[15].gt.velocity_mps[moving_bus]) == pytest.approx(8.0, abs=0.05)


def test_load_lidar_points(location: DatasetLocation, tmp_path: Path) -> None:
    keyframe = load_scene(location, "scene-0103").keyframes[5]
    points = load_lidar_points(keyframe)
    raw = np.fromfile(keyframe.lidar_path, dtype=np.float32).reshape(-1, 5)
    assert points.dtype == np.float32 and points.shape == (raw.shape[0], 4)
    assert np.array_equal(points, raw[:, :4])
    from nuscenes.utils.data_classes import LidarPointCloud

    assert np.array_equal(points, LidarPointCloud.from_file(str(keyframe.lidar_path)).points.T)  # as the devkit reads

    truncated = tmp_path / "cut.pcd.bin"
    truncated.write_bytes(keyframe.lidar_path.read_bytes()[:-3])
    with pytest.raises(DataError, match="is truncated"):
        load_lidar_points(_with_path(keyframe, truncated))
    with pytest.raises(DataError, match="is missing"):
        load_lidar_points(_with_path(keyframe, tmp_path / "gone.pcd.bin"))


def _with_path(keyframe, path: Path):
    from dataclasses import replace

    return replace(keyframe, lidar_path=path)


def test_the_devkit_s_splits_are_read_without_importing_it(
    location: DatasetLocation, monkeypatch: pytest.MonkeyPatch
) -> None:
    """``devkit_splits`` gives what ``create_splits_scenes`` gives, read from the devkit's source when the devkit
    is not loaded (its package loads scikit-learn and matplotlib: 2 s of CPU of a ``gnnpmb track``)."""
    import sys

    from nuscenes.utils.splits import create_splits_scenes

    want = create_splits_scenes()
    with monkeypatch.context() as patch:
        for name in [m for m in sys.modules if m == "nuscenes" or m.startswith("nuscenes.")]:
            patch.delitem(sys.modules, name)
        got = loader.devkit_splits()
        assert not any(m == "nuscenes" or m.startswith("nuscenes.") for m in sys.modules)  # the devkit not loaded
        assert list(got.items()) == list(want.items())  # the same splits in the same order
        got["mini_val"].append("scene-x")  # a new dict of new lists, as the devkit's function gives
        assert loader.devkit_splits()["mini_val"] == want["mini_val"]
        patch.setitem(sys.modules, "nuscenes", None)  # importing the devkit fails
        assert split_scenes("mini_val", location) == ["scene-0103", "scene-0916"]


def test_split_scenes(location: DatasetLocation, tables_only: Path) -> None:
    assert split_scenes("mini_val", location) == ["scene-0103", "scene-0916"]
    assert split_scenes("mini_train", location) == []
    assert split_scenes("staged", location) == ["scene-9001"]  # the demo's custom split
    # only the splits the devkit evaluates on this version are offered (not val, train, test on a mini version)
    splits = r"the splits of v1\.0-mini: mini_train, mini_val, staged$"
    with pytest.raises(UnknownNameError, match=rf"^unknown split 'minival' \(did you mean mini_val\?\); {splits}"):
        split_scenes("minival", location)
    with pytest.raises(UnknownNameError, match=rf"^unknown split 'nowhere'; {splits}"):
        split_scenes("nowhere", location)

    (tables_only / DEMO_VERSION / "splits.json").write_text(json.dumps({"hard": ["scene-0916", "scene-9999"]}))
    custom = check_dataroot(tables_only, None)
    assert split_scenes("hard", custom) == ["scene-0916"]
    (tables_only / DEMO_VERSION / "splits.json").write_text(json.dumps({"hard": "scene-0916"}))
    with pytest.raises(DataError, match="must map split names to lists of scene names"):
        split_scenes("hard", custom)
