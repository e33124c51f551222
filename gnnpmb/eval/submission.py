"""nuScenes tracking submissions: build them from tracker runs, write them atomically, and check them.

Layout (https://www.nuscenes.org/tracking):
``{"meta": {use_camera, use_lidar, use_radar, use_map, use_external}, "results": {sample_token: [box, ...]}}``
with every sample token of the evaluated split present (an empty list when nothing was tracked) and each box
``{"sample_token", "translation": [x, y, z], "size": [w, l, h], "rotation": [w, x, y, z],
"velocity": [vx, vy], "tracking_id", "tracking_name", "tracking_score"}`` in the global frame.
The devkit's own checks are asserts deep inside its loaders; ``check_submission`` finds the same problems
first and names them in one line.
"""

from __future__ import annotations

import json
import math
from collections.abc import Collection, Iterable, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from gnnpmb.data.detections import LIDAR_ONLY_META, VECTOR_FIELDS, physical_problem, short_repr
from gnnpmb.data.scene import SceneData
from gnnpmb.errors import DataError, NotThisDatasetError
from gnnpmb.pipeline import TrackingRun
from gnnpmb.symlinks import refuse_symlink_loop
from gnnpmb.types import TRACKING_CLASSES

SUBMISSION_META: dict[str, bool] = LIDAR_ONLY_META
"""What our submissions declare: LiDAR detections only."""

MAX_BOXES_PER_SAMPLE = 500
"""The devkit's ``max_boxes_per_sample`` of the ``tracking_nips_2019`` config."""

_REQUIRED_FIELDS = ("sample_token", "tracking_id", "tracking_name", "tracking_score")
QUAT_NORM_TOLERANCE = 1e-3
"""How far from 1 a results box's rotation quaternion may be (files written with 6 decimals are within 1e-5)."""


@dataclass(frozen=True, slots=True)
class SubmissionStats:
    """What a checked submission holds: samples (all of the split) and boxes in total."""

    samples: int
    boxes: int


def _box(token: str, translation, size, quat, velocity, track_id: str, class_name: str, score: float) -> dict:
    return {
        "sample_token": token,
        "translation": [float(v) for v in translation],
        "size": [float(v) for v in size],
        "rotation": [float(v) for v in quat],
        "velocity": [float(v) for v in velocity],
        "tracking_id": track_id,
        "tracking_name": class_name,
        "tracking_score": float(score),
    }


def run_results(run: TrackingRun) -> dict[str, list[dict[str, Any]]]:
    """The submission boxes of one tracker run, keyed by sample token (one entry per tracked keyframe).

    tracking_id is the tracker's integer id as a string; ids are unique within a scene (the devkit matches per
    scene). tracking_score is the estimate's score; the devkit averages it over each track.
    """
    results: dict[str, list[dict[str, Any]]] = {}
    for frame in run.frames:
        token = frame.keyframe.sample_token
        results[token] = [
            _box(
                token,
                e.translation_m,
                e.size_wlh_m,
                e.quat_wxyz,
                e.velocity_mps,
                str(e.track_id),
                e.class_name,
                e.score,
            )
            for e in frame.estimates
        ]
    return results


def gt_results(scene: SceneData) -> dict[str, list[dict[str, Any]]]:
    """A perfect 'tracker': the scene's ground truth as submission boxes (id = instance token, score 1).

    Boxes without LiDAR/radar points are left out, as the devkit drops them from the ground truth (it
    interpolates them back inside a track, for ground truth and submission alike). NaN GT velocities become 0.
    """
    results: dict[str, list[dict[str, Any]]] = {}
    for keyframe in scene.keyframes:
        gt = keyframe.gt
        keep = np.flatnonzero(np.asarray(keyframe.gt_num_pts) > 0)
        velocity = np.nan_to_num(np.asarray(gt.velocity_mps, dtype=float), nan=0.0)
        results[keyframe.sample_token] = [
            _box(
                keyframe.sample_token,
                gt.translation_m[i],
                gt.size_wlh_m[i],
                gt.quat_wxyz[i],
                velocity[i],
                str(gt.instance_id[i]),
                str(gt.class_name[i]),
                1.0,
            )
            for i in keep
        ]
    return results


