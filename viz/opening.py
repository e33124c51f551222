"""The way into a full recording (no ``--focus``): where it opens, the failure index, lost tracks and one label per
box.

* the **opening**: the first failure worth a look of the first run (``FailureReport.first_worth_opening``, found
  before anything is logged, ``gnnpmb.stages.findings.where_to_open``); the recording opens at its frame (its ``focus``
  timeline ends there, ``viz.timeline.Clock``) and its per-track plots show the tracks around it
  (``viz.blueprint``);
* ``trackers/<run>/failure_index`` (static TextDocument, ``log_failure_index``): every failure with its ``--focus``
  id, association errors first, one object's misses (or one track's false boxes) over consecutive frames on one row;
* ``world/trackers/<run>/lost`` (``log_lost_tracks``): at the frame of an ID switch, identity theft or
  fragmentation, the track that lost the object drawn pale when it is not drawn there itself (often it never was:
  output with too low an existence to be drawn, yet counted by the evaluation): its output box there, else its
  last one where the tracker predicted it (``lost_ghosts``);
* ``LabelNotes``: what a failure or a disagreement says about a drawn track goes into the track's own label at
  that frame (``203 · false track``) and the marker's label stays empty, so two labels never sit on one box.
"""

from __future__ import annotations

from collections import defaultdict
from collections.abc import Mapping, Sequence

import numpy as np
import rerun as rr

from gnnpmb.data.scene import SceneData
from gnnpmb.eval.failures import OPEN_FIRST, Failure, FailureKind, FailureReport, short_id
from gnnpmb.pipeline import TrackingRun
from gnnpmb.types import TrackEstimate
from gnnpmb.why.facts import TrackerFacts
from gnnpmb.why.words import SHOW_MIN_EXISTENCE, consecutive_runs, frames_text
from viz import paths
from viz.colors import faded, pack_rgba, packed_track_colors, readable_text, track_color
from viz.failure_style import KIND_COLORS, KIND_LABELS
from viz.geometry import estimate_boxes
from viz.label_room import CLEARANCE_PX, Candidate, Eye, eyes
from viz.label_size import HEIGHT_PX, width_px
from viz.timeline import FOCUS, FRAME, Clock

LOST_LOOKBACK = 20
"""A lost track is drawn with its last output box of at most this many frames back."""
LOST_KEEP = 0.4
"""A lost track keeps this share of its colour (``colors.faded``)."""
LOST_LINE_RADIUS_M = 0.05
LOST_KINDS = {FailureKind.ID_SWITCH: 0, FailureKind.IDENTITY_THEFT: 1, FailureKind.FRAGMENTATION: 0}
"""The failures that lose a track, and the position of the lost track in ``Failure.track_ids``."""


def lost_tracks(tracker: str) -> str:
    """Boxes3D: the tracks that lost their object, pale, at the failure frames."""
    return f"{paths.tracker_world(tracker)}/lost"


def drawn_tracks(run: TrackingRun) -> dict[tuple[int, int], TrackEstimate]:
    """(frame, track id) -> the estimate the viewer draws as a track (existence at least ``SHOW_MIN_EXISTENCE``)."""
    return {
        (fr.keyframe.index, e.track_id): e
        for fr in run.frames
        for e in fr.estimates
        if e.existence >= SHOW_MIN_EXISTENCE
    }


