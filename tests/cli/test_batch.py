"""``gnnpmb`` (track, eval, failures, demo-data) end to end on the synthetic demo, and its one-line errors."""

from __future__ import annotations

import functools
import json
import re
import subprocess
import sys
from pathlib import Path

import pytest

from cli.batch import app
from cli.errors import run_app
from gnnpmb.eval.nuscenes_eval import default_split
from gnnpmb.eval.submission import check_submission
from tests.inprocess import run_main

SCRIPT = Path(sys.executable).parent / "gnnpmb"
N_SAMPLES = 80


def run(argv: list[str], capsys: pytest.CaptureFixture[str]) -> tuple[int, str, str]:
    """The command in-process: (exit code, stdout, stderr)."""
    return run_main(functools.partial(run_app, app), argv, capsys)


def run_quiet(argv: list[str]) -> tuple[int, str]:
    """Run the app in-process for a module fixture (no capsys there): (exit code, stdout)."""
    import contextlib
    import io

    out = io.StringIO()
    with contextlib.redirect_stdout(out):
        try:
            run_app(app, argv)
            code = 0
        except SystemExit as exc:
            code = int(exc.code or 0)
    return code, out.getvalue()


@pytest.fixture(scope="module")
def tracked(demo_dataroot: Path, tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, str]:
    out = tmp_path_factory.mktemp("track") / "results.json"
    code, stdout = run_quiet(["track", "--dataroot", str(demo_dataroot), "--out", str(out), "--no-progress"])
    assert code == 0
    return out, stdout


@pytest.fixture(scope="module")
def evaluated(two_scene_dataroot: Path, tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, str]:
    """``gnnpmb track`` then ``gnnpmb eval`` of its file, as ``tracked`` and the README, on the demo's two scenes
    cut to 6 keyframes each (the devkit's evaluation of the whole demo's 80 frames takes 4 s more; what the table
    shows is what it read from the devkit's files either way): the results file and what eval printed."""
    out = tmp_path_factory.mktemp("eval") / "results.json"
    code, _ = run_quiet(["track", "--dataroot", str(two_scene_dataroot), "--out", str(out), "--no-progress"])
    assert code == 0
    code, stdout = run_quiet(["eval", str(out), "--dataroot", str(two_scene_dataroot), "--split", "mini_val"])
    assert code == 0
    return out, stdout


def test_track_writes_a_submission_for_every_sample_of_the_split(tracked: tuple[Path, str]) -> None:
    path, stdout = tracked
    match = re.fullmatch(
        rf"gnnpmb: 2 scenes of mini_val, 80 frames, (\d+) boxes, [\d.]+ ms/frame -> {re.escape(str(path))}\n",
        stdout,
    )
    assert match, stdout
    data = json.loads(path.read_text())
    tokens = list(data["results"])
    assert len(tokens) == N_SAMPLES
    stats = check_submission(data, path.name, "mini_val", tokens, set(tokens))
    assert stats.boxes == int(match.group(1)) > 0
    assert {b["tracking_name"] for boxes in data["results"].values() for b in boxes} >= {"car", "pedestrian"}
    assert sorted(p.name for p in path.parent.iterdir()) == ["results.json"]


def test_track_is_deterministic(tracked: tuple[Path, str], demo_dataroot: Path, tmp_path: Path, capsys) -> None:
    again = tmp_path / "again.json"
    argv = ["track", "--dataroot", str(demo_dataroot), "--nuscenes-version", "v1.0-mini", "--split", "mini_val"]
    code, _, _ = run([*argv, "--detector", "centerpoint", "--seed", "0", "--out", str(again), "--no-progress"], capsys)
    assert code == 0
    assert again.read_bytes() == tracked[0].read_bytes()