def build_submission(
    parts: Iterable[Mapping[str, list[dict[str, Any]]]], sample_tokens: Sequence[str]
) -> dict[str, Any]:
    """A submission of per-scene results with an entry (maybe empty) for every token in ``sample_tokens``.

    A sample with more than ``MAX_BOXES_PER_SAMPLE`` boxes (the evaluation's limit) keeps its highest-scoring
    ones (ties: earlier first), as the nuScenes submission rules ask. Raises ``DataError`` if a part holds a
    sample outside ``sample_tokens``.
    """
    results: dict[str, list[dict[str, Any]]] = {token: [] for token in sample_tokens}
    for part in parts:
        for token, boxes in part.items():
            if token not in results:
                raise DataError(f"tracked sample {token} is not one of the samples the submission is built for")
            kept = list(boxes)
            if len(kept) > MAX_BOXES_PER_SAMPLE:
                kept = sorted(kept, key=lambda b: -float(b["tracking_score"]))[:MAX_BOXES_PER_SAMPLE]
            results[token] = kept
    return {"meta": dict(SUBMISSION_META), "results": results}


def write_json(path: Path, data: Any) -> None:
    """Write ``data`` as JSON atomically (``gnnpmb.atomic``: a temporary file in the same folder, then
    ``os.replace``, with the one output file mode).

    NaN or infinite numbers are refused (they are not JSON); nothing is left behind on failure. A symlink at
    ``path`` is kept and its target written.
    """
    from gnnpmb.atomic import write_text
    from gnnpmb.os_errors import os_error_line

    text = json.dumps(data, allow_nan=False, separators=(",", ":"))  # the C encoder; json.dump is pure Python
    try:
        write_text(Path(path), text)
    except OSError as exc:
        raise DataError(os_error_line(exc, path)) from None


def write_submission(path: Path, submission: Mapping[str, Any]) -> None:
    """Write a tracking submission atomically (``write_json``)."""
    write_json(path, submission)


def check_results_file(path: Path) -> None:
    """A one-line ``DataError`` unless ``path`` is an existing file (checked before any slow work)."""
    path = Path(path)
    refuse_symlink_loop(path, "results file")
    if path.is_dir():
        raise DataError(f"results path {path} is a folder; pass the .json written by 'gnnpmb track'")
    if not path.is_file():
        raise DataError(f"results file not found: {path}; pass the .json written by 'gnnpmb track'")


def read_submission(path: Path) -> dict[str, Any]:
    """Parse a submission file; a missing, truncated or non-JSON file is a one-line ``DataError``."""
    path = Path(path)
    check_results_file(path)
    try:
        data = json.loads(path.read_bytes())
    except json.JSONDecodeError as exc:
        raise DataError(
            f"results file {path.name} is not valid JSON: {exc.msg} at line {exc.lineno}, "
            f"column {exc.colno}; is it truncated? Write it again"
        ) from None
    except UnicodeDecodeError as exc:
        raise DataError(f"results file {path.name} is not UTF-8 JSON text (bad byte at {exc.start})") from None
    if not isinstance(data, dict):
        raise DataError(
            f"results file {path.name} holds a JSON {type(data).__name__}, not a tracking submission "
            "{'meta': {...}, 'results': {sample_token: [boxes]}}"
        )
    return data


def _vector_problem(name: str, value: Any, length: int) -> str | None:
    try:
        array = np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        array = None
    if array is None or array.shape != (length,) or isinstance(value, str):
        return f"field '{name}' must be a list of {length} numbers, got {short_repr(value)}"
    if not np.isfinite(array).all():
        return f"field '{name}' has a NaN or infinite value: {short_repr(value)}"
    return None


def _value_problem(name: str, value: Any) -> str | None:
    """Why a well-formed field ``name`` cannot be a real box (the detection file's limits, ``physical_problem``,
    and a rotation that is not a unit quaternion), or None."""
    values = np.asarray(value, dtype=float)[None, :]
    problem = physical_problem(name, values)
    if problem is None and name == "rotation":
        norm = float(np.linalg.norm(values))
        if abs(norm - 1.0) > QUAT_NORM_TOLERANCE:
            problem = f"is not a unit quaternion (length {norm:.6g}); normalise it"
    return None if problem is None else f"field '{name}' {problem}: {short_repr(value)}"


