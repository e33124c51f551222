"""A study's result files (``results.csv``, ``results.json``, written atomically) and its best rows."""

from __future__ import annotations

import csv
import io
from collections.abc import Sequence
from pathlib import Path
from typing import Any

from gnnpmb.atomic import write_text
from gnnpmb.eval.submission import write_json
from gnnpmb.study.evaluate import OVERALL_METRICS, TIME_COLUMNS, class_column
from gnnpmb.types import TRACKING_CLASSES


def columns(keys: Sequence[str]) -> list[str]:
    """Column order: config index and id, the swept keys, the overall metrics, AMOTA per class, times."""
    return ["config", "id", *keys, *OVERALL_METRICS, *(class_column(c) for c in TRACKING_CLASSES), *TIME_COLUMNS]


def write_results(out_dir: Path, keys: Sequence[str], rows: Sequence[dict[str, Any]], meta: dict[str, Any]) -> None:
    """``results.csv`` (one row per configuration; empty cell = base value or no ground truth) and
    ``results.json`` (``{"meta": ..., "columns": [...], "rows": [...]}``)."""
    names = columns(keys)
    buffer = io.StringIO()
    writer = csv.DictWriter(buffer, fieldnames=names, extrasaction="ignore", lineterminator="\n")
    writer.writeheader()
    for row in rows:
        writer.writerow({k: "" if row.get(k) is None else row[k] for k in names})
    write_text(Path(out_dir) / "results.csv", buffer.getvalue())
    write_json(Path(out_dir) / "results.json", {"meta": meta, "columns": names, "rows": [dict(r) for r in rows]})


def best_rows(rows: Sequence[dict[str, Any]], n: int) -> list[dict[str, Any]]:
    """The ``n`` rows of highest AMOTA (ties: lower configuration index first)."""
    ranked = sorted(rows, key=lambda r: (-(r["amota"] if r["amota"] is not None else -1.0), r["config"]))
    return ranked[:n]


def best_amota(rows: Sequence[dict[str, Any]]) -> float | None:
    """The highest AMOTA among the rows, None if there is none."""
    values = [r["amota"] for r in rows if r.get("amota") is not None]
    return max(values) if values else None
