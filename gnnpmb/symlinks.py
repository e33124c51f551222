"""A symlink loop given as a path: one line naming it, wherever a path is read or written.

``Path.resolve`` raises ``RuntimeError`` on a loop (Python 3.11), ``is_file`` and ``exists`` answer False, so
without this check a loop reads as "not found" or ends in a traceback.
"""

from __future__ import annotations

import errno
import os
from pathlib import Path

from gnnpmb.errors import GnnpmbError


def is_symlink_loop(path: Path) -> bool:
    """Whether following the symlinks of ``path`` never ends (links that point back at each other)."""
    try:
        os.stat(path)
    except OSError as exc:
        return exc.errno == errno.ELOOP
    return False


def loop_line(path: Path, what: str) -> str:
    """The one line for ``what`` (e.g. ``--detections``) given as the symlink loop ``path``."""
    return f"{what} {path} is a symlink loop (its links point back at each other); remove the link or give another path"


def refuse_symlink_loop(path: Path, what: str) -> None:
    """A GnnpmbError naming ``path`` if it is a symlink loop; ``what`` names where it was given."""
    if is_symlink_loop(path):
        raise GnnpmbError(loop_line(path, what))
