"""``gnnpmb sweep``, ``tune`` and ``track --workers`` end to end on one demo scene cut to 6 keyframes.

Ray tests share one local Ray session per module (``ray_local``); in-process runs (``--workers 1``) need none. The
one-worker sweep of ``SWEEP`` is run once (``one_worker_sweep``): its output is checked, resumed, compared with the
tracker's own output and with two Ray workers.
"""

from __future__ import annotations

import contextlib
import csv
import functools
import io
import json
import tomllib
from pathlib import Path
from typing import NamedTuple

import pytest

from cli.batch import app
from cli.errors import run_app
from gnnpmb.config import load_config
from gnnpmb.study.results import TIME_COLUMNS
from gnnpmb.study.tune import DEFAULT_CLASS_SPACE
from tests.gnnpmb.study.conftest import TINY_FRAMES
from tests.inprocess import run_main

SWEEP = ["--param", "pmb.extraction_threshold=0.5,0.9", "--no-progress", "--detector", "pointpillars"]


def run(argv: list[str], capsys: pytest.CaptureFixture[str]) -> tuple[int, str, str]:
    """The command in-process: (exit code, stdout, stderr)."""
    return run_main(functools.partial(run_app, app), argv, capsys)


def scores(rows: list[dict]) -> list[dict]:
    """Rows without their timings (those differ between runs)."""
    return [{k: v for k, v in r.items() if k not in TIME_COLUMNS} for r in rows]


class OneWorkerSweep(NamedTuple):
    argv: list[str]
    code: int
    stdout: str
    stderr: str
    out: Path
    rows: list[dict]
    """The rows of ``results.json`` as the sweep first wrote them."""


@pytest.fixture(scope="module")
def one_worker_sweep(tiny_dataroot: Path, tmp_path_factory: pytest.TempPathFactory) -> OneWorkerSweep:
    """``gnnpmb sweep ... --workers 1`` with ``SWEEP`` on the tiny data in-process, run once for the module (the
    tests below read its first run's output; only the resume check runs it again, into the same folder)."""
    out = tmp_path_factory.mktemp("one_worker") / "sweep"
    argv = ["sweep", "--dataroot", str(tiny_dataroot), "--out", str(out), "--workers", "1", *SWEEP]
    stdout, stderr = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(stdout), contextlib.redirect_stderr(stderr):
        try:
            run_app(app, argv)
            code = 0
        except SystemExit as exc:
            code = int(exc.code or 0)
    rows = json.loads((out / "results.json").read_text())["rows"] if code == 0 else []
    return OneWorkerSweep(argv, code, stdout.getvalue(), stderr.getvalue(), out, rows)


def test_sweep_writes_results_and_a_second_run_does_no_work(
    one_worker_sweep: OneWorkerSweep, capsys: pytest.CaptureFixture[str]
) -> None:
    argv, code, stdout, stderr, out, _ = one_worker_sweep
    assert code == 0, stderr
    assert "2 of 2 configurations (0 from cache, 2 run)" in stdout
    with open(out / "results.csv", newline="") as f:
        rows = list(csv.DictReader(f))
    assert [r["pmb.extraction_threshold"] for r in rows] == ["0.5", "0.9"]
    for row in rows:
        assert 0.0 <= float(row["amota"]) <= 1.0
        assert int(row["tp"]) + int(row["fn"]) > 0
        assert float(row["wall_time_s"]) >= float(row["eval_time_s"]) > 0
        assert row["amota_car"] != ""
    data = json.loads((out / "results.json").read_text())
    assert [r["amota"] for r in data["rows"]] == [float(r["amota"]) for r in rows]
    assert data["meta"]["scenes"] == ["scene-0103"]
    assert len(list((out / "cache").glob("*.json"))) == 2
    assert (out / "amota_vs_pmb.extraction_threshold.png").stat().st_size > 0

    code, stdout, _ = run(argv, capsys)
    assert code == 0
    assert "2 of 2 configurations (2 from cache, 0 run)" in stdout
    assert scores(json.loads((out / "results.json").read_text())["rows"]) == scores(data["rows"])


def test_a_lower_extraction_threshold_reports_at_least_as_many_boxes(
    tiny_dataroot: Path, one_worker_sweep: OneWorkerSweep
) -> None:
    """Extraction only filters what is reported, so every box reported at threshold 0.9 is also reported at 0.5.
    Checked on the tracker's output: the devkit's tp + fp in the sweep rows are counted at each run's best-MOTA
    score threshold and need not grow when more boxes are reported."""
    from gnnpmb.config import TrackerConfig, with_params
    from gnnpmb.data.nuscenes import load_scene, resolve_dataroot
    from gnnpmb.pipeline import get_detections, run_tracker

    assert one_worker_sweep.code == 0, one_worker_sweep.stderr
    low, high = one_worker_sweep.rows
    assert low["tp"] + low["fn"] == high["tp"] + high["fn"]  # the same ground truth
    location = resolve_dataroot(tiny_dataroot, None)
    scene = load_scene(location, "scene-0103")
    detections = get_detections(scene, None, "pointpillars", 0)
    reported = {}
    for threshold in (0.5, 0.9):
        config = with_params(TrackerConfig(), {"pmb.extraction_threshold": threshold})
        frames = run_tracker(scene, detections, "gnnpmb", config).frames
        reported[threshold] = [{(e.class_name, e.track_id) for e in f.estimates} for f in frames]
    assert all(strict <= loose for loose, strict in zip(reported[0.5], reported[0.9], strict=True))
    assert sum(map(len, reported[0.5])) > sum(map(len, reported[0.9]))