class LabelNotes:
    """Notes to add to the labels of drawn tracks (and of lost tracks drawn pale, ``lost_ghosts``), per run, frame
    and track (module docstring); ``note`` says whether a note could be placed (the track is drawn there), so the
    caller leaves its own label empty. drawn: per run, ``drawn_tracks``; ghosts: per run, the (frame, track id) of
    its lost tracks drawn pale (``lost_ghosts``); views: the 3D views' cameras the labels are kept apart in
    (``view_eyes``; default ``viz.label_room.eyes()``)."""

    def __init__(
        self,
        drawn: Mapping[str, Mapping[tuple[int, int], TrackEstimate]],
        ghosts: Mapping[str, Mapping[tuple[int, int], tuple[TrackEstimate, tuple[float, float]]]] | None = None,
        views: Sequence[Eye] | None = None,
    ) -> None:
        self.drawn = drawn
        self.ghosts = ghosts or {}
        self.views = views
        self.notes: dict[str, dict[tuple[int, int], list[str]]] = defaultdict(dict)
        self.ghost_notes: dict[str, dict[tuple[int, int], list[str]]] = defaultdict(dict)
        self.ranks: dict[str, dict[tuple[int, int], int]] = defaultdict(dict)
        """Per run, (frame, track id) -> the rank of its most important note (lower first, ``keep_apart``)."""

    def note(self, tracker: str, frame: int, track_id: int, text: str, rank: int = 0) -> bool:
        key = (frame, track_id)
        if key in self.drawn.get(tracker, {}):
            into = self.notes[tracker]
        elif key in self.ghosts.get(tracker, ()):
            into = self.ghost_notes[tracker]
        else:
            return False
        texts = into.setdefault(key, [])
        if text not in texts:
            texts.append(text)
        self.ranks[tracker][key] = min(rank, self.ranks[tracker].get(key, rank))
        return True

    def keep_apart(self, tracker: str, scene: SceneData, others: Sequence[tuple[int, Candidate]] = ()) -> set[object]:
        """Drop the notes of ``tracker`` whose labels would cover a more important one in the bird's-eye view
        (``viz.label_room.keep_apart``), among them and the (frame, label) ``others`` (e.g. failure markers'); their
        tracks keep their boxes, and the words their hover text. Returns the keys of the ``others`` left out."""
        from viz.label_room import keep_apart

        by_frame: dict[int, list[Candidate]] = defaultdict(list)
        for frame, c in others:
            by_frame[frame].append(c)
        left_out: set[object] = set()
        for key, texts in self.notes[tracker].items():
            e = self.drawn[tracker][key]
            text = f"{key[1]} · {'; '.join(texts)}"
            xy = (float(e.translation_m[0]), float(e.translation_m[1]))
            z = float(e.translation_m[2])
            by_frame[key[0]].append(Candidate(self.ranks[tracker][key], ("drawn", key), text, xy, z))
        ghosts = self.ghosts.get(tracker, {})
        for key, texts in self.ghost_notes[tracker].items():
            at = ghosts[key][1]
            text = f"{key[1]} (lost) · {'; '.join(texts)}"
            by_frame[key[0]].append(Candidate(self.ranks[tracker][key], ("ghost", key), text, at))
        for frame, candidates in sorted(by_frame.items()):
            ordered = sorted(candidates, key=lambda c: str(c.key))
            kept = keep_apart(ordered, scene.keyframes[frame].ego_pose, self.views)
            for c in candidates:
                if c.key in kept:
                    continue
                kind, *key = c.key
                if kind == "drawn":
                    self.notes[tracker].pop(key[0])
                elif kind == "ghost":
                    self.ghost_notes[tracker].pop(key[0])
                else:
                    left_out.add(c.key)
        return left_out

    def has(self, tracker: str, frame: int, track_id: int) -> bool:
        """Whether track ``track_id`` of ``tracker`` is drawn (or drawn pale as lost) at ``frame``."""
        key = (frame, track_id)
        return key in self.drawn.get(tracker, {}) or key in self.ghosts.get(tracker, ())

    def send(self, stream: rr.RecordingStream, clock: Clock, scene: SceneData) -> None:
        """Each noted track's label at its noted frames: ``<id> · <note>; <note>`` (one call per track entity), its
        box there in its colour darkened to be read (Rerun writes a label in its box's colour: a pale olive track's
        "13 · ID switch: …" could not be read on the label's pale background, dev set scene-0916 pmbm)."""
        for tracker, notes in self.notes.items():
            by_track: dict[tuple[str, int], list[tuple[int, str]]] = defaultdict(list)
            for (frame, t), texts in sorted(notes.items()):
                e = self.drawn[tracker][(frame, t)]
                by_track[(e.class_name, t)].append((frame, f"{t} · {'; '.join(texts)}"))
            for (class_name, t), rows in by_track.items():
                frames = np.array([f for f, _ in rows], dtype=np.int64)
                stamps = np.array([scene.keyframes[f].timestamp_us for f in frames.tolist()], dtype=np.int64)
                labels = [text for _, text in rows]
                dark = pack_rgba(np.array([readable_text(track_color(t))], dtype=np.uint8))
                clock.send(
                    stream,
                    paths.track(tracker, class_name, t),
                    frames,
                    stamps,
                    lambda sel, labels=labels, dark=dark: rr.Boxes3D.columns(
                        labels=[labels[i] for i in sel],
                        show_labels=np.ones(len(sel), dtype=bool),
                        colors=np.repeat(dark, len(sel)),
                    ),
                )


