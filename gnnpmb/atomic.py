"""How every output is written: into a temporary file beside it, then renamed into place, with one file mode.

A temporary name carries its owner, ``.NAME.<host>-<pid>-<random><suffix>`` (a folder: ``.NAME.build-<host>-<pid>-
<random>``), so a later run can tell the leftover of a killed run (SIGKILL, a power cut) from the temporary file
of a run still going: ``sweep_leftovers`` deletes only those whose process is gone on this host.

File mode: a new output gets what a plain ``open`` would give (0666 minus the umask, e.g. 0644 under umask 022);
an output written over an existing file keeps that file's mode.
"""

from __future__ import annotations

import contextlib
import hashlib
import os
import re
import shutil
import socket
import stat
import tempfile
from collections.abc import Iterator
from pathlib import Path

_HOST = hashlib.sha256(socket.gethostname().encode()).hexdigest()[:6]
_LEFTOVER = re.compile(r"^\..+\.(?:[a-z]+-)?(?P<host>[0-9a-f]{6})-(?P<pid>\d+)-[0-9a-z_]+(?:\.[a-z]+)?$")
_SWEPT: set[Path] = set()
"""Folders already swept by this process."""


NAME_MAX_BYTES = 255
"""The longest file name (in bytes) of the usual Linux and macOS file systems."""
TEMP_TAIL_MAX_BYTES = 20
"""The longest random part and suffix a writer appends to ``temp_prefix`` (``viz.recording``: 12 hex digits and
``.partial``; ``atomic_path``: 8 characters and ``.tmp``)."""


def temp_name_bytes(target: Path) -> int:
    """The length in bytes of the longest temporary name written beside ``target`` (a file's or a folder's)."""
    return len(os.fsencode(temp_prefix(target, "build"))) + TEMP_TAIL_MAX_BYTES


def owner_tag() -> str:
    """``<host>-<pid>``: this host (a short hash of its name) and process, as temporary names carry them."""
    return f"{_HOST}-{os.getpid()}"


def temp_prefix(target: Path, kind: str = "") -> str:
    """The ``tempfile`` prefix of a temporary file (or, with ``kind`` e.g. ``build``, folder) for ``target``.

    A long name is cut (at ``NAME_MAX_BYTES`` minus the rest of the temporary name) so that every name the file
    system allows can be written: the temporary name is never longer than ``NAME_MAX_BYTES``."""
    tail = f".{kind + '-' if kind else ''}{owner_tag()}-"
    room = NAME_MAX_BYTES - 1 - len(tail.encode()) - TEMP_TAIL_MAX_BYTES
    name = os.fsencode(Path(target).name)
    if len(name) > room:
        name = name[:room]
    return f".{os.fsdecode(name)}{tail}"


def umask() -> int:
    """The process umask, read without changing it where Linux shows it (``os.umask`` sets it for a moment)."""
    with contextlib.suppress(OSError, ValueError, StopIteration):
        status = Path("/proc/self/status").read_text(encoding="ascii").splitlines()
        return int(next(line for line in status if line.startswith("Umask:")).split()[1], 8)
    mask = os.umask(0o022)
    os.umask(mask)
    return mask


def output_mode(target: Path) -> int:
    """The mode ``target`` gets when written: its current mode if it exists, else 0666 minus the umask."""
    with contextlib.suppress(OSError):
        return stat.S_IMODE(os.stat(target).st_mode)
    return 0o666 & ~umask()


def finish(tmp: Path, target: Path) -> None:
    """Give the finished temporary file ``tmp`` the output mode of ``target`` and rename it into place."""
    os.chmod(tmp, output_mode(target))
    os.replace(tmp, target)


@contextlib.contextmanager
def atomic_path(target: Path, suffix: str = ".tmp") -> Iterator[Path]:
    """A temporary path beside ``target`` for a writer that takes a path (e.g. ``savefig``); on leaving the block
    it replaces ``target``, on an exception (also Ctrl-C) it is deleted. A symlink at ``target`` is kept and its
    target written."""
    target = Path(target)
    if target.is_symlink():
        target = target.resolve()
    target.parent.mkdir(parents=True, exist_ok=True)
    sweep_leftovers(target.parent)
    fd, name = tempfile.mkstemp(prefix=temp_prefix(target), suffix=suffix, dir=target.parent)
    os.close(fd)
    tmp = Path(name)
    try:
        yield tmp
        finish(tmp, target)
    except BaseException:
        tmp.unlink(missing_ok=True)
        raise


def write_bytes(target: Path, data: bytes) -> None:
    """Write ``data`` to ``target`` atomically (``atomic_path``)."""
    with atomic_path(target) as tmp:
        tmp.write_bytes(data)


def write_text(target: Path, text: str) -> None:
    """Write UTF-8 ``text`` to ``target`` atomically (``atomic_path``), newlines as given."""
    write_bytes(target, text.encode("utf-8"))


def is_leftover(path: Path) -> bool:
    """Whether ``path`` is a temporary file or folder of a process of this host that is gone."""
    match = _LEFTOVER.match(path.name)
    if match is None or match["host"] != _HOST:
        return False
    pid = int(match["pid"])
    if pid == os.getpid():
        return False
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return True
    except OSError:  # e.g. another user's process: alive
        return False
    return False


def sweep_leftovers(folder: Path) -> None:
    """Delete the leftovers of killed runs in ``folder`` (``is_leftover``), once per folder and process; a file
    that cannot be deleted is left."""
    folder = Path(folder)
    if folder in _SWEPT:
        return
    _SWEPT.add(folder)
    try:
        entries = [e for e in os.scandir(folder) if e.name.startswith(".")]
    except OSError:
        return
    for entry in entries:
        path = Path(entry.path)
        if not is_leftover(path):
            continue
        with contextlib.suppress(OSError):
            if entry.is_dir(follow_symlinks=False):
                shutil.rmtree(path)
            else:
                path.unlink()
