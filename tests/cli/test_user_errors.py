"""Every user mistake of issue 10: exit code 2, one ``error:`` line on stderr, no traceback, no new or changed file
(a good output already sits at the output paths).

Cases that fail before the dataset is read run in-process (``tests.inprocess.run_script``: the console script's
code up to its exit, without a process start each); a few of them, one per entry point and kind of mistake, run
again through the installed scripts in real processes. The few that need the dataset (a bad box in one sample, an
empty submission) load the demo once each, in-process too; the variants of those are unit tests of the checks.
"""

from __future__ import annotations

import functools
import json
import os
import signal
import socket
import subprocess
import sys
import time
from collections.abc import Callable, Sequence
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass
from pathlib import Path
from typing import TypeVar

import pytest

from tests.inprocess import run_script_with

BIN = Path(sys.executable).parent
GOOD = b"a good output from an earlier run\n"
T = TypeVar("T")


@dataclass(frozen=True)
class Case:
    """A command line (``{w}`` = the work folder, ``{demo}`` = the demo dataroot) and a text its error line
    must contain."""

    name: str
    argv: tuple[str, ...]
    expected: str


def _case(name: str, command: str, expected: str) -> Case:
    return Case(name, tuple(command.split()), expected)


VIZ = "gnnpmb-viz"
SAVE = "--save {w}/good.rrd"
IS_INPUT = "is the --detections file"
CASES_BEFORE_DATA: tuple[Case, ...] = (
    # usage errors of gnnpmb-viz (typer's bundled click)
    _case("viz typo option", f"{VIZ} scene-0103 --frame 1", "no such option: --frame"),
    _case("viz typo tracker option", f"{VIZ} scene-0103 --trackr gnn {SAVE}", "--trackr"),
    _case("viz no scene", f"{VIZ}", "missing argument 'SCENE'"),
    _case("viz seed not int", f"{VIZ} scene-0103 --seed abc {SAVE}", "'--seed'"),
    _case("viz option without value", f"{VIZ} scene-0103 --save", "requires an argument"),
    _case("viz old --version V", f"{VIZ} scene-0103 --version v1.0-mini", "--nuscenes-version v1.0-mini"),
    _case("viz two scenes", f"{VIZ} scene-0103 scene-0916 {SAVE}", "unexpected extra argument"),
    _case("reproduce no file", f"{VIZ} reproduce", "missing argument 'FILE.rrd'"),
    _case("reproduce typo option", f"{VIZ} reproduce {{w}}/good.rrd --dataroott x", "--dataroott"),
    _case("reproduce not a recording", f"{VIZ} reproduce {{w}}/good.json", "good.json"),
    # names, ranges, conflicts
    _case("viz unknown tracker", f"{VIZ} scene-0103 --tracker nope {SAVE}", "unknown tracker"),
    _case("viz unknown tracker, no --save", f"{VIZ} scene-0103 --tracker simpletrak", "unknown tracker 'simpletrak'"),
    _case("viz unknown class", f"{VIZ} scene-0103 --classes car,tree {SAVE}", "unknown class"),
    _case("viz unknown preset", f"{VIZ} scene-0103 --detector yolo {SAVE}", "preset 'yolo'"),
    _case("viz bad frames", f"{VIZ} scene-0103 --frames 5:2 {SAVE}", "END must be greater"),
    _case("viz frames text", f"{VIZ} scene-0103 --frames abc {SAVE}", "bad --frames 'abc'"),
    _case(
        "viz detections and detector",
        f"{VIZ} scene-0103 --detections {{w}}/good.json --detector megvii {SAVE}",
        "not both",
    ),
    _case("viz save and serve", f"{VIZ} scene-0103 --serve {SAVE}", "not both"),
    _case("viz bad port", f"{VIZ} scene-0103 --serve --web-port 70000", "--web-port 70000"),
    _case("viz same ports", f"{VIZ} scene-0103 --serve --web-port 9100 --grpc-port 9100", "different ports"),
    _case("viz port in use", f"{VIZ} scene-0103 --serve --grpc-port {{busy_port}}", "in use"),
    _case("viz no display", f"{VIZ} scene-0103", "--save OUT.rrd"),
    _case("viz no such version", f"{VIZ} scene-0103 --nuscenes-version v1.0-trainval {SAVE}", "no v1.0-trainval/"),
    # input files
    _case("viz missing dataroot", f"{VIZ} scene-0103 --dataroot {{w}}/nowhere {SAVE}", "does not exist"),
    _case("viz detections folder", f"{VIZ} scene-0103 --detections {{w}} {SAVE}", "is a folder"),
    _case("viz detections missing", f"{VIZ} scene-0103 --detections {{w}}/no.json {SAVE}", "not found"),
    _case("viz detections truncated", f"{VIZ} scene-0103 --detections {{w}}/trunc.json {SAVE}", "truncated"),
    # output paths
    _case("viz save not rrd", f"{VIZ} scene-0103 --save {{w}}/good.json", "must end in .rrd"),
    _case("viz save folder", f"{VIZ} scene-0103 --save {{w}}/dir.rrd", "is a folder"),
    _case("viz save missing folder", f"{VIZ} scene-0103 --save {{w}}/no/x.rrd", "does not exist"),
    # gnnpmb
    _case(
        "batch no command",
        "gnnpmb",
        "missing a command (track, eval, failures, demo-data, sweep, tune, diff, calibrate)",
    ),
    _case("batch unknown command", "gnnpmb trak", "no such command 'trak'"),
    _case("batch old --version V", "gnnpmb track --version v1.0-mini", "--nuscenes-version"),
    _case("track no out", "gnnpmb track", "missing option '--out'"),
    _case("track typo option", "gnnpmb track --out {w}/good.json --trackr gnn", "--trackr"),
    _case("track seed not int", "gnnpmb track --out {w}/good.json --seed x", "'--seed'"),
    _case("track unknown tracker", "gnnpmb track --out {w}/good.json -t nope", "unknown tracker"),
    _case("track out folder", "gnnpmb track --out {w}", "is a folder"),
    _case("track out device", "gnnpmb track --out /dev/null", "not a regular file"),
    _case("track out missing folder", "gnnpmb track --out {w}/no/r.json", "does not exist"),
    _case(
        "track detections and detector",
        "gnnpmb track --out {w}/good.json --detections {w}/trunc.json --detector megvii",
        "not both",
    ),
    _case("track detections folder", "gnnpmb track --out {w}/good.json --detections {w}", "is a folder"),
    _case("track detections truncated", "gnnpmb track --out {w}/good.json --detections {w}/trunc.json", "truncated"),
    _case("track bad split", "gnnpmb track --out {w}/good.json --split nope", "unknown split"),
    _case("eval no file", "gnnpmb eval", "missing argument 'RESULTS.json'"),
    _case("eval missing file", "gnnpmb eval {w}/no.json", "not found"),
    _case("eval folder", "gnnpmb eval {w}", "is a folder"),
    _case("eval out device", "gnnpmb eval {w}/good.json --out /dev/null", "is a file, not a folder"),
    _case("eval out file", "gnnpmb eval {w}/good.json --out {w}/good.rrd", "is a file, not a folder"),
    _case("eval truncated", "gnnpmb eval {w}/trunc.json", "not valid JSON"),
    _case("failures no scene", "gnnpmb failures", "missing argument 'SCENE'"),
    _case("failures json folder", "gnnpmb failures scene-0103 --json {w}", "is a folder"),
    _case("failures json device", "gnnpmb failures scene-0103 --json /dev/null", "not a regular file"),
    _case("failures unknown tracker", "gnnpmb failures scene-0103 -t nope", "unknown tracker"),
    _case("demo-data no out", "gnnpmb demo-data", "missing option '--out'"),
    _case("demo-data out device", "gnnpmb demo-data --out /dev/null", "is a file, not a folder"),
    _case("demo-data out not empty", "gnnpmb demo-data --out {w}", "not empty"),
    _case("demo-data seed not int", "gnnpmb demo-data --out {w}/new --seed x", "'--seed'"),
    # issue 22: negative seeds, outputs that are inputs (however spelled), a parameter under its real section
    _case("viz seed negative", f"{VIZ} scene-0103 --seed -1 {SAVE}", "'--seed'"),
    _case("track seed negative", "gnnpmb track --out {w}/good.json --seed -1", "'--seed'"),
    _case("failures seed negative", "gnnpmb failures scene-0103 --seed -1", "'--seed'"),
    _case("demo-data seed negative", "gnnpmb demo-data --out {w}/new --seed -1", "'--seed'"),
    _case("tune seed negative", "gnnpmb tune --out {w}/t.toml --seed -1", "'--seed'"),
    _case("track out is detections", "gnnpmb track --out {w}/good.json --detections {w}/good.json", IS_INPUT),
    _case("track out relative", "gnnpmb track --out good.json --detections ./sub/../good.json", IS_INPUT),
    _case("track out hard link", "gnnpmb track --out {w}/hard.json --detections {w}/good.json", IS_INPUT),
    _case("track out symlink", "gnnpmb track --out {w}/good.json --detections {w}/link.json", IS_INPUT),
    _case(
        "failures json is a results file",
        "gnnpmb failures scene-0103 --results mine={w}/good.json --json {w}/good.json",
        "is the --results mine file",
    ),
    _case(
        "diff json is a results file",
        "gnnpmb diff gnnpmb mine={w}/good.json --json {w}/link.json",
        "is the --results mine file",
    ),
    _case("track out is params", "gnnpmb track --out {w}/good.json --params {w}/hard.json", "the --params file"),
    _case(
        "failures json is detections",
        "gnnpmb failures scene-0103 --json {w}/link.json --detections {w}/good.json",
        IS_INPUT,
    ),
    _case("viz save is params", f"{VIZ} scene-0103 --params {{w}}/good.rrd {SAVE}", "the --params file"),
    _case("reproduce save is file", f"{VIZ} reproduce {{w}}/good.rrd {SAVE}", "the FILE.rrd file"),
    _case("tune out is params", "gnnpmb tune --out {w}/good.toml --params {w}/good.toml", "the --params file"),
    _case(
        "sweep writes detections",
        "gnnpmb sweep --out {w} --param models.gate_chi2=20 --detections {w}/results.json",
        IS_INPUT,
    ),
    _case(
        "params class section", f"{VIZ} scene-0103 --params {{w}}/confirm.toml {SAVE}", "[classes.car] need confirm_m"
    ),
)


