"""Tracking failures (``gnnpmb.eval.failures``) as markers in a Rerun recording, to scrub straight to them.

Per failure kind and tracker: the involved ground-truth and track boxes at the failure's frame, drawn a little
larger than the objects in the kind's colour with labels naming the ids (``world/trackers/<tracker>/failures/
<kind>``), and a per-frame count series (``trackers/<tracker>/failures/<kind>``). Every failure is also a line
of one TextLog per tracker (``failure_log``). Everything is sent column-wise: a handful of calls per tracker
however many failures there are.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import TYPE_CHECKING

import numpy as np
import rerun as rr

from gnnpmb.data.scene import SceneData
from gnnpmb.eval.failures import OPEN_FIRST, Failure, FailureBox, FailureKind, FailureReport, short_id
from viz import paths
from viz.failure_style import KIND_COLORS, KIND_LABELS, KIND_LEVELS
from viz.markers import send_counts, send_marker_boxes, send_text_lines
from viz.timeline import PLAIN_CLOCK, Clock

if TYPE_CHECKING:
    from viz.opening import LabelNotes

MARKER_SCALE = 1.1
MARKER_MARGIN_M = 0.3
"""A marker box is the object's box times MARKER_SCALE plus MARKER_MARGIN_M: it encloses the drawn object."""
MARKER_LINE_RADIUS_M = 0.08
FOCUS_MARGIN_M = 0.5
"""In a focus recording, the focused failure's markers are this much wider than other markers of the same box
(an identity theft is also an ID switch of the same objects: its box would hide under the other's)."""


def failure_log(tracker: str) -> str:
    """TextLog of every failure of one tracker (``trackers/<tracker>/failure_log``).

    Not in ``viz/paths.py`` yet; kept beside the failure counts (``paths.failure_count``) but outside their
    ``failures/`` folder, so a time-series view of ``failures/**`` holds only the counts.
    """
    return f"{paths.tracker_root(tracker)}/failure_log"


def failure_label(kind: FailureKind, box: FailureBox) -> str:
    """``ID switch: old track 26``; a role that already names the kind is not repeated (``false track 20``); an
    object is ``GT a1b2c3`` as everywhere else in the viewer (the report's role says ``gt``)."""
    name = short_id(box.object_id) if box.is_gt else box.object_id
    role = f"{box.role[:-2]}GT" if box.is_gt else box.role
    if box.role.startswith(KIND_LABELS[kind]):
        return f"{role} {name}"
    return f"{KIND_LABELS[kind]}: {role} {name}"


def _frame_boxes(
    failures: list[Failure], n_frames: int, merged: Mapping[int, set[tuple[str, str]]] | None = None
) -> tuple[list[FailureBox], list[str], np.ndarray]:
    """The distinct boxes per frame (a box in several failures of one kind and frame is drawn once), their
    labels ("" for a box whose words a track's own label carries: ``merged``, per failure, (role, id)) and (F,)
    boxes per frame."""
    boxes: list[FailureBox] = []
    labels: list[str] = []
    lengths = np.zeros(n_frames, dtype=np.int64)
    seen: set[tuple[int, str, str]] = set()
    for failure in sorted(failures, key=lambda f: f.frame_index):
        carried = (merged or {}).get(id(failure), set())
        for box in failure.boxes:
            key = (failure.frame_index, box.role, box.object_id)
            if key in seen:
                continue
            seen.add(key)
            boxes.append(box)
            labels.append("" if (box.role, box.object_id) in carried else failure_label(failure.kind, box))
            lengths[failure.frame_index] += 1
    return boxes, labels, lengths


def _keep_apart(
    tracker: str,
    drawn: dict[FailureKind, tuple[list[FailureBox], list[str], np.ndarray]],
    notes: LabelNotes,
    scene: SceneData,
) -> None:
    """Blank the marker labels (and drop the track notes, ``LabelNotes.keep_apart``) that would cover a more
    important label of the same frame in the bird's-eye view (``viz.label_room``); markers that miss never show
    theirs."""
    from viz.label_room import Candidate

    markers = []
    for kind, (boxes, labels, lengths) in drawn.items():
        if kind is FailureKind.MISS:
            continue
        frame_of = np.repeat(np.arange(lengths.size), lengths)
        rank = OPEN_FIRST.index(kind)
        for k, (box, text) in enumerate(zip(boxes, labels, strict=True)):
            if text:
                xy = (float(box.translation_m[0]), float(box.translation_m[1]))
                z = float(box.translation_m[2])
                markers.append((int(frame_of[k]), Candidate(rank, ("marker", kind, k), text, xy, z)))
    dropped = notes.keep_apart(tracker, scene, markers)
    for _, kind, k in dropped:
        drawn[kind][1][k] = ""


