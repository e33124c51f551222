"""The official evaluation on the demo dataset: a perfect submission, the devkit's own checks, and bad inputs.

The full devkit evaluation takes seconds, so it runs once per module (the ground-truth submission).
"""

from __future__ import annotations

import json
import math
import shutil
from pathlib import Path

import pytest

from gnnpmb.config import TrackerConfig
from gnnpmb.data.nuscenes import DatasetLocation, check_dataroot, load_scene, open_nuscenes
from gnnpmb.errors import DataError, UnknownNameError
from gnnpmb.eval.nuscenes_eval import (
    DEVKIT_FILES,
    check_split_version,
    default_eval_dir,
    evaluate_submission,
    format_metric,
    quiet_devkit,
    split_sample_tokens,
    tracking_config,
    tracking_config_file,
)
from gnnpmb.eval.submission import (
    build_submission,
    check_submission,
    gt_results,
    run_results,
    write_submission,
)
from gnnpmb.pipeline import get_detections, run_tracker

SPLIT = "mini_val"
SCENES = ("scene-0103", "scene-0916")


@pytest.fixture(scope="module")
def location(demo_dataroot: Path) -> DatasetLocation:
    return check_dataroot(demo_dataroot, "v1.0-mini")


@pytest.fixture(scope="module")
def split_tokens(location: DatasetLocation) -> list[str]:
    return split_sample_tokens(open_nuscenes(location), SCENES)


@pytest.fixture(scope="module")
def gt_submission(location: DatasetLocation, split_tokens: list[str]) -> dict:
    return build_submission([gt_results(load_scene(location, name)) for name in SCENES], split_tokens)


@pytest.fixture(scope="module")
def gt_scores(tmp_path_factory: pytest.TempPathFactory, location: DatasetLocation, gt_submission: dict):
    path = tmp_path_factory.mktemp("gt") / "gt.json"
    write_submission(path, gt_submission)
    return evaluate_submission(path, location, SPLIT)


def test_the_config_file_read_without_the_devkit_holds_the_devkit_s_settings() -> None:
    read = tracking_config_file()
    assert read["class_range"] == tracking_config().class_range and read["dist_th_tp"] == tracking_config().dist_th_tp


def test_ground_truth_submission_is_perfect(gt_scores) -> None:
    assert gt_scores.overall["amota"] == pytest.approx(1.0)
    assert gt_scores.overall["mota"] == pytest.approx(1.0)
    assert gt_scores.overall["recall"] == pytest.approx(1.0)
    assert (gt_scores.overall["ids"], gt_scores.overall["fp"], gt_scores.overall["fn"]) == (0, 0, 0)
    scored = {c: m for c, m in gt_scores.per_class.items() if not math.isnan(m["amota"])}
    assert {"car", "pedestrian", "bus", "truck"} <= set(scored)
    assert all(m["amota"] == pytest.approx(1.0) and m["tp"] > 0 for m in scored.values())


def test_devkit_files_are_written_next_to_the_results_without_leftovers(gt_scores) -> None:
    out = gt_scores.summary_path.parent
    assert out == default_eval_dir(out.parent / "gt.json")
    assert sorted(p.name for p in out.iterdir()) == sorted(DEVKIT_FILES)
    summary = json.loads(gt_scores.summary_path.read_text())
    assert summary["amota"] == pytest.approx(1.0)
    assert summary["cfg"]["dist_th_tp"] == 2.0 and summary["cfg"]["num_thresholds"] == 40
    assert sorted(p.name for p in out.parent.iterdir()) == ["gt.json", "gt_eval"]


