"""Reading a saved ``.rrd`` back in tests: every logged row, grouped by entity path."""

from __future__ import annotations

from collections import defaultdict
from pathlib import Path
from typing import Any

import pyarrow.compute as pc
from rerun.chunk import RrdReader

LENGTH_ONLY = ("Points3D:positions", "Points3D:colors")
"""Big columns read back as their per-row length (key "<column>.len") instead of Python lists (LiDAR sweeps)."""


def read_rows(path: Path) -> dict[str, list[dict[str, Any]]]:
    """Entity path (without the leading "/") -> its rows (component columns by name, plus "frame" when the row is
    on the frame timeline, "static" and "row_id"); static rows first, then by frame in logging order (row ids
    increase with logging time, which is how the viewer orders rows at the same time)."""
    rows: dict[str, list[dict[str, Any]]] = defaultdict(list)
    for chunk in RrdReader(path).store().stream():
        batch = chunk.to_record_batch()
        for name in LENGTH_ONLY:
            if name in batch.schema.names:
                i = batch.schema.get_field_index(name)
                counts = pc.fill_null(pc.list_value_length(batch.column(i)), 0)
                batch = batch.remove_column(i).append_column(f"{name}.len", counts)
        for row in batch.to_pylist():
            row["row_id"] = row.pop("rerun.controls.RowId")
            row["static"] = chunk.is_static
            rows[chunk.entity_path.lstrip("/") or "/"].append(row)
    for entity_rows in rows.values():
        entity_rows.sort(key=lambda r: (not r["static"], r.get("frame", -1), r["row_id"]))
    return dict(rows)


def at_frame(rows: list[dict[str, Any]], frame: int) -> list[dict[str, Any]]:
    """The rows logged at one frame."""
    return [r for r in rows if r.get("frame") == frame]


def latest_at(rows: list[dict[str, Any]], frame: int, component: str) -> Any:
    """Value of a component as the viewer shows it at ``frame``: the last row at or before it, None if a Clear
    came later (or nothing was logged)."""
    value = None
    for r in rows:
        if r["static"] or r.get("frame", -1) > frame:
            continue
        if "Clear:is_recursive" in r:
            value = None
        elif component in r:
            value = r[component]
    return value
