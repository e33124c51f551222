from __future__ import annotations

from pathlib import Path

import pytest
import rerun as rr
from rerun.chunk import RrdReader

from gnnpmb.errors import DataError
from viz.recording import check_save_path, close_recording, open_recording, recording


def test_saved_recording_appears_only_when_closed(tmp_path: Path, strict: None) -> None:
    out = tmp_path / "run.rrd"
    stream = open_recording("run", out, None, strict=True)
    stream.set_time("frame", sequence=0)
    stream.log("x", rr.Points3D([[1.0, 2.0, 3.0]]))
    assert not out.exists()
    partial = [p.name for p in tmp_path.iterdir()]
    assert len(partial) == 1 and partial[0].startswith(".run.rrd.") and partial[0].endswith(".partial")
    close_recording(stream, out)
    assert [p.name for p in tmp_path.iterdir()] == ["run.rrd"]
    assert "/x" in RrdReader(out).store().schema().entity_paths()


def test_error_inside_the_context_leaves_nothing(tmp_path: Path, strict: None) -> None:
    out = tmp_path / "run.rrd"
    with pytest.raises(RuntimeError, match="boom"), recording("run", out, None, strict=True) as stream:
        stream.log("x", rr.Points3D([[1.0, 2.0, 3.0]]))
        raise RuntimeError("boom")
    assert list(tmp_path.iterdir()) == []


def test_context_manager_replaces_an_existing_file_atomically(tmp_path: Path, strict: None) -> None:
    out = tmp_path / "run.rrd"
    out.write_bytes(b"old")
    with recording("run", out, None, strict=True) as stream:
        stream.log("x", rr.Points3D([[1.0, 2.0, 3.0]]))
        assert out.read_bytes() == b"old"
    assert out.read_bytes() != b"old"
    assert [p.name for p in tmp_path.iterdir()] == ["run.rrd"]


def test_bad_save_paths_are_user_errors(tmp_path: Path) -> None:
    with pytest.raises(DataError, match=r"must end in \.rrd"):
        check_save_path(tmp_path / "out.txt")
    with pytest.raises(DataError, match="does not exist"):
        check_save_path(tmp_path / "missing" / "out.rrd")
    (tmp_path / "dir.rrd").mkdir()
    with pytest.raises(DataError, match="is a directory"):
        check_save_path(tmp_path / "dir.rrd")
    assert check_save_path(tmp_path / "ok.rrd") == tmp_path / "ok.rrd"


def test_close_with_a_path_needs_a_saving_stream(tmp_path: Path) -> None:
    stream = rr.RecordingStream("not-saving")
    with pytest.raises(ValueError, match="did not open for saving"):
        close_recording(stream, tmp_path / "x.rrd")
