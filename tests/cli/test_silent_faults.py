"""Issue 33 ("nothing silently wrong, part 3") in real processes: the dataset's files are inputs, caches key on
content, results files are checked like detection files, one sweep per study folder, full disks, long names and
symlink loops said in one line before the work, ``--serve`` on localhost, ``reproduce`` naming a change of code.

Each case runs a console script's command line and checks the exit code, the one ``error:`` line (or the right
answer where the input was legal) and the files left. Where the files are what is under test (caches, names,
results files) the command runs in-process (``tests.inprocess.run_script_with``: a new process's state, the
installed script's own code path), a process start less each (~2 s of CPU); each entry point is also run in
real processes here (the early refusals, the code change of ``reproduce``, a second sweep, a port taken) for the
real exit code and no traceback. The full disk is a real 2 MB tmpfs when running as root (skipped elsewhere;
``tests/gnnpmb/test_outputs.py`` checks the same lines in-process with the free space patched).
"""

from __future__ import annotations

import importlib
import json
import os
import shutil
import socket
import subprocess
import time
from collections.abc import Iterator
from pathlib import Path

import pytest

from tests.cli.test_user_errors import (
    VIZ,
    _check,
    _env,
    _problems_in_real_processes,
    _run,
    _scene_tokens,
    _snapshot,
    _start,
    _work_folder,
)
from tests.inprocess import run_script_with

DATASET_INPUT = "the dataset's files are inputs"
LOOP = "is a symlink loop"


def _cache_env(demo: Path, cache: Path, **extra: str) -> dict[str, str]:
    return _env(demo) | {"GNNPMB_CACHE_DIR": str(cache)} | extra


INDEXES_OPENED = (("gnnpmb.data.nuscenes", "_INDEXES"), ("gnnpmb.data.detections", "_opened"))
"""The dataset's and the detection file's indexes a process keeps open once read: emptied before each command
run in-process, so that each reads its index from the cache folder (``GNNPMB_CACHE_DIR``) as a new process would;
the caches on disk are what these tests are about."""


class _InProcess:
    """``_run``'s signature for the commands of one test run in-process (``run_script_with``), each starting with
    no index open (``INDEXES_OPENED``)."""

    def __init__(self, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]) -> None:
        self.monkeypatch, self.capsys = monkeypatch, capsys

    def __call__(self, command: list[str], env: dict[str, str], cwd: Path) -> subprocess.CompletedProcess:
        for module, name in INDEXES_OPENED:
            self.monkeypatch.setattr(importlib.import_module(module), name, {})
        return run_script_with(command, env, cwd, self.monkeypatch, self.capsys)


@pytest.fixture
def run_in(monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]) -> _InProcess:
    return _InProcess(monkeypatch, capsys)


def _tree(folder: Path) -> dict[str, bytes]:
    return {str(p.relative_to(folder)): p.read_bytes() for p in sorted(folder.rglob("*")) if p.is_file()}


def _copy_tables(demo: Path, to: Path) -> Path:
    """A dataroot at ``to`` with its own copy of the demo's tables; sensor files and maps linked to the demo's."""
    to.mkdir(parents=True)
    shutil.copytree(demo / "v1.0-mini", to / "v1.0-mini")
    for name in ("samples", "maps"):
        (to / name).symlink_to(demo / name)
    return to


def _detections(path: Path, demo: Path, x_m: float = 600.0) -> None:
    """A detection file with one car per sample of both demo scenes, at x = ``x_m`` + the keyframe index."""
    results = {}
    for scene in ("scene-0103", "scene-0916"):
        for k, token in enumerate(_scene_tokens(demo, scene)):
            results[token] = [
                {
                    "sample_token": token,
                    "translation": [x_m + k, 1600.0, 1.0],
                    "size": [2.0, 4.5, 1.6],
                    "rotation": [1.0, 0.0, 0.0, 0.0],
                    "velocity": [2.0, 0.0],
                    "detection_name": "car",
                    "detection_score": 0.9,
                    "attribute_name": "",
                }
            ]
    path.write_text(json.dumps({"meta": {"use_lidar": True}, "results": results}))


