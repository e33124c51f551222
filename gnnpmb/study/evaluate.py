"""Score one configuration: track every scene of the split, then one official evaluation (the devkit's
``TrackingEval`` through ``gnnpmb.eval.nuscenes_eval``), which gives the overall and the per-class metrics.

Runs wherever the task lands (this process or a Ray worker); the submission and the devkit's files go to a
temporary folder on that machine and are removed afterwards (those of a task that was killed, by the next
scoring on that machine: ``scratch_folder``).
"""

from __future__ import annotations

import contextlib
import math
import shutil
import tempfile
import time
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

from gnnpmb.atomic import sweep_leftovers, temp_prefix
from gnnpmb.config import TrackerConfig
from gnnpmb.study.data import StudyData, track_scene
from gnnpmb.study.grid import Assignment
from gnnpmb.types import TRACKING_CLASSES

if TYPE_CHECKING:
    from gnnpmb.eval.nuscenes_eval import TrackingScores

OVERALL_METRICS: tuple[str, ...] = ("amota", "amotp", "mota", "ids", "frag", "tp", "fp", "fn")
"""Overall metrics kept per configuration (the devkit's names)."""
COUNTS = frozenset({"ids", "frag", "tp", "fp", "fn"})


@dataclass(frozen=True, slots=True)
class ConfigJob:
    """One configuration to score: its index in the study, its values, and the config built from them."""

    index: int
    assignment: Assignment
    config: TrackerConfig
    tracker: str
    data: StudyData


def class_column(class_name: str) -> str:
    """Column of a class's AMOTA in the results (``amota_car``)."""
    return f"amota_{class_name}"


def _number(value: float, count: bool = False) -> float | int | None:
    """A metric for JSON/CSV: None where the devkit gives NaN (a class without ground truth); counts as int."""
    if value is None or math.isnan(value):
        return None
    return int(round(value)) if count else float(value)


TIME_COLUMNS: tuple[str, ...] = ("wall_time_s", "track_time_s", "eval_time_s")
"""Seconds a configuration took: in all, tracking, evaluating."""


def is_complete_row(row: Any) -> bool:
    """Whether ``row`` (e.g. read back from a study's cache) has every metric ``score_config`` writes, each a
    number or None (an entry written by another version, or edited, is not: it is scored again)."""
    if not isinstance(row, dict):
        return False
    names = [*OVERALL_METRICS, *(class_column(c) for c in TRACKING_CLASSES), *TIME_COLUMNS]
    values = [row.get(n, row) for n in names]  # a missing name gives the row itself: not a number
    return all(v is None or (isinstance(v, int | float) and not isinstance(v, bool)) for v in values)


def _empty_row(track_s: float, wall_s: float) -> dict[str, Any]:
    """The row of a configuration that tracked nothing: the devkit refuses an empty submission, and with no
    output every recall threshold is unreached, so AMOTA is 0 and TP = FP = IDS = FRAG = 0; the other metrics
    need the evaluation's ground-truth count and stay empty."""
    row: dict[str, Any] = dict.fromkeys(OVERALL_METRICS)
    row.update({"amota": 0.0, "tp": 0, "fp": 0, "ids": 0, "frag": 0})
    row.update({class_column(c): None for c in TRACKING_CLASSES})
    row.update({"track_time_s": round(track_s, 3), "eval_time_s": 0.0, "wall_time_s": round(wall_s, 3)})
    return row


def official_scores(data: StudyData, parts: list[dict[str, list[dict[str, Any]]]]) -> TrackingScores:
    """The official evaluation of the tracked scenes ``parts`` (sample token -> submission boxes, one per scene of
    ``data``), in a temporary folder on this machine that is removed afterwards."""
    from gnnpmb.eval.nuscenes_eval import run_tracking_eval
    from gnnpmb.eval.submission import build_submission, write_submission

    with scratch_folder() as scratch:
        results_path = scratch / "results.json"
        write_submission(results_path, build_submission(parts, data.sample_tokens))
        evaluated = data.evaluation or data.location
        return run_tracking_eval(results_path, evaluated.dataroot, evaluated.version, data.split, scratch / "eval")


SCRATCH_NAME = "gnnpmb-study"


@contextlib.contextmanager
def scratch_folder(root: Path | None = None) -> Iterator[Path]:
    """A new folder in ``root`` (the system's temporary folder), removed at the end of the block. Its name carries
    this process (``gnnpmb.atomic``), and the folders of processes that are gone are removed first: a stopped
    sweep's Ray workers are killed (``runner.run_tasks``) before their ``finally`` runs."""
    root = Path(tempfile.gettempdir()) if root is None else root
    sweep_leftovers(root)
    scratch = Path(tempfile.mkdtemp(prefix=temp_prefix(root / SCRATCH_NAME, "build"), dir=root))
    try:
        yield scratch
    finally:
        shutil.rmtree(scratch, ignore_errors=True)


def score_config(job: ConfigJob) -> dict[str, Any]:
    """Track and score one configuration: the overall metrics, AMOTA per class, and the times spent (s)."""
    start = time.perf_counter()
    parts = [track_scene(job.data, name, job.tracker, job.config).results for name in job.data.scene_names]
    track_s = time.perf_counter() - start
    if not any(boxes for part in parts for boxes in part.values()):
        return _empty_row(track_s, time.perf_counter() - start)
    eval_start = time.perf_counter()
    scores = official_scores(job.data, parts)
    eval_s = time.perf_counter() - eval_start
    row: dict[str, Any] = {m: _number(scores.overall[m], m in COUNTS) for m in OVERALL_METRICS}
    for class_name in TRACKING_CLASSES:
        metrics = scores.per_class.get(class_name)
        row[class_column(class_name)] = None if metrics is None else _number(metrics["amota"])
    row["track_time_s"] = round(track_s, 3)
    row["eval_time_s"] = round(eval_s, 3)
    row["wall_time_s"] = round(time.perf_counter() - start, 3)
    return row
