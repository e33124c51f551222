"""The evaluation on a version folder built from the index for some scenes equals the evaluation on the whole
dataset: the same metrics files, the same failure reports (the one-scene split's cell compares its scene's
report with a full load's, from the same tracks)."""

from __future__ import annotations

import json
import math
import shutil
from pathlib import Path

import pytest

from gnnpmb.data.eval_subset import eval_location
from gnnpmb.data.nuscenes import check_dataroot, load_scene, open_nuscenes, sample_tokens
from gnnpmb.eval.failures import find_failures
from gnnpmb.eval.nuscenes_eval import run_tracking_eval, tracking_config
from gnnpmb.eval.submission import build_submission, run_results, write_submission
from gnnpmb.pipeline import get_detections, run_tracker

SCENES = ("scene-0103", "scene-0916")


@pytest.fixture(scope="module")
def dataroot(demo_dataroot: Path, tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The demo with a custom split holding one scene, so a subset evaluation leaves a scene out."""
    root = tmp_path_factory.mktemp("subset") / "nuscenes"
    (root / "v1.0-mini").mkdir(parents=True)
    for table in (demo_dataroot / "v1.0-mini").glob("*.json"):
        shutil.copy(table, root / "v1.0-mini" / table.name)
    (root / "v1.0-mini" / "splits.json").write_text(json.dumps({"one": ["scene-0916"]}))
    for folder in ("samples", "maps"):
        (root / folder).symlink_to(demo_dataroot / folder)
    return root


TRACKER = "gnn"
"""The tracker whose results are evaluated: GNN outputs fewer boxes (867 on the two scenes with pointpillars,
GNN-PMB 13,085), which makes each of the devkit's evaluations 1.2 s of CPU cheaper; any results show whether a
subset evaluates as the whole does."""


@pytest.fixture(scope="module")
def results(dataroot: Path) -> dict[str, dict]:
    location = check_dataroot(dataroot, None)
    out = {}
    for name in SCENES:
        scene = load_scene(location, name)
        run = run_tracker(scene, get_detections(scene, None, "pointpillars", 0), TRACKER, _config())
        out[name] = run_results(run)
    return out


def _config():
    from gnnpmb.config import TrackerConfig

    return TrackerConfig()


def _metrics(folder: Path) -> dict:
    summary = json.loads((folder / "metrics_summary.json").read_text())
    summary.pop("eval_time")
    details = json.loads((folder / "metrics_details.json").read_text())
    return {"summary": summary, "details": details}


@pytest.mark.parametrize(
    ("split", "scenes"),
    [
        # two scenes of ten: the same subset path as one scene of ten, at 10 s of CPU (run by hand, -m exhaustive)
        pytest.param("mini_val", SCENES, marks=pytest.mark.exhaustive),
        ("one", ("scene-0916",)),
    ],
)
def test_split_metrics_equal_a_full_load(dataroot: Path, results: dict, tmp_path: Path, split: str, scenes) -> None:
    location = check_dataroot(dataroot, None)
    path = tmp_path / "results.json"
    write_submission(path, build_submission([results[n] for n in scenes], sample_tokens(location, scenes)))
    run_tracking_eval(path, location.dataroot, location.version, split, tmp_path / "full")
    subset = eval_location(location, scenes)
    assert subset.dataroot != location.dataroot
    run_tracking_eval(path, subset.dataroot, subset.version, split, tmp_path / "subset")
    assert _metrics(tmp_path / "subset") == _metrics(tmp_path / "full")

    if len(scenes) == 1:  # the same figures from the accumulation that found the scene's failures (gnnpmb diff's)
        official = _metrics(tmp_path / "full")["summary"]
        expected = (
            {
                c: {m: v.get(c, math.nan) for m, v in official["label_metrics"].items()}
                for c in tracking_config().class_names
            },
            {m: official[m] for m in official["label_metrics"]},
        )
        report = find_failures(open_nuscenes(subset), scenes[0], results[scenes[0]], TRACKER)
        assert report.scores is not None and _same(report.scores.as_floats(), expected)
        # and the failure report is the one a full load finds
        full = find_failures(open_nuscenes(location), scenes[0], results[scenes[0]], TRACKER)
        assert report.to_json() == full.to_json() and full.failures


def _same(a: object, b: object) -> bool:
    """Equal to 1e-12, NaN equal to NaN (the devkit's value of a class without ground truth): the devkit's float
    sums can differ in the last bit between two evaluations of the same boxes in one process (seen: an AMOTP of
    0.5513270090836757 and ...758), as numpy's summation loops depend on the arrays' memory alignment."""
    if isinstance(a, dict) and isinstance(b, dict):
        return list(a) == list(b) and all(_same(a[k], b[k]) for k in a)
    if isinstance(a, tuple) and isinstance(b, tuple):
        return len(a) == len(b) and all(_same(x, y) for x, y in zip(a, b, strict=True))
    return math.isclose(a, b, rel_tol=1e-12, abs_tol=1e-12) or (math.isnan(a) and math.isnan(b))  # type: ignore[arg-type]


def test_subset_holds_only_its_scenes(dataroot: Path) -> None:
    location = check_dataroot(dataroot, None)
    subset = eval_location(location, ["scene-0916"])
    tables = subset.dataroot / subset.version
    assert [s["name"] for s in json.loads((tables / "scene.json").read_text())] == ["scene-0916"]
    samples = json.loads((tables / "sample.json").read_text())
    assert {s["token"] for s in samples} == set(sample_tokens(location, ["scene-0916"]))
    assert eval_location(location, ["scene-0916"]) == subset


def test_damaged_subset_is_built_again(dataroot: Path) -> None:
    location = check_dataroot(dataroot, None)
    subset = eval_location(location, ["scene-0103"])
    table = subset.dataroot / subset.version / "sample_annotation.json"
    expected = table.read_text()
    table.write_text(expected[:100])
    assert eval_location(location, ["scene-0103"]) == subset and table.read_text() == expected
