"""A file's identity changes with its content, even when path, size, mtime and inode stay."""

from __future__ import annotations

import os
from pathlib import Path

from gnnpmb.data.file_identity import BLOCK_BYTES, file_identity


def _edit_keeping_mtime(path: Path, offset: int) -> None:
    st = path.stat()
    with open(path, "r+b") as f:
        f.seek(offset)
        byte = f.read(1)
        f.seek(offset)
        f.write(bytes([byte[0] ^ 1]))
    os.utime(path, ns=(st.st_atime_ns, st.st_mtime_ns))


def test_an_in_place_edit_with_the_old_mtime_changes_the_identity(tmp_path: Path) -> None:
    path = tmp_path / "table.json"
    path.write_bytes(b"x" * (3 * BLOCK_BYTES))
    for offset in (10, 3 * BLOCK_BYTES - 10, BLOCK_BYTES + 5):  # first block, last block, the middle
        before = file_identity(path)
        _edit_keeping_mtime(path, offset)
        after = file_identity(path)
        assert after[0:3] == before[0:3] and after[4] == before[4]  # path, size, mtime, inode
        assert after != before  # the change time moves; the edge digest too in the first and last block
    assert file_identity(tmp_path / "missing") == [str(tmp_path / "missing"), -1, -1, -1, -1, ""]


def test_the_edge_digest_sees_the_first_and_last_block(tmp_path: Path) -> None:
    path = tmp_path / "big.json"
    path.write_bytes(b"y" * (3 * BLOCK_BYTES))
    digest = file_identity(path)[5]
    _edit_keeping_mtime(path, 3 * BLOCK_BYTES - 1)
    assert file_identity(path)[5] != digest