def _bad_box_file(path: Path, demo: Path, field: str, value: object) -> None:
    """A detection file for scene-0103 whose first sample has one box with ``field`` = ``value``."""
    tokens = _scene_tokens(demo, "scene-0103")
    box = {
        "translation": [600.0, 1600.0, 1.0],
        "size": [2.0, 4.5, 1.6],
        "rotation": [1.0, 0.0, 0.0, 0.0],
        "velocity": [0.0, 0.0],
        "detection_name": "car",
        "detection_score": 0.9,
    } | {field: value}
    results: dict[str, list] = {t: [] for t in tokens}
    results[tokens[0]] = [box]
    path.write_text(json.dumps({"meta": {}, "results": results}))


def _scene_tokens(demo: Path, scene_name: str) -> list[str]:
    tables = demo / "v1.0-mini"
    scene = next(s for s in json.loads((tables / "scene.json").read_text()) if s["name"] == scene_name)
    samples = {s["token"]: s for s in json.loads((tables / "sample.json").read_text())}
    tokens, token = [], scene["first_sample_token"]
    while token:
        tokens.append(token)
        token = samples[token]["next"]
    return tokens


def _split_tokens(demo: Path) -> list[str]:
    return _scene_tokens(demo, "scene-0103") + _scene_tokens(demo, "scene-0916")


