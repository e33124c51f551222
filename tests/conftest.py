"""Shared fixtures: the synthetic demo dataset and its recording, made once per test session (shared by the xdist
workers), and runs of other trackers on it."""

from __future__ import annotations

import contextlib
import fcntl
import hashlib
import io
import os
import shutil
from collections.abc import Callable, Iterator, Sequence
from pathlib import Path

import pytest


@contextlib.contextmanager
def _locked(path: Path) -> Iterator[None]:
    with open(path, "w") as lock:
        fcntl.flock(lock, fcntl.LOCK_EX)
        try:
            yield
        finally:
            fcntl.flock(lock, fcntl.LOCK_UN)


def made_once(tmp_path_factory: pytest.TempPathFactory, name: str, make: Callable[[Path], None]) -> Path:
    """The folder ``name`` filled by ``make(folder)`` once per test session: under pytest-xdist the workers share
    it (made by the first that needs it while the others wait on a file lock, as xdist's documentation shows);
    treat it as read-only."""
    base = tmp_path_factory.getbasetemp()
    root = base.parent if os.environ.get("PYTEST_XDIST_WORKER") else base  # the session's folder of all workers
    folder, done = root / f"shared-{name}", root / f"shared-{name}.done"
    with _locked(root / f"shared-{name}.lock"):
        if not done.exists():
            shutil.rmtree(folder, ignore_errors=True)  # what a failed attempt left
            folder.mkdir()
            make(folder)
            done.touch()
    return folder


@pytest.fixture(scope="session")
def demo_dataroot(tmp_path_factory: pytest.TempPathFactory) -> Iterator[Path]:
    """Dataroot of the synthetic nuScenes-format demo (``v1.0-mini``, scenes scene-0103 and scene-0916).

    Generated with the default seed into a session temp dir; treat it as read-only: its tables must keep their
    identity (``file_identity``: size, times, inode, bytes) to the end of the session, which is checked then. The
    session's dataset index and failure reports of the demo key on it; a test that writes, touches, chmods or
    hard-links a table (``linkable_demo``) would make every later test index and evaluate the demo again.
    """
    from gnnpmb.data.demo import DEMO_SEED, generate_demo_dataset
    from gnnpmb.data.file_identity import file_identity

    def make(folder: Path) -> None:
        generate_demo_dataset(folder / "nuscenes", seed=DEMO_SEED)

    root = made_once(tmp_path_factory, "demo", make) / "nuscenes"
    tables = sorted((root / "v1.0-mini").iterdir())
    before = [file_identity(path) for path in tables]
    yield root
    changed = [path.name for path, was in zip(tables, before, strict=True) if file_identity(path) != was]
    assert not changed, f"the shared demo's tables changed during the session (written, touched or linked): {changed}"


@pytest.fixture(scope="session")
def linkable_demo(demo_dataroot: Path, tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A dataroot with its own copy of the demo's tables (``v1.0-mini``; sensor files and maps linked to the demo's),
    made once per session, for tests that hard-link a table file. A hard link moves the file's change time, which
    the dataset index and the failure reports key on (``gnnpmb.data.file_identity``): linking the shared demo's
    tables would make every later test of the session index and evaluate the demo again. Read-only but for
    links."""

    def make(folder: Path) -> None:
        (folder / "nuscenes").mkdir()
        shutil.copytree(demo_dataroot / "v1.0-mini", folder / "nuscenes" / "v1.0-mini")
        for name in ("samples", "maps"):
            (folder / "nuscenes" / name).symlink_to(demo_dataroot / name)

    return made_once(tmp_path_factory, "linkable-demo", make) / "nuscenes"


@pytest.fixture(scope="session")
def demo_recording(demo_dataroot: Path, tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, str]:
    """The README's demo command, ``gnnpmb-viz scene-0103 --save x.rrd`` (all defaults), run in-process on the
    demo: the recording (alone in its folder) and what the command printed on stdout, stripped."""
    from cli.app import main

    def make(folder: Path) -> None:
        (folder / "rrd").mkdir()
        stdout = io.StringIO()
        with contextlib.redirect_stdout(stdout):
            main(
                [
                    "scene-0103",
                    "--dataroot",
                    str(demo_dataroot),
                    "--save",
                    str(folder / "rrd" / "x.rrd"),
                    "--no-progress",
                ]
            )
        (folder / "stdout.txt").write_text(stdout.getvalue().strip())

    folder = made_once(tmp_path_factory, "demo-recording", make)
    return folder / "rrd" / "x.rrd", (folder / "stdout.txt").read_text()


@pytest.fixture(scope="session")
def viz_recording(
    demo_dataroot: Path, tmp_path_factory: pytest.TempPathFactory
) -> Callable[[Sequence[str]], tuple[Path, str]]:
    """``viz_recording(args)``: ``gnnpmb-viz ARGS --dataroot DEMO --save focus.rrd --no-progress`` run in-process
    on the demo, each command line once per test session (shared by the xdist workers and the modules that make
    the same recording): the recording and what the command printed on stdout; read-only."""
    from cli.app import main

    def run(args: Sequence[str]) -> tuple[Path, str]:
        def make(folder: Path) -> None:
            stdout = io.StringIO()
            with contextlib.redirect_stdout(stdout):
                main([*args, "--dataroot", str(demo_dataroot), "--save", str(folder / "focus.rrd"), "--no-progress"])
            (folder / "stdout.txt").write_text(stdout.getvalue())

        key = hashlib.sha256("\0".join(args).encode()).hexdigest()[:16]
        folder = made_once(tmp_path_factory, f"viz-{key}", make)
        return folder / "focus.rrd", (folder / "stdout.txt").read_text()

    return run


@pytest.fixture(scope="session")
def cv_results(demo_dataroot: Path, tmp_path_factory: pytest.TempPathFactory) -> Path:
    """Another tracker's results on the demo's ``mini_val`` scenes (a tracking submission written by
    ``examples/cv_tracker.py``, a constant-velocity tracker outside the registry, on the centerpoint preset), made
    once per session (shared by the xdist workers); read-only."""
    from examples.cv_tracker import track_scenes
    from gnnpmb.data.demo import DEMO_SCENES
    from gnnpmb.eval.submission import SUBMISSION_META, write_json

    def make(folder: Path) -> None:
        results = track_scenes(list(DEMO_SCENES), demo_dataroot, None, "centerpoint")
        write_json(folder / "cv.json", {"meta": dict(SUBMISSION_META), "results": results})

    return made_once(tmp_path_factory, "cv", make) / "cv.json"


@pytest.fixture(scope="session")
def swept_dataroot(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The demo's scene-0103 built with one LiDAR sweep between keyframes (nuScenes has nine; one keeps the
    tests quick), made once per session (shared by the xdist workers); read-only."""
    from gnnpmb.data import demo

    def make(folder: Path) -> None:
        with pytest.MonkeyPatch.context() as patch:
            patch.setattr(demo, "SWEEPS_PER_INTERVAL", 1)
            demo.generate_demo_dataset(folder / "data", scenes=("scene-0103",), sweeps=True)

    return made_once(tmp_path_factory, "swept", make) / "data"