def failure_notes(tracker: str, failure: Failure, notes: LabelNotes, *, quiet: bool = False) -> set[tuple[str, str]]:
    """Note ``failure`` on the labels of its drawn tracks; returns the (role, id) of its marker boxes whose label is
    then carried by a track (left empty on the marker). quiet: only say which (another failure's note says it, as an
    identity theft does for the ID switch it is)."""
    f, ids = failure.frame_index, failure.track_ids
    gt = short_id(failure.gt_ids[0]) if failure.gt_ids else ""
    merged: set[tuple[str, str]] = set()

    rank = OPEN_FIRST.index(failure.kind)

    def put(role: str, track: str, text: str) -> bool:
        if notes.has(tracker, f, int(track)) if quiet else notes.note(tracker, f, int(track), text, rank):
            merged.add((role, track))
            return True
        return False

    match failure.kind:
        case FailureKind.FALSE_TRACK:
            put("false track", ids[0], "false track")
        case FailureKind.ID_SWITCH:  # one label says both ids: the new track's, else the old one's
            if put("new track", ids[1], f"ID switch, was {ids[0]}"):
                merged.update({("gt", failure.gt_ids[0]), ("old track", ids[0])})
            elif put("old track", ids[0], f"ID switch: GT {gt} went to {ids[1]}"):
                merged.update({("gt", failure.gt_ids[0]), ("new track", ids[1])})
        case FailureKind.IDENTITY_THEFT:
            if put("thief track", ids[0], f"identity theft from {ids[1]}"):
                merged.update({("gt", failure.gt_ids[0]), ("victim track", ids[1])})
            elif put("victim track", ids[1], f"identity theft: GT {gt} went to {ids[0]}"):
                merged.update({("gt", failure.gt_ids[0]), ("thief track", ids[0])})
        case FailureKind.COALESCENCE:
            if put("track", ids[0], f"coalescence: {len(failure.gt_ids)} objects"):
                merged |= {("matched gt", failure.gt_ids[0])} | {("missed gt", g) for g in failure.gt_ids[1:]}
        case FailureKind.FRAGMENTATION:
            if put("track", ids[0], f"fragmentation (GT {gt})"):
                merged.add(("missed gt", failure.gt_ids[0]))
        case FailureKind.MISS:
            pass
    if failure.kind in (FailureKind.ID_SWITCH, FailureKind.IDENTITY_THEFT) and not merged:
        merged = {(b.role, b.object_id) for b in failure.boxes if b.role != "gt"}  # one label: the object's marker
    return merged


def _subject(f: Failure) -> tuple:
    return OPEN_FIRST.index(f.kind), f.class_name, f.gt_ids, f.track_ids


def log_failure_index(
    stream: rr.RecordingStream,
    tracker: str,
    report: FailureReport,
    opening: str | None,
    first_run: bool,
    frames: range | None = None,
) -> None:
    """The failure index of one run (module docstring) over ``frames`` (default all); ``opening``: the failure
    the recording opens at (of the first run; ``first_run``: whether this is it, so its ids open with ``--focus``
    as they are)."""
    stream.log(
        paths.failure_index_doc(tracker),
        rr.TextDocument(index_markdown(tracker, report, opening, first_run, frames), media_type="text/markdown"),
        static=True,
    )