def _empty_submission(path: Path, demo: Path) -> None:
    meta = {"use_camera": False, "use_lidar": True, "use_radar": False, "use_map": False, "use_external": False}
    path.write_text(json.dumps({"meta": meta, "results": {t: [] for t in _split_tokens(demo)}}))


@dataclass(frozen=True)
class DataCase:
    """A case that needs the demo dataset: a setup writing ``{w}/input.json`` and a command line."""

    name: str
    setup: Callable[[Path, Path], None]
    command: str
    expected: str


def _box_case(field: str, value: object, expected: str) -> DataCase:
    return DataCase(
        f"box {field}={value!r}",
        lambda path, demo: _bad_box_file(path, demo, field, value),
        f"{VIZ} scene-0103 --detections {{w}}/input.json {SAVE} --no-progress",
        expected,
    )


def _swapped_file(path: Path, demo: Path, kind: str) -> None:
    """A well-formed file of the other kind than the command expects, for the demo's mini_val samples: a detection
    file (``kind`` "detection") or a tracking submission ("tracking")."""
    meta = {"use_camera": False, "use_lidar": True, "use_radar": False, "use_map": False, "use_external": False}
    box = {"translation": [600.0, 1600.0, 1.0], "size": [2.0, 4.5, 1.6], "rotation": [1.0, 0.0, 0.0, 0.0]}
    box |= {"velocity": [0.0, 0.0]}
    if kind == "detection":
        box |= {"detection_name": "car", "detection_score": 0.9}
    else:
        box |= {"tracking_name": "car", "tracking_score": 0.9, "tracking_id": "1"}
    results = {t: [box | {"sample_token": t}] for t in _split_tokens(demo)}
    path.write_text(json.dumps({"meta": meta, "results": results}))


