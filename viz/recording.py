"""Opening and closing the Rerun recording: a spawned viewer, or an ``.rrd`` file written atomically.

A saved recording streams into a hidden temp file next to the target; ``close_recording`` finalises it
(``disconnect`` writes the footer) and renames it into place, and ``abort_recording`` deletes it, so an error
midway never leaves a half-written ``.rrd``. ``recording(...)`` wraps both in a context manager.
"""

from __future__ import annotations

import contextlib
import os
import uuid
from collections.abc import Iterator
from pathlib import Path

import rerun as rr
import rerun.blueprint as rrb

from gnnpmb.errors import DataError

APPLICATION_ID = "gnnpmb-viz"
BATCHER = rr.ChunkBatcherConfig(flush_tick=1.0, flush_num_bytes=8 * 1024 * 1024)
"""Live viewer: fewer, larger chunks than the default 200 ms / 1 MiB batcher, still arriving every second."""
SAVE_BATCHER = rr.ChunkBatcherConfig(flush_tick=3600.0, flush_num_bytes=1 << 30)
"""Saved recordings: nothing waits for the data, so each entity's rows go out as one chunk at the end. The web
viewer's load time grows with the number of chunks, not bytes (shared notes: 9k chunks took minutes)."""

_PENDING: dict[str, Path] = {}
"""Recording id -> the temp file a saved recording is being written to."""


def check_save_path(save: Path) -> Path:
    """The absolute output path, or a DataError saying why ``save`` cannot be written."""
    save = Path(save).expanduser().absolute()
    if save.suffix.lower() != ".rrd":
        raise DataError(f"--save {save.name}: the output file name must end in .rrd")
    if save.is_dir():
        raise DataError(f"--save {save}: is a directory; give a file name ending in .rrd")
    if not save.parent.is_dir():
        raise DataError(f"--save {save}: folder {save.parent} does not exist; create it first")
    if not os.access(save.parent, os.W_OK):
        raise DataError(f"--save {save}: folder {save.parent} is not writable")
    return save


def open_recording(
    name: str, save: Path | None, blueprint: rrb.BlueprintLike | None, *, strict: bool | None = None
) -> rr.RecordingStream:
    """A new recording stream (never the global one) named ``name``.

    save: write to this ``.rrd`` (via a temp file, see ``close_recording``); None spawns a Rerun viewer.
    strict: turn Rerun's strict mode on or off (process-wide: bad arguments raise instead of warning);
    None leaves it as it is.
    """
    target = check_save_path(save) if save is not None else None
    if strict is not None:
        rr.set_strict_mode(strict)
    stream = rr.RecordingStream(APPLICATION_ID, batcher_config=BATCHER if target is None else SAVE_BATCHER)
    stream.set_log_time_enabled(False)
    stream.send_recording_name(name)
    if target is None:
        stream.spawn(default_blueprint=blueprint)
        return stream
    tmp = target.parent / f".{target.name}.{uuid.uuid4().hex[:12]}.partial"
    _PENDING[stream.get_recording_id()] = tmp
    try:
        stream.save(tmp, default_blueprint=blueprint)
    except Exception:
        _discard(stream)
        raise
    return stream


def close_recording(stream: rr.RecordingStream, save: Path | None) -> None:
    """Finish the recording: flush and disconnect, then move a saved recording's temp file to ``save``."""
    stream.flush()
    stream.disconnect()
    tmp = _PENDING.pop(stream.get_recording_id(), None)
    if save is None:
        if tmp is not None:
            tmp.unlink(missing_ok=True)
        return
    if tmp is None:
        raise ValueError("close_recording(save=...) on a stream that open_recording did not open for saving")
    os.replace(tmp, check_save_path(save))


def abort_recording(stream: rr.RecordingStream) -> None:
    """Stop the recording and delete a saved recording's temp file (nothing is left at the target path)."""
    _discard(stream)


def _discard(stream: rr.RecordingStream) -> None:
    try:
        stream.disconnect()
    finally:
        tmp = _PENDING.pop(stream.get_recording_id(), None)
        if tmp is not None:
            tmp.unlink(missing_ok=True)


@contextlib.contextmanager
def recording(
    name: str, save: Path | None, blueprint: rrb.BlueprintLike | None, *, strict: bool | None = None
) -> Iterator[rr.RecordingStream]:
    """``open_recording`` ... ``close_recording``; on an exception the temp file is deleted instead."""
    stream = open_recording(name, save, blueprint, strict=strict)
    try:
        yield stream
    except BaseException:
        abort_recording(stream)
        raise
    close_recording(stream, save)
