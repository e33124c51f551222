"""Submission building, atomic writing and the one-line checks, on hand-made data (no dataset needed)."""

from __future__ import annotations

import json
import os
import re
import stat
from pathlib import Path

import numpy as np
import pytest

from gnnpmb.data.scene import Keyframe, Pose, SceneData
from gnnpmb.errors import DataError
from gnnpmb.eval.submission import (
    MAX_BOXES_PER_SAMPLE,
    SUBMISSION_META,
    build_submission,
    check_submission,
    gt_results,
    read_submission,
    run_results,
    write_submission,
)
from gnnpmb.pipeline import FrameResult, TrackingRun
from gnnpmb.types import Boxes, FrameDetections, TrackEstimate

SPLIT = ["s0", "s1", "s2"]
DATASET = SPLIT + ["other0", "other1"]


def box(token: str, track_id: str = "1", name: str = "car", **changes) -> dict:
    b = {
        "sample_token": token,
        "translation": [1.0, 2.0, 0.5],
        "size": [1.9, 4.5, 1.6],
        "rotation": [1.0, 0.0, 0.0, 0.0],
        "velocity": [0.5, 0.0],
        "tracking_id": track_id,
        "tracking_name": name,
        "tracking_score": 0.8,
    }
    b.update(changes)
    return b


def submission(**per_token: list[dict]) -> dict:
    results = {t: [box(t)] for t in SPLIT}
    results.update(per_token)
    return {"meta": dict(SUBMISSION_META), "results": results}


def check(data: dict) -> None:
    check_submission(data, "results.json", "mini_val", SPLIT, set(DATASET))


def keyframe(i: int, gt: Boxes, num_pts: list[int]) -> Keyframe:
    identity = Pose(np.zeros(3), np.array([1.0, 0.0, 0.0, 0.0]))
    return Keyframe(i, f"s{i}", 1_000_000 * i, identity, identity, Path("x.bin"), gt, np.array(num_pts))


def test_run_results_has_one_entry_per_frame_with_the_estimates() -> None:
    estimate = TrackEstimate(
        7, "pedestrian", (1.0, 2.0, 0.9), (0.6, 0.7, 1.8), (1.0, 0.0, 0.0, 0.0), (0.1, 0.2), 0.6, 0.95
    )
    frames = tuple(
        FrameResult(
            keyframe(i, Boxes.empty(), []),
            FrameDetections(Boxes.empty(), np.zeros(0, bool), np.zeros(0, bool), np.zeros(0, bool)),
            (estimate,) if i == 1 else (),
            0.0,
        )
        for i in range(2)
    )
    scene = SceneData("scene-x", "tok", "", Path("."), "v1.0-mini", True, tuple(f.keyframe for f in frames))
    results = run_results(TrackingRun("gnnpmb", scene, frames))
    assert results["s0"] == []
    assert results["s1"] == [
        {
            "sample_token": "s1",
            "translation": [1.0, 2.0, 0.9],
            "size": [0.6, 0.7, 1.8],
            "rotation": [1.0, 0.0, 0.0, 0.0],
            "velocity": [0.1, 0.2],
            "tracking_id": "7",
            "tracking_name": "pedestrian",
            "tracking_score": 0.6,
        }
    ]


def test_gt_results_drop_boxes_without_points_and_use_instance_ids() -> None:
    gt = Boxes(
        translation_m=np.array([[0.0, 0.0, 1.0], [5.0, 0.0, 1.0]]),
        size_wlh_m=np.ones((2, 3)),
        quat_wxyz=np.tile([1.0, 0.0, 0.0, 0.0], (2, 1)),
        velocity_mps=np.array([[np.nan, np.nan], [1.0, 0.0]]),
        score=np.ones(2),
        class_name=np.array(["car", "bus"], dtype=object),
        instance_id=np.array(["inst-a", "inst-b"], dtype=object),
    )
    scene = SceneData("scene-x", "tok", "", Path("."), "v1.0-mini", True, (keyframe(0, gt, [3, 0]),))
    results = gt_results(scene)
    assert [b["tracking_id"] for b in results["s0"]] == ["inst-a"]
    assert results["s0"][0]["velocity"] == [0.0, 0.0]
    assert results["s0"][0]["tracking_score"] == 1.0


