"""Another tracker's results as a run (``gnnpmb.foreign``): checked like a submission, placed on detections, replayed
as output-only events."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from gnnpmb.errors import GnnpmbError
from gnnpmb.foreign import NEAREST_M, OnHow, box_on
from gnnpmb.stages.runs import run_one
from gnnpmb.types import Boxes
from gnnpmb.why.facts import UseMode, Went
from tests.pipeline import prepare

SCENE = "scene-0103"


def _boxes() -> Boxes:
    q = np.array([[1.0, 0, 0, 0], [0.9, 0, 0, 0.43589]])
    return Boxes(
        translation_m=np.array([[0.0, 0.0, 1.0], [3.0, 0.0, 1.0]]),
        size_wlh_m=np.array([[2.0, 4.5, 1.6], [2.0, 4.5, 1.6]]),
        quat_wxyz=q,
        velocity_mps=np.zeros((2, 2)),
        score=np.array([0.9, 0.8]),
        class_name=np.array(["car", "car"], dtype=object),
        instance_id=np.array(["", ""], dtype=object),
    )


def test_a_box_sits_on_the_detection_it_carries_else_the_nearest_within_reach() -> None:
    det = _boxes()
    size = np.array([2.0, 4.5, 1.6])
    # the second detection's size, heading and height, though 1.2 m from it (a filtered position)
    on = box_on(np.array([1.8, 0.0]), 1.0, size, det.quat_wxyz[1], "car", det)
    assert (on.meas, on.how) == (1, OnHow.SAME_BOX) and on.distance_m == pytest.approx(1.2)
    on = box_on(np.array([2.8, 0.1]), 1.3, size, np.array([1.0, 0, 0, 0]), "car", det)  # another height
    assert (on.meas, on.how) == (1, OnHow.NEAREST)
    assert box_on(np.array([1.5, 0.0]), 1.3, size, np.array([1.0, 0, 0, 0]), "car", det) is None  # > NEAREST_M
    assert NEAREST_M < 1.5
    assert box_on(np.array([0.0, 0.0]), 1.0, size, det.quat_wxyz[0], "truck", det) is None  # another class


def _write(path: Path, data: dict) -> Path:
    path.write_text(json.dumps(data))
    return path


def test_results_of_a_scene_are_checked_and_replayed(demo_dataroot: Path, cv_results: Path) -> None:
    request = prepare(SCENE, [], results=[f"cv={cv_results}"], dataroot=demo_dataroot, frames="0:12")
    assert request.trackers == ("cv",) and request.capabilities("cv").output_only
    assert any("samples outside scene-0103 left out" in n for n in request.notices)  # scene-0916's, reported
    foreign = request.foreign["cv"]
    assert len(foreign.estimates) == len(request.scene.keyframes) and not foreign.original_ids
    recorded = run_one(request, "cv", record=True)
    run, facts = recorded.tracking, recorded.facts
    assert facts is not None
    assert [fr.keyframe.index for fr in run.frames] == list(range(12)) and run.tracker == "cv"
    assert all(fr.detections.kept.all() for fr in run.frames)  # every detection given: its own filter is unknown
    use = facts.use(5, "car")
    assert use.mode is UseMode.OUTPUT and not facts.has_existence
    on = [e for e in run.frames[5].estimates if e.class_name == "car" and e.meas_index >= 0]
    assert on and all(use.destinations[e.meas_index].went is Went.TRACK for e in on)
    assert any(d.went is Went.NO_OUTPUT for d in use.destinations.values())
    assert facts.decisions(5, "car") is None and facts.hypotheses(5, "car") is None


def test_ids_that_are_not_plain_integers_are_numbered(demo_dataroot: Path, cv_results: Path, tmp_path: Path) -> None:
    data = json.loads(cv_results.read_text())
    for boxes in data["results"].values():
        for b in boxes:
            b["tracking_id"] = f"cv-{b['tracking_id']}"
    path = _write(tmp_path / "named.json", data)
    request = prepare(SCENE, [], results=[f"cv={path}"], dataroot=demo_dataroot)
    foreign = request.foreign["cv"]
    first = foreign.estimates[0][0]
    assert foreign.original_ids[first.track_id].startswith("cv-")
    assert any("numbered 1 to" in n for n in request.notices)


@pytest.mark.parametrize(
    ("edit", "message"),
    [
        ("drop", "lacks 3 of the 40 samples of scene-0103"),
        ("unknown", "samples that are not in the dataset"),
        ("other scene", "has none of the 40 samples of scene-0103"),
        ("nan", "has a NaN or infinite value"),
        ("twice", "has two car boxes with tracking_id"),
        ("empty", "has no boxes in the 40 samples of scene-0103"),
    ],
)
def test_a_bad_results_file_is_one_line(
    demo_dataroot: Path, cv_results: Path, tmp_path: Path, edit: str, message: str
) -> None:
    data = json.loads(cv_results.read_text())
    scene = prepare(SCENE, ["gnn"], dataroot=demo_dataroot, frames="0:1").scene
    tokens = [k.sample_token for k in scene.keyframes]
    results = data["results"]
    match edit:
        case "drop":
            for t in tokens[:3]:
                del results[t]
        case "unknown":
            results["not-a-sample"] = []
        case "other scene":
            for t in tokens:
                del results[t]
        case "nan":
            box = next(b for t in tokens for b in results[t])
            box["translation"][0] = float("nan")
        case "twice":
            t = next(t for t in tokens if any(b["tracking_name"] == "car" for b in results[t]))
            car = next(b for b in results[t] if b["tracking_name"] == "car")
            results[t].append(dict(car))
        case "empty":
            for t in tokens:
                results[t] = []
    path = tmp_path / "bad.json"
    path.write_text(json.dumps(data))
    with pytest.raises(GnnpmbError) as raised:
        prepare(SCENE, [], results=[f"cv={path}"], dataroot=demo_dataroot)
    assert message in str(raised.value) and "\n" not in str(raised.value)
