"""Checks of output paths before any work: a command that will write a file or folder calls one of these
first, so a typo'd or unwritable path costs one ``error:`` line at start-up, not after minutes of tracking.

``check_output_file`` suits ``--out results.json``, ``--json report.json`` and ``--save run.rrd``;
``check_output_dir`` suits ``--out DIR`` folders. Both return the absolute path to write; a symlink to a file is
followed (the link's target is written and the link kept).
"""

from __future__ import annotations

import os
import stat
from pathlib import Path

from gnnpmb.errors import GnnpmbError


class OutputPathError(GnnpmbError):
    """An output path that cannot be written: a folder, a device, a missing or read-only folder."""


def check_output_file(path: Path, option: str, suffix: str | None = None) -> Path:
    """The absolute regular-file path to write for ``option`` (e.g. ``--out``), or an OutputPathError.

    suffix: the required extension (e.g. ``.json``), or None for any. A symlink resolves to its target.
    """
    given = Path(path).expanduser()
    target = given.resolve() if given.is_symlink() else given.absolute()
    if suffix is not None and target.suffix.lower() != suffix:
        raise OutputPathError(f"{option} {given}: the file name must end in {suffix}")
    if target.is_dir():
        raise OutputPathError(
            f"{option} {given}: is a folder; give a file name, e.g. {given / ('out' + (suffix or '.json'))}"
        )
    if target.exists() and not stat.S_ISREG(target.stat().st_mode):
        raise OutputPathError(f"{option} {given}: is not a regular file (a device or pipe); give a file path")
    _check_parent(target, option, given)
    if target.exists() and not os.access(target, os.W_OK):
        raise OutputPathError(f"{option} {given}: the file is read-only; choose another name or make it writable")
    return target


def check_output_dir(path: Path, option: str) -> Path:
    """The absolute folder to write into for ``option``: an existing writable folder, or a new one whose parent
    is writable; else an OutputPathError."""
    given = Path(path).expanduser()
    target = given.resolve() if given.is_symlink() else given.absolute()
    if target.exists():
        if not target.is_dir():
            raise OutputPathError(f"{option} {given}: is a file, not a folder; give a folder path")
        if not os.access(target, os.W_OK | os.X_OK):
            raise OutputPathError(f"{option} {given}: the folder is not writable; choose another")
        return target
    _check_parent(target, option, given)
    return target


def _check_parent(target: Path, option: str, given: Path) -> None:
    parent = target.parent
    if not parent.exists():
        raise OutputPathError(f"{option} {given}: folder {parent} does not exist; create it first")
    if not parent.is_dir():
        raise OutputPathError(f"{option} {given}: {parent} is a file, not a folder")
    if not os.access(parent, os.W_OK | os.X_OK):
        raise OutputPathError(f"{option} {given}: folder {parent} is not writable; choose another place")
