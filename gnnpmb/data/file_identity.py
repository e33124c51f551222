"""What a cache keys an input file on: its content, checked cheaply, not only what a user can set by accident.

Path, size, modification time and inode can all stay the same while the bytes change (an in-place edit at the
same size followed by ``touch -r``). The identity therefore also holds the inode change time (``st_ctime_ns``:
every write, ``touch`` and ``chmod`` moves it and no user call can set it back) and the SHA-256 of the file's first
and last ``BLOCK_BYTES`` with its size: a cheap digest read at every open. An index also keeps the digest of the
whole file, computed once while it is built.
"""

from __future__ import annotations

import hashlib
import os
from pathlib import Path
from typing import Any

BLOCK_BYTES = 64 * 1024
"""The size of the first and of the last block read by ``edge_digest``."""


def edge_digest(path: Path, size: int) -> str:
    """SHA-256 (hex) of the size and the first and last ``BLOCK_BYTES`` of the file at ``path`` (the whole file
    when it is at most two blocks)."""
    digest = hashlib.sha256(str(size).encode() + b"\0")
    with open(path, "rb") as f:
        if size <= 2 * BLOCK_BYTES:
            digest.update(f.read())
        else:
            digest.update(f.read(BLOCK_BYTES))
            f.seek(-BLOCK_BYTES, os.SEEK_END)
            digest.update(f.read(BLOCK_BYTES))
    return digest.hexdigest()


def file_identity(path: Path) -> list[Any]:
    """[absolute path, size, mtime ns, ctime ns, inode, edge digest] of the file at ``path``; a missing or
    unreadable one is [path, -1, -1, -1, -1, ""]."""
    try:
        st = os.stat(path)
        digest = edge_digest(path, st.st_size)
    except OSError:
        return [str(path), -1, -1, -1, -1, ""]
    return [str(path), st.st_size, st.st_mtime_ns, st.st_ctime_ns, st.st_ino, digest]