def log_failures(
    stream: rr.RecordingStream,
    tracker: str,
    report: FailureReport,
    scene: SceneData,
    frame_range: range | None = None,
    clock: Clock = PLAIN_CLOCK,
    *,
    show_labels: bool = True,
    involved: set[str] | None = None,
    focus_kind: FailureKind | None = None,
    notes: LabelNotes | None = None,
) -> None:
    """Log ``report`` (failures of ``tracker`` on ``scene``) on the recording's timelines (``clock``).

    show_labels: show the marker labels (a focus recording labels the involved objects itself); misses never do.
    involved: in a focus recording, the ids (instance tokens, track ids) of the objects the focus is about: the
    markers of other objects are drawn pale, so that another failure at the same frame does not read as this one;
    focus_kind: the focused failure's kind, whose markers are drawn around the others of the same objects
    (``FOCUS_MARGIN_M`` wider) instead of under them. notes: a full recording's ``viz.opening.LabelNotes``: what a
    failure says about a drawn track goes into the track's label, and the marker's label stays empty.
    Boxes of a kind show only at their frame (other frames get an empty batch); the count series has a value
    at every keyframe of ``frame_range`` (default: the whole scene; 0 when nothing failed). Failures outside the
    range are left out.
    """
    if tuple(report.sample_tokens) != tuple(scene.sample_tokens):
        raise ValueError(f"the failure report is for {report.scene_name}, not for the samples of {scene.name}")
    n = len(scene.keyframes)
    stamps = np.array([k.timestamp_us for k in scene.keyframes], dtype=np.int64)
    every_frame = np.arange(n) if frame_range is None else np.array(frame_range, dtype=np.int64)
    in_range = set(every_frame.tolist())
    merged: dict[int, set[tuple[str, str]]] = {}
    if notes is not None:
        from viz.opening import failure_notes

        thefts = {(f.frame_index, f.gt_ids) for f in report.of_kind(FailureKind.IDENTITY_THEFT)}
        for f in report.failures:
            if f.frame_index in in_range:
                quiet = f.kind is FailureKind.ID_SWITCH and (f.frame_index, f.gt_ids) in thefts
                merged[id(f)] = failure_notes(tracker, f, notes, quiet=quiet)
    drawn: dict[FailureKind, tuple[list[FailureBox], list[str], np.ndarray]] = {}
    for kind in FailureKind:
        failures = [f for f in report.of_kind(kind) if f.frame_index in in_range]
        if failures:
            drawn[kind] = _frame_boxes(failures, n, merged)
    if notes is not None:  # the words left on markers and tracks, clear of each other in the bird's-eye view
        _keep_apart(tracker, drawn, notes, scene)
    for kind in FailureKind:
        color = KIND_COLORS[kind]
        send_counts(
            stream,
            clock,
            paths.failure_count(tracker, kind.value),
            KIND_LABELS[kind],
            color,
            every_frame,
            stamps[every_frame],
            report.counts(kind)[every_frame],
        )
        if kind not in drawn:
            continue
        boxes, labels, lengths = drawn[kind]
        send_marker_boxes(
            stream,
            clock,
            paths.failures_world(tracker, kind.value),
            every_frame,
            stamps[every_frame],
            boxes,
            labels,
            lengths[every_frame],
            color=color,
            scale=MARKER_SCALE,
            margin_m=MARKER_MARGIN_M + (FOCUS_MARGIN_M if kind is focus_kind else 0.0),
            line_radius_m=MARKER_LINE_RADIUS_M,
            show_labels=show_labels and kind is not FailureKind.MISS,
            pale=None if involved is None else np.array([b.object_id not in involved for b in boxes], dtype=bool),
        )
    ids = dict(zip(map(id, report.failures), report.ids(), strict=True))
    logged = [f for f in report.failures if f.frame_index in in_range]
    if logged:
        at = np.array([f.frame_index for f in logged], dtype=np.int64)
        send_text_lines(
            stream,
            clock,
            failure_log(tracker),
            at,
            stamps[at],
            [f"[{ids[id(f)]}] {KIND_LABELS[f.kind]}: {f.describe()}" for f in logged],
            [KIND_LEVELS[f.kind] for f in logged],
        )
