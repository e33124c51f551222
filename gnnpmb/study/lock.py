"""One sweep at a time per study folder: a sweep reads the table there, adds its configurations and writes it back,
so two sweeps into one folder at once would each write a table without the other's grid.

``hold_study_folder`` takes an exclusive ``flock`` on ``DIR/cache/.sweep.lock`` before the table is read and keeps
it until the process ends (a sweep is one command); a second sweep says that it waits and then merges its grid
into the first one's table. The kernel releases the lock when a process dies, so a killed sweep never blocks the
folder.
"""

from __future__ import annotations

import fcntl
from collections.abc import Callable
from pathlib import Path
from typing import IO

from gnnpmb.study.cache import CACHE_FOLDER

LOCK_NAME = ".sweep.lock"
_HELD: dict[Path, IO[str]] = {}
"""The study folders this process holds, with their open lock files."""


def hold_study_folder(folder: Path, say: Callable[[str], None]) -> None:
    """Hold the study folder ``folder`` until this process ends; ``say`` gets one line if another sweep holds it
    (this one then waits for it)."""
    folder = Path(folder).absolute()
    if folder in _HELD:
        return
    cache = folder / CACHE_FOLDER
    cache.mkdir(parents=True, exist_ok=True)
    lock = open(cache / LOCK_NAME, "a")  # noqa: SIM115 - kept open (and locked) until the process ends; stays empty
    try:
        fcntl.flock(lock, fcntl.LOCK_EX | fcntl.LOCK_NB)
    except BlockingIOError:
        say(f"note: another sweep is writing {folder}; waiting for it to end, then adding to its table")
        fcntl.flock(lock, fcntl.LOCK_EX)
    _HELD[folder] = lock
