"""Failure reports stored between runs: read back equal, reused only for the same tracks, data and code."""

from __future__ import annotations

import copy
import json
from pathlib import Path

import numpy as np
import pytest

from gnnpmb.data.nuscenes import DatasetLocation, check_dataroot, load_scene, open_nuscenes
from gnnpmb.eval import failure_cache
from gnnpmb.eval.failure_cache import FAILURES_FOLDER, cached_report
from gnnpmb.eval.failures import FailureKind, FailureReport, find_failures
from gnnpmb.eval.submission import gt_results
from tests.gnnpmb.eval.test_failures import SCENE, relabel, visible_throughout

SWITCH_FRAME = 12


@pytest.fixture(scope="module")
def location(demo_dataroot: Path) -> DatasetLocation:
    return check_dataroot(demo_dataroot, "v1.0-mini")


@pytest.fixture(scope="module")
def nusc(location: DatasetLocation):
    return open_nuscenes(location)


@pytest.fixture(scope="module")
def switched(nusc, location: DatasetLocation) -> dict[str, list[dict]]:
    """The ground truth with one visible object's id changed from SWITCH_FRAME on: one ID switch."""
    scene = load_scene(location, SCENE)
    results = gt_results(scene)
    instance = sorted(visible_throughout(scene, range(SWITCH_FRAME - 1, SWITCH_FRAME + 1)))[0]
    relabel(results, range(SWITCH_FRAME, len(results)), instance, "switched")
    return results


@pytest.fixture(scope="module")
def report(nusc, switched: dict) -> FailureReport:
    return find_failures(nusc, SCENE, switched, "staged")


class Finder:
    """Stands in for the devkit evaluation of the cache's caller: returns ``report`` and counts its calls."""

    def __init__(self, report: FailureReport) -> None:
        self.report, self.calls = report, 0

    def __call__(self) -> FailureReport:
        self.calls += 1
        return self.report


def test_a_report_reads_back_equal(report: FailureReport) -> None:
    assert report.of_kind(FailureKind.ID_SWITCH)
    assert FailureReport.from_json(json.loads(json.dumps(report.to_json(), allow_nan=False))) == report


def test_the_second_run_of_the_same_tracks_reuses_the_report(
    report: FailureReport, location: DatasetLocation, switched: dict, tmp_path: Path
) -> None:
    find = Finder(report)
    first = cached_report(tmp_path, location, SCENE, "staged", switched, find)
    again = cached_report(tmp_path, location, SCENE, "staged", switched, find)
    assert find.calls == 1
    assert again == first and again.ids() == first.ids() == ["id_switch:1"]
    assert len(list((tmp_path / FAILURES_FOLDER).glob("*.json"))) == 1


def test_other_tracks_or_tracker_names_are_evaluated_again(
    report: FailureReport, location: DatasetLocation, switched: dict, tmp_path: Path
) -> None:
    cached_report(tmp_path, location, SCENE, "staged", switched, Finder(report))
    moved = copy.deepcopy(switched)
    first_box = next(boxes for boxes in moved.values() if boxes)[0]
    first_box["translation"][0] += 0.5
    find = Finder(report)
    cached_report(tmp_path, location, SCENE, "staged", moved, find)
    assert find.calls == 1
    renamed = Finder(report)
    cached_report(tmp_path, location, SCENE, "other", switched, renamed)
    assert renamed.calls == 1


def test_a_damaged_or_unwritable_cache_only_costs_an_evaluation(
    report: FailureReport, location: DatasetLocation, switched: dict, tmp_path: Path
) -> None:
    cached_report(tmp_path, location, SCENE, "staged", switched, Finder(report))
    (stored,) = (tmp_path / FAILURES_FOLDER).glob("*.json")
    stored.write_text('{"scene": "scene-0103", "failures": [', encoding="utf-8")
    find = Finder(report)
    report = cached_report(tmp_path, location, SCENE, "staged", switched, find)
    assert find.calls == 1 and report.ids() == ["id_switch:1"]
    assert FailureReport.from_json(json.loads(stored.read_text(encoding="utf-8"))["row"]) == report  # a checked row

    blocked = tmp_path / "file-not-folder"
    blocked.write_text("", encoding="utf-8")
    find = Finder(report)
    assert cached_report(blocked, location, SCENE, "staged", switched, find).ids() == ["id_switch:1"]
    assert find.calls == 1


def test_only_the_newest_reports_are_kept(
    report: FailureReport, location: DatasetLocation, switched: dict, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setattr(failure_cache, "MAX_REPORTS", 2)
    for name in ("a", "b", "c"):
        cached_report(tmp_path, location, SCENE, name, switched, Finder(report))
    assert len(list((tmp_path / FAILURES_FOLDER).glob("*.json"))) == 2
    newest = Finder(report)
    cached_report(tmp_path, location, SCENE, "c", switched, newest)
    assert newest.calls == 0


def test_the_key_counts_the_boxes_numbers_not_their_objects_order_of_tokens_or_spelling(
    location: DatasetLocation, switched: dict
) -> None:
    def key(results: dict) -> str:
        return failure_cache.report_key(location, SCENE, "staged", results)

    first = key(switched)
    assert key(dict(reversed(list(json.loads(json.dumps(switched)).items())))) == first
    spelled = copy.deepcopy(switched)
    box = next(boxes for boxes in spelled.values() if boxes)[0]
    assert box["tracking_score"] == 1.0
    box["tracking_score"] = 1  # the same number to the evaluation
    assert key(spelled) == first
    box["rotation"][1] = float(np.nextafter(box["rotation"][1], 1.0))  # one float64 step
    assert key(spelled) != first
    extra = copy.deepcopy(switched)
    next(boxes for boxes in extra.values() if boxes)[0]["attribute_name"] = ""  # another layout: JSON
    assert key(extra) not in (first, key(spelled)) and key(copy.deepcopy(extra)) == key(extra)
