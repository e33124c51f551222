"""Another tracker's results as a run: a nuScenes tracking submission read, checked and replayed as output-only
events, so its failures, findings and drawings come from the same code as a built-in tracker's.

Only the output is known: per keyframe, each track's box, id and score. ``scene_results`` checks the file like a
submission (``eval.submission.check_submission``: one line for the first problem) for the scene's samples and says
how many boxes lie in samples of other scenes (left out, reported as a notice) or in no sample of the dataset (an
error); ids that are not plain integers, or are shared by two classes, are numbered 1, 2, ... in order of
appearance (``ForeignResults.original_ids`` keeps the file's). Each box is placed on the detection it sits on by
one rule (``box_on``): the detection of its class whose size, heading and height it carries, else the nearest
detection of its class within ``NEAREST_M`` (BEV), else none; the rule that held is kept (``BoxOn``), so an
explanation says which.

``replay`` emits, per keyframe, ``FrameStarted`` and per class ``MeasurementsReceived`` (every detection given of
the class: the tracker's own preprocessing is unknown) and ``Extracted`` (the boxes); a ``why.facts.FactSink``
built with ``output_only`` reads them as output only.
"""

from __future__ import annotations

import enum
import functools
import re
from collections.abc import Callable, Collection, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from gnnpmb.data.scene import SceneData
from gnnpmb.errors import DataError, NotThisDatasetError
from gnnpmb.events import EventSink, Extracted, FrameStarted, MeasurementsReceived, NullSink
from gnnpmb.pipeline import FrameResult, TrackingRun, keyframe_steps
from gnnpmb.types import Boxes, FrameDetections, TrackEstimate

SAME_BOX_TOL = 1e-4
"""A box carries a detection's size, heading and height when each number is within this (m, quaternion units):
float32 files round-trip within it."""
NEAREST_M = 0.5
"""Without a detection of the same box, the nearest detection of its class within this BEV distance is the one it
sits on."""
_INTEGER_ID = re.compile(r"^(0|[1-9][0-9]{0,14})$")


class OnHow(enum.Enum):
    """How a box was found to sit on a detection (``box_on``)."""

    SAME_BOX = "same box"  # it carries the detection's size, heading and height
    NEAREST = "nearest"  # the nearest detection of its class within NEAREST_M


@dataclass(frozen=True, slots=True)
class BoxOn:
    """The detection a box sits on: its index in the frame's detections, how it was found, and the BEV distance
    (m) from the box centre to the detection's."""

    meas: int
    how: OnHow
    distance_m: float


def box_on(
    xy: np.ndarray, z: float, size_wlh: np.ndarray, quat_wxyz: np.ndarray, class_name: str, detections: Boxes
) -> BoxOn | None:
    """The detection a box (BEV centre ``xy`` (2,), height ``z``, size (3,), rotation (4,)) of ``class_name``
    sits on among ``detections``, by the module's rule; None: none."""
    if not len(detections):
        return None
    mine = np.asarray(detections.class_name) == class_name
    d = np.hypot(*(detections.translation_m[:, :2] - xy).T)
    same = (
        mine
        & np.all(np.abs(detections.size_wlh_m - size_wlh) <= SAME_BOX_TOL, axis=1)
        & np.all(np.abs(detections.quat_wxyz - quat_wxyz) <= SAME_BOX_TOL, axis=1)
        & (np.abs(detections.translation_m[:, 2] - z) <= SAME_BOX_TOL)
    )
    if same.any():
        m = int(np.flatnonzero(same)[np.argmin(d[same])])
        return BoxOn(m, OnHow.SAME_BOX, float(d[m]))
    near = mine & (d < NEAREST_M)
    if near.any():
        m = int(np.flatnonzero(near)[np.argmin(d[near])])
        return BoxOn(m, OnHow.NEAREST, float(d[m]))
    return None


@dataclass(frozen=True, slots=True)
class ForeignResults:
    """One scene of a results file: ``name``, ``path``; estimates[k]: the boxes of keyframe k (every keyframe of
    the scene) with their detection (``meas_index``) by ``box_on``; boxes_on: (frame, track id) -> how; original_ids:
    track id -> the file's id when the file's ids were renumbered (else empty); notices: what was left out."""

    name: str
    path: Path
    estimates: tuple[tuple[TrackEstimate, ...], ...]
    boxes_on: Mapping[tuple[int, int], BoxOn]
    original_ids: Mapping[int, str]
    notices: tuple[str, ...] = ()