@pytest.mark.parametrize(
    ("param", "message"),
    [
        ("pmb.gate_chi3=1,2", "unknown parameter 'gate_chi3'"),
        ("car.birth_wieght=0.1", "birth_wieght"),
        ("pmb.gate_chi2=", "has no values"),
        ("pmb.gate_chi2=abc", "not a number"),
        ("nosection=1", "bad parameter key"),
        ("pmb.gate_chi2=1,1", "repeats a value"),
    ],
)
def test_bad_parameters_fail_before_any_work(
    param: str, message: str, tiny_dataroot: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    out = tmp_path / "sweep"
    code, stdout, stderr = run(
        ["sweep", "--dataroot", str(tiny_dataroot), "--out", str(out), "--workers", "1", "--param", param], capsys
    )
    assert code == 2
    assert stderr.startswith("error: ") and stderr.count("\n") == 1 and message in stderr, stderr
    assert not out.exists()


def test_overlapping_keys_and_unreachable_cluster_are_one_line_errors(
    tiny_dataroot: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    base = ["sweep", "--dataroot", str(tiny_dataroot), "--out", str(tmp_path / "s")]
    code, _, stderr = run(base, capsys)
    assert code == 2 and stderr == "error: empty grid: give at least one --param KEY=V1,V2,...\n"
    code, _, stderr = run([*base, "--param", "car.q_x=0.1", "--param", "*.q_x=0.2"], capsys)
    assert code == 2 and "both set classes.car.q_x" in stderr
    code, _, stderr = run([*base, "--param", "pmb.gate_chi2=20", "--address", "127.0.0.1:1"], capsys)
    assert code == 2 and stderr.startswith("error: cannot reach the Ray cluster at 127.0.0.1:1")
    assert stderr.count("\n") == 1
    assert not (tmp_path / "s").exists()


def test_tune_writes_a_params_file_that_track_accepts(
    tiny_dataroot: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    texts = []
    for name in ("tuned.toml", "again.toml"):
        params = tmp_path / name
        code, stdout, stderr = run(
            [
                "tune",
                "--dataroot",
                str(tiny_dataroot),
                "--split",
                "mini_val",
                "--classes",
                "car",
                "--trials",
                "2",
                "--workers",
                "1",
                "--no-progress",
                "--out",
                str(params),
            ],
            capsys,
        )
        assert code == 0, stderr
        assert "tune: 2 trials on mini_val" in stdout and "best per class" in stdout
        texts.append(params.read_text())
    text = texts[0]
    assert texts[1] == text  # one worker: deterministic for a seed
    assert "car.q_x in [0.005, 2] log" in text.split("# search space:", 1)[1].split("\n", 1)[0]
    assert "# trials: 2 of 2 (Optuna TPE sampler, seed 0, in process)" in text
    assert set(tomllib.loads(text)) == {"classes"}
    assert set(tomllib.loads(text)["classes"]["car"]) == set(DEFAULT_CLASS_SPACE)  # every per-class key
    params = tmp_path / "tuned.toml"
    assert load_config(params).classes["car"].q_x == tomllib.loads(text)["classes"]["car"]["q_x"]
    out = tmp_path / "results.json"
    code, _, stderr = run(
        ["track", "--dataroot", str(tiny_dataroot), "--params", str(params), "--out", str(out), "--no-progress"],
        capsys,
    )
    assert code == 0, stderr


def test_tune_refuses_a_bad_space_before_any_work(
    tiny_dataroot: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    out = tmp_path / "t.toml"
    base = ["tune", "--dataroot", str(tiny_dataroot), "--split", "mini_val", "--workers", "1", "--out", str(out)]
    for extra, message in (
        (["--space", "car.q_x=1:0.1"], "need LOW < HIGH"),
        (["--space", "car.nope=0.1:1"], "unknown parameter 'nope'"),
        (["--classes", "boat"], "unknown class 'boat'"),
        (["--trials", "0"], "--trials must be at least 1"),
    ):
        code, _, stderr = run([*base, *extra], capsys)
        assert code == 2 and stderr.startswith("error: ") and message in stderr, stderr
    code, _, stderr = run(["tune", "--dataroot", str(tiny_dataroot), "--out", str(out)], capsys)
    assert code == 2 and "split mini_train has no scenes" in stderr
    assert not out.exists()


def test_sweep_and_track_on_two_ray_workers_equal_one_worker(
    ray_local: None,
    tiny_dataroot: Path,
    two_scene_dataroot: Path,
    one_worker_sweep: OneWorkerSweep,
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
) -> None:
    """The sweep's rows and ``track``'s submission are the same with two Ray workers as with one; ``track`` on the
    demo's two scenes cut to 6 keyframes each (one scene per worker; the whole demo only adds tracking work)."""
    assert one_worker_sweep.code == 0, one_worker_sweep.stderr
    out = tmp_path / "sweep2"
    argv = ["sweep", "--dataroot", str(tiny_dataroot), "--out", str(out), "--workers", "2", *SWEEP]
    code, _, stderr = run(argv, capsys)
    assert code == 0, stderr
    assert scores(json.loads((out / "results.json").read_text())["rows"]) == scores(one_worker_sweep.rows)

    submissions = {}
    for workers in ("1", "2"):
        out = tmp_path / f"track{workers}.json"
        argv = ["track", "--dataroot", str(two_scene_dataroot), "--out", str(out), "--workers", workers]
        argv.append("--no-progress")
        code, _, stderr = run(argv, capsys)
        assert code == 0, stderr
        submissions[workers] = out.read_bytes()
    assert submissions["1"] == submissions["2"]
    assert len(json.loads(submissions["2"])["results"]) == 2 * TINY_FRAMES  # both scenes, one per worker