def test_eval_prints_the_official_table(evaluated: tuple[Path, str]) -> None:
    path, printed = evaluated
    summary_path = path.parent / "results_eval" / "metrics_summary.json"
    summary = json.loads(summary_path.read_text())
    for header in ("AMOTA", "AMOTP", "MOTA", "MOTP", "RECALL", "MT", "ML", "TP", "FP", "FN", "IDS", "FRAG"):
        assert header in printed
    overall = next(line for line in printed.splitlines() if "overall" in line)
    cells = [c.strip() for c in re.split(r"[│|]", overall) if c.strip()]
    assert cells[0] == "overall"
    assert cells[1] == f"{summary['amota']:.3f}" and cells[3] == f"{summary['mota']:.3f}"
    assert cells[-2:] == [str(int(summary["ids"])), str(int(summary["frag"]))]
    for class_name in ("bicycle", "bus", "car", "motorcycle", "pedestrian", "trailer", "truck"):
        assert re.search(rf"│ {class_name}\s+│", printed)
    assert f"AMOTA {summary['amota']:.3f}" in printed and str(summary_path) in printed.replace("\n", "")


def test_failures_lists_frames_and_writes_json(demo_dataroot: Path, tmp_path: Path, capsys) -> None:
    report_path = tmp_path / "report.json"
    argv = ["failures", "scene-0916", "--tracker", "gnnpmb", "--dataroot", str(demo_dataroot)]
    code, out, err = run([*argv, "--detector", "centerpoint", "--json", str(report_path)], capsys)
    assert code == 0, err
    report = json.loads(report_path.read_text())
    assert report["scene"] == "scene-0916" and len(report["sample_tokens"]) == 40
    totals = report["totals"]
    assert f"scene-0916, gnnpmb: {totals['id_switch']} id_switch, {totals['fragmentation']} fragmentation" in out
    assert "failures per frame" in out and "best-MOTA threshold" in out
    assert sum(totals.values()) == len(report["failures"]) > 0
    for c in report["classes"]:
        ids = sum(f["kind"] == "id_switch" and f["class_name"] == c["class_name"] for f in report["failures"])
        assert ids == c["ids"]
    first = report["failures"][0]
    assert re.search(rf"│\s+{first['frame_index']} │ {first['kind']}", out)


def test_failures_why_explains_each_failure_and_writes_the_typed_findings(
    demo_dataroot: Path, tmp_path: Path, capsys
) -> None:
    report_path = tmp_path / "why.json"
    argv = ["failures", "scene-0916", "--tracker", "jpda", "--dataroot", str(demo_dataroot), "--detector", "megvii"]
    code, out, err = run([*argv, "--why", "--json", str(report_path)], capsys)
    assert code == 0, err
    report = json.loads(report_path.read_text())
    findings = report["findings"]
    assert [f["failure_id"] for f in findings] == [
        f"{kind}:{n}" for kind, n in _numbered([f["kind"] for f in report["failures"]])
    ]
    switch = next(f for f in findings if f["failure_id"] == "id_switch:1")
    assert switch["mode"] == "association probabilities" and {b["rule"] for b in switch["blame"]} >= {"not output"}
    assert switch["lost"]["steps"] and switch["lost"]["track_id"] == int(switch["track_ids"][0])
    lines = out.splitlines()
    head = lines.index(next(x for x in lines if x.startswith("id_switch:1 (frame ")))
    assert lines[head + 1].startswith("  Why (jpda, ") and "**" not in lines[head + 1]
    assert "given no detection" not in out and "→ ?" not in out


def _numbered(kinds: list[str]) -> list[tuple[str, int]]:
    seen: dict[str, int] = {}
    out = []
    for k in kinds:
        seen[k] = seen.get(k, 0) + 1
        out.append((k, seen[k]))
    return out


def test_demo_data_calls_the_generator(monkeypatch, tmp_path: Path, capsys) -> None:
    calls = []

    def fake(out: Path, seed: int, scenes: tuple[str, ...], sweeps: bool = False) -> Path:
        calls.append((out, seed, scenes) + (("sweeps",) if sweeps else ()))
        return out

    monkeypatch.setattr("gnnpmb.data.demo.generate_demo_dataset", fake)
    code, out, _ = run(["demo-data", "--out", str(tmp_path / "demo"), "--seed", "7"], capsys)
    assert code == 0 and calls == [(tmp_path / "demo", 7, ("scene-0103", "scene-0916", "scene-9001"))]
    assert out == f"demo dataset (v1.0-mini, seed 7, 3 scenes) -> {tmp_path / 'demo'}\n"
    code, out, _ = run(["demo-data", "--out", str(tmp_path / "d2"), "--scenes", "mini_train,scene-0103"], capsys)
    assert code == 0 and len(calls[-1][2]) == 9 and calls[-1][2][-1] == "scene-0103"
    code, out, _ = run(["demo-data", "--out", str(tmp_path / "d3"), "--scenes", "scene-0103", "--sweeps"], capsys)
    assert code == 0 and calls[-1] == (tmp_path / "d3", 0, ("scene-0103",), "sweeps")
    assert out == f"demo dataset (v1.0-mini, seed 0, 1 scenes, with sweeps) -> {tmp_path / 'd3'}\n"


