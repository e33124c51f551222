"""Another tracker's results file in the debugger (``--results NAME=FILE.json``): its failures listed and explained
by ``gnnpmb failures``, a focus recording read back, and its one-line errors."""

from __future__ import annotations

import contextlib
import io
import json
import re
import subprocess
import sys
from pathlib import Path

import pytest

from cli.app import main as viz_main
from tests.cli.test_failures_runs import shown_ids
from tests.inprocess import run_script, run_script_captured
from tests.viz.rrd import read_rows
from tests.viz.test_blueprint import stored_views
from viz import paths
from viz.blueprint import focus_doc

SCENE = "scene-0103"
CvFailures = tuple[subprocess.CompletedProcess[str], dict]


@pytest.fixture(scope="module")
def cv_failures(demo_dataroot: Path, cv_results: Path, tmp_path_factory: pytest.TempPathFactory) -> CvFailures:
    """``gnnpmb failures SCENE --results cv=FILE --tracker gnnpmb --why --json F`` in-process as the console script
    runs it (``tests.inprocess``; the script's own process start is checked in ``test_batch.py``), run once for the
    module: the finished command and the JSON it wrote (read-only)."""
    report = tmp_path_factory.mktemp("cv_failures") / "cv_failures.json"
    argv = ["gnnpmb", "failures", SCENE, "--results", f"cv={cv_results}", "--tracker", "gnnpmb"]
    proc = run_script_captured([*argv, "--dataroot", str(demo_dataroot), "--why", "--json", str(report)])
    assert proc.returncode == 0, proc.stderr
    return proc, json.loads(report.read_text())


def test_failures_of_a_results_file(cv_failures: CvFailures) -> None:
    proc, data = cv_failures
    assert "note: cv.json: " in proc.stderr and "samples outside scene-0103 left out" in proc.stderr
    out = proc.stdout
    assert f"{SCENE}, cv: " in out and f"{SCENE}, gnnpmb: " in out  # both runs, the results first
    assert out.index(f"{SCENE}, cv: ") < out.index(f"{SCENE}, gnnpmb: ")
    assert data["tracker"] == "cv" and [r["tracker"] for r in data["other_runs"]] == ["gnnpmb"]
    findings = data["findings"]
    assert findings and all(f["mode"] == "output only" for f in findings)
    why = [line for line in out.splitlines() if line.startswith("  Why (cv, ")]
    cv = out[out.index(f"{SCENE}, cv: ") : out.index(f"{SCENE}, gnnpmb: ")]
    assert len(why) == len(re.findall(r"^[a-z_]+:[\d, \-]+ \(frames? ", cv, flags=re.M))  # a Why per entry
    assert sorted(shown_ids(cv)) == sorted(f["failure_id"] for f in findings)  # every finding named once
    text = "\n".join(why)
    # Nothing about its update: no gates, existences, costs or births, only where its boxes were.
    for word in ("gate", "existence", "cost", "NIS", "started by", "was given", "(p "):
        assert word not in text, word
    assert "its box carries m" in text and "gnnpmb on the given detections" in text


