"""Checks of output paths before any work: a command that will write a file or folder calls one of these
first, so a typo'd or unwritable path costs one ``error:`` line at start-up, not after minutes of tracking.

``check_output_file`` suits ``--out results.json``, ``--json report.json`` and ``--save run.rrd``;
``check_output_dir`` suits ``--out DIR`` folders. Both return the absolute path to write; a symlink to a file is
followed (the link's target is written and the link kept). Both refuse an output that is one of the command's
inputs (``inputs``: option and path, e.g. ``("--detections", det)``), however it is spelled: a relative path, a
symlink or a hard link to the input (same device and inode). A folder counts as writable only once a file could
be created in it (permission bits say nothing to root; a read-only mount or an immutable folder refuses root too).
The leftovers of killed runs in the output's folder are swept on the way (``gnnpmb.atomic``).

A nuScenes dataset's files are inputs of every command, whether or not an option names them: an output that is a
table, the splits file or a sensor file of any dataset (by its place, ``gnnpmb.dataset_files``) is refused
here, and every output checked in this process is compared again with the dataset a command opens
(``check_dataset_inputs``, called when a dataroot is checked), which finds hard links too. A symlink loop, a name
longer than the file system allows (the temporary name included) are refused here too, naming the path.
"""

from __future__ import annotations

import os
import stat
import tempfile
from collections.abc import Sequence
from pathlib import Path

from gnnpmb.atomic import NAME_MAX_BYTES, sweep_leftovers, temp_name_bytes
from gnnpmb.dataset_files import dataset_file_of, linked_dataset_file
from gnnpmb.errors import GnnpmbError
from gnnpmb.symlinks import is_symlink_loop, loop_line

Inputs = Sequence[tuple[str, Path | None]]
"""A command's input files as (option, path); a None path (option not given) is skipped."""


class OutputPathError(GnnpmbError):
    """An output path that cannot be written: a folder, a device, a missing or read-only folder."""


_CHECKED: list[tuple[Path, str, Path]] = []
"""Every output file checked in this process: (absolute path, option, path as given)."""
_DATASETS: list[tuple[Path, str]] = []
"""Every dataset (dataroot, version) checked in this process."""


def same_file(a: Path, b: Path) -> bool:
    """Whether ``a`` and ``b`` name one file: the same device and inode when both exist (symlinks and hard links
    followed), else the same resolved path (a symlink loop is compared as spelled)."""
    try:
        return os.path.samefile(a, b)
    except OSError:
        return _resolved(a) == _resolved(b)


def _resolved(path: Path) -> Path:
    try:
        return Path(path).expanduser().resolve()
    except (OSError, RuntimeError):  # a symlink loop
        return Path(path).expanduser().absolute()


def _check_no_loop(given: Path, option: str) -> None:
    if is_symlink_loop(given):
        raise OutputPathError(loop_line(given, option))


def _check_name_length(target: Path, option: str, given: Path) -> None:
    """An OutputPathError when the output's name, or the temporary name written beside it first
    (``atomic.temp_name_bytes``), is longer than the folder's file system allows."""
    try:
        limit = int(os.pathconf(target.parent, "PC_NAME_MAX"))
    except (OSError, ValueError):
        limit = NAME_MAX_BYTES
    name_bytes, temp_bytes = len(os.fsencode(target.name)), temp_name_bytes(target)
    if name_bytes > limit:
        raise OutputPathError(
            f"{option} {given}: the name is {name_bytes} bytes long and the file system of {target.parent} allows "
            f"at most {limit}; give a shorter name"
        )
    if temp_bytes > limit:
        raise OutputPathError(
            f"{option} {given}: the temporary file written first beside it needs a {temp_bytes}-byte name and the "
            f"file system of {target.parent} allows at most {limit}; give a name of at most "
            f"{limit - (temp_bytes - name_bytes)} bytes"
        )


def _check_not_dataset(target: Path, option: str, given: Path) -> None:
    """An OutputPathError if ``target`` is a file of a nuScenes dataset (by place, or a hard link of a file of a
    dataset already opened by this process)."""
    found = dataset_file_of(target)
    if found is None:
        for dataroot, version in _DATASETS:
            linked = linked_dataset_file(target, dataroot, version)
            if linked is not None:
                found = f"a hard link of the nuScenes table or sensor file {linked}"
                break
    if found is not None:
        raise OutputPathError(
            f"{option} {given} is {found}: the dataset's files are inputs and writing it would destroy one; "
            f"give {option} a path outside the dataset"
        )