def index_markdown(
    tracker: str, report: FailureReport, opening: str | None, first_run: bool, frames: range | None = None
) -> str:
    """The failure index as markdown (``log_failure_index``)."""
    ids = dict(zip(map(id, report.failures), report.ids(), strict=True))
    kept = [f for f in report.failures if frames is None or f.frame_index in frames]
    total = len(kept)
    within = (
        ""
        if frames is None or len(frames) == len(report.sample_tokens)
        else f", frames {frames.start}–{frames.stop - 1}"
    )
    lines = [f"# {tracker}: {total} failure{'s' if total != 1 else ''} on {report.scene_name}{within}", ""]
    if opening is not None and first_run:
        f = report.by_id(opening)
        lines += [
            f"Opened at frame **{f.frame_index}** on **{opening}**, the first failure worth a look (association "
            f"errors first). The `{FOCUS}` timeline ends there: choose `{FRAME}` in the time panel to step through "
            "the whole scene.",
            "",
        ]
    how = "add `--focus ID` to the command" if first_run else f"give `--tracker {tracker}` first and add `--focus ID`"
    lines += [
        f"To open one with its explanation, {how} that made this recording. Where they are over the scene: the "
        "strip below the views. *interpolated*: the evaluation scored the object at a box it interpolated (it had no "
        "LiDAR or radar points there), often the evaluation's doing.",
        "",
        "| --focus ID | frames | kind | class | tracks | objects |",
        "|---|---|---|---|---|---|",
    ]
    for group in _groups(kept):
        first = group[0]
        span = id_span([ids[id(f)] for f in group])
        if ids[id(first)] == opening and first_run:
            span = f"**{span}** (opened)"
        frames = frames_text(f.frame_index for f in group).split(" ", 1)[1]
        tracks = ", ".join(dict.fromkeys(t for f in group for t in f.track_ids)) or "—"
        objects = ", ".join(f"GT {short_id(g)}" for g in dict.fromkeys(g for f in group for g in f.gt_ids)) or "—"
        if any(f.gt_interpolated for f in group):
            objects += " (interpolated)"
        lines.append(f"| {span} | {frames} | {KIND_LABELS[first.kind]} | {first.class_name} | {tracks} | {objects} |")
    return "\n".join(lines) + "\n"


def id_span(failure_ids: Sequence[str]) -> str:
    """A row's failure ids (``kind:N``, in order) as the index shows them: one id, ``kind:3 … kind:7`` for
    consecutive numbers, else every number (``false_track:3–7, 9, 12``): a row of one track's false boxes can skip
    numbers another track's failures took, and ``3 … 14`` would read as if those were in the row too."""
    if len(failure_ids) == 1:
        return failure_ids[0]
    kind = failure_ids[0].rsplit(":", 1)[0]
    numbers = [int(i.rsplit(":", 1)[1]) for i in failure_ids]
    if numbers == list(range(numbers[0], numbers[-1] + 1)):
        return f"{failure_ids[0]} … {failure_ids[-1]}"
    runs = consecutive_runs(numbers)
    return f"{kind}:" + ", ".join(f"{r[0]}–{r[-1]}" if len(r) > 1 else str(r[0]) for r in runs)


def _groups(failures: Sequence[Failure]) -> list[list[Failure]]:
    """The failures in rows, by ``OPEN_FIRST`` kind, then frame: a miss of one object or a false box of one track
    at consecutive frames joins the row of the frame before."""
    order = sorted(failures, key=lambda f: (_subject(f), f.frame_index))
    rows: list[list[Failure]] = []
    for f in order:
        last = rows[-1][-1] if rows else None
        joins = (
            last is not None
            and f.kind in (FailureKind.MISS, FailureKind.FALSE_TRACK)
            and _subject(last) == _subject(f)
            and f.frame_index == last.frame_index + 1
        )
        if joins:
            rows[-1].append(f)
        else:
            rows.append([f])
    return sorted(rows, key=lambda r: (OPEN_FIRST.index(r[0].kind), r[0].frame_index, r[0].class_name))


