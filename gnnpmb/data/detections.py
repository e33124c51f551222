"""nuScenes detection submission files: the JSON that CenterPoint, Megvii and PointPillars publish.

Layout: ``{"meta": {...}, "results": {sample_token: [box, ...]}}``, each box
``{"sample_token", "translation": [x, y, z], "size": [w, l, h], "rotation": [w, x, y, z],
"velocity": [vx, vy], "detection_name", "detection_score", "attribute_name"}`` in the global frame. The loader
needs the geometry, ``detection_name`` and ``detection_score``; it does not require ``attribute_name`` or the
per-box ``sample_token``. A NaN velocity (allowed by the devkit for detectors without velocity) means unknown
and becomes 0. Only the 7 tracking classes are kept (barrier, traffic_cone and construction_vehicle
boxes are dropped).

Result files of the full val split are 300-700 MB, so a file is read once, streamed, into a persistent index
in the user cache (``gnnpmb.data.detection_index``: each sample's converted boxes, or its first problem) and
every later command reads only the samples it needs; a rewritten file is indexed again. A malformed box is
reported only when a sample that contains it is requested.
"""

from __future__ import annotations

import json
import shutil
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any, TypeVar

import numpy as np

from gnnpmb.data.json_stream import JsonStreamError, NotUtf8Error
from gnnpmb.errors import DataError, NotThisDatasetError
from gnnpmb.symlinks import refuse_symlink_loop
from gnnpmb.types import TRACKING_CLASSES, Boxes

if TYPE_CHECKING:
    from gnnpmb.data.detection_index import DetectionIndex, UntrackedBox

T = TypeVar("T")

DETECTION_CLASSES: tuple[str, ...] = (
    "barrier",
    "bicycle",
    "bus",
    "car",
    "construction_vehicle",
    "motorcycle",
    "pedestrian",
    "traffic_cone",
    "trailer",
    "truck",
)
"""The ten nuScenes detection classes; all but barrier, traffic_cone and construction_vehicle are tracked."""
UNTRACKED_NAMES: tuple[str, ...] = tuple(c for c in DETECTION_CLASSES if c not in TRACKING_CLASSES)
"""The detection names the tracking evaluation has no class for: their boxes are kept aside for the explanations
(a car seen only as a construction_vehicle was seen, with a class no tracker takes)."""

VECTOR_FIELDS: tuple[tuple[str, int], ...] = (
    ("translation", 3),
    ("size", 3),
    ("rotation", 4),
    ("velocity", 2),
)
"""The list fields of a detection or tracking box and their lengths."""
LIDAR_ONLY_META: dict[str, bool] = {
    "use_camera": False,
    "use_lidar": True,
    "use_radar": False,
    "use_map": False,
    "use_external": False,
}
"""The ``meta`` of a submission made from LiDAR only: our tracking submissions and simulated detection files."""
MAX_ABS_COORD_M = 1e5
"""Largest accepted |x|, |y|, |z| of a box centre in the global frame (nuScenes maps span a few km)."""
MAX_SIZE_M = 100.0
"""Largest accepted box width, length or height; sizes must also be positive."""
MAX_SPEED_MPS = 200.0
"""Largest accepted |vx|, |vy| of a box (NaN is allowed: unknown velocity, read as 0)."""
MIN_QUAT_NORM = 1e-6
"""A rotation quaternion shorter than this has no direction (e.g. all zeros)."""


_opened: dict[tuple[str, int, int, int, int], DetectionIndex] = {}
"""The index of the detection file last used in this process, keyed by the file's identity."""


def _as_floats(value: Any) -> np.ndarray | None:
    """``value`` as a float array the way the fast path converts it, or None if it cannot be."""
    try:
        return np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        return None


def short_repr(value: Any) -> str:
    """``repr(value)`` cut to 60 characters, for an error line quoting a bad value."""
    text = repr(value)
    return text if len(text) <= 60 else text[:57] + "..."


def _box_problem(entry: Any) -> str | None:
    """What is wrong with one box entry, or None."""
    if not isinstance(entry, dict):
        return f"is a {type(entry).__name__}, not an object"
    if "detection_name" not in entry and "tracking_name" in entry:
        return (
            "is a track (tracking_name, no detection_name): this is a tracking results file, not detections; "
            "open it with --results NAME=FILE.json, score it with gnnpmb eval FILE.json"
        )
    for name, length in VECTOR_FIELDS:
        if name not in entry:
            return f"has no '{name}' field"
        value = _as_floats(entry[name])
        if value is None or value.shape != (length,):
            return f"field '{name}' must be a list of {length} numbers, got {short_repr(entry[name])}"
        if name != "velocity" and not _all_numbers(entry[name]):
            return f"field '{name}' must hold numbers, not text or null: {short_repr(entry[name])}"
        if name != "velocity" and not np.isfinite(value).all():
            return f"field '{name}' has a NaN or infinite value: {short_repr(entry[name])}"
        physical = physical_problem(name, value[None, :])
        if physical is not None:
            return f"field '{name}' {physical}: {short_repr(entry[name])}"
    if "detection_name" not in entry:
        return "has no 'detection_name' field"
    if entry["detection_name"] not in DETECTION_CLASSES:
        return f"has detection_name {entry['detection_name']!r}, not a nuScenes detection class"
    if "detection_score" not in entry:
        return "has no 'detection_score' field"
    raw_score = entry["detection_score"]
    if isinstance(raw_score, bool) or not isinstance(raw_score, int | float):
        return f"field 'detection_score' must be a number, got {short_repr(raw_score)}"
    score = _as_floats(raw_score)
    if score is None or score.shape != () or not np.isfinite(score):
        return f"field 'detection_score' must be a finite number, got {short_repr(entry['detection_score'])}"
    if not 0.0 <= float(score) <= 1.0:
        return f"field 'detection_score' must lie in [0, 1], got {float(score)}"
    return None


