"""The timelines a row is logged on, in one place.

Every keyframe is on ``frame`` (sequence = keyframe index in the scene) and ``timestamp`` (the keyframe's LiDAR
time). A focus recording (``gnnpmb-viz --focus``) adds ``focus`` (= the keyframe index) to the rows up to the
failure frame only: its blueprint shows the ``focus`` timeline following the newest data, so the viewer opens at
the failure frame (Rerun 0.41's blueprint cannot place the time cursor), while the frames after it stay on
``frame``.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
import pyarrow as pa
import rerun as rr

FRAME = "frame"
TIMESTAMP = "timestamp"
FOCUS = "focus"


@dataclass(frozen=True, slots=True)
class Clock:
    """Sets and builds the time of rows; focus_end: the last keyframe on the ``focus`` timeline (None: no
    focus timeline)."""

    focus_end: int | None = None

    def set(self, stream: rr.RecordingStream, frame_index: int, timestamp_us: int) -> None:
        """Point the stream's timelines at one keyframe."""
        stream.set_time(FRAME, sequence=int(frame_index))
        stream.set_time(TIMESTAMP, timestamp=np.datetime64(int(timestamp_us), "us"))
        if self.focus_end is None:
            return
        if frame_index <= self.focus_end:
            stream.set_time(FOCUS, sequence=int(frame_index))
        else:
            stream.disable_timeline(FOCUS)

    def send(
        self,
        stream: rr.RecordingStream,
        path: str,
        frames: np.ndarray,
        timestamps_us: np.ndarray,
        columns_of: Callable[[np.ndarray], rr.ComponentColumnList],
    ) -> None:
        """``send_columns`` of rows at (N,) keyframes; ``columns_of(rows)`` builds the columns of the selected
        rows (an index array, in order). Rows past ``focus_end`` go in a second call without the focus time."""
        frames = np.asarray(frames, dtype=np.int64)
        stamps = np.asarray(timestamps_us, dtype="datetime64[us]")
        if frames.size == 0:
            return
        groups = [np.arange(frames.size)]
        if self.focus_end is not None:
            on = frames <= self.focus_end
            groups = [np.flatnonzero(on), np.flatnonzero(~on)]
        for k, rows in enumerate(groups):
            if rows.size == 0:
                continue
            indexes = [
                rr.TimeColumn(FRAME, sequence=frames[rows]),
                rr.TimeColumn(TIMESTAMP, timestamp=stamps[rows]),
            ]
            if self.focus_end is not None and k == 0:
                indexes.append(rr.TimeColumn(FOCUS, sequence=frames[rows]))
            stream.send_columns(path, indexes=indexes, columns=columns_of(rows))

    def time_arrays(self, frames: np.ndarray, timestamps_us: np.ndarray) -> tuple[pa.Array, pa.Array]:
        """The Arrow ``frame`` and ``timestamp`` columns of rows at (N,) keyframes, for ``send_rows``."""
        frames = np.asarray(frames, dtype=np.int64)
        stamps_ns = np.asarray(timestamps_us, dtype=np.int64).astype("datetime64[us]").astype("datetime64[ns]")
        return pa.array(frames, pa.int64()), pa.array(stamps_ns, pa.timestamp("ns"))

    def send_rows(
        self,
        stream: rr.RecordingStream,
        path: str,
        frames: np.ndarray,
        times: tuple[pa.Array, pa.Array],
        columns: list[ListColumn],
    ) -> None:
        """``send_columns`` of R rows at (R,) non-decreasing keyframes, already in Arrow form: ``times`` from
        ``time_arrays``, one list per row in each column. Rows past ``focus_end`` go in a second call without the
        focus time."""
        n = len(frames)
        if n == 0:
            return
        split = n
        if self.focus_end is not None:
            if np.any(np.diff(frames) < 0):
                raise ValueError(f"rows of {path} are not in frame order")
            split = int(np.searchsorted(frames, self.focus_end, side="right"))
        for lo, hi, on_focus in ((0, split, self.focus_end is not None), (split, n, False)):
            if hi == lo:
                continue
            indexes = [_Times(FRAME, times[0].slice(lo, hi - lo)), _Times(TIMESTAMP, times[1].slice(lo, hi - lo))]
            if on_focus:
                indexes.append(_Times(FOCUS, times[0].slice(lo, hi - lo)))
            part = columns if (lo, hi) == (0, n) else [c.rows(lo, hi) for c in columns]
            stream.send_columns(path, indexes=indexes, columns=part)


@dataclass(frozen=True, slots=True)
class ListColumn:
    """A component column already in Arrow form, one list (the row's instances) per row: what
    ``rr.ComponentColumn`` builds, for ``send_columns``, without rebuilding the list array per call."""

    descriptor: rr.ComponentDescriptor
    lists: pa.ListArray

    def component_descriptor(self) -> rr.ComponentDescriptor:
        return self.descriptor

    def as_arrow_array(self) -> pa.ListArray:
        return self.lists

    def rows(self, lo: int, hi: int) -> ListColumn:
        """Rows lo..hi-1 (a zero-copy slice)."""
        return ListColumn(self.descriptor, self.lists.slice(lo, hi - lo))


@dataclass(frozen=True, slots=True)
class _Times:
    """A timeline column already in Arrow form (``rr.TimeColumnLike``)."""

    timeline: str
    times: pa.Array

    def timeline_name(self) -> str:
        return self.timeline

    def as_arrow_array(self) -> pa.Array:
        return self.times


PLAIN_CLOCK = Clock()
"""The clock of ordinary recordings: ``frame`` and ``timestamp`` only."""
