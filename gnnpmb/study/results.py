"""A study's result files (``results.csv``, ``results.json``, written atomically) and its best rows."""

from __future__ import annotations

import csv
import io
import os
import tempfile
from collections.abc import Sequence
from pathlib import Path
from typing import Any

from gnnpmb.eval.submission import write_json
from gnnpmb.study.evaluate import OVERALL_METRICS, class_column
from gnnpmb.types import TRACKING_CLASSES

TIME_COLUMNS: tuple[str, ...] = ("wall_time_s", "track_time_s", "eval_time_s")


def columns(keys: Sequence[str]) -> list[str]:
    """Column order: config index and id, the swept keys, the overall metrics, AMOTA per class, times."""
    return ["config", "id", *keys, *OVERALL_METRICS, *(class_column(c) for c in TRACKING_CLASSES), *TIME_COLUMNS]


def write_text(path: Path, text: str) -> None:
    """Write text atomically: a temporary file in the same folder, then ``os.replace``."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp", dir=path.parent)
    try:
        with os.fdopen(fd, "w", encoding="utf-8", newline="") as f:
            f.write(text)
        os.replace(tmp, path)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise


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
