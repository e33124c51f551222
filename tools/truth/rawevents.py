"""Tracker facts read from the raw events of one run (``gnnpmb.events`` via a ``ListSink``), with code of its own.

Definitions, each by what the events of that frame and class say (nothing of ``gnnpmb.why``):

* a track **has a column** at frame x when a ``CostMatrix`` of x lists it as a TRACK column;
* a track **is gone** at x when it has no column and no ``Predicted`` row at x (a column whose cost is +inf is not
  gone: the track was there and could not take the detection);
* a track **could not take** detection m at x when it has a column and every matrix of x gives (m, it) +inf
  (outside its gate, below an overlap test, beyond a distance threshold);
* a track **is deleted** at x when a ``Pruned`` or a delete ``TrackLogic`` event of x names it;
* a track's **birth** is the first ``Born`` event naming it: (its frame, the detection that started it).
"""

from __future__ import annotations

import math
from collections import defaultdict
from collections.abc import Iterable
from dataclasses import dataclass

import numpy as np

from gnnpmb.events import (
    Assignment,
    AxisKind,
    Born,
    CostMatrix,
    FrameStarted,
    MeasurementsReceived,
    Predicted,
    Pruned,
    TrackLogic,
    TrackLogicAction,
)


@dataclass
class RawEvents:
    """Events by (frame, class), each kind in emission order."""

    by: dict[tuple[int, str], dict[type, list]]

    @classmethod
    def of(cls, events: Iterable) -> RawEvents:
        by: dict[tuple[int, str], dict[type, list]] = defaultdict(lambda: defaultdict(list))
        frame = -1
        for e in events:
            if isinstance(e, FrameStarted):
                frame = e.frame_index
            else:
                by[(frame, e.class_name)][type(e)].append(e)
        return cls(by)

    def of_kind(self, frame: int, class_name: str, kind: type) -> list:
        return self.by.get((frame, class_name), {}).get(kind, [])

    def last(self, frame: int, class_name: str, kind: type):
        """The last event of ``kind`` at ``frame`` for ``class_name``; None when there is none."""
        found = self.of_kind(frame, class_name, kind)
        return found[-1] if found else None

    def matrices(self, frame: int, class_name: str) -> list[CostMatrix]:
        return self.of_kind(frame, class_name, CostMatrix)

    def columns(self, frame: int, class_name: str) -> set[int]:
        return {int(c.ref) for m in self.matrices(frame, class_name) for c in m.cols if c.kind is AxisKind.TRACK}

    def predicted(self, frame: int, class_name: str) -> set[int]:
        return {int(t) for p in self.of_kind(frame, class_name, Predicted) for t in np.asarray(p.track_ids)}

    def received(self, frame: int, class_name: str) -> set[int]:
        """The detections the tracker received at ``frame`` for ``class_name`` (after its preprocessing)."""
        return {
            int(m) for e in self.of_kind(frame, class_name, MeasurementsReceived) for m in np.asarray(e.meas_indices)
        }

    def gone(self, frame: int, class_name: str, track: int) -> bool:
        return track not in self.columns(frame, class_name) and track not in self.predicted(frame, class_name)

    def entry(self, frame: int, class_name: str, meas: int, track: int) -> float | None:
        """The cheapest cost any matrix of the frame gives (meas, track); None when no matrix has both."""
        found = None
        for m in self.matrices(frame, class_name):
            rows = [i for i, r in enumerate(m.rows) if r.kind is AxisKind.MEASUREMENT and int(r.ref) == meas]
            cols = [k for k, c in enumerate(m.cols) if c.kind is AxisKind.TRACK and int(c.ref) == track]
            if rows and cols:
                v = float(np.asarray(m.cost)[rows[0], cols[0]])
                found = v if found is None else min(found, v)
        return found

    def could_not_take(self, frame: int, class_name: str, meas: int, track: int) -> bool:
        v = self.entry(frame, class_name, meas, track)
        return v is not None and not math.isfinite(v)

    def deleted(self, frame: int, class_name: str, track: int) -> bool:
        if any(p.track_id == track for p in self.of_kind(frame, class_name, Pruned)):
            return True
        return any(
            t.track_id == track and t.action is TrackLogicAction.DELETED
            for t in self.of_kind(frame, class_name, TrackLogic)
        )

    def deciding(self, frame: int, class_name: str) -> tuple[CostMatrix, Assignment] | None:
        """The matrix the frame's (last) assignment indexes, with that assignment; None without one."""
        a = self.last(frame, class_name, Assignment)
        if a is None:
            return None
        same = [m for m in self.matrices(frame, class_name) if m.hypothesis == a.hypothesis]
        return (same[-1], a) if same else None

    def born(self, frame: int, class_name: str) -> dict[int, int]:
        """Detection -> the track it started at ``frame``."""
        return {
            int(m): int(t)
            for b in self.of_kind(frame, class_name, Born)
            for t, m in zip(np.asarray(b.track_ids), np.asarray(b.meas_indices), strict=True)
        }

    def birth(self, class_name: str, track: int) -> tuple[int, int] | None:
        """(frame, detection) of the first ``Born`` event naming ``track``; None when none does."""
        for frame in sorted({f for f, c in self.by if c == class_name}):
            for m, t in self.born(frame, class_name).items():
                if t == track:
                    return frame, m
        return None