def _edit_in_place(path: Path, old: bytes, new: bytes) -> None:
    """Overwrite ``old`` with ``new`` (same length) in the file itself (same inode), then give it back its
    modification time: path, size, mtime and inode all stay as they were."""
    assert len(old) == len(new)
    st = path.stat()
    data = path.read_bytes()
    with open(path, "r+b") as f:
        f.seek(data.index(old))
        f.write(new)
    os.utime(path, ns=(st.st_atime_ns, st.st_mtime_ns))
    after = path.stat()
    assert (after.st_size, after.st_mtime_ns, after.st_ino) == (st.st_size, st.st_mtime_ns, st.st_ino)


def _submission(path: Path, demo: Path, box_of: callable) -> None:
    """A tracking submission for mini_val with ``box_of(token, k)`` as the one box of the k-th sample."""
    tokens = _scene_tokens(demo, "scene-0103") + _scene_tokens(demo, "scene-0916")
    results = {t: [box_of(t, k)] for k, t in enumerate(tokens)}
    path.write_text(json.dumps({"meta": {"use_lidar": True}, "results": results}))


def _box(token: str, k: int, **changes: object) -> dict:
    box = {
        "sample_token": token,
        "translation": [600.0 + k, 1600.0, 1.0],
        "size": [2.0, 4.5, 1.6],
        "rotation": [1.0, 0.0, 0.0, 0.0],
        "velocity": [0.0, 0.0],
        "tracking_id": str(k),
        "tracking_name": "car",
        "tracking_score": 0.9,
    }
    return box | changes


# --- case 1, 8, 11, 14: refused at start-up, before the dataset is read --------------------------------------------


EARLY_CASES: tuple[tuple[str, str, str], ...] = (
    # (name, command with {demo} for the dataroot, text of the error line)
    ("1 out is a table", "gnnpmb track --out {demo}/v1.0-mini/sample_annotation.json", DATASET_INPUT),
    ("1 out is the splits file", "gnnpmb track --out {demo}/v1.0-mini/splits.json", DATASET_INPUT),
    ("1 out is a table, relative", "gnnpmb track --out demo/v1.0-mini/scene.json", DATASET_INPUT),
    ("1 out is a table, symlink", "gnnpmb track --out table.json", DATASET_INPUT),
    ("1 out is a table, hard link", "gnnpmb track --out hard-table.json", "a hard link of the nuScenes file"),
    ("1 json is a table", "gnnpmb failures scene-0103 --json {demo}/v1.0-mini/scene.json", DATASET_INPUT),
    ("1 save in the sensor folder", f"{VIZ} scene-0103 --save {{demo}}/samples/x.rrd", DATASET_INPUT),
    ("1 eval out is the table folder", "gnnpmb eval good.json --out {demo}/v1.0-mini", DATASET_INPUT),
    ("8 loop out", "gnnpmb track --out loop.json", LOOP),
    ("8 loop detections", "gnnpmb track --out new.json --detections loop.json", LOOP),
    ("8 loop params", "gnnpmb track --out new.json --params loop.json", LOOP),
    ("8 loop save", f"{VIZ} scene-0103 --save loop.rrd", LOOP),
    ("8 loop results", "gnnpmb failures scene-0103 --results mine=loop.json", LOOP),
    ("8 loop eval", "gnnpmb eval loop.json", LOOP),
    ("8 loop recording", f"{VIZ} reproduce loop.rrd", LOOP),
    ("8 loop dataroot", "gnnpmb track --out new.json --dataroot loop.json", LOOP),
    ("11 name too long", f"gnnpmb track --out {'n' * 252}.json", "the name is 257 bytes long"),
    ("14 bind not an address", f"{VIZ} scene-0103 --serve --bind nowhere", "--bind nowhere: not an IP address"),
    ("14 bind without serve", f"{VIZ} scene-0103 --save x.rrd --bind 0.0.0.0", "--bind only applies with --serve"),
)


def _early_work(case: tuple[str, str, str], root: Path, demo: Path) -> Path:
    """The case's work folder: good outputs, the dataset linked in (``demo``, ``table.json``, a hard link of a
    table) and symlink loops."""
    work = _work_folder(root / case[0].replace(" ", "_").replace(",", ""))
    (work / "demo").symlink_to(demo)
    (work / "table.json").symlink_to(demo / "v1.0-mini" / "sample_annotation.json")
    os.link(demo / "v1.0-mini" / "sample_annotation.json", work / "hard-table.json")
    for suffix in (".json", ".rrd"):
        (work / f"loop{suffix}").symlink_to(f"loop2{suffix}")
        (work / f"loop2{suffix}").symlink_to(f"loop{suffix}")
    return work