def lost_ghosts(
    report: FailureReport, run: TrackingRun, facts: TrackerFacts, frames: Sequence[int]
) -> dict[tuple[int, int], tuple[TrackEstimate, tuple[float, float]]]:
    """(frame, track id) -> (a box of it, BEV centre to draw it at) for the track each ID switch, identity theft
    and fragmentation in ``frames`` lost, when it is not drawn at that frame: its output box there (output with an
    existence too low to be drawn), else its last output box of at most ``LOST_LOOKBACK`` frames back, where the
    tracker predicted it or else where that box was (module docstring)."""
    drawn = drawn_tracks(run)
    output = {(fr.keyframe.index, e.track_id): e for fr in run.frames for e in fr.estimates}
    out: dict[tuple[int, int], tuple[TrackEstimate, tuple[float, float]]] = {}
    for failure in report.failures:
        at = LOST_KINDS.get(failure.kind)
        if at is None or failure.frame_index not in frames:
            continue
        f, t = failure.frame_index, int(failure.track_ids[at])
        if (f, t) in drawn or (f, t) in out:
            continue
        back = range(f, max(-1, f - 1 - LOST_LOOKBACK), -1)
        last = next((output[(j, t)] for j in back if (j, t) in output), None)
        if last is None:
            continue
        xy = (float(last.translation_m[0]), float(last.translation_m[1]))
        step = facts.steps(t, failure.class_name).get(f)
        if (f, t) not in output and step is not None and step.predicted_xy_m is not None:
            xy = step.predicted_xy_m
        out[(f, t)] = (last, xy)
    return out


def log_lost_tracks(
    stream: rr.RecordingStream,
    tracker: str,
    ghosts: Mapping[tuple[int, int], tuple[TrackEstimate, tuple[float, float]]],
    notes: LabelNotes,
    scene: SceneData,
    clock: Clock,
    frames: Sequence[int],
) -> None:
    """The lost tracks (``lost_ghosts``) pale at their failure frames, labelled ``26 (lost) · <notes>``; an empty
    batch at the other keyframes of ``frames`` (nothing when there is none at all). The labels show at a frame only
    when a failure noted one of them there, and only on those (``LabelNotes.keep_apart`` placed them; a lost track
    another label names, as an ID switch's new track does, is a pale box without words)."""
    if not ghosts:
        return
    every = np.array(list(frames), dtype=np.int64)
    stamps = np.array([scene.keyframes[i].timestamp_us for i in every.tolist()], dtype=np.int64)
    rows = [sorted((t, *ghosts[(i, t)]) for (j, t) in ghosts if j == i) for i in every.tolist()]
    flat = [(i, g) for i, row in zip(every.tolist(), rows, strict=True) for g in row]
    boxes = estimate_boxes([e for _, (_, e, _) in flat])
    centers = boxes.centers_m.copy()
    centers[:, :2] = np.array([xy for _, (*_, xy) in flat], dtype=np.float64)
    colors = faded(packed_track_colors(np.array([t for _, (t, *_) in flat], dtype=np.int64)), LOST_KEEP)
    labels, noted = [], set()
    for i, (t, *_) in flat:
        said = notes.ghost_notes.get(tracker, {}).get((i, t), [])
        labels.append(f"{t} (lost) · {'; '.join(said)}" if said else "")  # no note: no words beside the others
        if said:
            noted.add(i)
    shown = np.isin(every, list(noted))
    lengths = np.array([len(r) for r in rows], dtype=np.int64)
    starts = np.concatenate([[0], np.cumsum(lengths)[:-1]])

    def columns(sel: np.ndarray) -> rr.ComponentColumnList:
        idx = np.concatenate([np.arange(starts[r], starts[r] + lengths[r]) for r in sel]).astype(np.int64)
        return rr.Boxes3D.columns(
            centers=centers[idx],
            half_sizes=0.5 * boxes.sizes_xyz_m[idx],
            quaternions=boxes.quat_xyzw[idx],
            colors=colors[idx],
            radii=np.full(idx.size, LOST_LINE_RADIUS_M, dtype=np.float32),
            labels=[labels[i] for i in idx.tolist()],
        ).partition(lengths[sel])

    clock.send(stream, lost_tracks(tracker), every, stamps, columns)
    clock.send(stream, lost_tracks(tracker), every, stamps, lambda sel: rr.Boxes3D.columns(show_labels=shown[sel]))


