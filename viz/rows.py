"""Per-frame rows of entities, kept as plain arrays and sent column-wise, many entities at once.

Building a Rerun archetype and logging it costs ~100 µs per call, and the tracker logger draws a dozen
entities per class and frame plus one per reported track: logging them one call at a time made the logger six
times slower than the tracker. ``RowBuffer`` keeps each row's instance arrays instead, and a flush sends every
entity's rows with one ``send_columns``. Converting each entity's rows to Arrow on its own (``Archetype.columns``,
``TimeColumn``) still cost ~250 µs per entity, most of a saved recording's finish; ``send_entities`` converts the
rows of all entities of one archetype in one go (one Arrow list array per field, one array per timeline) and sends
each entity zero-copy slices of them. Elementwise drawing work (positions, colours, labels, outlines) can wait
for the flush too: a row put with a ``Build`` holds raw values that the builder turns into the archetype's fields
once for all the entity's rows. A row with no instances is an empty batch: the entity shows nothing from that
frame on.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import pyarrow as pa
import rerun as rr
from rerun.components import LineStrip2DBatch, LineStrip3DBatch
from rerun.encodings import Vec2DBatch, Vec3DBatch

from viz.timeline import Clock, ListColumn

STRIPS = "strips"
"""The field holding line strips (each row: an (n, k, 3) array or a list of (k_i, 3) strips)."""


@dataclass(frozen=True, slots=True)
class EntityRows:
    """Rows of one archetype on one entity, ready to send.

    frames: (R,) keyframe indices, non-decreasing; timestamps_us: (R,); fields: field name -> (instances of all
    rows, concatenated: an (N, ...) array or a list of N items; (R,) instances per row, summing to N).
    """

    path: str
    frames: np.ndarray
    timestamps_us: np.ndarray
    fields: dict[str, tuple[Any, np.ndarray]]


def send_entities(
    stream: rr.RecordingStream, clock: Clock, archetype: type, entities: list[EntityRows], *, static: bool = False
) -> None:
    """``send_columns`` of each entity's rows (one call per entity, split only by the clock), with the Arrow
    arrays of every field and timeline built once for all of them. static: each entity holds one row, logged
    as static data (its frames and timestamps are ignored)."""
    entities = [e for e in entities if len(e.frames)]
    if not entities:
        return
    row_counts = np.array([len(e.frames) for e in entities], dtype=np.int64)
    if static and np.any(row_counts != 1):
        raise ValueError("static entities hold one row each")
    row_start = np.concatenate([[0], np.cumsum(row_counts)])
    frames = np.concatenate([np.asarray(e.frames, dtype=np.int64) for e in entities])
    stamps = np.concatenate([np.asarray(e.timestamps_us, dtype=np.int64) for e in entities])
    times = None if static else clock.time_arrays(frames, stamps)
    names = list(dict.fromkeys(name for e in entities for name in e.fields))
    lists: dict[str, tuple[rr.ComponentDescriptor, pa.ListArray]] = {}
    for name in names:
        parts = [e.fields[name] for e in entities if name in e.fields]
        descriptor, flat = _flat_column(archetype, name, [p[0] for p in parts])
        lengths = np.concatenate([np.asarray(p[1], dtype=np.int64) for p in parts])
        offsets = np.zeros(lengths.size + 1, dtype=np.int32)
        np.cumsum(lengths, out=offsets[1:])
        lists[name] = (descriptor, pa.ListArray.from_arrays(pa.array(offsets), flat))
    first_row = dict.fromkeys(names, 0)  # field -> its list row of the next entity holding it
    for k, e in enumerate(entities):
        r0, r1 = int(row_start[k]), int(row_start[k + 1])
        cols = []
        for name in e.fields:
            descriptor, rows = lists[name]
            cols.append(ListColumn(descriptor, rows.slice(first_row[name], r1 - r0)))
            first_row[name] += r1 - r0
        if times is None:
            stream.send_columns(e.path, indexes=[], columns=cols)
        else:
            clock.send_rows(
                stream, e.path, frames[r0:r1], (times[0].slice(r0, r1 - r0), times[1].slice(r0, r1 - r0)), cols
            )


def _flat_column(archetype: type, name: str, flats: list[Any]) -> tuple[rr.ComponentDescriptor, pa.Array]:
    """The descriptor and the flat Arrow array (one element per instance) of field ``name`` of ``archetype``
    over the concatenated instances ``flats`` (arrays, or lists of strings or strips)."""
    if name == STRIPS:
        arrays = all(isinstance(f, np.ndarray) and f.ndim == 3 for f in flats)
        same = arrays and len({f.shape[1] for f in flats}) == 1
        value: Any = strips_array(np.concatenate(flats) if same else [strip for flat in flats for strip in flat])
    elif isinstance(flats[0], list):
        value = pa.array([item for flat in flats for item in flat], type=pa.utf8())
    else:
        value = np.concatenate(flats)
    (column,) = archetype.columns(**{name: value})
    return column.descriptor, column.component_batch.as_arrow_array()


Build = Callable[[dict[str, Any]], dict[str, Any]]
"""Turns the concatenated raw fields of rows (each (N, ...) or a list of N) into the archetype's fields, one
instance per raw instance (see ``RowBuffer.put``)."""


@dataclass(slots=True)
class _Rows:
    """Rows of one archetype on one entity: frames, timestamps (us), per-field values per row (None: cleared),
    each field's empty value, and the ``Build`` of raw rows (None: the rows hold the archetype's fields)."""

    archetype: type
    build: Build | None = None
    frames: list[int] = field(default_factory=list)
    stamps: list[int] = field(default_factory=list)
    values: dict[str, list[Any]] = field(default_factory=dict)
    empty: dict[str, Any] = field(default_factory=dict)

    def entity(self, path: str) -> EntityRows:
        """The rows as ``EntityRows``; a row without a field (a cleared row) has no instances of it."""
        flats, lengths = {}, {}
        for name, per_row in self.values.items():
            present = [v for v in per_row if v is not None]
            lengths[name] = np.fromiter(
                (0 if v is None else len(v) for v in per_row), dtype=np.int64, count=len(per_row)
            )
            empty = self.empty[name]
            if isinstance(empty, list):
                flats[name] = [item for v in present for item in v]
            else:
                flats[name] = np.concatenate(present) if present else empty
        if self.build is None:
            fields = {name: (flat, lengths[name]) for name, flat in flats.items()}
        else:
            per_row = next(iter(lengths.values()), np.zeros(len(self.frames), dtype=np.int64))
            fields = {name: (flat, per_row) for name, flat in self.build(flats).items()}
        return EntityRows(path, np.asarray(self.frames), np.asarray(self.stamps), fields)


class RowBuffer:
    """Collects rows (``put``, ``clear``) and sends them (``flush``)."""

    def __init__(self, stream: rr.RecordingStream, clock: Clock) -> None:
        self.stream = stream
        self.clock = clock
        self._rows: dict[tuple[str, type], _Rows] = {}
        self._by_path: dict[str, list[_Rows]] = {}
        self._static_sent: set[tuple[str, type]] = set()

    def put(
        self,
        path: str,
        archetype: type,
        frame: int,
        timestamp_us: int,
        n: int,
        static: dict[str, Any] | None = None,
        build: Build | None = None,
        **fields: Any,
    ) -> None:
        """One row of ``n`` instances: each field is an (n, ...) array or a list of n items (``strips``,
        ``labels``). ``static`` mono fields (e.g. show_labels) are logged once for the entity. With ``build``
        (the same for every row of the entity) the fields are raw values, each with n instances, that ``build``
        turns into the archetype's fields when the rows are sent: elementwise work done once for all the rows
        instead of once per frame."""
        key = (path, archetype)
        rows = self._rows.get(key)
        if rows is None:
            rows = self._rows[key] = _Rows(archetype, build)
            self._by_path.setdefault(path, []).append(rows)
        if static and key not in self._static_sent:
            self.stream.log(path, archetype.from_fields(**static), static=True)
            self._static_sent.add(key)
        rows.frames.append(int(frame))
        rows.stamps.append(int(timestamp_us))
        n_rows = len(rows.frames)
        values = rows.values
        for name, value in fields.items():
            per_row = values.get(name)
            if per_row is None:
                per_row = values[name] = [None] * (n_rows - 1)
                rows.empty[name] = [] if name == STRIPS or isinstance(value, list) else np.asarray(value)[:0]
            per_row.append(value)
        if len(fields) != len(values):
            for per_row in values.values():
                if len(per_row) < n_rows:
                    per_row.append(None)

    def clear(self, path: str, frame: int, timestamp_us: int) -> None:
        """An empty row (nothing shown from ``frame`` on) for every archetype drawn on ``path``."""
        for rows in self._by_path.get(path, ()):
            rows.frames.append(int(frame))
            rows.stamps.append(int(timestamp_us))
            for values in rows.values.values():
                values.append(None)

    def flush(self) -> None:
        """Send every collected row (one ``send_columns`` per entity and archetype, split only by the clock)."""
        by_archetype: dict[type, list[EntityRows]] = {}
        for (path, archetype), rows in self._rows.items():
            if rows.frames:
                by_archetype.setdefault(archetype, []).append(rows.entity(path))
            rows.frames, rows.stamps = [], []
            rows.values = {name: [] for name in rows.values}
        for archetype, entities in by_archetype.items():
            send_entities(self.stream, self.clock, archetype, entities)


_FLOAT32_MAX = float(np.finfo(np.float32).max)


def _float32(values: Any) -> np.ndarray:
    """``values`` as float32, clipped to float32's range (a gate of ``gate_chi2 = 1e308`` is drawn at the
    largest float32 instead of overflowing to infinity with a numpy warning)."""
    return np.clip(np.asarray(values, dtype=np.float64), -_FLOAT32_MAX, _FLOAT32_MAX).astype(np.float32)


_STRIP_BATCHES = {2: (LineStrip2DBatch, Vec2DBatch), 3: (LineStrip3DBatch, Vec3DBatch)}
"""Per point dimension: the Arrow batch of line strips and of their points."""


def strips_array(strips: list[Any] | np.ndarray, dims: int = 3) -> pa.Array:
    """The Arrow ``LineStrip3D`` (``dims`` 3) or ``LineStrip2D`` (``dims`` 2) array of ``strips`` (each a
    (k_i, dims) array or list of points; an (n, k, dims) array counts as n strips), built from one concatenated
    point array: Rerun's own conversion handles strips one at a time."""
    if isinstance(strips, np.ndarray) and strips.ndim == 3:  # N strips of k points each
        n, k = strips.shape[:2]
        return flat_strips_array(strips.reshape(-1, dims), np.arange(0, (n + 1) * k, k), dims)
    strips = [np.asarray(strip).reshape(-1, dims) for strip in strips]
    offsets = np.zeros(len(strips) + 1, dtype=np.int64)
    np.cumsum(np.fromiter((s.shape[0] for s in strips), dtype=np.int64, count=len(strips)), out=offsets[1:])
    return flat_strips_array(np.concatenate(strips) if strips else np.zeros((0, dims)), offsets, dims)


def flat_strips_array(points: np.ndarray, offsets: np.ndarray, dims: int = 3) -> pa.Array:
    """The Arrow ``LineStrip3D`` (``dims`` 3) or ``LineStrip2D`` (``dims`` 2) array of S strips given flat: their
    (P, dims) points and the (S + 1,) offsets of each strip's first point into them."""
    strip_batch, point_batch = _STRIP_BATCHES[dims]
    inner = point_batch(_float32(points).reshape(-1, dims)).as_arrow_array()
    offsets = pa.array(np.asarray(offsets, dtype=np.int32))
    return pa.ListArray.from_arrays(offsets, inner, type=strip_batch._ARROW_DATATYPE)
