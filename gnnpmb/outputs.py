"""Checks of output paths before any work: a command that will write a file or folder calls one of these
first, so a typo'd or unwritable path costs one ``error:`` line at start-up, not after minutes of tracking.

``check_output_file`` suits ``--out results.json``, ``--json report.json`` and ``--save run.rrd``;
``check_output_dir`` suits ``--out DIR`` folders. Both return the absolute path to write; a symlink to a file is
followed (the link's target is written and the link kept). Both refuse an output that is one of the command's
inputs (``inputs``: option and path, e.g. ``("--detections", det)``), however it is spelled: a relative path, a
symlink or a hard link to the input (same device and inode). A folder counts as writable only once a file could
be created in it (permission bits say nothing to root; a read-only mount or an immutable folder refuses root too).
The leftovers of killed runs in the output's folder are swept on the way (``gnnpmb.atomic``).
"""

from __future__ import annotations

import os
import stat
import tempfile
from collections.abc import Sequence
from pathlib import Path

from gnnpmb.atomic import sweep_leftovers
from gnnpmb.errors import GnnpmbError

Inputs = Sequence[tuple[str, Path | None]]
"""A command's input files as (option, path); a None path (option not given) is skipped."""


class OutputPathError(GnnpmbError):
    """An output path that cannot be written: a folder, a device, a missing or read-only folder."""


def same_file(a: Path, b: Path) -> bool:
    """Whether ``a`` and ``b`` name one file: the same device and inode when both exist (symlinks and hard links
    followed), else the same resolved path."""
    try:
        return os.path.samefile(a, b)
    except OSError:
        return Path(a).expanduser().resolve() == Path(b).expanduser().resolve()


def check_not_input(target: Path, option: str, given: Path, inputs: Inputs) -> None:
    """An OutputPathError if writing ``target`` (``option``'s value ``given``) would replace one of ``inputs``."""
    for input_option, path in inputs:
        if path is not None and same_file(target, path):
            raise OutputPathError(
                f"{option} {given} is the {input_option} file {path}: writing it would destroy that input; "
                f"give {option} another path"
            )


def check_output_file(path: Path, option: str, suffix: str | None = None, *, inputs: Inputs = ()) -> Path:
    """The absolute regular-file path to write for ``option`` (e.g. ``--out``), or an OutputPathError.

    suffix: the required extension (e.g. ``.json``), or None for any. A symlink resolves to its target.
    inputs: the command's input files, which the output must not be.
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
    check_not_input(target, option, given, inputs)
    _check_parent(target, option, given)
    if target.exists() and not os.access(target, os.W_OK):
        raise OutputPathError(f"{option} {given}: the file is read-only; choose another name or make it writable")
    return target


def check_output_dir(
    path: Path, option: str, *, files: Sequence[str] = (), folders: Sequence[str] = (), inputs: Inputs = ()
) -> Path:
    """The absolute folder to write into for ``option``: an existing writable folder, or a new one whose parent
    is writable; else an OutputPathError.

    files, folders: the names the command writes in it; each must be a file (or a folder) there, writable,
    and none of ``inputs``.
    """
    given = Path(path).expanduser()
    target = given.resolve() if given.is_symlink() else given.absolute()
    if not target.exists():
        _check_parent(target, option, given)
        return target
    if not target.is_dir():
        raise OutputPathError(f"{option} {given}: is a file, not a folder; give a folder path")
    _check_writable(target, option, given)
    for name in files:
        inner = target / name
        if inner.is_dir() or (inner.exists() and not stat.S_ISREG(inner.stat().st_mode)):
            raise OutputPathError(f"{option} {given}: {inner} is not a regular file; move it away first")
        check_not_input(inner, option, given / name, inputs)
    for name in folders:
        inner = target / name
        if inner.exists() and not inner.is_dir():
            raise OutputPathError(f"{option} {given}: {inner} is not a folder; move it away first")
        if inner.is_dir():
            _check_writable(inner, option, given / name)
    return target


def _check_parent(target: Path, option: str, given: Path) -> None:
    parent = target.parent
    if not parent.exists():
        raise OutputPathError(f"{option} {given}: folder {parent} does not exist; create it first")
    if not parent.is_dir():
        raise OutputPathError(f"{option} {given}: {parent} is a file, not a folder")
    _check_writable(parent, option, given)


def _check_writable(folder: Path, option: str, given: Path) -> None:
    """An OutputPathError unless a file can be created in ``folder`` (tried: the only test that holds for root,
    a read-only mount and an immutable folder alike). Sweeps the folder's leftovers of killed runs."""
    try:
        fd, name = tempfile.mkstemp(prefix=".gnnpmb-write-check-", dir=folder)
    except OSError as exc:
        raise OutputPathError(
            f"{option} {given}: cannot write in folder {folder} ({exc.strerror or exc}); choose another place"
        ) from None
    os.close(fd)
    os.unlink(name)
    sweep_leftovers(folder)
