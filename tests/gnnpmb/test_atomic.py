"""One way to write outputs (``gnnpmb.atomic``): owner-tagged temporary names, one file mode, stale leftovers."""

from __future__ import annotations

import os
import stat
import subprocess
from pathlib import Path

import pytest

from gnnpmb import atomic


def _dead_pid() -> int:
    proc = subprocess.Popen(["true"])
    proc.wait()
    return proc.pid


def test_a_leftover_is_a_temporary_name_of_a_process_of_this_host_that_is_gone(tmp_path: Path) -> None:
    host = atomic.owner_tag().split("-")[0]
    dead = _dead_pid()
    assert atomic.temp_prefix(tmp_path / "r.json") == f".r.json.{atomic.owner_tag()}-"
    assert atomic.is_leftover(tmp_path / f".r.json.{host}-{dead}-ab_c9.tmp")
    assert atomic.is_leftover(tmp_path / f".demo-v2.build-{host}-{dead}-ab_c9")
    assert not atomic.is_leftover(tmp_path / f".r.json.{host}-{os.getpid()}-ab_c9.tmp")  # this process
    assert not atomic.is_leftover(tmp_path / f".r.json.{host}-{os.getppid()}-ab_c9.tmp")  # alive
    other = "000000" if host != "000000" else "ffffff"
    assert not atomic.is_leftover(tmp_path / f".r.json.{other}-{dead}-ab_c9.tmp")  # another host's
    assert not atomic.is_leftover(tmp_path / "r.json") and not atomic.is_leftover(tmp_path / ".r.json.1a2b.partial")


def test_writes_replace_atomically_with_one_mode(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(atomic, "umask", lambda: 0o027)
    new, old = tmp_path / "new.csv", tmp_path / "old.csv"
    old.write_text("old")
    old.chmod(0o600)
    atomic.write_text(new, "a\n")
    atomic.write_text(old, "b\n")
    assert (new.read_text(), old.read_text()) == ("a\n", "b\n")
    assert stat.S_IMODE(new.stat().st_mode) == 0o640 and stat.S_IMODE(old.stat().st_mode) == 0o600
    with pytest.raises(KeyboardInterrupt), atomic.atomic_path(old) as tmp:
        tmp.write_text("half")
        raise KeyboardInterrupt
    assert old.read_text() == "b\n" and sorted(p.name for p in tmp_path.iterdir()) == ["new.csv", "old.csv"]


def test_umask_is_read_without_changing_it() -> None:
    before = os.umask(0o027)
    try:
        assert atomic.umask() == 0o027 and atomic.umask() == 0o027
    finally:
        os.umask(before)
