"""Opening and closing the Rerun recording: a spawned viewer, or an ``.rrd`` file written atomically.

A saved recording streams into a hidden temp file next to the target (named as ``gnnpmb.atomic`` names them, so
the leftover of a killed run is swept by the next one); ``close_recording`` finalises it (``disconnect`` writes
the footer) and renames it into place with the one output file mode, and ``abort_recording`` deletes it, so an
error midway never leaves a half-written ``.rrd``. A live viewer is started and checked by ``viz.viewer``, and
checked again before the recording counts as sent. ``recording(...)`` wraps both in a context manager.
"""

from __future__ import annotations

import contextlib
import os
import uuid
from collections.abc import Iterator
from pathlib import Path

import rerun as rr
import rerun.blueprint as rrb

from gnnpmb.atomic import finish, sweep_leftovers, temp_prefix
from gnnpmb.errors import DataError
from viz.viewer import Viewer, ViewerError, check_alive, start_viewer

APPLICATION_ID = "gnnpmb-viz"
BATCHER = rr.ChunkBatcherConfig(flush_tick=1.0, flush_num_bytes=8 * 1024 * 1024)
"""Live viewer: fewer, larger chunks than the default 200 ms / 1 MiB batcher, still arriving every second."""
SAVE_BATCHER = rr.ChunkBatcherConfig(flush_tick=3600.0, flush_num_bytes=1 << 30)
"""Saved recordings: nothing waits for the data, so each entity's rows go out as one chunk at the end. The web
viewer's load time grows with the number of chunks, not bytes (shared notes: 9k chunks took minutes)."""

FLUSH_STALL_S = 5.0
"""At close, a saved recording's flush gives up once its file has not grown for this long. If Rerun's file writer
died (disk full), Rerun 0.41's flush, and its disconnect, can wait forever."""
_PENDING: dict[str, Path] = {}
"""Recording id -> the temp file a saved recording is being written to."""
_VIEWERS: dict[str, Viewer] = {}
"""Recording id -> the native viewer a live recording streams to."""


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
        viewer = start_viewer()
        stream.connect_grpc(viewer.url, default_blueprint=blueprint)
        _VIEWERS[stream.get_recording_id()] = viewer
        return stream
    sweep_leftovers(target.parent)
    tmp = target.parent / f"{temp_prefix(target)}{uuid.uuid4().hex[:12]}.partial"
    _PENDING[stream.get_recording_id()] = tmp
    try:
        stream.save(tmp, default_blueprint=blueprint)
    except BaseException:  # Ctrl-C while the blueprint is written must not leave the temp file either
        _discard(stream)
        raise
    return stream


def _flush(stream: rr.RecordingStream, tmp: Path | None) -> None:
    """``stream.flush()``, in 1 s steps while ``tmp`` (the file being written, if any) keeps growing; a
    RuntimeError once it stalls for ``FLUSH_STALL_S``. A live recording flushes while its viewer runs (a
    ViewerError once it has exited)."""
    if tmp is None:
        viewer = _VIEWERS.get(stream.get_recording_id())
        if viewer is None:
            stream.flush()
            return
        while True:
            check_alive(viewer)
            with contextlib.suppress(RuntimeError):  # not yet sent: ask the viewer again
                stream.flush(timeout_sec=1.0)
                return
    last_size, stalled_s = -1, 0.0
    while True:
        try:
            stream.flush(timeout_sec=1.0)
            return
        except RuntimeError:
            size = tmp.stat().st_size if tmp.exists() else -1
            stalled_s = stalled_s + 1.0 if size == last_size else 0.0
            if stalled_s >= FLUSH_STALL_S:
                raise
            last_size = size


def close_recording(stream: rr.RecordingStream, save: Path | None) -> None:
    """Finish the recording: flush and disconnect, then move a saved recording's temp file to ``save``."""
    tmp = _PENDING.get(stream.get_recording_id())
    _flush(stream, tmp)
    stream.disconnect()
    viewer = _VIEWERS.pop(stream.get_recording_id(), None)
    if viewer is not None:
        check_alive(viewer)
    if save is None:
        if tmp is not None:
            tmp.unlink(missing_ok=True)
            _PENDING.pop(stream.get_recording_id(), None)
        return
    if tmp is None:
        raise ValueError("close_recording(save=...) on a stream that open_recording did not open for saving")
    finish(tmp, check_save_path(save))
    _PENDING.pop(stream.get_recording_id(), None)


def abort_recording(stream: rr.RecordingStream) -> None:
    """Stop the recording and delete a saved recording's temp file (nothing is left at the target path)."""
    _discard(stream)


def _forget(stream: rr.RecordingStream) -> None:
    """Delete a saved recording's temp file without touching the stream."""
    _VIEWERS.pop(stream.get_recording_id(), None)
    tmp = _PENDING.pop(stream.get_recording_id(), None)
    if tmp is not None:
        tmp.unlink(missing_ok=True)


def _discard(stream: rr.RecordingStream) -> None:
    viewer = _VIEWERS.pop(stream.get_recording_id(), None)
    if viewer is not None and not viewer.alive():
        return  # with its viewer gone, disconnect can wait forever
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
    """``open_recording`` ... ``close_recording``; on an exception (also while finishing the file, e.g. Ctrl-C
    or a full disk) the temp file is deleted instead and the file at ``save`` is left as it was."""
    stream = open_recording(name, save, blueprint, strict=strict)
    try:
        yield stream
    except BaseException:
        abort_recording(stream)
        raise
    try:
        close_recording(stream, save)
    except ViewerError:
        _forget(stream)  # no disconnect: with its viewer gone it can wait forever
        raise
    except RuntimeError as exc:  # Rerun's file writer failed, e.g. "File-writer thread shut down prematurely"
        _forget(stream)  # no disconnect: with a dead file writer it can wait forever
        raise DataError(
            f"cannot write the recording {save} (Rerun: {exc}); is the disk full? Free space or --save elsewhere"
        ) from None
    except BaseException:
        abort_recording(stream)
        raise
