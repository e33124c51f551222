"""Faults of issue 22 in real processes: signals, leftovers of killed runs, read-only folders, a stale display, a Ray
address that is no Ray head, ``--frames`` and its failure ids, file modes, extreme parameters, a truncated
recording. Each checks the exit code, the first line of stderr and the files left.

The read-only folder is made immutable with ``chattr +i`` when running as root (permission bits do not stop root;
an immutable folder does), else read-only with ``chmod``; the test is skipped where neither holds.
"""

from __future__ import annotations

import json
import os
import shutil
import signal
import stat
import subprocess
import time
import warnings
from collections.abc import Callable, Iterator
from pathlib import Path

import pytest

from gnnpmb import atomic
from gnnpmb.data.demo import GENERATOR_VERSION
from tests.cli.test_user_errors import BIN, VIZ, _env, _snapshot, _start, _work_folder
from tests.gnnpmb.study.test_runner import FakeHead
from tests.inprocess import run_script_with, umask

QUICK_VIZ = f"{VIZ} scene-0103 --tracker gnn --frames 0:3 --no-failures --no-progress"


def _fault_env(demo: Path, cache: Path, **extra: str) -> dict[str, str]:
    env = _env(demo) | {"GNNPMB_CACHE_DIR": str(cache), "PATH": f"{BIN}{os.pathsep}{os.environ['PATH']}"}
    return env | extra


def _run(command: str, env: dict[str, str], cwd: Path, timeout: float = 180) -> subprocess.CompletedProcess[str]:
    proc = _start(command.split(), env, cwd)
    out, err = proc.communicate(timeout=timeout)
    return subprocess.CompletedProcess(proc.args, proc.returncode, out, err)


def _wait_for(found: Callable[[], bool], proc: subprocess.Popen[str], timeout: float = 120) -> None:
    deadline = time.monotonic() + timeout
    while not found():
        assert proc.poll() is None, proc.communicate()
        assert time.monotonic() < deadline, "timed out"
        time.sleep(0.05)


def _one_line(err: str, start: str) -> None:
    lines = err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith(start), err
    assert "Traceback" not in err


def _dead_pid() -> int:
    """The id of a process that has exited (and been reaped)."""
    proc = subprocess.Popen(["true"])
    proc.wait()
    return proc.pid


def _mode(path: Path) -> int:
    return stat.S_IMODE(path.stat().st_mode)


def test_sigterm_while_saving_is_like_ctrl_c(demo_dataroot: Path, tmp_path: Path) -> None:
    """As ``test_user_errors.test_ctrl_c_while_saving_leaves_no_partial_file``, with SIGTERM (and as there,
    without the failure report: the signal comes while the recording is written, after the evaluation)."""
    work = _work_folder(tmp_path / "w")
    before = _snapshot(work)
    argv = [VIZ, "scene-0103", "--tracker", "gnn", "--no-failures", "--save", str(work / "good.rrd"), "--no-progress"]
    proc = _start(argv, _fault_env(demo_dataroot, tmp_path / "cache"), work)
    _wait_for(lambda: any(p.name.endswith(".partial") for p in work.iterdir()), proc)
    proc.send_signal(signal.SIGTERM)
    _, err = proc.communicate(timeout=120)
    assert proc.returncode == 143, err
    _one_line(err, "terminated by SIGTERM")
    assert _snapshot(work) == before


@pytest.mark.parametrize(
    ("sig", "code", "line"),
    [(signal.SIGINT, 130, "interrupted by Ctrl-C"), (signal.SIGTERM, 143, "terminated by SIGTERM")],
    ids=["int", "term"],
)
def test_a_stopped_track_says_so_and_removes_its_demo_build(
    sig: signal.Signals, code: int, line: str, tmp_path: Path, demo_dataroot: Path
) -> None:
    """Stopped while it builds the demo (no dataroot given): one line, and no half-built demo left."""
    cache = tmp_path / "cache"
    env = {k: v for k, v in _fault_env(demo_dataroot, cache).items() if k != "NUSCENES_DATAROOT"}
    proc = _start(["gnnpmb", "track", "--out", str(tmp_path / "t.json"), "--no-progress"], env, tmp_path)
    _wait_for(lambda: cache.is_dir() and any(".build-" in p.name for p in cache.iterdir()), proc)
    proc.send_signal(sig)
    _, err = proc.communicate(timeout=120)
    assert proc.returncode == code, err
    _one_line(err, line)
    assert list(cache.iterdir()) == [] and not (tmp_path / "t.json").exists()