EARLY_REAL_PROCESS = ("1 out is a table, hard link", "8 loop save")
"""Early cases run again through the installed scripts (one per entry point)."""


@pytest.mark.parametrize("case", EARLY_CASES, ids=lambda c: c[0])
def test_outputs_onto_the_dataset_loops_and_long_names_are_one_line_before_any_work(
    case: tuple[str, str, str],
    linkable_demo: Path,
    tmp_path: Path,
    monkeypatch: pytest.MonkeyPatch,
    capsys: pytest.CaptureFixture[str],
) -> None:
    """In-process (``tests.inprocess.run_script``); the dataset's tables are unchanged after each. The dataset is
    ``linkable_demo`` (its own tables): the hard link of a table must not touch the shared demo's."""
    name, command, expected = case
    demo = linkable_demo
    dataset_before = _tree(demo / "v1.0-mini")
    work = _early_work(case, tmp_path, demo)
    before = _snapshot(work)
    proc = run_script_with(command.format(demo=demo).split(), _env(demo), work, monkeypatch, capsys)
    assert _check(name, proc, expected) == []
    assert _snapshot(work) == before
    assert _tree(demo / "v1.0-mini") == dataset_before


def test_early_refusals_in_real_processes(linkable_demo: Path, tmp_path: Path) -> None:
    demo = linkable_demo
    dataset_before = _tree(demo / "v1.0-mini")
    env = _env(demo)
    cases = [c for c in EARLY_CASES if c[0] in EARLY_REAL_PROCESS]
    assert len(cases) == len(EARLY_REAL_PROCESS)

    def one(case: tuple[str, str, str]) -> tuple[str, Path, list[str], str]:
        work = _early_work(case, tmp_path, demo)
        return case[0], work, case[1].format(demo=demo).split(), case[2]

    assert _problems_in_real_processes(cases, one, env) == []
    assert _tree(demo / "v1.0-mini") == dataset_before


def test_a_255_byte_output_name_is_written(demo_dataroot: Path, tmp_path: Path, run_in: _InProcess) -> None:
    """The longest legal name works: the temporary file beside it is named within the limit too."""
    name = "r" * 250 + ".json"
    track = ["gnnpmb", "track", "--out", name, "--tracker", "gnn", "--no-progress"]
    proc = run_in(track, _env(demo_dataroot), tmp_path)
    assert proc.returncode == 0, proc.stderr
    assert [p.name for p in tmp_path.iterdir()] == [name]
    assert json.loads((tmp_path / name).read_text())["results"]


def test_a_port_taken_on_ipv6_loopback_counts_as_in_use(demo_dataroot: Path, tmp_path: Path) -> None:
    if not socket.has_ipv6:
        pytest.skip("no IPv6 here")
    with socket.socket(socket.AF_INET6) as taken:
        taken.setsockopt(socket.IPPROTO_IPV6, socket.IPV6_V6ONLY, 1)
        try:
            taken.bind(("::1", 0))
        except OSError:
            pytest.skip("no ::1 here")
        taken.listen()
        port = taken.getsockname()[1]
        proc = _run([VIZ, "scene-0103", "--serve", "--web-port", str(port)], _env(demo_dataroot), cwd=tmp_path)
    assert _check("port on ::1", proc, f"--web-port {port}: the port is in use on ::1") == []


# --- case 14: what --serve listens on --------------------------------------------------------------------------------


# --- case 2: caches key on content ------------------------------------------------------------------------------------


def _tracking_own_detections(demo: Path, folder: Path) -> tuple[dict[str, str], list[str]]:
    """A cache folder and a detection file (``_detections``) in ``folder``: the environment and the ``gnnpmb track``
    command line that reads that file, its output name to be appended."""
    _detections(folder / "det.json", demo)
    env = _cache_env(demo, folder / "cache")
    return env, ["gnnpmb", "track", "--detections", "det.json", "--tracker", "gnn", "--no-progress", "--out"]