TIMELINE_KINDS: tuple[FailureKind, ...] = OPEN_FIRST
"""The order of the failure timeline's rows, top to bottom: association errors first (a kind that did not occur
gets no row)."""
TICK_EVERY = 5
"""Frame numbers are written under the failure timeline every this many keyframes."""
LABEL_SPAN = 7.0
"""Least keyframes' worth of room on the left of the failure timeline for the row names (``label_span``)."""
SCENE_COLUMN_PX = 0.9 * 1920 * 3 / 5
"""Width the runs' views share at 1920 px (the scene column, ``viz.blueprint`` 3:2, less a tenth for borders)."""
ROW_PX = HEIGHT_PX + CLEARANCE_PX
"""Height one row of the failure timeline needs: a row name (``viz.label_size``) and air, so names of adjacent rows
never touch."""
VIEW_TITLE_PX = 24.0
"""Height of a view's title bar."""
RUN_COLUMN_PX = {False: 815.0, True: 489.0}
"""Height of one run's views (bird's-eye, perspective and failure timeline) at 1920 x 1080 in a recording of two
runs or more, without and with the camera grid below them: 1019 px under the web viewer's bars, 4/5 of it above
the comparison panel, 3/5 of that above the cameras (``viz.blueprint``; 481 px measured on a screenshot)."""
BELOW_ROWS = 0.9
"""Steps below the last row's centre the failure timeline shows: the frame numbers written 0.8 steps below it,
under their anchor (a name's height)."""
SCENE_SHARES = (6.0, 4.0)
"""Row shares of the bird's-eye and the perspective view above the failure timeline."""
LONGEST_NAME = max(len(f"{name} (999)") for name in KIND_LABELS.values())


def failure_timeline(tracker: str) -> str:
    """2D chart of one run's failures over the scene (``log_failure_timeline``)."""
    return f"{paths.tracker_root(tracker)}/failure_timeline"


def timeline_rows(report: FailureReport, frames: range) -> list[FailureKind]:
    """The kinds with a failure in ``frames``, in ``TIMELINE_KINDS`` order (at least one row)."""
    rows = [k for k in TIMELINE_KINDS if any(f.frame_index in frames for f in report.of_kind(k))]
    return rows or [TIMELINE_KINDS[0]]


def label_span(frames: range, runs: int = 1) -> float:
    """Keyframes' worth of room on the left of the failure timeline for the longest row name ("identity theft
    (999)"), centred there: the view is as wide as the scene column shared by ``runs`` runs and shows the frames
    plus this room, so the room is the name's width over the width left for the frames."""
    text_px = float(width_px(LONGEST_NAME)) + 2.0 * CLEARANCE_PX  # and air either side
    view_px = SCENE_COLUMN_PX / max(runs, 1)
    return max(LABEL_SPAN, text_px * (len(frames) + 0.5) / max(view_px - text_px, text_px))


def strip_share(rows: int, cameras: bool = False) -> float:
    """Row share of the failure timeline beside ``SCENE_SHARES`` that holds its ``rows`` rows ``ROW_PX`` apart (and
    the frame numbers under them, ``timeline_bounds``: rows + 1 + ``BELOW_ROWS`` steps) in the run column's height
    (``RUN_COLUMN_PX``, with or without the camera grid); at least 2."""
    need_px = ROW_PX * (rows + 1 + BELOW_ROWS) + VIEW_TITLE_PX
    column_px = RUN_COLUMN_PX[cameras]
    return max(2.0, sum(SCENE_SHARES) * need_px / max(column_px - need_px, 1.0))


def view_eyes(rows: int, cameras: bool = False, runs: int = 2) -> tuple[Eye, ...]:
    """The default cameras of a full recording's bird's-eye and perspective views with their sizes (content,
    under the title) at 1920 x 1080 above a failure timeline of ``rows`` rows (``strip_share``), ``runs`` side by
    side (3/5 of the width), for the labels' room (``viz.label_room``)."""
    shares = sum(SCENE_SHARES) + strip_share(rows, cameras)
    bev, perspective = (RUN_COLUMN_PX[cameras] * share / shares - VIEW_TITLE_PX for share in SCENE_SHARES)
    return eyes(bev, perspective, 1920 * 3 / 5 / max(runs, 1))


def row_step(frames: range, runs: int = 1) -> float:
    """Units between two rows of the failure timeline. A 2D view shows x and y at one scale, set by its width (the
    frames and ``label_span`` over the run's share of ``SCENE_COLUMN_PX``), so rows one unit apart would be a few
    pixels apart and their names would overlap: rows are ``ROW_PX`` apart at that scale."""
    span = frames.stop + 0.5 - (frames.start - label_span(frames, runs))
    return ROW_PX * span / (SCENE_COLUMN_PX / max(runs, 1))