def check_dataset_inputs(dataroot: Path, version: str) -> None:
    """An OutputPathError if an output checked in this process is a file of the dataset ``dataroot``/``version``
    (a hard link of one included); later outputs are checked against it too. Called when a dataroot is
    checked, before the dataset is read."""
    if (dataroot, version) not in _DATASETS:
        _DATASETS.append((dataroot, version))
    for target, option, given in _CHECKED:
        linked = linked_dataset_file(target, dataroot, version)
        if linked is not None:
            raise OutputPathError(
                f"{option} {given} is a hard link of the nuScenes file {linked}: the dataset's files are inputs and "
                f"writing it would destroy one; give {option} a path outside the dataset"
            )


def check_not_input(target: Path, option: str, given: Path, inputs: Inputs) -> None:
    """An OutputPathError if writing ``target`` (``option``'s value ``given``) would replace one of ``inputs``."""
    for input_option, path in inputs:
        if path is not None and same_file(target, path):
            raise OutputPathError(
                f"{option} {given} is the {input_option} file {path}: writing it would destroy that input; "
                f"give {option} another path"
            )


def _given_and_target(path: Path, option: str) -> tuple[Path, Path]:
    """``option``'s value as given (``~`` expanded) and the absolute path it writes (a symlink resolved), or an
    OutputPathError for a name too long or a symlink loop."""
    given = Path(path).expanduser()
    _check_name_length(given.absolute(), option, given)
    _check_no_loop(given, option)
    return given, given.resolve() if given.is_symlink() else given.absolute()


def check_output_file(path: Path, option: str, suffix: str | None = None, *, inputs: Inputs = ()) -> Path:
    """The absolute regular-file path to write for ``option`` (e.g. ``--out``), or an OutputPathError.

    suffix: the required extension (e.g. ``.json``), or None for any. A symlink resolves to its target.
    inputs: the command's input files, which the output must not be.
    """
    given, target = _given_and_target(path, option)
    if suffix is not None and target.suffix.lower() != suffix:
        raise OutputPathError(f"{option} {given}: the file name must end in {suffix}")
    _check_name_length(target, option, given)
    if target.is_dir():
        raise OutputPathError(
            f"{option} {given}: is a folder; give a file name, e.g. {given / ('out' + (suffix or '.json'))}"
        )
    if target.exists() and not stat.S_ISREG(target.stat().st_mode):
        raise OutputPathError(f"{option} {given}: is not a regular file (a device or pipe); give a file path")
    check_not_input(target, option, given, inputs)
    _check_not_dataset(target, option, given)
    _check_parent(target, option, given)
    if target.exists() and not os.access(target, os.W_OK):
        raise OutputPathError(f"{option} {given}: the file is read-only; choose another name or make it writable")
    _CHECKED.append((target, option, given))
    return target


def check_output_dir(
    path: Path, option: str, *, files: Sequence[str] = (), folders: Sequence[str] = (), inputs: Inputs = ()
) -> Path:
    """The absolute folder to write into for ``option``: an existing writable folder, or a new one whose parent
    is writable; else an OutputPathError.

    files, folders: the names the command writes in it; each must be a file (or a folder) there, writable,
    and none of ``inputs``.
    """
    given, target = _given_and_target(path, option)
    _check_name_length(target, option, given)
    _check_not_dataset(target, option, given)
    if not target.exists():
        _check_parent(target, option, given)
        _CHECKED.extend((target / name, option, given / name) for name in files)
        return target
    if not target.is_dir():
        raise OutputPathError(f"{option} {given}: is a file, not a folder; give a folder path")
    _check_writable(target, option, given)
    for name in files:
        inner = target / name
        if inner.is_dir() or (inner.exists() and not stat.S_ISREG(inner.stat().st_mode)):
            raise OutputPathError(f"{option} {given}: {inner} is not a regular file; move it away first")
        check_not_input(inner, option, given / name, inputs)
        _check_not_dataset(inner, option, given / name)
        _check_name_length(inner, option, given / name)
        _CHECKED.append((inner, option, given / name))
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
    free = free_bytes(folder)
    if free is not None and free < MIN_FREE_BYTES:
        raise OutputPathError(
            f"{option} {given}: the disk of folder {folder} is full ({free // 1024} kB free); free space there or "
            "choose another place"
        )


MIN_FREE_BYTES = 1 << 20
"""A folder whose file system has less room than this is full for any output (a submission, a recording or a
table takes more), which is told at start-up instead of after the work."""


def free_bytes(folder: Path) -> int | None:
    """The bytes this process may still write on ``folder``'s file system (root may use the reserved blocks too),
    or None when the system does not say."""
    try:
        st = os.statvfs(folder)
    except (OSError, AttributeError):
        return None
    blocks = st.f_bfree if os.geteuid() == 0 else st.f_bavail
    return blocks * st.f_frsize
