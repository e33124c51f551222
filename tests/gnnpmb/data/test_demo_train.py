"""The generated mini_train scenes: loadable by the devkit next to the val scenes, varied, deterministic, and
leaving the val scenes unchanged."""

from __future__ import annotations

import hashlib
from pathlib import Path

import pytest
from nuscenes.eval.tracking.utils import category_to_tracking_name
from nuscenes.nuscenes import NuScenes

from gnnpmb.data import demo
from gnnpmb.data.demo import DEMO_SCENES, DEMO_VERSION, SYNTHETIC_MARKER, check_demo_scenes, generate_demo_dataset
from gnnpmb.data.demo_train import TRAIN_SCENES, train_scene
from gnnpmb.errors import DataError


@pytest.fixture(scope="module")
def full_dataroot(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return generate_demo_dataset(tmp_path_factory.mktemp("full") / "nuscenes", scenes=DEMO_SCENES + TRAIN_SCENES)


def _classes_per_scene(nusc: NuScenes) -> dict[str, set[str]]:
    out: dict[str, set[str]] = {}
    for scene in nusc.scene:
        names: set[str] = set()
        token = scene["first_sample_token"]
        while token:
            sample = nusc.get("sample", token)
            for ann in sample["anns"]:
                a = nusc.get("sample_annotation", ann)
                if a["num_lidar_pts"] > 0 and category_to_tracking_name(a["category_name"]):
                    names.add(f"{category_to_tracking_name(a['category_name'])}/{a['instance_token']}")
            token = sample["next"]
        out[scene["name"]] = names
    return out


def test_all_ten_mini_scene_names_load_and_train_scenes_are_varied(full_dataroot: Path) -> None:
    nusc = NuScenes(version=DEMO_VERSION, dataroot=str(full_dataroot), verbose=False)
    assert sorted(s["name"] for s in nusc.scene) == sorted(DEMO_SCENES + TRAIN_SCENES)
    assert all(s["description"].startswith(SYNTHETIC_MARKER) for s in nusc.scene)
    tracks = _classes_per_scene(nusc)
    counts = [len(tracks[n]) for n in TRAIN_SCENES]
    assert min(counts) >= 8 and len(set(counts)) >= 5, counts
    classes = {t.split("/")[0] for n in TRAIN_SCENES for t in tracks[n]}
    assert {"car", "pedestrian", "truck", "bicycle"} <= classes
    assert len({round(train_scene(n)[0].road_heading_rad, 6) for n in TRAIN_SCENES}) == len(TRAIN_SCENES)
    assert any(h.scene_name in TRAIN_SCENES for h in demo.CLUTTER_HOTSPOTS)


def _digest(root: Path, names: tuple[str, ...]) -> str:
    h = hashlib.sha256()
    for name in names:
        for p in sorted((root / "samples" / "LIDAR_TOP").glob(f"gnnpmb-demo-{name}__*")):
            h.update(p.read_bytes())
    return h.hexdigest()


def test_val_scenes_are_identical_with_or_without_the_train_scenes(full_dataroot: Path, demo_dataroot: Path) -> None:
    assert _digest(full_dataroot, DEMO_SCENES) == _digest(demo_dataroot, DEMO_SCENES)


def test_train_layouts_are_deterministic() -> None:
    assert train_scene("scene-0061") == train_scene("scene-0061")


def test_unknown_demo_scene_is_refused(tmp_path: Path) -> None:
    with pytest.raises(DataError, match="unknown demo scene 'scene-9999'"):
        check_demo_scenes(("scene-0061", "scene-9999"))
    with pytest.raises(DataError, match="unknown demo scene"):
        generate_demo_dataset(tmp_path / "x", scenes=("scene-9999",))
    assert check_demo_scenes(("scene-1100", "scene-0061")) == ("scene-0061", "scene-1100")
