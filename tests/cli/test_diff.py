"""``gnnpmb diff A B``: failures fixed, introduced and kept between two runs, matched by kind, frame and object or
place; the metric deltas; the focus ids that open a change with both runs side by side."""

from __future__ import annotations

import contextlib
import io
import json
from pathlib import Path

import pytest

from cli.app import main as viz_main
from gnnpmb.diff import Change, match_failures, scene_diff
from gnnpmb.eval.failures import Failure, FailureBox, FailureKind, FailureReport
from tests.inprocess import run_script
from tests.viz.rrd import read_rows
from viz.blueprint import focus_doc

SCENE = "scene-0103"
PAPER = "gnnpmb/params/paper.toml"


def _failure(kind: FailureKind, frame: int, gt: tuple[str, ...], tracks: tuple[str, ...], x: float = 0.0) -> Failure:
    box = FailureBox("gt" if gt else "false track", (gt or tracks)[0], (x, 0.0, 1.0), (2.0, 4.5, 1.6), (1, 0, 0, 0))
    return Failure(kind, frame, f"s{frame}", "car", gt, tracks, (box,))


def _report(failures: list[Failure]) -> FailureReport:
    return FailureReport("scene-x", "t", tuple(f"s{i}" for i in range(5)), (), tuple(failures))


def test_failures_are_matched_by_what_they_are_about_not_by_track_ids() -> None:
    a = _report(
        [
            _failure(FailureKind.ID_SWITCH, 2, ("g1",), ("4", "9")),
            _failure(FailureKind.MISS, 3, ("g2",), ()),
            _failure(FailureKind.FALSE_TRACK, 3, (), ("7",), x=10.0),
        ]
    )
    b = _report(
        [
            _failure(FailureKind.ID_SWITCH, 2, ("g1",), ("40", "90")),  # the same switch, other ids: kept
            _failure(FailureKind.FALSE_TRACK, 3, (), ("70",), x=11.5),  # within 2 m: the same false track
            _failure(FailureKind.FALSE_TRACK, 3, (), ("71",), x=30.0),  # elsewhere: introduced
        ]
    )
    pairs = match_failures(a, b)
    assert len(pairs) == 4
    entries = scene_diff("scene-x", a, b)
    got = {(e.diff_id, e.kind.value, e.before, e.after) for e in entries}
    assert got == {
        ("diff:kept:1", "id_switch", "id_switch:1", "id_switch:1"),
        ("diff:kept:2", "false_track", "false_track:1", "false_track:1"),
        ("diff:introduced:1", "false_track", None, "false_track:2"),
        ("diff:fixed:1", "miss", "miss:1", None),
    }
    assert [e.change for e in entries] == [Change.KEPT, Change.KEPT, Change.INTRODUCED, Change.FIXED]


def test_a_fixed_failure_names_what_the_other_run_had_there_instead() -> None:
    """dev set scene-0757 centerpoint, phd -> cphd: a fragmentation of car 96bc69 "fixed by B" where B lost the car
    for good; without ``instead`` the row read as if B had tracked it."""
    a = _report([_failure(FailureKind.FRAGMENTATION, 4, ("g3",), ("5",)), _failure(FailureKind.MISS, 4, ("g4",), ())])
    b = _report([_failure(FailureKind.MISS, 4, ("g3",), ())])
    entries = {e.diff_id: e for e in scene_diff("scene-x", a, b)}
    assert {k: (e.kind.value, e.instead) for k, e in entries.items()} == {
        "diff:fixed:1": ("fragmentation", ("miss:1",)),
        "diff:fixed:2": ("miss", ()),
        "diff:introduced:1": ("miss", ("fragmentation:1",)),
    }
    assert entries["diff:fixed:1"].to_json()["instead"] == ["miss:1"]


