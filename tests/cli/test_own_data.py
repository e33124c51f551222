"""A user's own nuScenes-format data (here the demo's tables with their scene descriptions rewritten, so they are
not the built-in demo's, and no sensor files) through the commands the README gives: what the terminal says when
the detections were left out."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from tests.gnnpmb.study.conftest import cut_dataset
from tests.inprocess import run_script

SCENES, FRAMES = ("scene-0103", "scene-0916"), 6
SIMULATED = "note: no --detections: the detections are simulated from the dataset's annotations (--detector"


@pytest.fixture(scope="module")
def own_dataroot(demo_dataroot: Path, tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The demo's tables, scenes described as a user's own (not the demo's marker), no sensor files; both scenes cut
    to their first ``FRAMES`` keyframes (what is said does not depend on the length, the commands' work does)."""
    root = cut_dataset(demo_dataroot, tmp_path_factory.mktemp("own") / "nuscenes", SCENES, FRAMES)
    for link in ("samples", "maps"):  # the sensor files and maps stay behind
        (root / link).unlink(missing_ok=True)
    scenes = root / "v1.0-mini" / "scene.json"
    rows = json.loads(scenes.read_text())
    scenes.write_text(json.dumps([r | {"description": f"own drive {i}"} for i, r in enumerate(rows)]))
    return root


@pytest.fixture(scope="module")
def own_detections(own_dataroot: Path, tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A detection file for every sample of the dataset (empty lists: a detector that saw nothing)."""
    samples = json.loads((own_dataroot / "v1.0-mini" / "sample.json").read_text())
    path = tmp_path_factory.mktemp("det") / "det.json"
    path.write_text(json.dumps({"meta": {}, "results": {s["token"]: [] for s in samples}}))
    return path


@pytest.mark.parametrize(
    "command",
    [
        "gnnpmb failures scene-0103 --frames 0:4",
        "gnnpmb-viz scene-0103 --frames 0:4 --save {w}/x.rrd --no-progress",
        "gnnpmb track --split mini_val --tracker greedy --out {w}/r.json --no-progress",
        "gnnpmb diff greedy gnn --scene scene-0103",
    ],
    ids=["failures", "viz", "track", "diff"],
)
def test_own_data_without_detections_says_they_are_simulated(
    command: str, own_dataroot: Path, own_detections: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Leaving out --detections on one's own data tracks a simulated detector's boxes: said once, with the fix."""
    argv = [*command.format(w=tmp_path).split(), "--dataroot", str(own_dataroot)]
    done = run_script(argv, capsys)
    assert done.returncode == 0, done.stderr
    notes = [line for line in done.stderr.splitlines() if line.startswith(SIMULATED)]
    assert len(notes) == 1, done.stderr
    assert notes[0].endswith("pass --detections FILE.json to track your detector's")
    if not command.startswith("gnnpmb diff"):  # a detector that saw nothing cannot be diffed: nothing to evaluate
        done = run_script([*argv, "--detections", str(own_detections)], capsys)
        assert done.returncode == 0, done.stderr
        assert SIMULATED not in done.stderr


def test_the_demo_without_detections_says_nothing(demo_dataroot: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """On the built-in demo the simulated detector is the point: no note."""
    done = run_script(["gnnpmb", "failures", "scene-0103", "--frames", "0:4", "--dataroot", str(demo_dataroot)], capsys)
    assert done.returncode == 0, done.stderr
    assert SIMULATED not in done.stderr