def test_demo_data_refuses_an_unknown_scene(tmp_path: Path, capsys) -> None:
    code, _, err = run(["demo-data", "--out", str(tmp_path / "demo"), "--scenes", "scene-0104"], capsys)
    assert code == 2 and "unknown demo scene 'scene-0104'" in _one_error_line(err)
    assert not (tmp_path / "demo").exists()


def _one_error_line(err: str) -> str:
    lines = err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("error: "), err
    return lines[0]


def test_track_errors_write_nothing(demo_dataroot: Path, tmp_path: Path, capsys) -> None:
    out = tmp_path / "results.json"
    base = ["track", "--dataroot", str(demo_dataroot), "--out", str(out), "--no-progress"]
    empty_detections = tmp_path / "dets.json"
    empty_detections.write_text(json.dumps({"meta": {}, "results": {}}))
    cases = [
        (["--tracker", "nope"], "unknown tracker 'nope'"),
        (["--detector", "nope"], "unknown detector preset 'nope'"),
        (
            ["--detections", str(empty_detections), "--detector", "megvii"],
            "either --detections FILE or --detector",
        ),
        (["--detections", str(empty_detections)], "has no boxes entry for 40 of the 40"),
        (["--split", "val"], "split val cannot be evaluated on dataset version v1.0-mini"),
        (["--split", "nowhere"], "unknown split 'nowhere'"),
    ]
    for extra, message in cases:
        code, _, err = run(base + extra, capsys)
        assert code == 2, extra
        assert message in _one_error_line(err)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["dets.json"]


def test_eval_errors_are_one_line(demo_dataroot: Path, tracked: tuple[Path, str], tmp_path: Path, capsys) -> None:
    good = json.loads(tracked[0].read_text())
    tokens = list(good["results"])
    missing = {"meta": good["meta"], "results": {t: good["results"][t] for t in tokens[40:]}}
    (tmp_path / "missing.json").write_text(json.dumps(missing))
    nan = json.loads(json.dumps(good))
    nan["results"][tokens[3]] = [{**nan["results"][tokens[3]][0], "size": [float("nan"), 1.0, 1.0]}]
    (tmp_path / "nan.json").write_text(json.dumps(nan))
    cases = [
        (
            "missing.json",
            [],
            "missing.json lacks 40 of the 80 samples of split mini_val; was it made for another split?",
        ),
        ("nan.json", [], f"nan.json: box 0 of sample {tokens[3]} field 'size' has a NaN or infinite value"),
        ("absent.json", [], "results file not found"),
        ("missing.json", ["--split", "val"], "split val cannot be evaluated on dataset version v1.0-mini"),
    ]
    for name, extra, message in cases:
        code, _, err = run(["eval", str(tmp_path / name), "--dataroot", str(demo_dataroot), *extra], capsys)
        assert code == 2, name
        assert _one_error_line(err) == f"error: {message}" or message in err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["missing.json", "nan.json"]


def test_failures_and_demo_data_errors(demo_dataroot: Path, tmp_path: Path, capsys) -> None:
    code, _, err = run(["failures", "scene-9999", "--dataroot", str(demo_dataroot)], capsys)
    assert code == 2 and "unknown scene 'scene-9999'" in _one_error_line(err)
    (tmp_path / "full").mkdir()
    (tmp_path / "full" / "keep.txt").write_text("mine")
    code, _, err = run(["demo-data", "--out", str(tmp_path / "full")], capsys)
    assert code == 2 and "refusing to write the demo dataset" in _one_error_line(err)
    assert [p.name for p in (tmp_path / "full").iterdir()] == ["keep.txt"]