def test_diff_of_the_papers_parameters_and_the_defaults(
    demo_dataroot: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    """``gnnpmb diff`` as the console script runs it, in-process (``tests.inprocess``; the script's start in a
    real process is checked in ``tests/cli/test_user_errors.py``). With no failure report stored, the devkit
    accumulates each class of each run once: the metrics come from the accumulation that found the failures."""
    from nuscenes.eval.tracking.algo import TrackingEvaluation

    from gnnpmb.eval.nuscenes_eval import tracking_config

    monkeypatch.setenv("GNNPMB_CACHE_DIR", str(tmp_path / "cache"))
    accumulated: list[str] = []
    accumulate = TrackingEvaluation.accumulate
    monkeypatch.setattr(
        TrackingEvaluation, "accumulate", lambda self: accumulated.append(self.class_name) or accumulate(self)
    )
    out = tmp_path / "diff.json"
    proc = run_script(
        [
            "gnnpmb",
            "diff",
            f"gnnpmb:{PAPER}",
            "gnnpmb",
            "--scene",
            SCENE,
            "--dataroot",
            str(demo_dataroot),
            "--json",
            str(out),
        ],
        capsys,
    )
    assert proc.returncode == 0, proc.stderr
    assert sorted(accumulated) == sorted(tracking_config().class_names * 2)
    data = json.loads(out.read_text())
    assert (data["a"], data["b"], data["where"]) == (f"gnnpmb:{PAPER}", "gnnpmb", SCENE)
    totals = data["totals"]
    assert totals["fixed"] > 0 and sum(totals.values()) == len(data["changes"])
    last = proc.stdout.strip().splitlines()[-2]
    assert last.startswith(f"gnnpmb against gnnpmb-paper on {SCENE}: {totals['fixed']} failures fixed, ")
    assert f"{totals['introduced']} introduced, {totals['kept']} kept; AMOTA " in last
    amota = next(m for m in data["metrics"] if (m["class_name"], m["metric"]) == ("overall", "amota"))
    assert f"AMOTA {amota['a']:.3f} -> {amota['b']:.3f}" in last
    assert {m["class_name"] for m in data["metrics"]} >= {"car", "pedestrian", "overall"}
    change = data["changes"][0]
    assert change["command"] == (
        f"gnnpmb-viz {SCENE} --tracker gnnpmb:{PAPER} --tracker gnnpmb --dataroot {demo_dataroot} "
        f"--focus {change['id']}"
    )
    assert "fixed by B" in proc.stdout and "AMOTA" in proc.stdout

    # The id opens that change with both runs side by side, explained.
    pick = next(c for c in data["changes"] if c["change"] == "fixed" and c["kind"] == "id_switch")
    rec = tmp_path / "change.rrd"
    argv = [SCENE, "--tracker", f"gnnpmb:{PAPER}", "--tracker", "gnnpmb", "--dataroot", str(demo_dataroot)]
    with contextlib.redirect_stdout(io.StringIO()) as stdout:
        viz_main([*argv, "--focus", pick["id"], "--save", str(rec), "--no-progress"])
    assert f"focus: {pick['id']} (fixed from gnnpmb-paper to gnnpmb): {pick['a']} at frame {pick['frame']}" in (
        stdout.getvalue()
    )
    doc = read_rows(rec)[focus_doc()][0]["TextDocument:text"][0]
    assert "**Why** (gnnpmb-paper, " in doc and "gnnpmb on the same detections did not" in doc


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["gnnpmb", "gnnpmb"], "A and B are the same run (gnnpmb)"),
        (["gnnpmb", "pmbm", "--scene", SCENE, "--split", "mini_val"], "pass either --scene SCENE or --split NAME"),
        (["gnnpmb", "nope"], "unknown tracker 'nope'"),
        (["gnnpmb", "pmbm", "--scene", "scene-9999"], "unknown scene 'scene-9999'"),
    ],
)
def test_diff_errors_are_one_line(demo_dataroot: Path, args: list[str], message: str) -> None:
    from cli.batch import app
    from cli.errors import run_app

    err = io.StringIO()
    with contextlib.redirect_stderr(err), contextlib.redirect_stdout(io.StringIO()), pytest.raises(SystemExit) as ex:
        run_app(app, ["diff", *args, "--dataroot", str(demo_dataroot)])
    lines = err.getvalue().strip().splitlines()
    assert ex.value.code == 2 and len(lines) == 1 and message in lines[0], lines