def test_a_detection_file_edited_in_place_with_its_old_mtime_is_read_again(
    demo_dataroot: Path, tmp_path: Path, run_in: _InProcess
) -> None:
    env, track = _tracking_own_detections(demo_dataroot, tmp_path)
    first = run_in([*track, "a.json"], env, tmp_path)
    assert first.returncode == 0, first.stderr
    _edit_in_place(tmp_path / "det.json", b"[601.0, 1600.0", b"[951.0, 1600.0")
    second = run_in([*track, "b.json"], env, tmp_path)
    assert second.returncode == 0, second.stderr
    assert (tmp_path / "a.json").read_bytes() != (tmp_path / "b.json").read_bytes()  # the old code: identical


def test_reproduce_hashes_the_detection_file_itself(demo_dataroot: Path, tmp_path: Path, run_in: _InProcess) -> None:
    env = _cache_env(demo_dataroot, tmp_path / "cache")
    _detections(tmp_path / "det.json", demo_dataroot)
    record = [VIZ, "scene-0103", "--detections", "det.json", "--tracker", "gnn", "--frames", "0:3"]
    proc = run_in([*record, "--no-failures", "--no-progress", "--save", "run.rrd"], env, tmp_path)
    assert proc.returncode == 0, proc.stderr
    _edit_in_place(tmp_path / "det.json", b"[601.0, 1600.0", b"[951.0, 1600.0")
    proc = run_in([VIZ, "reproduce", "run.rrd"], env, tmp_path)
    assert _check("reproduce after an edit", proc, "det.json has changed since the recording") == []


# --- case 7: a damaged index side file is rebuilt ---------------------------------------------------------------------


