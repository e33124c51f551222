"""Disagreements between trackers (``gnnpmb.compare``) in a Rerun recording, shared by every tracker's view.

Per kind: the involved boxes (the GT object, or the track only one tracker reports) drawn a little larger than
the objects in the kind's colour at their frame, under ``world/trackers/<viewer>/comparison/<kind>`` for each
tracker's views (the colour says which kind; the words, e.g. "only pmbm: track 92", are the boxes' labels, shown
on hover, not printed over the view); a per-frame count series (``comparison/counts/<kind>``); and one TextLog
line per disagreement (``comparison/log``). Everything is sent column-wise: a few calls however many
disagreements there are.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
import rerun as rr

from gnnpmb.compare import Comparison, Disagreement, DisagreementKind
from gnnpmb.data.scene import SceneData
from gnnpmb.eval.failures import short_id
from viz import paths
from viz.markers import send_counts, send_marker_boxes, send_text_lines
from viz.timeline import PLAIN_CLOCK, Clock

COMPARISON = "comparison"
KIND_COLORS: dict[DisagreementKind, tuple[int, int, int]] = {
    DisagreementKind.MISSED_BY_ONE: (0, 190, 255),
    DisagreementKind.ID_CHANGE: (170, 80, 255),
    DisagreementKind.ONLY_IN_ONE: (255, 120, 200),
}
"""Colours apart from the class colours and from the failure markers' (``viz.failure_style.KIND_COLORS``)."""
KIND_LABELS: dict[DisagreementKind, str] = {
    DisagreementKind.MISSED_BY_ONE: "shown by one only",
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


def focus_log_path() -> str:
    """TextLog of the disagreements about the focused class (a focus recording opens on it)."""
    return f"{COMPARISON}/log_focus_class"


def counts_root() -> str:
    return f"{COMPARISON}/counts"


def count_path(kind: DisagreementKind) -> str:
    """Scalars: disagreements of one kind per frame."""
    return f"{counts_root()}/{kind.value}"


def markers_path(kind: DisagreementKind, viewer: str) -> str:
    """Boxes3D of the objects involved in disagreements of one kind, as tracker ``viewer``'s views show them (only
    there: each view labels them in its own terms, ``log_comparison``)."""
    return f"{paths.tracker_world(viewer)}/{COMPARISON}/{kind.value}"


def marker_label(d: Disagreement) -> str:
    """Short box label naming the trackers and ids."""
    match d.kind:
        case DisagreementKind.MISSED_BY_ONE:
            mine = f"only {d.tracker} tracks GT {short_id(d.gt_id)} (track {d.track_ids[0]})"
            if d.elsewhere is not None:
                return f"{mine}; {d.other}'s track {d.elsewhere[0]} is on GT {short_id(d.elsewhere[1])}"
            if d.unshown is not None:
                return f"{mine}; {d.other}'s track {d.unshown} is below the display threshold"
            return mine
        case DisagreementKind.ID_CHANGE:
            old, new, kept = d.track_ids
            return f"{d.tracker} {old}->{new}, {d.other} kept {kept}: GT {short_id(d.gt_id)}"
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


def log_comparison(
    stream: rr.RecordingStream,
    comparison: Comparison,
    scene: SceneData,
    clock: Clock = PLAIN_CLOCK,
    *,
    show_labels: bool = True,
    focus_class: str | None = None,
) -> None:
    """Log ``comparison`` (over keyframes of ``scene``) on the recording's timelines (``clock``): per kind a
    count at every compared frame and, for each tracker's views, marker boxes (an empty batch at frames without
    any), plus the text log. show_labels: show the marker labels (recordings of ``gnnpmb-viz`` do not: which run
    did what is the marker's colour, its words a click away and in the log); focus_class: also log the
    disagreements about this class on their own (``focus_log_path``)."""
    frames = np.asarray(comparison.frame_indices, dtype=np.int64)
    stamps = np.array([scene.keyframes[i].timestamp_us for i in frames.tolist()], dtype=np.int64)
    for kind in DisagreementKind:
        color = KIND_COLORS[kind]
        send_counts(stream, clock, count_path(kind), KIND_LABELS[kind], color, frames, stamps, comparison.counts(kind))
        found = comparison.of_kind(kind)
        if not found:
            continue
        boxes, labels, lengths = _markers(found, comparison.frame_indices)
        for viewer in comparison.trackers:
            send_marker_boxes(
                stream,
                clock,
                markers_path(kind, viewer),
                frames,
                stamps,
                boxes,
                labels,
                lengths,
                color=color,
                scale=MARKER_SCALE,
                margin_m=MARKER_MARGIN_M,
                line_radius_m=MARKER_LINE_RADIUS_M,
                show_labels=show_labels,
            )
    _log_lines(stream, clock, log_path(), comparison.disagreements, scene)
    if focus_class is not None:
        about = [d for d in comparison.disagreements if d.class_name == focus_class]
        _log_lines(stream, clock, focus_log_path(), about, scene)


def _log_lines(
    stream: rr.RecordingStream, clock: Clock, path: str, disagreements: Sequence[Disagreement], scene: SceneData
) -> None:
    """One TextLog line per disagreement, at its frame (nothing if there is none)."""
    if not disagreements:
        return
    at = np.array([d.frame_index for d in disagreements], dtype=np.int64)
    send_text_lines(
        stream,
        clock,
        path,
        at,
        np.array([scene.keyframes[i].timestamp_us for i in at.tolist()], dtype=np.int64),
        [f"{KIND_LABELS[d.kind]}: {d.describe()}" for d in disagreements],
        [KIND_LEVELS[d.kind] for d in disagreements],
    )