def test_build_submission_fills_every_sample_and_refuses_strangers() -> None:
    sub = build_submission([{"s1": [box("s1")]}], SPLIT)
    assert sub["meta"] == SUBMISSION_META
    assert list(sub["results"]) == SPLIT
    assert sub["results"]["s0"] == [] and len(sub["results"]["s1"]) == 1
    with pytest.raises(DataError, match="other0"):
        build_submission([{"other0": []}], SPLIT)


def test_build_submission_keeps_the_500_best_scored_boxes_of_a_sample() -> None:
    boxes = [box("s1", track_id=str(i), tracking_score=(i % 7) / 10) for i in range(503)]
    kept = build_submission([{"s1": boxes}], SPLIT)["results"]["s1"]
    assert len(kept) == 500
    dropped = {b["tracking_id"] for b in boxes} - {b["tracking_id"] for b in kept}
    assert all(float(next(b for b in boxes if b["tracking_id"] == t)["tracking_score"]) == 0.0 for t in dropped)
    assert [b["tracking_id"] for b in build_submission([{"s1": boxes[:3]}], SPLIT)["results"]["s1"]] == ["0", "1", "2"]


def test_valid_submission_passes() -> None:
    stats = check_submission(submission(), "results.json", "mini_val", SPLIT, set(DATASET))
    assert (stats.samples, stats.boxes) == (3, 3)


def test_missing_samples_name_the_split() -> None:
    data = submission()
    del data["results"]["s0"], data["results"]["s2"]
    with pytest.raises(DataError) as err:
        check(data)
    assert str(err.value) == ("results.json lacks 2 of the 3 samples of split mini_val; was it made for another split?")


def test_samples_of_other_splits_and_unknown_samples_are_told_apart() -> None:
    with pytest.raises(DataError, match="1 samples of other splits than mini_val .e.g. other1"):
        check(submission(other1=[]))
    with pytest.raises(DataError, match="not in the dataset .e.g. nowhere.; was it made for another dataset"):
        check(submission(nowhere=[]))


@pytest.mark.parametrize(
    ("bad_box", "message"),
    [
        (box("s1", translation=[1.0, float("nan"), 0.0]), "box 0 of sample s1 field 'translation' has a NaN"),
        (box("s1", velocity=[0.0, float("inf")]), "field 'velocity' has a NaN or infinite value"),
        (box("s1", size=[1.0, 2.0]), "field 'size' must be a list of 3 numbers, got [1.0, 2.0]"),
        (box("s1", rotation="1 0 0 0"), "field 'rotation' must be a list of 4 numbers"),
        (box("s1", name="barrier"), "has tracking_name 'barrier', not one of the tracking classes"),
        (box("s1", tracking_score=float("nan")), "field 'tracking_score' must be finite"),
        (box("s1", tracking_score="high"), "field 'tracking_score' must be a number"),
        (box("s1", tracking_id=""), "field 'tracking_id' must be a non-empty string"),
        (box("s1", sample_token="s2"), "has sample_token 's2'; it must equal its results key"),
        (
            {k: v for k, v in box("s1").items() if k != "velocity"},
            "box 0 of sample s1 has no 'velocity' field",
        ),
        ("a box", "box 0 of sample s1 is a str, not an object"),
    ],
)
def test_bad_boxes_are_named(bad_box: object, message: str) -> None:
    with pytest.raises(DataError) as err:
        check(submission(s1=[bad_box]))
    assert message in str(err.value)
    assert "\n" not in str(err.value)


def test_bad_box_after_good_ones_is_found() -> None:
    with pytest.raises(DataError, match="box 2 of sample s2 has tracking_name 'cone'"):
        check(submission(s2=[box("s2"), box("s2", "2"), box("s2", "3", name="cone")]))


def test_too_many_boxes_and_bad_layout() -> None:
    with pytest.raises(DataError, match=f"at most {MAX_BOXES_PER_SAMPLE} per sample"):
        check(submission(s0=[box("s0", str(i)) for i in range(MAX_BOXES_PER_SAMPLE + 1)]))
    with pytest.raises(DataError, match="results entry of sample s0 is a dict"):
        check(submission(s0={}))
    with pytest.raises(DataError, match="no 'results' object"):
        check({"meta": {}, "results": [1]})
    with pytest.raises(DataError, match="no 'meta' object"):
        check({"results": submission()["results"]})