def timeline_bounds(frames: range, rows: int, runs: int = 1) -> tuple[tuple[float, float], tuple[float, float]]:
    """(x range, y range) the failure timeline's view shows: every frame and row (``row_step`` apart), the row
    names on the left (``label_span``, for ``runs`` runs side by side) and the frame numbers below."""
    step = row_step(frames, runs)
    return (frames.start - label_span(frames, runs), frames.stop + 0.5), (-step, (rows + BELOW_ROWS) * step)


def log_failure_timeline(
    stream: rr.RecordingStream,
    tracker: str,
    report: FailureReport,
    scene: SceneData,
    clock: Clock,
    frames: range,
    opening: str | None = None,
    runs: int = 1,
) -> None:
    """Where a run's failures are over the whole scene, whatever timeline the viewer is on: one row per kind that
    occurred (``timeline_rows``), a dot in the kind's colour at each frame with failures of that kind (larger for
    more), the frame numbers below, the failure the recording opens at boxed, and a cursor at the current frame
    (the only part that moves with time). A time series would show only the frames of the timeline it is on, and
    the one a full recording opens on ends at its opening failure. runs: how many runs' views share the width
    (``label_span``)."""
    root = failure_timeline(tracker)
    kinds = timeline_rows(report, frames)
    step = row_step(frames, runs)
    xs, ys, colors, radii = [], [], [], []
    for row, kind in enumerate(kinds):
        counts = report.counts(kind)
        for f in frames:
            if counts[f]:
                xs.append(f)
                ys.append(row * step)
                colors.append(KIND_COLORS[kind])
                radii.append(0.2 + 0.05 * min(int(counts[f]), 4))
    stream.log(
        f"{root}/failures",
        rr.Points2D(
            np.column_stack([xs, ys]).reshape(-1, 2), colors=np.array(colors, np.uint8).reshape(-1, 3), radii=radii
        ),
        static=True,
    )
    n_of = {k: sum(f.frame_index in frames for f in report.of_kind(k)) for k in kinds}
    stream.log(
        f"{root}/kinds",
        rr.Points2D(
            np.column_stack(
                [np.full(len(kinds), frames.start - label_span(frames, runs) / 2), step * np.arange(len(kinds))]
            ),
            colors=[KIND_COLORS[k] for k in kinds],
            radii=0.01,
            labels=[f"{KIND_LABELS[k]} ({n_of[k]})" for k in kinds],
            show_labels=True,
        ),
        static=True,
    )
    ticks = [f for f in frames if (f - frames.start) % TICK_EVERY == 0]
    stream.log(
        f"{root}/frames",
        rr.Points2D(
            np.column_stack([ticks, np.full(len(ticks), (len(kinds) - 0.2) * step)]),
            colors=[(120, 120, 120)],
            radii=0.01,
            labels=[str(f) for f in ticks],
            show_labels=True,
        ),
        static=True,
    )
    if opening is not None and report.by_id(opening).kind in kinds:
        f = report.by_id(opening)
        stream.log(
            f"{root}/opened",
            rr.Boxes2D(
                centers=[(f.frame_index, kinds.index(f.kind) * step)], half_sizes=[(0.5, 0.45)], colors=[(40, 40, 40)]
            ),
            static=True,
        )
    every = np.array(list(frames), dtype=np.int64)
    stamps = np.array([scene.keyframes[i].timestamp_us for i in every.tolist()], dtype=np.int64)
    top, bottom = -0.6 * step, (len(kinds) - 0.5) * step
    strips = np.stack(
        [np.column_stack([every, np.full(every.size, top)]), np.column_stack([every, np.full(every.size, bottom)])],
        axis=1,
    )
    stream.log(f"{root}/now", rr.LineStrips2D.from_fields(colors=[(90, 90, 90)], radii=[0.04]), static=True)
    clock.send(stream, f"{root}/now", every, stamps, lambda sel: rr.LineStrips2D.columns(strips=strips[sel]))
