"""The persistent dataset index: built once, rebuilt when a table changes or the index is damaged, and a bad
table is one clear error."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import numpy as np
import pytest

from gnnpmb.data import dataset_index
from gnnpmb.data import nuscenes as loader
from gnnpmb.data.nuscenes import check_dataroot, load_scene
from gnnpmb.errors import DataError

SCENE = "scene-0916"


@pytest.fixture()
def dataroot(demo_dataroot: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    """A copy of the demo's tables (LiDAR shared) and an empty cache."""
    monkeypatch.setenv("GNNPMB_CACHE_DIR", str(tmp_path / "cache"))
    root = tmp_path / "nuscenes"
    shutil.copytree(demo_dataroot / "v1.0-mini", root / "v1.0-mini")
    (root / "samples").symlink_to(demo_dataroot / "samples")
    loader._INDEXES.clear()
    return root


@pytest.fixture()
def builds(monkeypatch: pytest.MonkeyPatch) -> list[int]:
    calls: list[int] = []
    build = dataset_index._build
    monkeypatch.setattr(dataset_index, "_build", lambda *a: calls.append(1) or build(*a))
    return calls


def _same_scene(a, b) -> bool:
    return all(
        ka.sample_token == kb.sample_token
        and np.array_equal(ka.gt.translation_m, kb.gt.translation_m)
        and np.array_equal(ka.gt.velocity_mps, kb.gt.velocity_mps)
        and list(ka.gt.instance_id) == list(kb.gt.instance_id)
        and np.array_equal(ka.ego_pose.translation_m, kb.ego_pose.translation_m)
        for ka, kb in zip(a.keyframes, b.keyframes, strict=True)
    )


def test_built_once_and_again_when_a_table_changes(dataroot: Path, builds: list[int]) -> None:
    location = check_dataroot(dataroot, None)
    first = load_scene(location, SCENE)
    loader._INDEXES.clear()  # as a new process would
    assert _same_scene(load_scene(location, SCENE), first) and len(builds) == 1
    scenes = json.loads((dataroot / "v1.0-mini" / "scene.json").read_text())
    scenes[1]["description"] = "renamed"
    (dataroot / "v1.0-mini" / "scene.json").write_text(json.dumps(scenes))
    loader._INDEXES.clear()
    assert load_scene(location, scenes[1]["name"]).description == "renamed" and len(builds) == 2


def test_damaged_index_is_rebuilt(dataroot: Path, builds: list[int]) -> None:
    location = check_dataroot(dataroot, None)
    expected = load_scene(location, SCENE)
    (folder,) = (dataroot.parent / "cache" / "index").glob("dataset-*")
    annotations = folder / "annotations.arrow"
    raw = bytearray(annotations.read_bytes())
    middle = len(raw) // 2
    raw[middle : middle + 8] = bytes(8)  # values overwritten, sizes unchanged
    annotations.write_bytes(bytes(raw))
    loader._INDEXES.clear()
    assert _same_scene(load_scene(location, SCENE), expected)
    loader._INDEXES.clear()
    samples = folder / "samples.arrow"
    samples.write_bytes(samples.read_bytes()[:-100])  # truncated: not trusted when opened
    assert _same_scene(load_scene(location, SCENE), expected)
    (folder / "manifest.json").unlink()  # a build stopped before its manifest
    loader._INDEXES.clear()
    assert _same_scene(load_scene(location, SCENE), expected) and len(builds) >= 3


def test_bad_table_is_one_line(dataroot: Path) -> None:
    table = dataroot / "v1.0-mini" / "sample_annotation.json"
    table.write_text(table.read_text()[:5000])
    location = check_dataroot(dataroot, None)
    with pytest.raises(DataError, match=r"v1.0-mini/sample_annotation.json cannot be read \(JsonStreamError: ") as info:
        load_scene(location, SCENE)
    assert "\n" not in str(info.value) and "line" in str(info.value)
    table.write_text(json.dumps([{"token": "a", "sample_token": "nowhere"}]))
    with pytest.raises(DataError, match="sample_annotation.json cannot be read .*field"):
        load_scene(check_dataroot(dataroot, None), SCENE)


def test_cli_reads_a_damaged_index_and_refuses_a_garbled_table(
    dataroot: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    import functools

    from cli.batch import app
    from cli.errors import run_app
    from tests.inprocess import run_main

    def failures() -> tuple[int, str, str]:
        loader._INDEXES.clear()
        # six keyframes: the index is read whole whatever the window; the whole scene only adds evaluation
        argv = ["failures", SCENE, "--dataroot", str(dataroot), "--detector", "pointpillars", "--frames", "0:6"]
        return run_main(functools.partial(run_app, app), argv, capsys)

    code, first, _ = failures()
    assert code == 0 and "false_track" in first
    (folder,) = (dataroot.parent / "cache" / "index").glob("dataset-*")
    (folder / "samples.arrow").write_bytes(b"garbage")
    assert failures()[:2] == (0, first)
    table = dataroot / "v1.0-mini" / "sample.json"
    table.write_text(table.read_text()[:-200])
    code, _, err = failures()
    lines = err.strip().splitlines()
    assert code == 2 and len(lines) == 1 and lines[0].startswith("error: ")
    assert "v1.0-mini/sample.json cannot be read" in lines[0] and "line" in lines[0]


def test_an_index_is_built_without_the_devkit_and_names_classes_as_the_devkit_does(
    dataroot: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The devkit's package loads scikit-learn and matplotlib (a second of CPU in each process that indexes a
    dataset): the index's tracking classes come from ``TRACKING_NAME_OF_CATEGORY``, the devkit's own mapping."""
    import sys

    from nuscenes.eval.tracking.utils import category_to_tracking_name

    from gnnpmb.classes import TRACKING_NAME_OF_CATEGORY

    categories = json.loads((dataroot / "v1.0-mini" / "category.json").read_text())
    names = {c["name"] for c in categories} | set(TRACKING_NAME_OF_CATEGORY) | {"animal", "vehicle.emergency.police"}
    assert {n: TRACKING_NAME_OF_CATEGORY.get(n) for n in names} == {n: category_to_tracking_name(n) for n in names}
    with monkeypatch.context() as patch:
        for name in [m for m in sys.modules if m == "nuscenes" or m.startswith("nuscenes.")]:
            patch.delitem(sys.modules, name)
        patch.setitem(sys.modules, "nuscenes", None)  # importing the devkit fails
        scene = load_scene(check_dataroot(dataroot, None), SCENE)
    classes = {c for k in scene.keyframes for c in k.gt.class_name}
    assert {"car", "pedestrian"} <= classes <= set(TRACKING_NAME_OF_CATEGORY.values())