def _flip_a_byte(path: Path) -> None:
    data = bytearray(path.read_bytes())
    position = data.index(b'"', len(data) // 2) + 1  # inside a string: still JSON, another value
    data[position] ^= 0x01
    path.write_bytes(bytes(data))


@pytest.mark.parametrize("side_file", ["scenes.json", "small.json"])
def test_a_damaged_dataset_index_side_file_is_rebuilt(
    side_file: str, demo_dataroot: Path, tmp_path: Path, run_in: _InProcess
) -> None:
    """A flipped byte in a side file of the dataset's index: the next run rebuilds the index and says the same."""
    env = _cache_env(demo_dataroot, tmp_path / "cache")
    command = ["gnnpmb", "failures", "scene-0103", "--tracker", "gnn", "--frames", "0:2"]
    first = run_in(command, env, tmp_path)
    assert first.returncode == 0, first.stderr
    (index,) = (tmp_path / "cache" / "index").glob("dataset-*")
    intact = (index / side_file).read_bytes()
    _flip_a_byte(index / side_file)
    second = run_in(command, env, tmp_path)
    assert second.returncode == 0, second.stderr
    assert second.stdout == first.stdout
    assert (index / side_file).read_bytes() == intact  # rebuilt, not read as it was (nor left damaged)


def test_a_damaged_detection_index_side_file_is_rebuilt(
    demo_dataroot: Path, tmp_path: Path, run_in: _InProcess
) -> None:
    env, track = _tracking_own_detections(demo_dataroot, tmp_path)
    assert run_in([*track, "a.json"], env, tmp_path).returncode == 0
    (index,) = (tmp_path / "cache" / "index").glob("detections-*")
    intact = (index / "samples.json").read_bytes()
    _flip_a_byte(index / "samples.json")
    second = run_in([*track, "b.json"], env, tmp_path)
    assert second.returncode == 0, second.stderr
    assert (tmp_path / "a.json").read_bytes() == (tmp_path / "b.json").read_bytes()
    assert (index / "samples.json").read_bytes() == intact  # rebuilt, not read as it was (nor left damaged)


# --- case 3, 5, 6, 12: results files and tables checked like detection files ------------------------------------------


RESULTS_CASES = {
    "mixed ids": (lambda t, k: _box(t, k, tracking_id=k if k % 2 else str(k)), "tracking_id is an integer"),
    "zero quaternion": (lambda t, k: _box(t, k, rotation=[0.0, 0.0, 0.0, 0.0]), "is not a rotation"),
    "non-unit quaternion": (lambda t, k: _box(t, k, rotation=[0.5, 0.0, 0.0, 0.0]), "not a unit quaternion"),
    "zero size": (lambda t, k: _box(t, k, size=[0.0, 4.5, 1.6]), "field 'size' must be positive"),
    "far away": (lambda t, k: _box(t, k, translation=[1e6 + 600.0, 1600.0, 1.0]), "beyond 1e+05 m"),
}


@pytest.mark.parametrize("name", RESULTS_CASES)
def test_results_files_the_devkit_would_read_otherwise_are_one_line(
    name: str,
    demo_dataroot: Path,
    tmp_path: Path,
    monkeypatch: pytest.MonkeyPatch,
    capsys: pytest.CaptureFixture[str],
) -> None:
    """In-process (``tests.inprocess.run_script_with``): the checks of the file are under test; a results file's
    one line in a real process is ``test_user_errors``' 'eval truncated'."""
    box_of, expected = RESULTS_CASES[name]
    env = _cache_env(demo_dataroot, tmp_path / "cache")
    work = tmp_path / "work"
    work.mkdir()
    _submission(work / "r.json", demo_dataroot, box_of)
    before = _snapshot(work)
    for command in (
        ["gnnpmb", "eval", "r.json", "--out", "ev"],
        ["gnnpmb", "failures", "scene-0103", "--results", "mine=r.json"],
    ):
        proc = run_script_with(command, env, work, monkeypatch, capsys)
        assert _check(f"{name}: {command[1]}", proc, expected) == []
    assert _snapshot(work) == before


def test_a_dataset_without_annotations_is_said_once(demo_dataroot: Path, tmp_path: Path, run_in: _InProcess) -> None:
    root = _copy_tables(demo_dataroot, tmp_path / "test-like")
    (root / "v1.0-mini" / "sample_annotation.json").write_text("[]")
    env = _cache_env(demo_dataroot, tmp_path / "cache")
    _submission(tmp_path / "r.json", demo_dataroot, lambda t, k: _box(t, k))
    proc = run_in(["gnnpmb", "eval", "r.json", "--dataroot", str(root), "--out", "ev"], env, tmp_path)
    assert _check("eval", proc, "split mini_val of") == []
    assert "has no ground truth" in proc.stderr
    proc = run_in(["gnnpmb", "failures", "scene-0103", "--dataroot", str(root), "-t", "gnn"], env, tmp_path)
    assert _check("failures", proc, "scene-0103 has no ground-truth boxes") == []
    assert not (tmp_path / "ev").exists()


def test_a_first_sample_token_that_names_no_sample_is_one_line(
    demo_dataroot: Path, tmp_path: Path, run_in: _InProcess
) -> None:
    root = _copy_tables(demo_dataroot, tmp_path / "edited")
    scenes = json.loads((root / "v1.0-mini" / "scene.json").read_text())
    scenes[0]["first_sample_token"] = "f" * 32
    (root / "v1.0-mini" / "scene.json").write_text(json.dumps(scenes))
    env = _cache_env(demo_dataroot, tmp_path / "cache")
    proc = run_in(["gnnpmb", "failures", scenes[0]["name"], "--dataroot", str(root)], env, tmp_path)
    expected = f"v1.0-mini/scene.json: scene '{scenes[0]['name']}' has first_sample_token '{'f' * 32}', the token of no"
    assert _check("bad first sample", proc, expected) == []


# --- case 4: one sweep at a time per study folder ------------------------------------------------------------------


def test_a_second_sweep_into_a_folder_waits_for_the_first(demo_dataroot: Path, tmp_path: Path) -> None:
    """Another process holds the study folder (as a running sweep does): the sweep says so and waits; it runs once
    the folder is let go. On the study tests' tiny data (one scene cut to a few keyframes) and one worker (no
    Ray instance for one configuration): the wait is the point, not the sweep's work."""
    import sys

    from tests.gnnpmb.study.conftest import TINY_FRAMES, TINY_SCENE, cut_dataset

    tiny = cut_dataset(demo_dataroot, tmp_path / "tiny", [TINY_SCENE], TINY_FRAMES)
    env = _cache_env(tiny, tmp_path / "cache")
    study = tmp_path / "study"
    holder = subprocess.Popen(
        [
            sys.executable,
            "-c",
            "import sys; from gnnpmb.study.lock import hold_study_folder; "
            f"hold_study_folder({str(study)!r}, print); print('held', flush=True); sys.stdin.readline()",
        ],
        stdin=subprocess.PIPE,
        stdout=subprocess.PIPE,
        text=True,
    )
    assert holder.stdout.readline().strip() == "held"
    sweep = ["gnnpmb", "sweep", "--out", "study", "--tracker", "gnn", "--param", "models.gate_chi2=20"]
    sweep += ["--workers", "1", "--no-progress"]
    proc = _start(sweep, env, tmp_path)
    first = proc.stderr.readline()
    assert first.startswith(f"note: another sweep is writing {study}; waiting"), first
    time.sleep(1.0)
    assert proc.poll() is None and not (study / "results.json").exists()  # still waiting
    holder.communicate("go\n", timeout=60)
    out, err = proc.communicate(timeout=600)
    assert proc.returncode == 0, err
    assert len(json.loads((study / "results.json").read_text())["rows"]) == 1


# --- case 10: full disk ---------------------------------------------------------------------------------------------


@pytest.fixture
def full_disk(tmp_path: Path) -> Iterator[Path]:
    """A 2 MB tmpfs filled to 1.8 MB (root only)."""
    if os.geteuid() != 0 or shutil.which("mount") is None:
        pytest.skip("mounting a tmpfs needs root")
    mount = tmp_path / "small"
    mount.mkdir()
    done = subprocess.run(["mount", "-t", "tmpfs", "-o", "size=2m", "tmpfs", str(mount)], capture_output=True)
    if done.returncode != 0:
        pytest.skip(f"cannot mount a tmpfs here: {done.stderr!r}")
    try:
        (mount / "fill").write_bytes(b"\0" * 1_800_000)
        yield mount
    finally:
        subprocess.run(["umount", str(mount)], check=False)


def test_a_full_disk_is_one_line_naming_the_place(
    demo_dataroot: Path, tmp_path: Path, full_disk: Path, run_in: _InProcess
) -> None:
    env = _cache_env(demo_dataroot, tmp_path / "cache")
    proc = run_in(["gnnpmb", "track", "--out", str(full_disk / "r.json")], env, tmp_path)
    assert (
        _check("out on a full disk", proc, f"--out {full_disk / 'r.json'}: the disk of folder {full_disk} is full")
        == []
    )
    cache = full_disk / "cache"
    proc = run_in(["gnnpmb", "track", "--out", "r.json", "--no-progress"], _cache_env(demo_dataroot, cache), tmp_path)
    assert _check("cache on a full disk", proc, f"cannot write {cache}/index/dataset-") == []
    assert f"free space in {cache} or point GNNPMB_CACHE_DIR at a folder with room" in proc.stderr
    assert sorted(p.name for p in full_disk.iterdir()) == ["cache", "fill"]
    assert not (tmp_path / "r.json").exists()


# --- case 13: reproduce says when the code differs --------------------------------------------------------------------


def test_reproduce_names_a_change_of_code(demo_dataroot: Path, tmp_path: Path, run_in: _InProcess) -> None:
    """The recording is made by a copy of the package that differs by one comment (same version number), in a real
    process (its ``PYTHONPATH`` is the change); ``reproduce`` runs this checkout's code, in-process as a new process
    of the console script would (a process start less)."""
    import gnnpmb

    copy = tmp_path / "code"
    shutil.copytree(Path(gnnpmb.__file__).parent, copy / "gnnpmb")
    with open(copy / "gnnpmb" / "kalman.py", "a") as f:
        f.write("# an edit\n")
    env = _cache_env(demo_dataroot, tmp_path / "cache")
    record = [VIZ, "scene-0103", "--tracker", "gnn", "--frames", "0:3", "--no-failures", "--no-progress"]
    proc = _run([*record, "--save", "run.rrd"], env | {"PYTHONPATH": str(copy)}, cwd=tmp_path)
    assert proc.returncode == 0, proc.stderr
    proc = run_in([VIZ, "reproduce", "run.rrd"], env, cwd=tmp_path)
    assert proc.returncode == 0, proc.stderr
    assert "note: recorded with other gnnpmb code (source digest" in proc.stderr
    assert "gnn: identical" in proc.stdout