def _values_fine(name: str, array: np.ndarray) -> bool:
    """Whether (n, k) values of field ``name`` all pass ``_value_problem`` (vectorised)."""
    if physical_problem(name, array) is not None:
        return False
    return name != "rotation" or bool((np.abs(np.linalg.norm(array, axis=1) - 1.0) <= QUAT_NORM_TOLERANCE).all())


def _box_problem(token: str, box: Any) -> str | None:
    """What is wrong with one submission box, or None (the devkit's TrackingBox checks, and finiteness)."""
    if not isinstance(box, dict):
        return f"is a {type(box).__name__}, not an object"
    if "tracking_name" not in box and "detection_name" in box:
        return (
            "is a detection (detection_name, no tracking_name): this is a detection file, not tracking results; "
            "pass it as --detections FILE.json (gnnpmb track --detections FILE.json --out results.json tracks it)"
        )
    for name in _REQUIRED_FIELDS + tuple(n for n, _ in VECTOR_FIELDS):
        if name not in box:
            return f"has no '{name}' field"
    if box["sample_token"] != token:
        return f"has sample_token {short_repr(box['sample_token'])}; it must equal its results key"
    for name, length in VECTOR_FIELDS:
        problem = _vector_problem(name, box[name], length) or _value_problem(name, box[name])
        if problem is not None:
            return problem
    track_id = box["tracking_id"]
    if isinstance(track_id, bool) or not isinstance(track_id, str | int) or track_id == "":
        return f"field 'tracking_id' must be a non-empty string, got {short_repr(track_id)}"
    if box["tracking_name"] not in TRACKING_CLASSES:
        return (
            f"has tracking_name {short_repr(box['tracking_name'])}, not one of the tracking classes "
            f"({', '.join(TRACKING_CLASSES)})"
        )
    score = box["tracking_score"]
    if isinstance(score, bool) or not isinstance(score, int | float):
        return f"field 'tracking_score' must be a number, got {short_repr(score)}"
    if not math.isfinite(score):
        return f"field 'tracking_score' must be finite, got {score}"
    return None


def _sample_fine(token: str, boxes: list) -> bool:
    """Fast vectorised check of one sample's boxes; False means 'look closer' (``_box_problem``)."""
    try:
        if any(b["sample_token"] != token for b in boxes):
            return False
        for name, length in VECTOR_FIELDS:
            if any(isinstance(b[name], str) for b in boxes):
                return False
            array = np.array([b[name] for b in boxes], dtype=float)
            if array.shape != (len(boxes), length) or not np.isfinite(array).all():
                return False
            if not _values_fine(name, array):
                return False
        scores = [b["tracking_score"] for b in boxes]
        names = [b["tracking_name"] for b in boxes]
        ids = [b["tracking_id"] for b in boxes]
    except (KeyError, TypeError, ValueError):
        return False
    return (
        all(type(s) in (int, float) and math.isfinite(s) for s in scores)
        and all(n in TRACKING_CLASSES for n in names)
        and all(type(i) in (str, int) and i != "" for i in ids)
    )


def check_in_dataset(source: str, tokens: Sequence[str], dataset_tokens: Collection[str]) -> None:
    """Raise a one-line ``DataError`` naming the first of ``tokens`` (a results file's sample tokens) that is not
    one of ``dataset_tokens`` (the dataset version's)."""
    unknown = [t for t in tokens if t not in dataset_tokens]
    if unknown:
        raise NotThisDatasetError(
            f"{source} has {len(unknown)} samples that are not in the dataset (e.g. {unknown[0]}); was it made for "
            "another dataset version?"
        )


