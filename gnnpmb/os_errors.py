"""An operating-system error on a user's path as one line: the path, the reason and what to do.

A full disk (``ENOSPC``, a quota, a file-size limit), a symlink loop and a name longer than the file system
allows each get their own hint; a full cache folder says how to move the cache.
"""

from __future__ import annotations

import contextlib
import errno
import os
from pathlib import Path

from gnnpmb.symlinks import loop_line

_WRITE_ERRORS = frozenset({errno.ENOSPC, errno.EDQUOT, errno.EFBIG})
"""Errors only a write raises: the line says "cannot write" and how to make room."""


def os_error_line(exc: OSError, path: Path | str | None = None) -> str:
    """``exc`` (raised on ``path``, else on its own ``filename``) as one line without the ``error:`` prefix."""
    reason = exc.strerror or str(exc)
    where = path if path is not None else exc.filename
    if where is None:
        return reason
    name = os.fsdecode(where)
    if exc.errno in _WRITE_ERRORS:
        return f"cannot write {name}: {reason}; {room_hint(name)}"
    if exc.errno == errno.ELOOP:
        return loop_line(Path(name), "path")
    if exc.errno == errno.ENAMETOOLONG:
        return f"cannot write or read {name}: a name in it is longer than the file system allows; give a shorter name"
    return f"cannot write or read {name}: {reason}"


def room_hint(path: str) -> str:
    """What to do when the file system of ``path`` is full: free space, or (for the cache) move the cache."""
    from gnnpmb.cache_folder import CACHE_ENV, cache_root

    with contextlib.suppress(OSError, ValueError):
        if Path(path).absolute().is_relative_to(cache_root().absolute()):
            return f"free space in {cache_root()} or point {CACHE_ENV} at a folder with room"
    return "free space on that disk or write to a folder with room (e.g. another --out)"