def _all_numbers(value: Any) -> bool:
    """Whether a JSON list holds only numbers (``np.asarray(..., dtype=float)`` also converts "1.5")."""
    return isinstance(value, list) and all(type(v) in (int, float) for v in value)


def physical_problem(name: str, values: np.ndarray) -> str | None:
    """Why (n, k) values of field ``name`` cannot be a real box, or None: centres beyond ``MAX_ABS_COORD_M``,
    sizes not in (0, ``MAX_SIZE_M``], speeds beyond ``MAX_SPEED_MPS`` (NaN, unknown, passes), quaternions of
    (almost) zero length."""
    if name == "translation" and (np.abs(values) > MAX_ABS_COORD_M).any():
        return f"is beyond {MAX_ABS_COORD_M:.0e} m from the map origin"
    if name == "size" and ((values <= 0.0) | (values > MAX_SIZE_M)).any():
        return f"must be positive and at most {MAX_SIZE_M:g} m"
    if name == "velocity" and (np.abs(values) > MAX_SPEED_MPS).any():
        return f"is faster than {MAX_SPEED_MPS:g} m/s"
    if name == "rotation" and (np.linalg.norm(values, axis=1) < MIN_QUAT_NORM).any():
        return "is not a rotation (a quaternion of zero length)"
    return None


def _diagnose(token: str, entries: Any) -> str:
    """One-line description of the first malformed box of a sample."""
    if not isinstance(entries, list):
        return f"results entry of sample {token} is a {type(entries).__name__}, not a list of boxes"
    for k, entry in enumerate(entries):
        problem = _box_problem(entry)
        if problem is not None:
            return f"box {k} of sample {token} {problem}"
    return f"the boxes of sample {token} could not be read"


def convert_sample(token: str, entries: Any) -> Boxes | str:
    """The tracking-class boxes of one sample's entries, or a problem description (checked fully only on the
    slow path, when the fast vectorised conversion finds something wrong)."""
    if not isinstance(entries, list):
        return _diagnose(token, entries)
    if not entries:
        return Boxes.empty()
    n = len(entries)
    try:
        names = np.array([e["detection_name"] for e in entries], dtype=object)
        scores = [e["detection_score"] for e in entries]
        raw_score = np.array(scores)
        raw = {name: np.array([e[name] for e in entries]) for name, _ in VECTOR_FIELDS if name != "velocity"}
        velocity = np.array([e["velocity"] for e in entries], dtype=float)
    except (KeyError, TypeError, ValueError):
        return _diagnose(token, entries)
    if not all(type(v) in (int, float) for v in scores) or any(a.dtype.kind not in "if" for a in raw.values()):
        return _diagnose(token, entries)
    score = raw_score.astype(float)
    arrays = {name: a.astype(float) for name, a in raw.items()} | {"velocity": velocity}
    fine = (
        all(arrays[name].shape == (n, length) for name, length in VECTOR_FIELDS)
        and score.shape == (n,)
        and all(np.isfinite(a).all() for name, a in arrays.items() if name != "velocity")
        and np.isfinite(score).all()
        and ((score >= 0.0) & (score <= 1.0)).all()
        and np.isin(names.astype(str), DETECTION_CLASSES).all()
        and all(physical_problem(name, arrays[name]) is None for name, _ in VECTOR_FIELDS)
    )
    if not fine:
        return _diagnose(token, entries)
    keep = np.flatnonzero(np.isin(names.astype(str), TRACKING_CLASSES))
    return Boxes(
        translation_m=arrays["translation"][keep],
        size_wlh_m=arrays["size"][keep],
        quat_wxyz=arrays["rotation"][keep],
        velocity_mps=np.nan_to_num(arrays["velocity"][keep], nan=0.0, posinf=0.0, neginf=0.0),
        score=score[keep],
        class_name=names[keep],
        instance_id=np.full(keep.size, "", dtype=object),
    )


def untracked_boxes(entries: list[Any]) -> list[UntrackedBox]:
    """(name, score, x m, y m) of a sample's boxes of ``UNTRACKED_NAMES`` (entries ``convert_sample`` checked)."""
    return [
        (str(e["detection_name"]), float(e["detection_score"]), float(e["translation"][0]), float(e["translation"][1]))
        for e in entries
        if e["detection_name"] in UNTRACKED_NAMES
    ]


