"""A scoring task's scratch folder: removed when it ends, and, when the task was killed (a stopped sweep's Ray
workers are), by the next scoring on the machine instead of staying in the temporary folder forever."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

from gnnpmb.atomic import owner_tag
from gnnpmb.study.evaluate import SCRATCH_NAME, scratch_folder


def _gone_pid() -> int:
    """The pid of a process that has ended."""
    child = subprocess.Popen([sys.executable, "-c", "pass"])
    child.wait()
    return child.pid


def test_a_killed_task_scratch_is_removed_by_the_next_and_a_running_one_is_kept(tmp_path: Path) -> None:
    host = owner_tag().split("-")[0]
    killed = tmp_path / f".{SCRATCH_NAME}.build-{host}-{_gone_pid()}-abc123"
    running = tmp_path / f".{SCRATCH_NAME}.build-{host}-{os.getppid()}-def456"
    for folder in (killed, running):
        (folder / "eval").mkdir(parents=True)
        (folder / "results.json").write_text("{}")
    with scratch_folder(tmp_path) as scratch:
        assert scratch.is_dir() and scratch.parent == tmp_path
        assert scratch.name.startswith(f".{SCRATCH_NAME}.build-{owner_tag()}-")
        assert not killed.exists()
        assert running.is_dir()
    assert not scratch.exists()
    assert sorted(p.name for p in tmp_path.iterdir()) == [running.name]