CASES_WITH_DATA: tuple[DataCase, ...] = (
    # the other field checks are unit tests (tests/gnnpmb/data/test_detections.py)
    _box_case("size", [2.0, -4.5, 1.6], "field 'size' must be positive"),
    DataCase(
        "eval a detection file",
        lambda path, demo: _swapped_file(path, demo, "detection"),
        "gnnpmb eval {w}/input.json --split mini_val --out {w}/ev",
        "this is a detection file, not tracking results; pass it as --detections FILE.json",
    ),
    DataCase(
        "results run of a detection file",
        lambda path, demo: _swapped_file(path, demo, "detection"),
        "gnnpmb failures scene-0103 --results mine={w}/input.json",
        "this is a detection file, not tracking results",
    ),
    DataCase(
        "tracking results as detections",
        lambda path, demo: _swapped_file(path, demo, "tracking"),
        f"{VIZ} scene-0103 --detections {{w}}/input.json {SAVE} --no-progress",
        "this is a tracking results file, not detections; open it with --results NAME=FILE.json",
    ),
    # duplicate ids: tests/gnnpmb/eval/test_submission.py
    DataCase(
        "eval empty submission",
        _empty_submission,
        "gnnpmb eval {w}/input.json --split mini_val --out {w}/ev",
        "has no boxes in any of the 80 samples",
    ),
)


def _snapshot(folder: Path) -> dict[str, bytes | None]:
    return {str(p.relative_to(folder)): (p.read_bytes() if p.is_file() else None) for p in sorted(folder.rglob("*"))}


def _work_folder(root: Path) -> Path:
    work = root
    work.mkdir(parents=True, exist_ok=True)
    for name in ("good.rrd", "good.json", "good.toml"):
        (work / name).write_bytes(GOOD)
    (work / "trunc.json").write_text('{"meta": {}, "results": {"abc": [')
    (work / "dir.rrd").mkdir()
    (work / "sub").mkdir()
    os.link(work / "good.json", work / "hard.json")
    (work / "link.json").symlink_to("good.json")
    (work / "confirm.toml").write_text("[classes.car]\nconfirm_m = 5\n")
    return work


def _run(argv: list[str], env: dict[str, str], **kwargs) -> subprocess.CompletedProcess[str]:
    exe = str(BIN / argv[0])
    return subprocess.run([exe, *argv[1:]], capture_output=True, text=True, env=env, timeout=300, **kwargs)


def _start(argv: list[str], env: dict[str, str], cwd: Path) -> subprocess.Popen[str]:
    """An installed script started in a real process (SIGINT at its default, umask 022), its output piped."""
    return subprocess.Popen(
        [str(BIN / argv[0]), *argv[1:]],
        cwd=cwd,
        env=env,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        preexec_fn=lambda: (signal.signal(signal.SIGINT, signal.SIG_DFL), os.umask(0o022)),
    )


def _env(demo: Path) -> dict[str, str]:
    env = {k: v for k, v in os.environ.items() if k not in ("DISPLAY", "WAYLAND_DISPLAY")}
    env["NUSCENES_DATAROOT"] = str(demo)  # never build a demo in the user's cache
    env["COLUMNS"] = "200"
    return env


def _check(name: str, proc: subprocess.CompletedProcess[str], expected: str) -> list[str]:
    """Problems with one case's outcome (empty when it behaved)."""
    problems = []
    lines = proc.stderr.strip().splitlines()
    if proc.returncode != 2:
        problems.append(f"exit {proc.returncode}")
    if len(lines) != 1 or not lines[0].startswith("error: "):
        problems.append(f"stderr is not one error line: {proc.stderr[-400:]!r}")
    elif expected not in lines[0]:
        problems.append(f"{expected!r} not in {lines[0]!r}")
    if "Traceback" in proc.stderr + proc.stdout:
        problems.append("traceback")
    return [f"{name}: {p}" for p in problems]


