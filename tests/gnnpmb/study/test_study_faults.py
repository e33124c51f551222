"""Faults of issue 22 in a study folder on the tiny data: a second grid joins the table (or is refused), a damaged
cache entry is scored again, outputs get one file mode (the folder's commands in-process: the folder, not the
process, is under test), and SIGTERM during a Ray sweep keeps what finished (a real process: the signal is)."""

from __future__ import annotations

import csv
import json
import signal
import stat
import subprocess
import time
from pathlib import Path

import pytest

from tests.cli.test_faults import _fault_env, _one_line, _start, _wait_for
from tests.cli.test_user_errors import _snapshot
from tests.inprocess import run_script_with, umask

SWEEP = "gnnpmb sweep --dataroot {root} --out {out} --no-progress --detector pointpillars"


def _rows(out: Path) -> list[dict[str, str]]:
    with open(out / "results.csv", newline="") as f:
        return list(csv.DictReader(f))


def test_a_second_grid_joins_the_table_and_another_study_is_refused(
    tiny_dataroot: Path,
    tmp_path: Path,
    monkeypatch: pytest.MonkeyPatch,
    capsys: pytest.CaptureFixture[str],
) -> None:
    out = tmp_path / "sw"
    env = _fault_env(tiny_dataroot, tmp_path / "cache")
    sweep = SWEEP.format(root=tiny_dataroot, out=out) + " --workers 1"

    def _run(command: str, env: dict[str, str], cwd: Path) -> subprocess.CompletedProcess[str]:
        with umask(0o022):  # a shell's usual mask, as the real processes had it
            return run_script_with(command.split(), env, cwd, monkeypatch, capsys)

    first = _run(f"{sweep} --param models.birth_weight=0.1,0.3", env, tmp_path)
    assert first.returncode == 0 and first.stderr == "", first.stderr
    second = _run(f"{sweep} --param car.q_x=0.2", env, tmp_path)
    assert second.returncode == 0, second.stderr
    _one_line(second.stderr, f"note: {out} already holds a table of models.birth_weight")
    assert "3 of 3 configurations (2 from cache, 1 run)" in second.stdout
    rows = _rows(out)
    assert [(r["models.birth_weight"], r["car.q_x"]) for r in rows] == [("0.1", ""), ("0.3", ""), ("", "0.2")]
    plots = sorted(p.name for p in out.glob("*.png"))
    assert plots == ["amota_vs_car.q_x.png", "amota_vs_models.birth_weight.png"]
    for name in ("results.csv", "results.json", *plots):
        assert stat.S_IMODE((out / name).stat().st_mode) == 0o644  # umask 022, like any new file

    before = _snapshot(out)
    other = _run(f"{sweep} --param car.q_x=0.2 --tracker gnn", env, tmp_path)
    assert other.returncode == 2
    _one_line(other.stderr, f"error: --out {out} holds a study of another kind (tracker gnnpmb;")
    assert "give a new --out folder" in other.stderr and _snapshot(out) == before

    entry = next(p for p in (out / "cache").glob("*.json") if json.loads(p.read_text())["row"]["amota"] is not None)
    entry.write_text("{}")  # valid JSON, no metrics: must be scored again, not read as empty cells
    again = _run(f"{sweep} --param car.q_x=0.2", env, tmp_path)
    assert again.returncode == 0, again.stderr
    assert "3 of 3 configurations (2 from cache, 1 run)" in again.stdout
    assert all(r["amota"] != "" for r in _rows(out)) and "amota" in json.loads(entry.read_text())["row"]


def test_sigterm_during_a_ray_sweep_keeps_what_finished(tiny_dataroot: Path, tmp_path: Path) -> None:
    out = tmp_path / "sw"
    values = ",".join(f"{0.05 * k:.2f}" for k in range(1, 11))
    argv = [
        *SWEEP.format(root=tiny_dataroot, out=out).split(),
        "--workers",
        "2",
        "--param",
        f"models.birth_weight={values}",
    ]
    proc = _start(argv, _fault_env(tiny_dataroot, tmp_path / "cache"), tmp_path)
    _wait_for(lambda: (out / "cache").is_dir() and any((out / "cache").glob("*.json")), proc, timeout=180)
    start = time.monotonic()
    proc.send_signal(signal.SIGTERM)
    _, err = proc.communicate(timeout=120)
    assert proc.returncode == 143, err
    _one_line(err, "terminated by SIGTERM: ")
    assert "configurations left; run the same command again to resume" in err
    assert time.monotonic() - start < 60
    finished = list((out / "cache").glob("*.json"))
    assert 1 <= len(_rows(out)) == len(finished) < 10
