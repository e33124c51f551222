"""Failure reports kept between runs, so reopening a scene does not evaluate the same tracks again.

``find_failures`` runs the devkit's evaluation of a scene (about 3 s of a 6 s ``gnnpmb-viz`` run on the demo);
an engineer often runs the same command again, e.g. with ``--focus`` on a failure the first run listed. A
report is a pure function of the scene's ground truth, the tracker's submission boxes and the code, so it is
stored under ``<cache root>/failures/<key>.json`` where key = SHA-256 of (scene, tracker, the submission boxes,
the dataset's table files (``provenance.tables_fingerprint``: size, times, a digest of their edges), the code
version: ``gnnpmb`` sources and devkit, motmetrics and numpy versions). Any change of tracks, parameters, data
or code gives another key. A damaged file counts as
absent and one that cannot be written is skipped; files are written atomically, and only the newest
``MAX_REPORTS`` are kept.
"""

from __future__ import annotations

import contextlib
import hashlib
import json
from collections.abc import Callable, Mapping, Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from gnnpmb.errors import DataError
from gnnpmb.eval.failures import FailureReport
from gnnpmb.eval.result_cache import ResultCache

if TYPE_CHECKING:
    from gnnpmb.data.nuscenes import DatasetLocation

FAILURES_FOLDER = "failures"
MAX_REPORTS = 500
"""The cache keeps the most recently written reports up to this many (each is tens of kB)."""


def report_key(
    location: DatasetLocation,
    scene_name: str,
    tracker: str,
    results: Mapping[str, Sequence[Mapping[str, Any]]],
    keyframes: range | None = None,
    classes: Sequence[str] | None = None,
) -> str:
    """Cache key (hex SHA-256) of the failure report of ``results`` (submission boxes by sample token), evaluated
    on ``keyframes`` only (None: the whole scene) and ``classes`` only (None: all)."""
    from gnnpmb.provenance import code_version, tables_fingerprint

    boxes = results_digest(results)
    blob = {
        "dataroot": str(location.dataroot),
        "version": location.version,
        "tables": tables_fingerprint(location),
        "scene": scene_name,
        "tracker": tracker,
        "results": boxes,
        "code": code_version(),
    }
    if keyframes is not None:
        blob["keyframes"] = [keyframes.start, keyframes.stop]
    if classes is not None:
        blob["classes"] = sorted(classes)
    return hashlib.sha256(json.dumps(blob, sort_keys=True, allow_nan=True).encode()).hexdigest()


_BOX_TEXTS = ("sample_token", "tracking_id", "tracking_name")
_BOX_FIELDS = frozenset({*_BOX_TEXTS, "translation", "size", "rotation", "velocity", "tracking_score"})


def results_digest(results: Mapping[str, Sequence[Mapping[str, Any]]]) -> str:
    """SHA-256 of submission boxes by sample token (tokens in order, each token's boxes as given). Boxes of the
    submission's own layout (``submission.run_results``: its eight fields, 13 numbers) count by their texts in
    JSON and their numbers as float64 bytes: exact, and a quarter of the time of their JSON text (the warm demo's
    7,400 boxes: 80 ms as JSON); a number's spelling does not count (1 and 1.0 are one number to the evaluation
    too). A token with a box of any other layout counts by the canonical JSON of its boxes."""
    digest = hashlib.sha256()
    for token in sorted(results):
        boxes = results[token]
        numbers = _box_numbers(boxes)
        if numbers is None:
            digest.update(b"json" + json.dumps([token, boxes], sort_keys=True, allow_nan=True).encode())
        else:
            texts = [[box[name] for name in _BOX_TEXTS] for box in boxes]
            digest.update(b"boxes" + json.dumps([token, texts]).encode() + numbers.tobytes())
    return digest.hexdigest()


def _box_numbers(boxes: Sequence[Mapping[str, Any]]) -> np.ndarray | None:
    """(N, 13) float64 numbers of N boxes (translation, size, rotation, velocity, score), None unless every box
    has exactly the submission's fields with 3, 3, 4 and 2 numbers and a number."""
    rows = []
    try:
        for box in boxes:
            if box.keys() != _BOX_FIELDS:
                return None
            t, s, r, v = box["translation"], box["size"], box["rotation"], box["velocity"]
            if len(t) != 3 or len(s) != 3 or len(r) != 4 or len(v) != 2:
                return None
            rows.append([*t, *s, *r, *v, box["tracking_score"]])
        numbers = np.array(rows).reshape(len(rows), 13)
    except (TypeError, ValueError):  # a vector that is no list, or numbers of ragged or mixed kinds
        return None
    return numbers.astype(np.float64) if numbers.dtype.kind in "biuf" else None


def cached_report(
    root: Path,
    location: DatasetLocation,
    scene_name: str,
    tracker: str,
    results: Mapping[str, Sequence[Mapping[str, Any]]],
    find: Callable[[], FailureReport],
    keyframes: range | None = None,
    classes: Sequence[str] | None = None,
) -> FailureReport:
    """The stored report for these inputs (evaluated on ``keyframes`` and ``classes``, None: all), else ``find()``'s,
    stored under ``root/failures``."""
    cache = ResultCache(root / FAILURES_FOLDER)
    key = report_key(location, scene_name, tracker, results, keyframes, classes)
    stored = cache.get(key)
    if stored is not None:
        try:
            return FailureReport.from_json(stored)
        except (KeyError, TypeError, ValueError):
            pass  # written by an incompatible version: evaluate again and overwrite
    report = find()
    with contextlib.suppress(OSError, DataError):  # a read-only or full cache only costs the next run the evaluation
        cache.put(key, report.to_json())
        _drop_oldest(root / FAILURES_FOLDER, MAX_REPORTS)
    return report


def scene_report(
    location: DatasetLocation,
    scene_name: str,
    tracker: str,
    results: Mapping[str, Sequence[Mapping[str, Any]]],
    keyframes: range | None = None,
    classes: Sequence[str] | None = None,
) -> FailureReport:
    """The failure report of one scene's tracking results (on ``keyframes`` and ``classes`` only, None: all):
    stored, else found by the devkit's evaluation on a version folder holding only that scene
    (``gnnpmb.data.eval_subset``)."""
    from gnnpmb.cache_folder import cache_root
    from gnnpmb.data.eval_subset import eval_location
    from gnnpmb.data.nuscenes import open_nuscenes
    from gnnpmb.eval.failures import find_failures

    def find() -> FailureReport:
        nusc = open_nuscenes(eval_location(location, [scene_name]))
        return find_failures(nusc, scene_name, results, tracker, keyframes=keyframes, classes=classes)

    return cached_report(cache_root(), location, scene_name, tracker, results, find, keyframes, classes)


def _drop_oldest(folder: Path, keep: int) -> None:
    """Delete all but the ``keep`` most recently modified reports in ``folder``."""
    files = sorted(folder.glob("*.json"), key=lambda p: p.stat().st_mtime_ns, reverse=True)
    for path in files[keep:]:
        path.unlink(missing_ok=True)