def _problems_in_real_processes(
    cases: Sequence[T], one: Callable[[T], tuple[str, Path, list[str], str]], env: dict[str, str]
) -> list[str]:
    """Each case run in a real process, two at a time: ``one(case)`` prepares its work folder and gives (name,
    work folder, command line, expected error); the problems of every case whose outcome or files were wrong."""

    def run(case: T) -> list[str]:
        name, work, argv, expected = one(case)
        before = _snapshot(work)
        problems = _check(name, _run(argv, env, cwd=work), expected)
        if _snapshot(work) != before:
            problems.append(f"{name}: files changed")
        return problems

    with ThreadPoolExecutor(max_workers=2) as pool:
        return [p for found in pool.map(run, cases) for p in found]


@pytest.fixture(scope="module")
def busy_port() -> int:
    """A TCP port held open for the module (the 'port in use' case)."""
    sock = socket.socket(socket.AF_INET, socket.SOCK_STREAM)
    sock.bind(("0.0.0.0", 0))
    sock.listen(1)
    yield sock.getsockname()[1]
    sock.close()


REAL_PROCESS = (
    "viz typo option",
    "reproduce not a recording",
    "viz port in use",
    "batch unknown command",
    "track out hard link",
    "eval truncated",
)
"""Cases run again through the installed scripts: each entry point (``gnnpmb-viz``, its ``reproduce``,
``gnnpmb``) with a parser's usage error and with one of our own checks."""


def _case_work(root: Path, case: Case, busy_port: int) -> tuple[Path, list[str]]:
    """The case's work folder (good outputs in place) and its command line."""
    work = _work_folder(root / case.name.replace(" ", "_").replace(",", ""))
    return work, [a.format(w=work, busy_port=busy_port) for a in case.argv]


@pytest.mark.parametrize("case", CASES_BEFORE_DATA, ids=lambda c: c.name)
def test_mistakes_found_before_the_data_are_one_line(
    case: Case,
    demo_dataroot: Path,
    tmp_path: Path,
    busy_port: int,
    monkeypatch: pytest.MonkeyPatch,
    capsys: pytest.CaptureFixture[str],
) -> None:
    work, argv = _case_work(tmp_path, case, busy_port)
    before = _snapshot(work)
    proc = run_script_with(argv, _env(demo_dataroot), work, monkeypatch, capsys)
    assert _check(case.name, proc, case.expected) == []
    assert _snapshot(work) == before


def test_mistakes_in_real_processes_are_one_line(demo_dataroot: Path, tmp_path: Path, busy_port: int) -> None:
    env = _env(demo_dataroot)
    cases = [c for c in CASES_BEFORE_DATA if c.name in REAL_PROCESS]
    assert len(cases) == len(REAL_PROCESS)

    def one(case: Case) -> tuple[str, Path, list[str], str]:
        return case.name, *_case_work(tmp_path, case, busy_port), case.expected

    assert _problems_in_real_processes(cases, one, env) == []


@pytest.mark.parametrize("case", CASES_WITH_DATA, ids=lambda c: c.name)
def test_mistakes_found_in_the_data_are_one_line(
    case: DataCase,
    demo_dataroot: Path,
    tmp_path: Path,
    monkeypatch: pytest.MonkeyPatch,
    capsys: pytest.CaptureFixture[str],
) -> None:
    work = _work_folder(tmp_path / "w")
    case.setup(work / "input.json", demo_dataroot)
    before = _snapshot(work)
    proc = run_script_with(case.command.format(w=work).split(), _env(demo_dataroot), work, monkeypatch, capsys)
    assert _check(case.name, proc, case.expected) == []
    assert _snapshot(work) == before


def _limit_file_size(max_bytes: int) -> None:
    """In the child: files cannot grow beyond max_bytes (EFBIG instead of SIGXFSZ), like a full disk."""
    import resource

    signal.signal(signal.SIGXFSZ, signal.SIG_IGN)
    resource.setrlimit(resource.RLIMIT_FSIZE, (max_bytes, max_bytes))


@pytest.mark.parametrize(
    ("command", "max_bytes"),
    [
        ("gnnpmb track --out {w}/good.json --no-progress", 64 * 1024),
        # larger: Rerun 0.41 can hang for good when its file cannot even hold the header and blueprint
        (f"{VIZ} scene-0103 --tracker gnn --frames 0:3 --no-failures {SAVE} --no-progress", 512 * 1024),
    ],
    ids=["track", "viz"],
)
def test_a_full_disk_is_one_line_and_leaves_no_partial_file(
    command: str, max_bytes: int, demo_dataroot: Path, tmp_path: Path
) -> None:
    work = _work_folder(tmp_path / "w")
    before = _snapshot(work)
    limit = functools.partial(_limit_file_size, max_bytes)
    proc = _run(command.format(w=work).split(), _env(demo_dataroot), cwd=work, preexec_fn=limit)
    assert _check("full disk", proc, "cannot write") == []
    assert _snapshot(work) == before