def check_submission(
    data: Any,
    source: str,
    split: str,
    split_tokens: Sequence[str],
    dataset_tokens: Collection[str],
    max_boxes_per_sample: int = MAX_BOXES_PER_SAMPLE,
) -> SubmissionStats:
    """Check a parsed submission against the split it is evaluated on; raise ``DataError`` (one line) on the
    first problem. ``source`` names the file in messages; ``split_tokens`` are the split's sample tokens and
    ``dataset_tokens`` every sample token of the dataset version (to tell 'other split' from 'other dataset').
    """
    if not isinstance(data, dict) or not isinstance(data.get("results"), dict):
        raise DataError(
            f"{source} has no 'results' object keyed by sample token; a tracking submission is "
            "{'meta': {...}, 'results': {sample_token: [boxes]}}"
        )
    if not isinstance(data.get("meta"), dict):
        raise DataError(
            f"{source} has no 'meta' object; add \"meta\": {json.dumps(SUBMISSION_META)} (what the tracker used)"
        )
    results: dict[str, Any] = data["results"]
    wanted = set(split_tokens)
    missing = [t for t in split_tokens if t not in results]
    extra = [t for t in results if t not in wanted]
    if missing:
        raise NotThisDatasetError(
            f"{source} lacks {len(missing)} of the {len(split_tokens)} samples of split {split}; "
            "was it made for another split?"
        )
    if extra:
        check_in_dataset(source, extra, dataset_tokens)
        raise NotThisDatasetError(
            f"{source} has {len(extra)} samples of other splits than {split} (e.g. {extra[0]}); "
            "evaluate it on the split it was made for"
        )
    check_id_types(results, source)
    n_boxes = 0
    for token in split_tokens:
        boxes = results[token]
        if not isinstance(boxes, list):
            raise DataError(f"{source}: results entry of sample {token} is a {type(boxes).__name__}, not a list")
        if len(boxes) > max_boxes_per_sample:
            raise DataError(
                f"{source}: sample {token} has {len(boxes)} boxes; the evaluation allows at most "
                f"{max_boxes_per_sample} per sample (drop the lowest-scoring ones)"
            )
        if boxes and not _sample_fine(token, boxes):
            for k, box in enumerate(boxes):
                problem = _box_problem(token, box)
                if problem is not None:
                    raise DataError(f"{source}: box {k} of sample {token} {problem}")
        duplicate = _duplicate_id(boxes)
        if duplicate is not None:
            raise DataError(
                f"{source}: sample {token} has two {duplicate[0]} boxes with tracking_id {duplicate[1]!r}; "
                "a track has at most one box per sample (give each track its own id)"
            )
        n_boxes += len(boxes)
    if n_boxes == 0:
        raise DataError(
            f"{source} has no boxes in any of the {len(split_tokens)} samples of split {split}: nothing to "
            "score (did the tracker keep no tracks? check score_threshold and the detections)"
        )
    return SubmissionStats(samples=len(split_tokens), boxes=n_boxes)


def check_id_types(results: Mapping[str, Any], source: str) -> None:
    """A one-line DataError when the file's ``tracking_id`` values are integers in some boxes and strings in others:
    the devkit keeps each id as read, so 5 and "5" are two tracks to it, while a reader that turns ids into text
    would join them. One type per file keeps every reader of the file in agreement."""
    first: dict[type, str] = {}
    for token, boxes in results.items():
        if not isinstance(boxes, list):
            continue
        for box in boxes:
            track_id = box.get("tracking_id") if isinstance(box, dict) else None
            kind = type(track_id)
            if kind in (int, str) and kind not in first:
                first[kind] = token
                if len(first) == 2:
                    raise DataError(
                        f"{source}: tracking_id is an integer in some boxes (e.g. sample {first[int]}) and a string "
                        f'in others (e.g. sample {first[str]}); the official evaluation counts 5 and "5" as two '
                        "tracks: write every id as a string"
                    )


def _duplicate_id(boxes: list[dict[str, Any]]) -> tuple[str, str] | None:
    """The first (class, tracking_id) that occurs twice among one sample's boxes, or None."""
    seen: set[tuple[str, str]] = set()
    for box in boxes:
        key = (str(box["tracking_name"]), str(box["tracking_id"]))
        if key in seen:
            return key
        seen.add(key)
    return None