def read_results(path: Path) -> dict[str, Any]:
    """The parsed results file (``eval.submission.read_submission``: one line for a missing, truncated or non-JSON
    file) with a ``results`` object keyed by sample token; a file read is kept while it is unchanged (a split is
    read once for all its scenes). Treat it as read-only."""
    from gnnpmb.data.file_identity import file_identity

    path = Path(path).absolute()
    return _read(path, tuple(file_identity(path)[1:]))


@functools.lru_cache(maxsize=2)
def _read(path: Path, identity: tuple[Any, ...]) -> dict[str, Any]:
    from gnnpmb.eval.submission import read_submission

    data = read_submission(path)
    if not isinstance(data.get("results"), dict):
        raise DataError(
            f"{Path(path).name} has no 'results' object keyed by sample token; a tracking submission is "
            "{'meta': {...}, 'results': {sample_token: [boxes]}}"
        )
    return data


def check_coverage(
    data: Mapping[str, Any], source: str, what: str, tokens: Sequence[str], dataset_tokens: Collection[str]
) -> str | None:
    """Raise a one-line ``DataError`` unless ``data`` has an entry for every one of ``tokens`` (the samples of
    ``what``, e.g. "scene-0103" or "split mini_val") and only samples of the dataset; returns a notice about the
    boxes of other samples it holds (left out), None when there are none."""
    results = data["results"]
    missing = [t for t in tokens if t not in results]
    if len(missing) == len(tokens):
        raise NotThisDatasetError(
            f"{source} has none of the {len(tokens)} samples of {what}; was it made for another scene, split or "
            "dataset version?"
        )
    if missing:
        raise NotThisDatasetError(
            f"{source} lacks {len(missing)} of the {len(tokens)} samples of {what} (e.g. {missing[0]})"
        )
    from gnnpmb.eval.submission import check_in_dataset

    wanted = set(tokens)
    extra = [t for t in results if t not in wanted]
    check_in_dataset(source, extra, dataset_tokens)
    if not extra:
        return None
    boxes = sum(len(results[t]) if isinstance(results[t], list) else 0 for t in extra)
    return f"{source}: {boxes} boxes in {len(extra)} samples outside {what} left out"


def scene_results(
    name: str,
    path: Path,
    data: Mapping[str, Any],
    scene: SceneData,
    frames: Sequence[FrameDetections],
    classes: Sequence[str],
    dataset_tokens: Collection[str],
) -> ForeignResults:
    """Scene ``scene`` of a parsed results file (``read_results``), checked like a submission, each box placed on
    the detection it sits on among ``frames`` (the scene's detections, one per keyframe); boxes of classes not in
    ``classes`` are left out."""
    from gnnpmb.eval.submission import SUBMISSION_META, check_submission

    source = Path(path).name
    tokens = [k.sample_token for k in scene.keyframes]
    notice = check_coverage(data, source, scene.name, tokens, dataset_tokens)
    _check_whole_file(data, source)
    if not any(data["results"][t] for t in tokens if isinstance(data["results"][t], list)):
        raise DataError(f"{source} has no boxes in the {len(tokens)} samples of {scene.name}: nothing to show")
    part = {"meta": data.get("meta", SUBMISSION_META), "results": {t: data["results"][t] for t in tokens}}
    check_submission(part, source, scene.name, tokens, set(tokens))
    boxes = [[b for b in part["results"][t] if b["tracking_name"] in classes] for t in tokens]
    ids, renumbered = _numbering(boxes)
    estimates, boxes_on = [], {}
    for k, (rows, fr) in enumerate(zip(boxes, frames, strict=True)):
        out = []
        for b in rows:
            t = ids[(str(b["tracking_id"]), b["tracking_name"])]
            xyz = np.asarray(b["translation"], dtype=np.float64)
            size = np.asarray(b["size"], dtype=np.float64)
            quat = np.asarray(b["rotation"], dtype=np.float64)
            on = box_on(xyz[:2], float(xyz[2]), size, quat, b["tracking_name"], fr.boxes)
            if on is not None:
                boxes_on[(scene.keyframes[k].index, t)] = on
            out.append(
                TrackEstimate(
                    track_id=t,
                    class_name=str(b["tracking_name"]),
                    translation_m=tuple(float(v) for v in xyz),
                    size_wlh_m=tuple(float(v) for v in size),
                    quat_wxyz=tuple(float(v) for v in quat),
                    velocity_mps=tuple(float(v) for v in b["velocity"]),
                    score=float(b["tracking_score"]),
                    existence=1.0,
                    meas_index=on.meas if on is not None else -1,
                )
            )
        estimates.append(tuple(sorted(out, key=lambda e: (e.class_name, e.track_id))))
    original = {t: i for (i, _), t in ids.items()} if renumbered else {}
    notices = (notice,) if notice else ()
    if original:
        notices += (
            f"{source}: its tracking ids are not integers unique across classes; numbered 1 to {len(original)} in "
            "order of appearance",
        )
    return ForeignResults(name, Path(path), tuple(estimates), boxes_on, original, notices)


