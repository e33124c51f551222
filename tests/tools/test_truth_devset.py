"""The independent checker (``tools.truth``) on the dev set, a world this project did not make. In CI: two cells
of mini_val, each with a tracker whose findings exercise the rules that broke there (GNN's counterfactuals and
margins, AB3DMOT's lost tracks with a column of infinite cost), and one of mini_train (PHD's false track beside an
object the devkit matched to a track's interpolated box, with PMBM's outcome on the same detections: the other
run's and the shares' sentences); and a results file of a tracker outside the project (``examples/cv_tracker.py``'s
constant-velocity tracker on the same detections), whose boxes the findings place on detections. Every checkable
sentence holds. The whole matrix (13 trackers × 10 scenes × 3
presets, mini_train detections for the 8 mini_train scenes) is ``-m exhaustive`` or
``uv run python -m tools.truth --all-scenes`` (docs/debugging.md)."""

from __future__ import annotations

import dataclasses
import os
from pathlib import Path

import pytest

from gnnpmb.foreign import OnHow
from gnnpmb.registry import TRACKER_NAMES
from tools.truth import __main__ as truth_main
from tools.truth.__main__ import PRESETS, other_of, run_cell, run_scene

DEVSET = Path(os.environ.get("GNNPMB_DEVSET", str(truth_main.DEVSET)))
HAS_DEVSET = pytest.mark.skipif(not (DEVSET / "v1.0-mini").is_dir(), reason=f"no dev set at {DEVSET} (GNNPMB_DEVSET)")
SQUARE = [  # (scene, preset, tracker, the run its findings compare with)
    ("scene-0103", "centerpoint", "gnn", None),
    ("scene-0916", "megvii", "ab3dmot", None),
    # mini_train: at frame 34 the devkit matched the object beside false_track:12 to track 57's interpolated box,
    # which no output holds (the explainer named track 49)
    ("scene-0553", "megvii", "phd", "pmbm"),
]
SCENES = truth_main.MINI_VAL + truth_main.MINI_TRAIN
BY_HAND = [
    ("scene-0916", "megvii", "cphd", "pmbm"),  # pmbm switched where cphd had a theft: it failed here too
    # the independent audit of round 42 (mini_train, the trackers first checked there): a soft share left unsaid,
    # another run's interpolated match called "did not have this failure", another run's switch called "did not fail"
    ("scene-1100", "centerpoint", "cphd", "simpletrack"),
    ("scene-1094", "pointpillars", "cbmot", "greedy"),
    ("scene-0553", "megvii", "prob3dmot", "ab3dmot"),
]
"""Cells run by hand (``-m exhaustive``): each checks the same kinds of sentence as a cell of ``SQUARE`` (CPHD's
beside PMBM's: matched, gone, misleading, detector, other run, share, output, tracker, evaluation and fields, as
PHD's beside PMBM's on scene-0553), at 6 s of CPU each."""


def _holds(scene: str, preset: str, tracker: str, other: str | None) -> None:
    where: list = []
    tally, findings = run_cell(tracker, scene, preset, DEVSET, where=where, other=other)
    assert findings > 0 and sum(tally.checked.values()) > 0, "nothing was checked"
    assert where == [], [f"{p}: [{c.kind}] {c.sentence} -- {c.truth}" for p, c in where[:5]]


@HAS_DEVSET
@pytest.mark.parametrize(("scene", "preset", "tracker", "other"), SQUARE)
def test_no_checkable_sentence_on_the_dev_set_is_false(scene: str, preset: str, tracker: str, other: str) -> None:
    _holds(scene, preset, tracker, other)


@HAS_DEVSET
@pytest.mark.exhaustive
@pytest.mark.parametrize(("scene", "preset", "tracker", "other"), BY_HAND)
def test_no_checkable_sentence_in_the_cells_run_by_hand_is_false(
    scene: str, preset: str, tracker: str, other: str
) -> None:
    _holds(scene, preset, tracker, other)


@HAS_DEVSET
@pytest.mark.exhaustive
@pytest.mark.parametrize("tracker", TRACKER_NAMES)
@pytest.mark.parametrize("preset", PRESETS)
@pytest.mark.parametrize("scene", SCENES)
def test_the_whole_dev_set_matrix_holds(scene: str, preset: str, tracker: str) -> None:
    _holds(scene, preset, tracker, other_of(tracker, "pmbm"))


def _cv_results(scene_name: str, detections: Path, out: Path) -> Path:
    """``examples/cv_tracker.py``'s tracker run on a dev-set scene's detection file, written as a submission."""
    from examples.cv_tracker import ConstantVelocityTracker
    from gnnpmb.data.nuscenes import load_scene, resolve_dataroot
    from gnnpmb.eval.submission import SUBMISSION_META, write_json
    from gnnpmb.pipeline import get_detections

    scene = load_scene(resolve_dataroot(DEVSET, "v1.0-mini", (scene_name,)), scene_name)
    boxes = get_detections(scene, detections, "centerpoint", 0)
    tracker, previous, results = ConstantVelocityTracker(), None, {}
    for k in scene.keyframes:
        dt_s = 0.0 if previous is None else (k.timestamp_us - previous) * 1e-6
        previous = k.timestamp_us
        results[k.sample_token] = tracker.step(k.sample_token, boxes[k.sample_token], dt_s)
    write_json(out, {"meta": dict(SUBMISSION_META), "results": results})
    return out


@HAS_DEVSET
def test_no_checkable_sentence_about_a_results_file_is_false(tmp_path: Path) -> None:
    detections = DEVSET / "detections" / "pointpillars_mini_val.json"
    cv = _cv_results("scene-0916", detections, tmp_path / "cv.json")
    where: list = []
    seen: list = []
    (tally, findings) = run_scene(
        "scene-0916",
        "pointpillars",
        {"cv": None},
        DEVSET,
        where=where,
        results={"cv": cv},
        seen=lambda f, src: seen.append((f, src)),
    )["cv"]
    assert findings > 0 and tally.checked["output"] > 0 and tally.checked["fields"] > 10 * findings
    assert where == [], [f"{p}: [{c.kind}] {c.sentence} -- {c.truth}" for p, c in where[:5]]
    # a field made false (the box's placement on a detection) is caught
    f, src = next((f, s) for f, s in seen if f.boxes_on)
    frame, track, on = f.boxes_on[0]
    how = OnHow.NEAREST if on.how is OnHow.SAME_BOX else OnHow.SAME_BOX
    lie = dataclasses.replace(f, boxes_on=((frame, track, dataclasses.replace(on, how=how)),))
    assert any("output on" in p for p in _field_problems(lie, src))
    moved = dataclasses.replace(f, boxes_on=((frame, track, dataclasses.replace(on, meas=on.meas + 1)),))
    assert _field_problems(moved, src)


def _field_problems(f, src) -> list[str]:
    from tools.truth.fields import check_fields
    from tools.truth.sentences import Tally

    out = Tally()
    check_fields(f, src, out, lambda kind, sentence, why: out.found.append(f"{sentence}: {why}"))
    return out.found
