"""Disagreements between trackers (``gnnpmb.compare``) in a Rerun recording, shared by every tracker's view.

Per kind: the involved boxes (the GT object, or the track only one tracker reports) drawn a little larger than
the objects in the kind's colour at their frame, under ``world/comparison/<kind>`` so every tracker's 3D view
shows them (the views hide only other trackers' ``world/trackers/...``); a per-frame count series
(``comparison/counts/<kind>``); and one TextLog line per disagreement (``comparison/log``). Everything is sent
column-wise: a few calls however many disagreements there are.
"""

from __future__ import annotations

import numpy as np
import rerun as rr

from gnnpmb.compare import Comparison, Disagreement, DisagreementKind, short_gt_id
from gnnpmb.data.scene import SceneData
from viz import paths
from viz.geometry import quat_wxyz_to_xyzw, size_wlh_to_xyz

COMPARISON = "comparison"
KIND_COLORS: dict[DisagreementKind, tuple[int, int, int]] = {
    DisagreementKind.MISSED_BY_ONE: (0, 190, 255),
    DisagreementKind.ID_CHANGE: (170, 80, 255),
    DisagreementKind.ONLY_IN_ONE: (255, 120, 200),
}
"""Colours apart from the class colours and from the failure markers' (``viz.failures.KIND_COLORS``)."""
KIND_LABELS: dict[DisagreementKind, str] = {
    DisagreementKind.MISSED_BY_ONE: "tracked by one only",
    DisagreementKind.ID_CHANGE: "id changed in one only",
    DisagreementKind.ONLY_IN_ONE: "track in one only",
}
KIND_LEVELS: dict[DisagreementKind, str] = {
    DisagreementKind.MISSED_BY_ONE: "WARN",
    DisagreementKind.ID_CHANGE: "WARN",
    DisagreementKind.ONLY_IN_ONE: "INFO",
}
MARKER_SCALE = 1.2
MARKER_MARGIN_M = 0.6
"""Marker box = object box x MARKER_SCALE + MARKER_MARGIN_M: outside the failure markers (x 1.1 + 0.3 m)."""
MARKER_LINE_RADIUS_M = 0.1


def log_path() -> str:
    """TextLog of every disagreement."""
    return f"{COMPARISON}/log"


def counts_root() -> str:
    return f"{COMPARISON}/counts"


def count_path(kind: DisagreementKind) -> str:
    """Scalars: disagreements of one kind per frame."""
    return f"{counts_root()}/{kind.value}"


def markers_path(kind: DisagreementKind) -> str:
    """Boxes3D of the objects involved in disagreements of one kind (in every tracker's 3D view)."""
    return f"{paths.WORLD}/{COMPARISON}/{kind.value}"


def marker_label(d: Disagreement) -> str:
    """Short box label naming the trackers and ids."""
    match d.kind:
        case DisagreementKind.MISSED_BY_ONE:
            return f"only {d.tracker} tracks GT {short_gt_id(d.gt_id)} (track {d.track_ids[0]})"
        case DisagreementKind.ID_CHANGE:
            old, new, kept = d.track_ids
            return f"{d.tracker} {old}->{new}, {d.other} kept {kept}: GT {short_gt_id(d.gt_id)}"
        case DisagreementKind.ONLY_IN_ONE:
            return f"only {d.tracker}: track {d.track_ids[0]}"
    raise AssertionError(d.kind)


def _markers(
    disagreements: list[Disagreement], frame_indices: tuple[int, ...]
) -> tuple[list[Disagreement], list[str], np.ndarray]:
    """One box per object and frame (labels of several disagreements about it joined), and (F,) boxes per
    frame."""
    position = {f: i for i, f in enumerate(frame_indices)}
    boxes: dict[tuple[int, str], Disagreement] = {}
    labels: dict[tuple[int, str], list[str]] = {}
    for d in disagreements:
        key = (d.frame_index, d.gt_id or f"{d.tracker}/{d.track_ids[0]}")
        boxes.setdefault(key, d)
        labels.setdefault(key, []).append(marker_label(d))
    keys = sorted(boxes, key=lambda k: (position[k[0]], k[1]))
    lengths = np.zeros(len(frame_indices), dtype=np.int64)
    for frame, _ in keys:
        lengths[position[frame]] += 1
    return [boxes[k] for k in keys], ["; ".join(labels[k]) for k in keys], lengths


def log_comparison(stream: rr.RecordingStream, comparison: Comparison, scene: SceneData) -> None:
    """Log ``comparison`` (over keyframes of ``scene``) on the frame and timestamp timelines: per kind a count
    at every compared frame and marker boxes (an empty batch at frames without any), plus the text log."""
    frames = np.asarray(comparison.frame_indices, dtype=np.int64)
    stamps = np.array([scene.keyframes[i].timestamp_us for i in frames.tolist()], dtype="datetime64[us]")

    def indexes(at: np.ndarray) -> list[rr.TimeColumn]:
        return [rr.TimeColumn("frame", sequence=frames[at]), rr.TimeColumn("timestamp", timestamp=stamps[at])]

    every = np.arange(frames.size)
    for kind in DisagreementKind:
        color = KIND_COLORS[kind]
        stream.log(count_path(kind), rr.SeriesLines(names=KIND_LABELS[kind], colors=[color]), static=True)
        stream.send_columns(
            count_path(kind),
            indexes=indexes(every),
            columns=rr.Scalars.columns(scalars=comparison.counts(kind).astype(np.float64)),
        )
        found = comparison.of_kind(kind)
        if not found:
            continue
        boxes, labels, lengths = _markers(found, comparison.frame_indices)
        sizes = size_wlh_to_xyz(np.array([b.size_wlh_m for b in boxes], dtype=np.float64))
        stream.send_columns(
            markers_path(kind),
            indexes=indexes(every),
            columns=rr.Boxes3D.columns(
                centers=np.array([b.translation_m for b in boxes], dtype=np.float64),
                half_sizes=0.5 * (sizes * MARKER_SCALE + MARKER_MARGIN_M),
                quaternions=quat_wxyz_to_xyzw(np.array([b.quat_wxyz for b in boxes], dtype=np.float64)),
                colors=np.tile(np.array(color, dtype=np.uint8), (len(boxes), 1)),
                radii=np.full(len(boxes), MARKER_LINE_RADIUS_M, dtype=np.float32),
                labels=labels,
            ).partition(lengths),
        )
    if comparison.disagreements:
        position = {f: i for i, f in enumerate(comparison.frame_indices)}
        at = np.array([position[d.frame_index] for d in comparison.disagreements], dtype=np.int64)
        stream.send_columns(
            log_path(),
            indexes=indexes(at),
            columns=rr.TextLog.columns(
                text=[f"{KIND_LABELS[d.kind]}: {d.describe()}" for d in comparison.disagreements],
                level=[KIND_LEVELS[d.kind] for d in comparison.disagreements],
            ),
        )