def _cached_demo(demo: Path, cache: Path) -> None:
    """The demo in ``cache`` as ``ensure_demo_dataset`` keeps it (its parts linked, not copied)."""
    folder = cache / f"demo-v{GENERATOR_VERSION}"
    folder.mkdir(parents=True)
    for part in demo.iterdir():
        (folder / part.name).symlink_to(part)


def test_leftovers_of_killed_runs_are_swept_and_live_ones_kept(demo_dataroot: Path, tmp_path: Path) -> None:
    work, cache = tmp_path / "w", tmp_path / "cache"
    work.mkdir()
    _cached_demo(demo_dataroot, cache)
    host, dead, alive = atomic.owner_tag().split("-")[0], _dead_pid(), os.getpid()
    stale = [work / f".good.rrd.{host}-{dead}-0a1b2c.partial", work / f".r.json.{host}-{dead}-x_y.tmp"]
    kept = [work / f".good.rrd.{host}-{alive}-0a1b2c.partial", work / ".good.rrd.1c5c8f7cee48.partial"]
    for path in stale + kept:
        path.write_bytes(b"x" * 1000)
    builds = {
        name: cache / f".demo-v{GENERATOR_VERSION}.build-{host}-{pid}-k3j"
        for name, pid in (("dead", dead), ("alive", alive))
    }
    for build in builds.values():
        (build / "data").mkdir(parents=True)
    (work / "other.rrd").write_bytes(b"old")
    (work / "other.rrd").chmod(0o640)
    env = {k: v for k, v in _fault_env(demo_dataroot, cache).items() if k != "NUSCENES_DATAROOT"}
    proc = _run(f"{QUICK_VIZ} --save {work / 'other.rrd'}", env, work)
    assert proc.returncode == 0 and proc.stderr == "", proc.stderr
    assert not any(p.exists() for p in stale) and all(p.exists() for p in kept)
    assert not builds["dead"].exists() and builds["alive"].exists()
    assert _mode(work / "other.rrd") == 0o640  # written over: keeps its mode


@pytest.fixture
def read_only(tmp_path: Path) -> Iterator[Path]:
    """A folder nothing can be created in, even by root."""
    folder = tmp_path / "ro"
    folder.mkdir()
    if os.geteuid() == 0:
        if shutil.which("chattr") is None or subprocess.run(["chattr", "+i", str(folder)], check=False).returncode:
            pytest.skip("running as root without chattr +i: no folder is read-only for root here")
    else:
        folder.chmod(0o555)
    try:
        yield folder
    finally:
        if os.geteuid() == 0:
            subprocess.run(["chattr", "-i", str(folder)], check=False)
        folder.chmod(0o755)


@pytest.mark.parametrize(
    "command",
    [
        "gnnpmb tune --out {ro}/t.toml --split mini_val --classes car --trials 1 --workers 1 --no-progress",
        "gnnpmb sweep --out {ro}/sw --param models.birth_weight=0.1,0.2 --workers 1 --no-progress",
        "gnnpmb sweep --out {ro} --param models.birth_weight=0.1,0.2 --workers 1 --no-progress",
    ],
    ids=["tune", "sweep new folder", "sweep folder"],
)
def test_a_study_checks_its_outputs_before_any_work(
    command: str, read_only: Path, demo_dataroot: Path, tmp_path: Path
) -> None:
    start = time.monotonic()
    proc = _run(command.format(ro=read_only), _fault_env(demo_dataroot, tmp_path / "cache"), tmp_path)
    assert proc.returncode == 2
    _one_line(proc.stderr, "error: --out")
    assert "cannot write in folder" in proc.stderr
    assert time.monotonic() - start < 15  # refused before the first configuration (one takes seconds)
    assert list(read_only.iterdir()) == []


def test_a_stale_display_is_one_line(demo_dataroot: Path, tmp_path: Path) -> None:
    if shutil.which("rerun", path=str(BIN)) is None:
        pytest.skip("no Rerun viewer program in this environment")
    if Path("/tmp/.X11-unix/X99").exists():
        pytest.skip("an X server answers on :99 here")
    start = time.monotonic()
    proc = _run(QUICK_VIZ, _fault_env(demo_dataroot, tmp_path / "cache", DISPLAY=":99"), tmp_path, timeout=120)
    assert proc.returncode == 2, proc.stderr
    _one_line(proc.stderr, "error: the Rerun viewer exited")
    assert "DISPLAY=:99" in proc.stderr and "streamed" not in proc.stdout
    assert time.monotonic() - start < 60


