"""Output paths in-process (the real-process cases are in ``tests/cli/test_silent_faults.py``): a full disk, a name
the file system cannot hold, the dataset's files, and the one-line text of an OS error."""

from __future__ import annotations

import errno
import os
from pathlib import Path

import pytest

from gnnpmb import outputs
from gnnpmb.atomic import NAME_MAX_BYTES, temp_name_bytes, temp_prefix
from gnnpmb.os_errors import os_error_line
from gnnpmb.outputs import OutputPathError, check_output_dir, check_output_file


def test_a_full_disk_is_refused_at_start_up(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(outputs, "free_bytes", lambda _folder: 4096)
    with pytest.raises(OutputPathError, match=r"--out .*r.json: the disk of folder .* is full \(4 kB free\)"):
        check_output_file(tmp_path / "r.json", "--out")
    with pytest.raises(OutputPathError, match="is full"):
        check_output_dir(tmp_path, "--out")
    monkeypatch.setattr(outputs, "free_bytes", lambda _folder: outputs.MIN_FREE_BYTES)
    assert check_output_file(tmp_path / "r.json", "--out") == tmp_path / "r.json"


@pytest.mark.parametrize("length", [1, 100, 200, 250, 255])
def test_every_legal_name_has_a_temporary_name_within_the_limit(length: int, tmp_path: Path) -> None:
    target = tmp_path / ("x" * length)
    assert temp_name_bytes(target) <= NAME_MAX_BYTES
    assert temp_prefix(target).startswith(".x")
    check_output_file(target, "--out")


def test_a_name_beyond_the_limit_is_refused_before_it_is_touched(tmp_path: Path) -> None:
    with pytest.raises(OutputPathError, match="the name is 256 bytes long and the file system of .* allows at most"):
        check_output_file(tmp_path / ("x" * 256), "--out")


def test_a_hard_link_of_a_table_is_refused_once_the_dataset_is_known(
    linkable_demo: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setattr(outputs, "_CHECKED", [])
    monkeypatch.setattr(outputs, "_DATASETS", [])
    link = tmp_path / "copy.json"
    os.link(linkable_demo / "v1.0-mini" / "sample.json", link)
    check_output_file(link, "--out")  # the dataset is not known yet: its place says nothing
    with pytest.raises(OutputPathError, match="is a hard link of the nuScenes file .*sample.json"):
        outputs.check_dataset_inputs(linkable_demo, "v1.0-mini")
    with pytest.raises(OutputPathError, match="a hard link of the nuScenes table or sensor file"):
        check_output_file(link, "--json")


@pytest.mark.parametrize(
    ("error", "expected"),
    [
        (OSError(errno.ENOSPC, "No space left on device", "/data/r.json"), "cannot write /data/r.json: No space left"),
        (OSError(errno.ELOOP, "Too many levels", "/data/l.json"), "path /data/l.json is a symlink loop"),
        (OSError(errno.ENAMETOOLONG, "File name too long", "/data/x"), "longer than the file system allows"),
        (OSError(errno.EACCES, "Permission denied", "/data/x"), "cannot write or read /data/x: Permission denied"),
    ],
)
def test_os_errors_name_the_path_and_what_to_do(error: OSError, expected: str) -> None:
    assert expected in os_error_line(error)


def test_a_full_cache_says_how_to_move_the_cache(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("GNNPMB_CACHE_DIR", str(tmp_path))
    line = os_error_line(OSError(errno.ENOSPC, "No space left on device", str(tmp_path / "index" / "x")))
    assert line.endswith(f"free space in {tmp_path} or point GNNPMB_CACHE_DIR at a folder with room")