def test_truncated_results_in_a_real_process(demo_dataroot: Path, tmp_path: Path) -> None:
    path = tmp_path / "truncated.json"
    path.write_text('{"meta": {"use_lidar": true}, "results": {"abc": [{"sample_token": "abc", "transl')
    done = subprocess.run(
        [str(SCRIPT), "eval", str(path), "--dataroot", str(demo_dataroot)],
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert done.returncode == 2
    assert done.stdout == ""
    assert _one_error_line(done.stderr).startswith("error: results file truncated.json is not valid JSON: ")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["truncated.json"]


def test_default_split() -> None:
    assert default_split("v1.0-mini") == "mini_val"
    assert default_split("v1.0-trainval") == "val"
    assert default_split("v1.0-test") == "test"


def test_a_stop_that_click_turned_into_abort_still_exits_130_with_its_line(capsys: pytest.CaptureFixture[str]) -> None:
    # click raises Abort from a KeyboardInterrupt (Ctrl-C, or SIGTERM via gnnpmb.signals) that reaches it outside
    # the command's own handling, e.g. during a Ray sweep's shutdown: that was exit 1 with nothing said
    import typer

    def app(args: list[str], standalone_mode: bool) -> None:
        try:
            raise KeyboardInterrupt
        except KeyboardInterrupt as e:
            raise typer.Abort() from e

    with pytest.raises(SystemExit) as stop:
        run_app(app, [])
    assert stop.value.code == 130
    assert capsys.readouterr().err.strip() == "interrupted by Ctrl-C: unfinished outputs were not written"


def test_classes_are_the_only_ones_evaluated_in_failures_and_the_viewer(
    demo_dataroot: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """``--classes car``: the failures are the cars' alone (the other classes, not tracked, are no one's misses),
    the same in ``gnnpmb failures`` and in ``gnnpmb-viz``'s summary, so the ids one lists the other opens."""
    from tests.inprocess import run_script

    common = ["scene-0103", "--classes", "car", "--frames", "0:10", "--dataroot", str(demo_dataroot)]
    listed = run_script(["gnnpmb", "failures", *common, "--json", str(tmp_path / "f.json")], capsys)
    assert listed.returncode == 0, listed.stderr
    report = json.loads((tmp_path / "f.json").read_text())
    assert [c["class_name"] for c in report["classes"]] == ["car"]
    assert {f["class_name"] for f in report["failures"]} <= {"car"}
    (car,) = report["classes"]
    assert report["totals"]["miss"] == car["fn"]
    (totals,) = re.findall(
        r"scene-0103, gnnpmb in keyframes 0:10 \(only those were tracked and evaluated\): (.*)", listed.stdout
    )
    shown = run_script(["gnnpmb-viz", *common, "--save", str(tmp_path / "x.rrd"), "--no-progress"], capsys)
    assert shown.returncode == 0, shown.stderr
    assert f"gnnpmb failures in keyframes 0:10 (only those were tracked and evaluated): {totals}" in shown.stdout


@pytest.mark.parametrize("command", ["eval {r} --split staged", "diff mine={r} greedy --split staged"])
def test_a_results_file_of_another_split_names_that_split(
    command: str, tracked: tuple[Path, str], demo_dataroot: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """A submission of mini_val scored or diffed on another split: the error line names the split it holds."""
    argv = [*command.format(r=tracked[0]).split(), "--dataroot", str(demo_dataroot)]
    code, out, err = run(argv, capsys)
    assert code == 2 and out == ""
    assert err.startswith("error: results.json ") and len(err.splitlines()) == 1, err
    assert err.rstrip().endswith(f"It holds the {N_SAMPLES} samples of split mini_val: pass --split mini_val")


def test_a_failed_track_prints_its_error_line_alone(
    demo_dataroot: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """With the progress bar on (the default) and stderr no terminal (a pipe, a CI log), a track that fails
    prints its one ``error:`` line and nothing else: no empty line left by the bar."""
    detections = tmp_path / "det.json"
    detections.write_text(json.dumps({"meta": {}, "results": {"0" * 32: []}}))
    argv = [
        "track",
        "--dataroot",
        str(demo_dataroot),
        "--detections",
        str(detections),
        "--out",
        str(tmp_path / "r.json"),
    ]
    code, out, err = run(argv, capsys)
    assert (code, out) == (2, "")
    assert err.startswith("error: detections file det.json has no boxes entry") and err.count("\n") == 1, repr(err)
    assert not (tmp_path / "r.json").exists()
