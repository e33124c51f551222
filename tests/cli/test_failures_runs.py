"""``gnnpmb failures --why`` says a repeated story once (``why.runs``): what the user reads, from hand-made
findings printed by the command's own ``print_findings``, and the command end to end on the tiny demo."""

from __future__ import annotations

import functools
import io
import json
import re
from pathlib import Path

import pytest
from rich.console import Console

from cli.batch import app
from cli.errors import run_app
from cli.failures import print_findings
from gnnpmb.eval.failures import FailureKind
from gnnpmb.why.findings import Blame, Finding, Near, OtherRun, Rule, Sighting
from tests.inprocess import run_main

GT = "bdb19c" + "0" * 26
OTHER_GT = "9348e3" + "0" * 26
SAME = OtherRun("immortal", True, ())
DIFFERENT = OtherRun("immortal", False, (), missed=True)


def miss(
    n: int,
    frame: int,
    *,
    points: int = 25,
    gt: str = GT,
    other: OtherRun = SAME,
    near: Near | None = None,
    track_ids: tuple[int, ...] = (),
) -> Finding:
    """miss:n at ``frame``: the detector gave nothing within 2 m (or, with ``near``, a detection of another class)."""
    rule = Rule.OTHER_CLASS if near is not None else Rule.NO_DETECTION
    return Finding(
        failure_id=f"miss:{n}",
        kind=FailureKind.MISS,
        tracker="gnnpmb",
        frame=frame,
        class_name="bicycle",
        gt_id=gt,
        track_ids=track_ids,
        window=(frame, frame),
        deciding=(frame,),
        blame=(Blame(rule, (frame,)),),
        sightings=(Sighting(frame, points, None, near, None, None, ()),),
        mode="assigned",
        has_existence=True,
        others=(other,),
    )


def printed(findings: list[Finding], *, each: bool = False) -> list[str]:
    out = io.StringIO()
    print_findings(findings, Console(file=out, width=100), each=each)
    return out.getvalue().splitlines()


def test_a_run_of_alike_findings_prints_once_with_its_ids_and_each_frames_values() -> None:
    lines = printed([miss(1, 6, points=25), miss(2, 7, points=31), miss(3, 8, points=31)])
    assert lines[0] == "miss:1-3 (frames 6-8, bicycle): the detector's doing"
    assert lines[1] == (
        "  Why (gnnpmb, the detector's doing): at frame <frame> the detector gave no detection of a tracked class "
        "within 2 m of bicycle GT bdb19c (<points> LiDAR and radar points in its box): the detector missed it; "
        "immortal on the same detections failed here too."
    )
    assert lines[2] == "  per frame (frame: <points>): 6: 25; 7: 31; 8: 31"
    assert sum(line.startswith("miss:") for line in lines) == 1
    assert "every finding is in --json" in lines[-1]


def test_a_value_that_does_not_vary_stays_in_the_text_and_only_the_frame_needs_no_line() -> None:
    lines = printed([miss(1, 6), miss(2, 7)])
    assert lines[0] == "miss:1-2 (frames 6-7, bicycle): the detector's doing"
    assert "(25 LiDAR and radar points in its box)" in lines[1] and not any(
        line.startswith("  per frame") for line in lines
    )


def test_findings_of_different_objects_or_tracks_are_never_joined() -> None:
    lines = printed([miss(1, 6), miss(2, 7, gt=OTHER_GT), miss(3, 8)])
    assert [line.split(" (")[0] for line in lines if line.startswith("miss:")] == ["miss:1", "miss:2", "miss:3"]
    lines = printed([miss(1, 6, track_ids=(41,)), miss(2, 7, track_ids=(42,))])
    assert [line.split(" (")[0] for line in lines if line.startswith("miss:")] == ["miss:1", "miss:2"]