def test_a_focus_recording_of_a_results_run(
    demo_dataroot: Path, cv_results: Path, tmp_path: Path, cv_failures: CvFailures
) -> None:
    _, report = cv_failures  # the results file's failures as ``gnnpmb failures`` lists them
    pick = next(f"id_switch:{n}" for n, _ in enumerate([f for f in report["failures"] if f["kind"] == "id_switch"], 1))
    out = tmp_path / "cv.rrd"
    argv = [SCENE, "--results", f"cv={cv_results}", "-t", "gnnpmb", "--dataroot", str(demo_dataroot)]
    with contextlib.redirect_stdout(io.StringIO()) as stdout, contextlib.redirect_stderr(io.StringIO()):
        viz_main([*argv, "--focus", pick, "--save", str(out), "--no-progress"])
    assert f"focus: {pick} at frame" in stdout.getvalue() and "(cv)" in stdout.getvalue()
    rows = read_rows(out)
    doc = rows[focus_doc()][0]["TextDocument:text"][0]
    assert "**Why** (cv, " in doc and "| detection under its box | output |" in doc
    assert not any(p.startswith(f"{paths.tracker_world('cv')}/gates") for p in rows)  # drawn without introspection
    assert not any(p.startswith(paths.existence_root("cv")) for p in rows)
    assert any(p.startswith(paths.tracks("cv", "car") + "/") for p in rows)
    views = stored_views(out)
    assert {"cv bird's-eye", "cv 3D", "gnnpmb bird's-eye"} <= set(views)
    assert not any(
        name.startswith("cv ") and ("existence" in name or "cost" in name or "NIS" in name) for name in views
    )


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["--results", "gnnpmb={f}"], "results name 'gnnpmb' is a built-in tracker's"),
        (["--results", "mine={missing}"], "results file not found"),
        (["--results", "mine"], "bad --results 'mine': use NAME=FILE.json"),
        # the same run twice is one run (not "two runs are named 'a'"); a window of frames is enough to see it
        (["--results", "a={f}", "--tracker", "a={f}", "--frames", "0:5"], ""),
        (["--results", "a={f}", "--tracker", "a=gnnpmb"], "two runs are named 'a'"),
    ],
)
def test_results_errors_are_one_line(
    demo_dataroot: Path,
    cv_results: Path,
    tmp_path: Path,
    args: list[str],
    message: str,
    capsys: pytest.CaptureFixture[str],
) -> None:
    """In-process (``tests.inprocess.run_script``); ``gnnpmb failures --results`` in a real process is the test
    above."""
    args = [a.format(f=cv_results, missing=tmp_path / "missing.json") for a in args]
    proc = run_script(["gnnpmb", "failures", SCENE, *args, "--dataroot", str(demo_dataroot)], capsys)
    assert "Traceback" not in proc.stderr
    if not message:
        assert proc.returncode == 0, proc.stderr
        return
    lines = proc.stderr.strip().splitlines()
    assert proc.returncode == 2 and len(lines) == 1 and lines[0].startswith("error: ") and message in lines[0], lines


def test_a_recording_of_a_results_file_and_a_tracker_with_its_own_parameters_reproduces(
    demo_dataroot: Path, cv_results: Path, tmp_path: Path
) -> None:
    rec = tmp_path / "rep.rrd"
    argv = [SCENE, "--results", f"cv={cv_results}", "-t", "gnnpmb:gnnpmb/params/paper.toml", "--frames", "0:6"]
    with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(io.StringIO()):
        viz_main([*argv, "--dataroot", str(demo_dataroot), "--no-failures", "--save", str(rec), "--no-progress"])
    out = io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(io.StringIO()):
        viz_main(["reproduce", str(rec)])
    assert "cv: identical (6 frames)" in out.getvalue() and "gnnpmb-paper: identical (6 frames)" in out.getvalue()


def test_the_example_tracker_runs_on_ones_own_detection_file(demo_dataroot: Path, tmp_path: Path) -> None:
    """``examples/cv_tracker.py`` (docs/debugging.md's "a constant-velocity tracker of your own") on a detection file
    of one's own: it tracks that file's boxes; a bad dataroot is one ``error:`` line, exit 2, no file written."""
    tables = demo_dataroot / "v1.0-mini"
    scene = next(s for s in json.loads((tables / "scene.json").read_text()) if s["name"] == SCENE)
    samples = {s["token"]: s for s in json.loads((tables / "sample.json").read_text())}
    first = samples[scene["first_sample_token"]]
    box = {"translation": [600.0, 1600.0, 1.0], "size": [2.0, 4.5, 1.6], "rotation": [1.0, 0.0, 0.0, 0.0]}
    box |= {"velocity": [0.0, 0.0], "detection_name": "car", "detection_score": 0.9}
    detections = tmp_path / "det.json"
    detections.write_text(json.dumps({"meta": {}, "results": {t: [] for t in samples} | {first["token"]: [box]}}))
    out = tmp_path / "cv.json"
    cv = [sys.executable, "-m", "examples.cv_tracker", "--scene", SCENE, "--out", str(out)]
    done = subprocess.run(
        [*cv, "--dataroot", str(demo_dataroot), "--detections", str(detections)], capture_output=True, text=True
    )
    assert done.returncode == 0, done.stderr
    results = json.loads(out.read_text())["results"]
    assert [b["translation"] for b in results[first["token"]]] == [box["translation"]]
    assert sum(len(b) for b in results.values()) == 1 + 2  # the car, then coasting for MAX_MISSES frames
    out.unlink()
    done = subprocess.run([*cv, "--dataroot", str(tmp_path / "nope")], capture_output=True, text=True)
    assert done.returncode == 2
    assert done.stderr.startswith("error: dataroot ") and len(done.stderr.splitlines()) == 1, done.stderr
    assert not out.exists()