@pytest.mark.parametrize(
    ("reply", "seen"),
    [(None, "no answer within"), (b"HTTP/1.0 400 Bad\r\n\r\n", "HTTP/1.0 400")],
    ids=["silent", "http"],
)
def test_an_address_that_is_no_ray_head_is_one_line_in_bounded_time(
    reply: bytes | None, seen: str, demo_dataroot: Path, tmp_path: Path
) -> None:
    head = FakeHead(reply)
    try:
        start = time.monotonic()
        command = f"gnnpmb sweep --out {tmp_path / 's'} --param models.gate_chi2=20 --address {head.address}"
        proc = _run(command, _fault_env(demo_dataroot, tmp_path / "cache"), tmp_path, timeout=60)
        elapsed = time.monotonic() - start
    finally:
        head.close()
    assert proc.returncode == 2
    _one_line(proc.stderr, f"error: cannot reach the Ray cluster at {head.address}")
    assert seen in proc.stderr and elapsed < 30
    assert not (tmp_path / "s").exists()


def test_frames_evaluates_and_numbers_failures_within_the_window(
    demo_dataroot: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    """In-process (``tests.inprocess.run_script_with``): the numbering, not the process, is under test."""
    env = _fault_env(demo_dataroot, tmp_path / "cache")

    def _run(command: str, env: dict[str, str], cwd: Path) -> subprocess.CompletedProcess[str]:
        return run_script_with(command.split(), env, cwd, monkeypatch, capsys)

    listed = _run("gnnpmb failures scene-0103 --frames 10:30 --json f.json", env, tmp_path)
    assert listed.returncode == 0, listed.stderr
    totals = next(line for line in listed.stdout.splitlines() if line.startswith("scene-0103, gnnpmb"))
    assert totals.startswith("scene-0103, gnnpmb in keyframes 10:30 (only those were tracked and evaluated): ")
    report = json.loads((tmp_path / "f.json").read_text())
    assert report["frames"] == [10, 30] and report["failures"]
    assert all(10 <= f["frame_index"] < 30 for f in report["failures"])
    numbered: dict[str, int] = {}
    ids = []
    for f in report["failures"]:
        numbered[f["kind"]] = numbered.get(f["kind"], 0) + 1
        ids.append(f"{f['kind']}:{numbered[f['kind']]}")
    last = len(ids) - 1  # the last failure listed: its id is one only the window's numbering has
    viewed = _run(f"{VIZ} scene-0103 --frames 10:30 --focus {ids[last]} --save f.rrd --no-progress", env, tmp_path)
    assert viewed.returncode == 0, viewed.stderr
    failure = report["failures"][last]
    expected = f"focus: {ids[last]} at frame {failure['frame_index']} (gnnpmb): {failure['description']}"
    assert expected in viewed.stdout.splitlines()
    whole = _run(f"{VIZ} scene-0103 --frames 10:30 --save a.rrd --no-progress", env, tmp_path)
    assert whole.returncode == 0, whole.stderr
    summary = next(line for line in whole.stdout.splitlines() if line.startswith("gnnpmb failures"))
    assert summary.startswith(
        f"gnnpmb failures in keyframes 10:30 (only those were tracked and evaluated): {totals.split(': ', 1)[1]}"
    )


def test_a_gate_at_the_float_limit_and_new_outputs_follow_one_mode(
    demo_dataroot: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    """``gate_chi2 = 1e308`` draws without a numpy warning; a new recording gets 0644 under umask 022. In-process
    (``tests.inprocess``): the drawing and the file, not the process, are under test; every warning is recorded
    (pytest would otherwise keep them from stderr)."""
    (tmp_path / "big.toml").write_text("[models]\ngate_chi2 = 1e308\n")
    command = (
        f"{VIZ} scene-0103 --tracker gnnpmb --frames 0:3 --no-failures --params big.toml --save g.rrd --no-progress"
    )
    env = _fault_env(demo_dataroot, tmp_path / "cache")
    with umask(0o022), warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        proc = run_script_with(command.split(), env, tmp_path, monkeypatch, capsys)
    assert proc.returncode == 0 and proc.stderr == "", proc.stderr
    assert [str(w.message) for w in caught] == []
    assert _mode(tmp_path / "g.rrd") == 0o644


def test_a_truncated_recording_is_one_line(demo_dataroot: Path, tmp_path: Path) -> None:
    import rerun as rr

    stream = rr.RecordingStream("gnnpmb-viz-test")
    stream.save(tmp_path / "full.rrd")
    stream.log("points", rr.Points3D([[0.0, 0.0, 0.0]] * 1000))
    stream.disconnect()
    data = (tmp_path / "full.rrd").read_bytes()
    (tmp_path / "cut.rrd").write_bytes(data[: len(data) // 2])
    proc = _run(f"{VIZ} reproduce cut.rrd", _fault_env(demo_dataroot, tmp_path / "cache"), tmp_path)
    assert proc.returncode == 2
    _one_line(proc.stderr, "error: cut.rrd is not a readable Rerun recording")