def test_a_differing_reason_or_a_gap_in_frames_breaks_the_run() -> None:
    truck = Near(15, "truck", 0.97, 0.3, True)
    lines = printed([miss(1, 6), miss(2, 7), miss(3, 8, near=truck), miss(4, 9), miss(5, 11)])
    heads = [line for line in lines if line.startswith("miss:")]
    assert [h.split(" (")[0] for h in heads] == ["miss:1-2", "miss:3", "miss:4", "miss:5"]
    assert "but a truck detection, m15 (score 0.97), 0.3 m away" in lines[lines.index(heads[1]) + 1]


def test_a_differing_comparison_breaks_the_run_and_a_repeated_one_names_where_it_was_said() -> None:
    lines = printed([miss(1, 6), miss(2, 7, other=DIFFERENT), miss(3, 9, other=DIFFERENT, points=3)])
    heads = [line for line in lines if line.startswith("miss:")]
    assert [h.split(" (")[0] for h in heads] == ["miss:1", "miss:2", "miss:3"]
    assert lines[lines.index(heads[1]) + 1].endswith(
        "; immortal on the same detections had no counted track on the object here either."
    )
    assert lines[lines.index(heads[2]) + 1].endswith("the detector missed it; immortal: as for miss:2.")
    assert "'T: as for ID'" in lines[-1]


def test_a_lone_finding_reads_as_before() -> None:
    lines = printed([miss(1, 6), miss(2, 8, gt=OTHER_GT)])
    assert lines[0] == "miss:1 (frame 6, bicycle): the detector's doing"
    assert "at frame 6 the detector gave no detection" in lines[1]
    assert not any("(findings alike" in line for line in lines)  # nothing was joined: no note


def test_each_prints_every_finding_in_full() -> None:
    lines = printed([miss(1, 6, points=25), miss(2, 7, points=31)], each=True)
    assert [line for line in lines if line.startswith("miss:")] == [
        "miss:1 (frame 6, bicycle): the detector's doing",
        "miss:2 (frame 7, bicycle): the detector's doing",
    ]
    assert "at frame 7 the detector gave no detection" in lines[3] and "(31 LiDAR and radar points" in lines[3]
    assert len(lines) == 4


def run(argv: list[str], capsys: pytest.CaptureFixture[str]) -> tuple[int, str, str]:
    return run_main(functools.partial(run_app, app), argv, capsys)


def test_the_command_keeps_every_finding_in_json_and_every_id_in_the_text(
    two_scene_dataroot: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    path = tmp_path / "why.json"
    argv = ["failures", "scene-0916", "--dataroot", str(two_scene_dataroot), "--why", "--json", str(path)]
    code, out, err = run(argv, capsys)
    assert code == 0, err
    report = json.loads(path.read_text())
    assert len(report["findings"]) == len(report["failures"]) > 0
    assert {f["failure_id"] for f in report["findings"]} == set(_ids(report["failures"]))
    assert sorted(shown_ids(out)) == sorted(_ids(report["failures"]))  # each once


def shown_ids(out: str) -> list[str]:
    """Every failure id the headings of ``failures --why`` name (``miss:12-14`` names three), as often as named."""
    shown = []
    for head in re.findall(r"^([a-z_]+:[\d, \-]+) \(frames? ", out, flags=re.M):
        kind, numbers = head.split(":")
        for part in numbers.split(", "):
            a, _, b = part.partition("-")
            shown += [f"{kind}:{n}" for n in range(int(a), int(b or a) + 1)]
    return shown


def test_each_without_why_is_a_one_line_error(demo_dataroot: Path, capsys: pytest.CaptureFixture[str]) -> None:
    code, out, err = run(["failures", "scene-0916", "--dataroot", str(demo_dataroot), "--each"], capsys)
    assert code == 2 and out == ""
    assert err.strip() == "error: --each prints the findings of --why in full: add --why"


def _ids(failures: list[dict]) -> list[str]:
    seen: dict[str, int] = {}
    out = []
    for f in failures:
        seen[f["kind"]] = seen.get(f["kind"], 0) + 1
        out.append(f"{f['kind']}:{seen[f['kind']]}")
    return out