@pytest.fixture(scope="session")
def two_scene_dataroot(demo_dataroot: Path, tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The demo's two mini_val scenes cut to their first 6 keyframes each (split mini_val holds both; LiDAR files
    linked), made once per session (shared by the xdist workers); read-only."""
    from tests.gnnpmb.study.conftest import TINY_FRAMES, cut_dataset

    def make(folder: Path) -> None:
        cut_dataset(demo_dataroot, folder / "nuscenes", ["scene-0103", "scene-0916"], TINY_FRAMES)

    return made_once(tmp_path_factory, "two-scenes", make) / "nuscenes"


MODULE_CPU_S = Path(__file__).with_name("module_cpu_s.json")
"""CPU seconds of each test module in a suite run (``python -m tests.cpu_log DIR --write``): what the workers'
order is planned by on a fresh clone, where pytest has no durations of its own yet."""
UNMEASURED_TEST_CPU_S = 0.3
"""A module not in ``MODULE_CPU_S`` (new) counts this many CPU seconds per test."""


_OWN_CACHE: list[Path] = []


def pytest_configure(config: pytest.Config) -> None:
    """The test session's own gnnpmb cache folder (``$GNNPMB_CACHE_DIR``), made by the first process (the xdist
    controller; its workers and the console scripts the tests start inherit it) and removed at its end: what the
    suite checks never depends on indexes, failure reports or a demo that an earlier run or another session left in
    the user's cache folder, and it writes nothing there. A ``GNNPMB_CACHE_DIR`` already set is kept."""
    import tempfile

    from gnnpmb.cache_folder import CACHE_ENV

    if not os.environ.get(CACHE_ENV):
        folder = Path(tempfile.mkdtemp(prefix="gnnpmb-test-cache-"))
        os.environ[CACHE_ENV] = str(folder)
        _OWN_CACHE.append(folder)


def pytest_unconfigure(config: pytest.Config) -> None:
    for folder in _OWN_CACHE:
        shutil.rmtree(folder, ignore_errors=True)


def pytest_collection_modifyitems(config: pytest.Config, items: list[pytest.Item]) -> None:
    """Modules in the order the workers should take them (``scripts/test.sh`` runs ``--dist loadscope
    --no-loadscope-reorder``: a worker that runs out of work takes the next module): first those opening the web
    viewer in Chromium (``browser``: a minute or two of software WebGL, so it starts at once), then
    the rest costliest first by ``MODULE_CPU_S`` (longest processing time first: the modules left at the end are
    the cheap ones, so the workers finish together rather than one running a 40 s module while the other idles);
    a module's tests keep their order."""
    import json

    costs = json.loads(MODULE_CPU_S.read_text()) if MODULE_CPU_S.is_file() else {}
    modules: dict[str, list[pytest.Item]] = {}
    for item in items:
        modules.setdefault(item.nodeid.split("::")[0], []).append(item)

    def rank(name: str) -> tuple[int, float]:
        browser = any(mark.name == "browser" for test in modules[name] for mark in test.iter_markers())
        return (0 if browser else 1, -costs.get(name, UNMEASURED_TEST_CPU_S * len(modules[name])))

    items[:] = [item for name in sorted(modules, key=rank) for item in modules[name]]