_CHECKED_FILES: list[Mapping[str, Any]] = []
"""The last parsed results files whose whole-file checks passed (as many as ``read_results`` keeps)."""


def _check_whole_file(data: Mapping[str, Any], source: str) -> None:
    """The checks that need every sample of the file (``check_id_types``), once per parsed file (a split's scenes
    share one)."""
    from gnnpmb.eval.submission import check_id_types

    if any(seen is data for seen in _CHECKED_FILES):
        return
    check_id_types(data["results"], source)
    _CHECKED_FILES[:] = [*_CHECKED_FILES[-1:], data]


def _numbering(boxes: Sequence[Sequence[Mapping[str, Any]]]) -> tuple[dict[tuple[str, str], int], bool]:
    """(file id, class) -> track id, and whether the ids were renumbered: the file's ids where every one is a plain
    integer used by one class only, else 1, 2, ... in order of appearance."""
    keys = list(dict.fromkeys((str(b["tracking_id"]), str(b["tracking_name"])) for rows in boxes for b in rows))
    if all(_INTEGER_ID.match(i) for i, _ in keys) and len({i for i, _ in keys}) == len(keys):
        return {key: int(key[0]) for key in keys}, False
    return {key: k + 1 for k, key in enumerate(keys)}, True


def given_detections(frame: FrameDetections) -> FrameDetections:
    """Every detection of ``frame`` as received: what a results run is compared with (its tracker's own score
    threshold and suppression are unknown)."""
    n = len(frame.boxes)
    none = np.zeros(n, dtype=bool)
    return FrameDetections(frame.boxes, np.ones(n, dtype=bool), none, none.copy())


def replay(
    results: ForeignResults,
    scene: SceneData,
    frames: Sequence[FrameDetections],
    classes: Sequence[str],
    frame_range: range | None = None,
    sink: EventSink | None = None,
    on_frame: Callable[[], None] | None = None,
) -> TrackingRun:
    """The results as a ``TrackingRun`` named ``results.name`` over ``frame_range`` (default all keyframes), its
    output-only events sent to ``sink`` (module docstring)."""
    sink = sink or NullSink()
    received = [given_detections(frame) for frame in frames]
    out: list[FrameResult] = []
    for i, keyframe, dt_s in keyframe_steps(scene, frame_range):
        given = received[i]
        estimates = results.estimates[i]
        if sink.enabled:
            sink.emit(FrameStarted(results.name, i, keyframe.sample_token, keyframe.timestamp_us, dt_s))
            boxes = given.boxes
            for c in classes:
                idx = np.flatnonzero(np.asarray(boxes.class_name) == c)
                sink.emit(MeasurementsReceived(c, idx, boxes.translation_m[idx], boxes.score[idx]))
                sink.emit(Extracted(c, tuple(e for e in estimates if e.class_name == c), 0.0))
        out.append(FrameResult(keyframe, given, estimates, 0.0))
        if on_frame is not None:
            on_frame()
    return TrackingRun(tracker=results.name, scene=scene, frames=tuple(out))