def _read_error(path: Path, exc: Exception) -> DataError:
    """The one line for a detection file that cannot be read as a submission."""
    if isinstance(exc, JsonStreamError):
        return DataError(
            f"detections file {path} is not valid JSON: {exc}; is it truncated? Download or generate it again"
        )
    if isinstance(exc, NotUtf8Error):
        return DataError(
            f"detections file {path} is not UTF-8 JSON text (bad byte at position {exc.byte}); "
            "pass a nuScenes detection results .json file"
        )
    if isinstance(exc, TypeError) and len(exc.args) == 2 and exc.args[1] is not None:
        return DataError(f"'results' in detections file {path} is a {exc.args[0]}, not an object keyed by sample token")
    if isinstance(exc, KeyError | TypeError):
        return DataError(
            f"detections file {path} has no 'results' object; "
            "expected a nuScenes detection submission {'meta': ..., 'results': {sample_token: [boxes]}}"
        )
    return DataError(f"cannot read detections file {path}: {getattr(exc, 'strerror', None) or exc}")


def _index(path: Path) -> DetectionIndex:
    """The file's index (``gnnpmb.data.detection_index``: parsed once per file and kept in the user cache),
    opened once per process while the file is unchanged."""
    from gnnpmb.cache_folder import cache_root
    from gnnpmb.data.detection_index import open_detection_index

    refuse_symlink_loop(path, "detections file")
    try:
        st = path.stat()
    except FileNotFoundError:
        raise DataError(
            f"detections file not found: {path}; check the path (or use a simulated detector preset)"
        ) from None
    if path.is_dir():
        raise DataError(f"detections path {path} is a folder; pass a nuScenes detection results .json file")
    if not path.is_file():
        raise DataError(f"detections path {path} is not a file; pass a nuScenes detection results .json file")
    resolved = path.resolve()
    key = (str(resolved), st.st_ino, st.st_mtime_ns, st.st_ctime_ns, st.st_size)
    if key not in _opened:
        _opened.clear()
        _opened[key] = open_detection_index(
            cache_root(), resolved, convert_sample, untracked_boxes, lambda exc: _read_error(path, exc)
        )
    return _opened[key]


def check_detection_file(path: Path) -> None:
    """Index (once) or open the index of a detection file now, so a missing, non-JSON or malformed file fails
    before a dataset is loaded; problems inside one sample's boxes are still reported when that sample is
    loaded."""
    _index(Path(path))


def detection_file_sha256(path: Path) -> str:
    """SHA-256 (hex) of a detection file's bytes, computed when it was indexed."""
    return _index(Path(path)).sha256


def load_detection_file(path: Path, sample_tokens: Sequence[str], scene_name: str | None = None) -> dict[str, Boxes]:
    """Tracking-class detection boxes of exactly ``sample_tokens`` (in that order) from a submission file.

    scene_name only makes error messages clearer. Raises ``DataError`` when the file is missing or malformed,
    a requested sample has a malformed box, or some requested samples have no entry (an empty list is fine).
    """
    path = Path(path)

    def read(index: DetectionIndex) -> dict[str, Boxes]:
        missing = [t for t in sample_tokens if t not in index]
        if missing:
            where = f"the {len(sample_tokens)} " + (f"samples of {scene_name}" if scene_name else "requested samples")
            raise NotThisDatasetError(
                f"detections file {path.name} has no boxes entry for {len(missing)} of {where} "
                f"(first missing: {missing[0]}); is it for another split or version?"
            )
        for token in sample_tokens:
            if token in index.problems:
                raise DataError(f"detections file {path.name}: {index.problems[token]}")
        return {token: index.boxes(token) for token in sample_tokens}

    return _from_index(path, read)


def untracked_detection_boxes(path: Path, sample_tokens: Sequence[str]) -> dict[str, tuple[UntrackedBox, ...]]:
    """Per sample token of ``sample_tokens`` with any, its boxes of ``UNTRACKED_NAMES`` in the detection file
    ``path`` (name, score, x m, y m), from the file's index (read once per file, whatever its size)."""
    return _from_index(Path(path), lambda index: {t: boxes for t in sample_tokens if (boxes := index.untracked(t))})


def _from_index(path: Path, read: Callable[[DetectionIndex], T]) -> T:
    """``read`` of the detection file's index; an index found damaged while reading is deleted and built again."""
    from gnnpmb.data.index_store import IndexDamaged

    index = _index(path)
    try:
        return read(index)
    except IndexDamaged:
        _opened.clear()
        shutil.rmtree(index.store.folder, ignore_errors=True)
        return _from_index(path, read)


def write_detection_file(path: Path, submission: dict[str, Any]) -> None:
    """Write a detection submission as JSON, atomically (``gnnpmb.atomic``)."""
    from gnnpmb.atomic import write_text

    write_text(Path(path), json.dumps(submission, allow_nan=False, separators=(",", ":")))
