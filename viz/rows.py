"""Per-frame rows of spatial entities, kept as plain arrays and sent column-wise.

Building a Rerun archetype and logging it costs ~100 µs per call, and the tracker logger draws a dozen
entities per class and frame plus one per reported track: logging them one call at a time made the logger six
times slower than the tracker. ``RowBuffer`` keeps each row's instance arrays instead and sends every entity's
rows with one ``send_columns`` per flush (``Archetype.columns(...).partition(lengths)``), through the
recording's ``Clock``. A row with no instances is an empty batch: the entity shows nothing from that frame on.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np
import pyarrow as pa
import rerun as rr
from rerun.components import LineStrip3DBatch
from rerun.encodings import Vec3DBatch

from viz.timeline import Clock


@dataclass(slots=True)
class _Rows:
    """Rows of one archetype on one entity: frames, timestamps (us), instances per row, per-field values."""

    archetype: type
    frames: list[int] = field(default_factory=list)
    stamps: list[int] = field(default_factory=list)
    lengths: list[int] = field(default_factory=list)
    values: dict[str, list[Any]] = field(default_factory=dict)
    empty: dict[str, Any] = field(default_factory=dict)


class RowBuffer:
    """Collects rows (``put``, ``clear``) and sends them (``flush``)."""

    def __init__(self, stream: rr.RecordingStream, clock: Clock) -> None:
        self.stream = stream
        self.clock = clock
        self._rows: dict[tuple[str, type], _Rows] = {}
        self._static_sent: set[tuple[str, type]] = set()

    def put(
        self,
        path: str,
        archetype: type,
        frame: int,
        timestamp_us: int,
        n: int,
        static: dict[str, Any] | None = None,
        **fields: Any,
    ) -> None:
        """One row of ``n`` instances: each field is an (n, ...) array or a list of n items (``strips``,
        ``labels``). ``static`` mono fields (e.g. show_labels) are logged once for the entity."""
        key = (path, archetype)
        rows = self._rows.get(key)
        if rows is None:
            rows = self._rows[key] = _Rows(archetype)
        if static and key not in self._static_sent:
            self.stream.log(path, archetype.from_fields(**static), static=True)
            self._static_sent.add(key)
        rows.frames.append(int(frame))
        rows.stamps.append(int(timestamp_us))
        rows.lengths.append(int(n))
        for name, value in fields.items():
            if name not in rows.values:
                rows.values[name] = [None] * (len(rows.frames) - 1)
                rows.empty[name] = [] if isinstance(value, list) else np.asarray(value)[:0]
            rows.values[name].append(value)
        for values in rows.values.values():
            if len(values) < len(rows.frames):
                values.append(None)

    def clear(self, path: str, frame: int, timestamp_us: int) -> None:
        """An empty row (nothing shown from ``frame`` on) for every archetype drawn on ``path``."""
        for (p, _), rows in self._rows.items():
            if p == path:
                rows.frames.append(int(frame))
                rows.stamps.append(int(timestamp_us))
                rows.lengths.append(0)
                for values in rows.values.values():
                    values.append(None)

    def flush(self) -> None:
        """Send every collected row (one ``send_columns`` per entity and archetype, split only by the clock)."""
        for (path, _), rows in self._rows.items():
            if rows.frames:
                self.clock.send(self.stream, path, np.asarray(rows.frames), np.asarray(rows.stamps), _columns(rows))
            rows.frames, rows.stamps, rows.lengths = [], [], []
            rows.values = {name: [] for name in rows.values}


def _columns(rows: _Rows):
    lengths = np.asarray(rows.lengths, dtype=np.int64)
    values = {name: list(v) for name, v in rows.values.items()}
    empty = dict(rows.empty)
    archetype = rows.archetype

    def columns_of(selected: np.ndarray) -> rr.ComponentColumnList:
        fields = {}
        for name, per_row in values.items():
            chosen = [per_row[i] for i in selected.tolist() if per_row[i] is not None]
            if name == "strips":
                fields[name] = _strips_array(chosen)
            elif isinstance(empty[name], list):
                fields[name] = pa.array([item for row in chosen for item in row], type=pa.utf8())
            else:
                fields[name] = np.concatenate(chosen) if chosen else empty[name]
        return archetype.columns(**fields).partition(lengths[selected])

    return columns_of


def _strips_array(rows: list[Any]) -> pa.Array:
    """The Arrow ``LineStrip3D`` array of every strip of ``rows`` (each an (n, k, 3) array of n strips of k
    points, or a list of (k_i, 3) strips), built from one concatenated point array: Rerun's own conversion
    handles strips one at a time."""
    strips = [np.asarray(strip, dtype=np.float32).reshape(-1, 3) for row in rows for strip in row]
    lengths = np.fromiter((s.shape[0] for s in strips), dtype=np.int32, count=len(strips))
    offsets = np.zeros(len(strips) + 1, dtype=np.int32)
    np.cumsum(lengths, out=offsets[1:])
    points = np.concatenate(strips) if strips else np.zeros((0, 3), dtype=np.float32)
    inner = Vec3DBatch(points).as_arrow_array()
    return pa.ListArray.from_arrays(pa.array(offsets), inner, type=LineStrip3DBatch._ARROW_DATATYPE)