def test_tracker_submission_passes_the_devkits_own_checks(
    tmp_path: Path, location: DatasetLocation, split_tokens: list[str]
) -> None:
    from nuscenes.eval.common.loaders import load_gt, load_prediction
    from nuscenes.eval.tracking.data_classes import TrackingBox

    nusc = open_nuscenes(location)
    parts = []
    for name in SCENES:
        scene = load_scene(location, name)
        parts.append(
            run_results(run_tracker(scene, get_detections(scene, None, "megvii", 3), "gnnpmb", TrackerConfig()))
        )
    path = tmp_path / "results.json"
    write_submission(path, build_submission(parts, split_tokens))
    stats = check_submission(json.loads(path.read_text()), path.name, SPLIT, split_tokens, set(split_tokens))
    assert stats.samples == 80 and stats.boxes > 200
    cfg = tracking_config()
    with quiet_devkit():
        pred, meta = load_prediction(str(path), cfg.max_boxes_per_sample, TrackingBox)
        gt = load_gt(nusc, SPLIT, TrackingBox)
    assert set(pred.sample_tokens) == set(gt.sample_tokens) == set(split_tokens)
    assert meta["use_lidar"] is True
    assert {b.tracking_name for b in pred.all} <= set(cfg.tracking_names)


def _write(path: Path, data: dict, allow_nan: bool = False) -> Path:
    path.write_text(json.dumps(data, allow_nan=allow_nan))
    return path


def test_missing_samples_fail_before_the_devkit_runs(
    tmp_path: Path, location: DatasetLocation, gt_submission: dict, split_tokens: list[str]
) -> None:
    data = json.loads(json.dumps(gt_submission))
    for token in split_tokens[:40]:
        del data["results"][token]
    path = _write(tmp_path / "results.json", data)
    with pytest.raises(DataError) as err:
        evaluate_submission(path, location, SPLIT)
    assert str(err.value) == (
        "results.json lacks 40 of the 80 samples of split mini_val; was it made for another split?"
    )
    assert not default_eval_dir(path).exists()


def test_nan_box_is_named_and_old_metrics_stay(
    tmp_path: Path, location: DatasetLocation, gt_submission: dict, split_tokens: list[str]
) -> None:
    data = json.loads(json.dumps(gt_submission))
    token = split_tokens[5]
    data["results"][token][0]["translation"][0] = float("nan")
    path = _write(tmp_path / "results.json", data, allow_nan=True)
    out = tmp_path / "metrics"
    out.mkdir()
    (out / "metrics_summary.json").write_text("old")
    with pytest.raises(DataError, match=f"box 0 of sample {token} field 'translation' has a NaN"):
        evaluate_submission(path, location, SPLIT, out)
    assert (out / "metrics_summary.json").read_text() == "old"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["metrics", "results.json"]


def test_results_of_another_split(tmp_path: Path, demo_dataroot: Path, gt_submission: dict) -> None:
    root = tmp_path / "nuscenes"
    shutil.copytree(demo_dataroot / "v1.0-mini", root / "v1.0-mini")
    shutil.copytree(demo_dataroot / "maps", root / "maps")
    (root / "v1.0-mini" / "splits.json").write_text(json.dumps({"first": ["scene-0103"], "second": ["scene-0916"]}))
    custom = check_dataroot(root, "v1.0-mini")
    nusc = open_nuscenes(custom)
    first = split_sample_tokens(nusc, ["scene-0103"])
    path = _write(
        tmp_path / "first.json",
        {"meta": gt_submission["meta"], "results": {t: gt_submission["results"][t] for t in first}},
    )
    with pytest.raises(
        DataError, match="first.json lacks 40 of the 40 samples of split second; was it made for another"
    ):
        evaluate_submission(path, custom, "second")
    with pytest.raises(DataError, match="split mini_train has no scenes"):
        evaluate_submission(path, custom, "mini_train")
    with pytest.raises(UnknownNameError, match="unknown split 'thrid'"):
        evaluate_submission(path, custom, "thrid")


def test_split_and_version_must_agree() -> None:
    check_split_version("mini_val", "v1.0-mini")
    check_split_version("my_custom_split", "v1.0-mini")
    with pytest.raises(DataError, match="split val cannot be evaluated on dataset version v1.0-mini"):
        check_split_version("val", "v1.0-mini")
    with pytest.raises(DataError, match="ending in 'mini'"):
        check_split_version("mini_train", "v1.0-trainval")


def test_format_metric() -> None:
    assert format_metric("amota", 0.12345) == "0.123"
    assert format_metric("ids", 3.0) == "3"
    assert format_metric("mota", float("nan")) == "-"