def test_ctrl_c_while_saving_leaves_no_partial_file(demo_dataroot: Path, tmp_path: Path) -> None:
    """Ctrl-C once the recording's temp file exists. Without the failure report (``--no-failures``): the
    recording is opened after the evaluation, which would only add 4 s of CPU before the signal."""
    work = _work_folder(tmp_path / "w")
    before = _snapshot(work)
    argv = [VIZ, "scene-0103", "--tracker", "gnn", "--no-failures", "--save", str(work / "good.rrd"), "--no-progress"]
    proc = _start(argv, _env(demo_dataroot), work)
    deadline = time.monotonic() + 120
    while not any(p.name.endswith(".partial") for p in work.iterdir()) and time.monotonic() < deadline:
        time.sleep(0.05)
    proc.send_signal(signal.SIGINT)
    _, err = proc.communicate(timeout=120)
    assert proc.returncode == 130, err
    assert err == "interrupted by Ctrl-C: unfinished outputs were not written\n"
    assert _snapshot(work) == before


def _other_dataset_files(work: Path) -> None:
    """A detection file and a tracking submission of a dataset that is not the demo (sample tokens it lacks)."""
    box = {"translation": [1.0, 2.0, 1.0], "size": [2.0, 4.5, 1.6], "rotation": [1.0, 0.0, 0.0, 0.0]}
    box |= {"velocity": [0.0, 0.0], "sample_token": "0" * 32}
    det = box | {"detection_name": "car", "detection_score": 0.9}
    track = box | {"tracking_name": "car", "tracking_score": 0.9, "tracking_id": "1"}
    meta = {"use_camera": False, "use_lidar": True, "use_radar": False, "use_map": False, "use_external": False}
    (work / "own_det.json").write_text(json.dumps({"meta": meta, "results": {"0" * 32: [det]}}))
    (work / "own_results.json").write_text(json.dumps({"meta": meta, "results": {"0" * 32: [track]}}))


NO_DATAROOT = "no --dataroot or $NUSCENES_DATAROOT was given, so this is the built-in demo dataset"


@pytest.mark.parametrize(
    ("command", "expected"),
    [
        (f"{VIZ} scene-0103 --detections {{w}}/own_det.json {SAVE} --no-progress", "has no boxes entry for 40"),
        ("gnnpmb failures scene-0103 --detections {w}/own_det.json", "has no boxes entry for 40"),
        ("gnnpmb failures scene-0103 --results mine={w}/own_results.json", "has none of the 40 samples"),
        ("gnnpmb eval {w}/own_results.json --split mini_val --out {w}/ev", "lacks 80 of the 80 samples"),
    ],
    ids=["viz detections", "failures detections", "failures results", "eval"],
)
def test_own_files_without_a_dataroot_say_the_demo_was_used(
    command: str,
    expected: str,
    demo_dataroot: Path,
    tmp_path: Path,
    monkeypatch: pytest.MonkeyPatch,
    capsys: pytest.CaptureFixture[str],
) -> None:
    """A new user's first mistake: their own detection or results file, and no --dataroot. The demo is used, so
    the file fits none of its samples; the error line says why and how to point at their data."""
    import gnnpmb.data.nuscenes

    work = _work_folder(tmp_path / "w")
    _other_dataset_files(work)
    before = _snapshot(work)
    monkeypatch.setattr(gnnpmb.data.nuscenes, "ensure_demo_dataset", lambda *a, **k: demo_dataroot)
    env = {k: v for k, v in _env(demo_dataroot).items() if k != "NUSCENES_DATAROOT"}
    proc = run_script_with(command.format(w=work).split(), env, work, monkeypatch, capsys)
    assert _check(command, proc, expected) == []
    assert NO_DATAROOT in proc.stderr
    assert "pass --dataroot DIR" in proc.stderr
    assert _snapshot(work) == before
    with_root = f"{command} --dataroot {demo_dataroot}".format(w=work).split()
    proc = run_script_with(with_root, env, work, monkeypatch, capsys)
    assert _check(command, proc, expected) == []
    assert NO_DATAROOT not in proc.stderr