def test_integer_tracking_ids_are_accepted() -> None:
    check(submission(**{t: [box(t, track_id=3)] for t in SPLIT}))


def test_integer_and_string_ids_in_one_file_are_refused() -> None:
    """The devkit keeps ids as read (3 and "3" are two tracks to it): one type per file (issue 33 case 3)."""
    with pytest.raises(DataError, match=r"tracking_id is an integer in some boxes \(e.g. sample s1\) and a string"):
        check(submission(s1=[box("s1", track_id=3)]))


@pytest.mark.parametrize(
    ("changes", "message"),
    [
        ({"rotation": [0.0, 0.0, 0.0, 0.0]}, "field 'rotation' is not a rotation"),
        ({"rotation": [2.0, 0.0, 0.0, 0.0]}, "field 'rotation' is not a unit quaternion (length 2)"),
        ({"size": [0.0, 4.5, 1.6]}, "field 'size' must be positive"),
        ({"size": [-1.0, 4.5, 1.6]}, "field 'size' must be positive"),
        ({"translation": [1e6 + 600.0, 1600.0, 1.0]}, "field 'translation' is beyond 1e+05 m"),
        ({"velocity": [900.0, 0.0]}, "field 'velocity' is faster than 200 m/s"),
    ],
)
def test_impossible_boxes_are_refused_like_in_detection_files(changes: dict, message: str) -> None:
    with pytest.raises(DataError, match=re.escape(f"box 0 of sample s1 {message}")):
        check(submission(s1=[box("s1", **changes)]))


def test_write_is_atomic_and_refuses_nan(tmp_path: Path) -> None:
    path = tmp_path / "out" / "results.json"
    write_submission(path, submission())
    before = path.read_bytes()
    with pytest.raises(ValueError):
        write_submission(path, submission(s0=[box("s0", tracking_score=float("nan"))]))
    assert path.read_bytes() == before
    assert sorted(p.name for p in path.parent.iterdir()) == ["results.json"]
    assert read_submission(path) == json.loads(before)


@pytest.mark.parametrize(
    ("content", "message"),
    [
        (
            b'{"meta": {}, "results": {"s0": [',
            "is not valid JSON: Expecting value at line 1, column 33; is it truncated",
        ),
        (b'{"meta": "\xe9"}', "is not UTF-8 JSON text"),
        (b"[1, 2]", "holds a JSON list, not a tracking submission"),
    ],
)
def test_read_reports_broken_files(tmp_path: Path, content: bytes, message: str) -> None:
    path = tmp_path / "results.json"
    path.write_bytes(content)
    with pytest.raises(DataError, match=message.replace("(", ".").replace(")", ".")):
        read_submission(path)
    with pytest.raises(DataError, match="results file not found"):
        read_submission(tmp_path / "missing.json")


def test_empty_submission_is_refused_with_a_hint() -> None:
    empty = {"meta": dict(SUBMISSION_META), "results": {t: [] for t in SPLIT}}
    with pytest.raises(DataError, match=f"has no boxes in any of the {len(SPLIT)} samples of split mini_val"):
        check(empty)


def test_duplicate_tracking_id_in_one_sample_is_refused() -> None:
    token = SPLIT[0]
    twice = [box(token, "7"), box(token, "7", translation=[5.0, 2.0, 0.5])]
    with pytest.raises(DataError, match=f"sample {token} has two car boxes with tracking_id '7'"):
        check(submission(**{token: twice}))
    check(submission(**{token: [box(token, "7"), box(token, "7", name="pedestrian")]}))


def test_json_output_follows_the_umask_and_keeps_a_symlink_and_a_mode(tmp_path: Path) -> None:
    """One file-mode policy for every output (``gnnpmb.atomic``): a new file gets 0666 minus the umask, a file
    written over keeps its mode."""
    target = tmp_path / "real.json"
    link = tmp_path / "link.json"
    target.write_text("{}")
    target.chmod(0o604)
    link.symlink_to(target)
    new = tmp_path / "new.json"
    old = os.umask(0o027)
    try:
        write_submission(link, submission())
        write_submission(new, submission())
    finally:
        os.umask(old)
    assert link.is_symlink() and read_submission(target) == submission()
    assert stat.S_IMODE(target.stat().st_mode) == 0o604
    assert stat.S_IMODE(new.stat().st_mode) == 0o640
