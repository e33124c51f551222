"""``TrackerLogger``: an ``EventSink`` that draws one tracker's introspection events in Rerun so a failure can be
explained from the picture.

Per frame and class, from the events alone:

* **which detection went to which track**: a line from each track's predicted position to the detection it was
  given, in the track's colour (``associations``); pairs inside a gate that the solver did not choose as dimmed
  lines (``gated_pairs``); detections are named ``m<idx>`` everywhere (labels, lines, tables, log);
* **why**: the decision view (``viz.decisions``): per conflict the chosen pair, its cost, the best alternative
  and the margin, as a document and as a labelled cost grid with the chosen cells outlined;
* **what happened before**: one entity per extracted track (``tracks/<class>/<id>``: its box and a trail of its
  last ``TRAIL_FRAMES`` positions), per-track series (existence, normalised innovation, chosen cost) and a story
  log per class: confirmed, missed, no longer shown, ended at INFO/WARN; candidates' births and prunings
  aggregated into one DEBUG line per class and frame; close calls at INFO.

Candidate Bernoullis (predicted existence below ``gate_min_existence``, the many births on clutter) get no gate,
no box and no own series: their predicted means go to one hidden-by-default entity per class and their number to
one series per class. Time series are collected and sent column-wise by ``finish()`` (one chunk per series).
Events of one class are buffered and drawn when the frame closes, so every view of a frame is consistent.
"""

from __future__ import annotations

import math
from collections import deque
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np
import rerun as rr

from gnnpmb.events import (
    Assignment,
    AxisKind,
    AxisLabel,
    Born,
    BudgetReached,
    Cardinality,
    CostMatrix,
    Event,
    Extracted,
    FrameStarted,
    Gated,
    GlobalHypotheses,
    IntensityWeights,
    Marginals,
    MeasurementsReceived,
    Merged,
    Posterior,
    Predicted,
    Pruned,
    TrackLogic,
    TrackLogicAction,
    label_positions,
)
from gnnpmb.explain import Decisions, explain
from gnnpmb.gating import ellipse_outline
from gnnpmb.types import TrackEstimate
from viz import paths
from viz.colors import (
    CLASS_COLORS,
    CLASS_IDS,
    faded,
    involved_track_colors,
    pack_rgba,
    packed_track_colors,
    track_color,
)
from viz.decisions import (
    CLOSE_CALL_MARGIN,
    column_name,
    cost_colors,
    decision_grid,
    decisions_markdown,
    existence_text,
    meas_name,
)
from viz.geometry import estimate_boxes, lift_xy
from viz.rows import Build, EntityRows, RowBuffer, send_entities
from viz.timeline import PLAIN_CLOCK, Clock

TRACK_LINE_RADIUS_M = 0.06
TRAIL_RADIUS_M = 0.05
TRAIL_FRAMES = 10
"""A track's trail shows its positions over the last this many frames."""
ASSOCIATION_RADIUS_M = 0.07
GATED_PAIR_RADIUS_M = 0.025
GATED_PAIR_KEEP = 0.45
"""Lines from a track to a detection inside its gate that it was not given keep this share of the track's colour
(``colors.faded``): faint beside the chosen pairs."""
DIMMED_KEEP = 0.3
"""In a focus recording, the tracks not involved (their boxes, trails, gates, predictions and association lines)
keep this share of their colour, so the involved ones stand out."""
GATE_LINE_RADIUS_M = 0.03
PREDICTED_POINT_RADIUS_M = 0.25
CANDIDATE_POINT_RADIUS_M = 0.12
SERIES_MARKER_SIZE = 3.0
"""Marker size of the samples of an involved track's series (a track born at the focus frame has one sample:
a line alone would not show it)."""
MAX_HYPOTHESIS_SERIES = 10
"""Log weights are plotted for the best this many PMBM global hypotheses."""
CHOSEN_CELL_RGBA = int(pack_rgba(np.array([[255, 210, 0]], dtype=np.uint8))[0])
THRESHOLD_COLOR = (150, 150, 150)
SHOW_MIN_EXISTENCE = 0.5
"""Extracted tracks are drawn as tracks (own entity, box, trail, story, series) from this existence on. The
submission may hold far less likely Bernoullis (a low extraction threshold with score = detection score x
existence helps AMOTA); drawing them all would bury the picture (and the viewer in chunks)."""
FLUSH_FRAMES = 10
"""Default cadence: story lines and spatial rows are sent column-wise every this many frames (and at the end),
so a live viewer sees them within seconds; a saved recording passes ``flush_frames=None`` (only at the end: one
chunk per entity)."""
_STATIC_ROW = np.zeros(1, dtype=np.int64)
"""The one row of static data (``viz.rows.send_entities(static=True)`` ignores its time)."""
CANDIDATE_COLOR = int(pack_rgba(np.array([[160, 160, 160]], dtype=np.uint8))[0])

_LEVEL_BY_ACTION = {
    TrackLogicAction.TENTATIVE: "DEBUG",
    TrackLogicAction.CONFIRMED: "INFO",
    TrackLogicAction.DELETED: "WARN",
}


@dataclass(slots=True)
class _Series:
    """One scalar time series being collected: frame indices, timestamps (us), values, and its style."""

    name: str
    color: tuple[int, int, int] | None
    frames: list[int] = field(default_factory=list)
    timestamps_us: list[int] = field(default_factory=list)
    values: list[float] = field(default_factory=list)


@dataclass(frozen=True, slots=True)
class TrackStep:
    """One focused track at one frame: predicted existence and BEV position, the detections inside its gate with
    their NIS, the detection it was given (-1: none), its existence after the update (NaN if gone) and
    whether it was reported."""

    prior_existence: float
    predicted_xy_m: tuple[float, float]
    gated: tuple[tuple[int, float], ...]
    given: int
    posterior_existence: float
    reported: bool


@dataclass(slots=True)
class _ClassFrame:
    """The events of one class in the current frame, drawn together when the frame closes."""

    meas: MeasurementsReceived | None = None
    predicted: Predicted | None = None
    gated: Gated | None = None
    costs: dict[int, CostMatrix] = field(default_factory=dict)
    assignment: Assignment | None = None
    born: list[Born] = field(default_factory=list)
    pruned: list[Pruned] = field(default_factory=list)
    merged: list[Merged] = field(default_factory=list)
    logic: list[TrackLogic] = field(default_factory=list)
    posterior: Posterior | None = None
    extracted: Extracted | None = None
    hypotheses: GlobalHypotheses | None = None

    @property
    def cost(self) -> CostMatrix | None:
        """The cost matrix the frame's assignment was chosen over: that of the assignment's prior hypothesis (PMBM's
        best posterior may come from another prior hypothesis than the first); hypothesis 0's without one."""
        return self.costs.get(self.assignment.hypothesis if self.assignment is not None else 0)


class TrackerLogger:
    """An ``EventSink`` logging one tracker's events to ``stream`` under that tracker's entity paths.

    gate_z_m: height at which gates, lines and predicted means of tracks with no known box height are drawn
    (global z). gate_points: vertices per gate ellipse. log_predicted: draw the predicted means.
    gate_min_existence: tracks whose predicted existence reaches it are drawn (gate, prediction, gated pairs);
    the others are candidates. show_min_existence: extracted tracks below it are not drawn as tracks (focused
    tracks always are). clock: the timelines rows go on (``viz.timeline``). log_frames: draw and log
    only these keyframes (None: all); the others still feed the tracks' history (trails, series, story state).
    focus_tracks: their conflicts come first in the decision view, and they take distinct colours
    (``colors.involved_track_colors``, away from the colour of ``focus_class``, their class). flush_frames: send
    buffered rows every this many frames (None: only at the end). has_existence: False for a tracker whose
    tracks have no existence probability (``registry.tracker_has_existence``; its events carry 1): no existence
    series (flat lines at 1, a chunk pair per track) and no existence in the story. Call ``finish()`` after the
    last frame: it sends what is buffered and the time series.
    """

    enabled = True

    def __init__(
        self,
        stream: rr.RecordingStream,
        tracker_name: str,
        *,
        gate_z_m: float = 0.0,
        gate_points: int = 32,
        log_predicted: bool = True,
        gate_min_existence: float = 0.1,
        show_min_existence: float = SHOW_MIN_EXISTENCE,
        clock: Clock = PLAIN_CLOCK,
        log_frames: range | None = None,
        focus_tracks: set[int] | None = None,
        flush_frames: int | None = FLUSH_FRAMES,
        has_existence: bool = True,
        focus_class: str | None = None,
    ) -> None:
        paths.tracker_root(tracker_name)  # rejects names that cannot be an entity-path segment
        self.stream = stream
        self.tracker = tracker_name
        self.gate_z_m = gate_z_m
        self.gate_points = gate_points
        self.log_predicted = log_predicted
        self.gate_min_existence = gate_min_existence
        self.show_min_existence = show_min_existence
        self.clock = clock
        self.log_frames = log_frames
        self.focus_tracks = focus_tracks
        self.flush_frames = flush_frames
        self.has_existence = has_existence
        self.involved_rgb = involved_track_colors(focus_tracks or (), CLASS_COLORS.get(focus_class or ""))
        """Focus track id -> its RGB (``colors.involved_track_colors``), in every view and plot."""
        packed = pack_rgba(np.array(list(self.involved_rgb.values()), dtype=np.uint8).reshape(-1, 3))
        self._involved_packed = dict(zip(self.involved_rgb, packed.tolist(), strict=True))
        self._rows = RowBuffer(stream, clock)
        self._buffered: set[str] = set()
        self._drawing = True
        self.has_gates = False
        """Whether the tracker gates (a ``Gated`` event came): greedy matches within a distance instead."""
        self.decisions: dict[int, list[Decisions]] = {}
        """Frame index -> the decisions of every class (kept for the focus view and tests)."""
        self.given: dict[int, dict[int, str]] = {}
        """Frame -> detection index -> where it went ("track 12", "new"), for the focus tracks' class only."""
        self.track_steps: dict[int, dict[int, TrackStep]] = {}
        """Focused track id -> frame -> its ``TrackStep`` (only for ``focus_tracks``)."""
        self.story: list[tuple[int, str, str, str]] = []
        """Every story line logged: (frame, class, text, level)."""
        self.sent_series: dict[str, tuple[np.ndarray, np.ndarray]] = {}
        """With ``focus_tracks``: series path -> (K,) frames and (K,) values of every time series ``finish`` sent
        (the focus view places its plots' legends from them)."""
        self._frame = -1  # current keyframe index; -1 before the first FrameStarted
        self._timestamp_us = 0
        self._live: set[str] = set()
        self._touched: set[str] = set()
        self._classes: dict[str, _ClassFrame] = {}
        self._texts: dict[str, tuple[list[int], list[int], list[str], list[str]]] = {}
        self._frames_since_text_flush = 0
        self._series: dict[str, _Series] = {}
        self._multi: dict[str, tuple[list[str], list[int], list[int], list[np.ndarray]]] = {}
        self._track_z: dict[int, float] = {}
        self._trails: dict[int, deque[tuple[float, float, float]]] = {}
        self._reported: set[int] = set()  # tracks extracted in the previous frame
        self._extracted_ids: set[int] = set()  # tracks extracted at least once
        self._track_series: dict[str, tuple[str, int]] = {}  # series path -> (class, track id)
        self._track_paths: dict[tuple[Callable, str, int], str] = {}  # (paths function, class, track id) -> path
        self._handlers: dict[type, Callable] = {
            FrameStarted: self._on_frame_started,
            MeasurementsReceived: self._store("meas"),
            Predicted: self._store("predicted"),
            Gated: self._on_gated,
            CostMatrix: self._on_cost,
            Assignment: self._on_assignment,
            Born: self._append("born"),
            Posterior: self._store("posterior"),
            Pruned: self._append("pruned"),
            Extracted: self._store("extracted"),
            GlobalHypotheses: self._on_hypotheses,
            Marginals: self._on_marginals,
            Merged: self._append("merged"),
            Cardinality: self._on_cardinality,
            IntensityWeights: self._on_intensity,
            TrackLogic: self._append("logic"),
            BudgetReached: self._on_budget,
        }

    @property
    def reported_ever(self) -> set[int]:
        """Ids of the tracks output at least once so far (the others are candidates)."""
        return self._extracted_ids

    def emit(self, event: Event) -> None:
        handler = self._handlers.get(type(event))
        if handler is None:
            raise TypeError(f"TrackerLogger cannot log {type(event).__name__}")
        if self._frame < 0 and not isinstance(event, FrameStarted):
            raise RuntimeError(f"{type(event).__name__} emitted outside a frame (before FrameStarted or after finish)")
        handler(event)

    def finish(self) -> None:
        """End the last frame and send every collected time series (column-wise). Safe to call twice."""
        if self._frame >= 0:
            self._close_frame()
            self._frame = -1
        self._flush_texts()
        self._rows.flush()
        scalars: list[EntityRows] = []
        styles: list[EntityRows] = []
        one = np.ones(1, dtype=np.int64)
        for path, series in self._series.items():
            owner = self._track_series.get(path)
            if owner is not None and owner[1] not in self._extracted_ids and owner[1] not in self._focused:
                continue  # a candidate's series: only the per-class candidate count is kept
            style = {"names": ([series.name], one)}
            if series.color is not None:
                style["colors"] = (np.array([series.color], dtype=np.uint8), one)
            styles.append(EntityRows(path, _STATIC_ROW, _STATIC_ROW, style))
            if owner is not None and owner[1] in self._focused:  # an involved track: a marker at every sample
                marked = rr.SeriesPoints(
                    names=series.name, colors=series.color, markers="circle", marker_sizes=SERIES_MARKER_SIZE
                )
                self.stream.log(path, marked, static=True)  # a handful of series: one call each is cheap
            values = np.asarray(series.values, dtype=np.float64)
            if self.focus_tracks:
                self.sent_series[path] = (np.asarray(series.frames), values)
            scalars.append(
                EntityRows(path, np.asarray(series.frames), np.asarray(series.timestamps_us), _one_per_row(values))
            )
        for path, (names, frames, stamps, values) in self._multi.items():
            styles.append(EntityRows(path, _STATIC_ROW, _STATIC_ROW, {"names": (names, np.array([len(names)]))}))
            stacked = np.stack(values)
            lengths = np.full(stacked.shape[0], stacked.shape[1], dtype=np.int64)
            scalars.append(
                EntityRows(path, np.asarray(frames), np.asarray(stamps), {"scalars": (stacked.ravel(), lengths)})
            )
        send_entities(self.stream, self.clock, rr.SeriesLines, styles, static=True)
        send_entities(self.stream, self.clock, rr.Scalars, scalars)
        self._series.clear()
        self._track_series.clear()
        self._track_paths.clear()
        self._multi.clear()

    # Event intake.
    def _store(self, name: str) -> Callable[[Event], None]:
        def handler(event: Event) -> None:
            setattr(self._class_frame(event.class_name), name, event)

        return handler

    def _append(self, name: str) -> Callable[[Event], None]:
        def handler(event: Event) -> None:
            getattr(self._class_frame(event.class_name), name).append(event)

        return handler

    def _class_frame(self, class_name: str) -> _ClassFrame:
        cf = self._classes.get(class_name)
        if cf is None:
            cf = self._classes[class_name] = _ClassFrame()
        return cf

    def _on_gated(self, event: Gated) -> None:
        self.has_gates = True
        self._class_frame(event.class_name).gated = event

    def _on_cost(self, event: CostMatrix) -> None:
        self._class_frame(event.class_name).costs[event.hypothesis] = event

    def _on_assignment(self, event: Assignment) -> None:
        self._class_frame(event.class_name).assignment = event

    # Frame bookkeeping.
    def _on_frame_started(self, event: FrameStarted) -> None:
        if self._frame >= 0:
            self._close_frame()
        self._frame = event.frame_index
        self._timestamp_us = event.timestamp_us
        self._drawing = self.log_frames is None or event.frame_index in self.log_frames
        self.clock.set(self.stream, event.frame_index, event.timestamp_us)

    def _close_frame(self) -> None:
        """Draw the frame's classes, the decision view and the story lines; clear what was drawn last frame but
        not in this one."""
        self.clock.set(self.stream, self._frame, self._timestamp_us)
        reported: set[int] = set()
        decisions: list[Decisions] = []
        matrices: dict[str, CostMatrix] = {}
        fallbacks: list[CostMatrix] = []
        hypotheses = [cf.hypotheses for cf in self._classes.values() if cf.hypotheses is not None]
        for class_name, cf in self._classes.items():
            reported |= self._draw_class(class_name, cf)
            if self._drawing and cf.cost is not None and cf.assignment is not None:
                d = explain(cf.cost, cf.assignment)
                if d is None:
                    fallbacks.append(cf.cost)
                else:
                    decisions.append(d)
                    matrices[class_name] = cf.cost
                    self._story_close_calls(d, _born_tracks(cf))
        self._reported = reported
        self._classes = {}
        if decisions or fallbacks:
            self.decisions[self._frame] = decisions
            self._draw_decisions(decisions, matrices, fallbacks, hypotheses)
        if self._drawing:
            for path in sorted(self._live - self._touched):
                if path in self._buffered:
                    self._rows.clear(path, self._frame, self._timestamp_us)
                else:
                    self.stream.log(path, rr.Clear(recursive=False))
            self._live = self._touched
        self._touched = set()
        self._frames_since_text_flush += 1
        if self.flush_frames is not None and self._frames_since_text_flush >= self.flush_frames:
            self._flush_texts()
            self._rows.flush()

    def _flush_texts(self) -> None:
        logs = [
            EntityRows(
                path,
                np.asarray(frames),
                np.asarray(stamps),
                {
                    "text": (texts, np.ones(len(texts), dtype=np.int64)),
                    "level": (levels, np.ones(len(levels), dtype=np.int64)),
                },
            )
            for path, (frames, stamps, texts, levels) in self._texts.items()
        ]
        send_entities(self.stream, self.clock, rr.TextLog, logs)
        self._texts.clear()
        self._frames_since_text_flush = 0

    def _show(self, path: str, *archetypes: rr.AsComponents) -> None:
        if not self._drawing:
            return
        for archetype in archetypes:
            self.stream.log(path, archetype)
        self._touched.add(path)

    def _put(
        self, path: str, archetype: type, n: int, static: dict | None = None, build: Build | None = None, **fields
    ) -> None:
        """A buffered row of ``n`` instances on ``path`` (see ``viz.rows``)."""
        if not self._drawing:
            return
        self._rows.put(path, archetype, self._frame, self._timestamp_us, n, static, build, **fields)
        self._buffered.add(path)
        self._touched.add(path)

    def _text(self, class_name: str, text: str, level: str) -> None:
        if not self._drawing:
            return
        self.story.append((self._frame, class_name, text, level))
        frames, stamps, texts, levels = self._texts.setdefault(paths.events(self.tracker, class_name), ([], [], [], []))
        frames.append(self._frame)
        stamps.append(self._timestamp_us)
        texts.append(text)
        levels.append(level)

    def _sample(self, path: str, value: float, name: str = "", color: tuple[int, int, int] | None = None) -> None:
        """Append one point to a time series at the current frame (a repeat in the same frame replaces it);
        nothing after the last of ``log_frames``."""
        if self.log_frames is not None and self._frame >= self.log_frames.stop:
            return
        series = self._series.get(path)
        if series is None:
            series = self._series[path] = _Series(name or path.rsplit("/", 1)[-1], color)
        if series.frames and series.frames[-1] == self._frame:
            series.values[-1] = float(value)
            return
        series.frames.append(self._frame)
        series.timestamps_us.append(self._timestamp_us)
        series.values.append(float(value))

    def _track_sample(
        self, series: Callable[[str, str, int], str], class_name: str, track_id: int, value: float, what: str
    ) -> None:
        """A sample of one track's series (``series``: its ``viz.paths`` function); paths are built once."""
        key = (series, class_name, track_id)
        path = self._track_paths.get(key)
        if path is None:
            path = self._track_paths[key] = series(self.tracker, class_name, track_id)
            self._track_series.setdefault(path, (class_name, track_id))
        if path in self._series:  # name and colour only matter for a new series
            self._sample(path, value)
        else:
            color = self.involved_rgb.get(track_id) or track_color(track_id)
            self._sample(path, value, f"{track_id} {class_name} {what}", color)

    def _z_of(self, track_ids: np.ndarray) -> np.ndarray:
        """(K,) last known box height of each track, gate_z_m for tracks never extracted."""
        z_of, default = self._track_z.get, self.gate_z_m
        return np.array([z_of(t, default) for t in np.asarray(track_ids).tolist()], dtype=np.float64)

    # One class, one frame.
    def _draw_class(self, class_name: str, cf: _ClassFrame) -> set[int]:
        """Draw one class's frame; returns the ids of its extracted tracks."""
        focus = self.focus_tracks or set()
        extracted = cf.extracted.estimates if cf.extracted is not None else ()
        estimates = tuple(e for e in extracted if e.existence >= self.show_min_existence)
        drawn = estimates + tuple(e for e in extracted if e.existence < self.show_min_existence and e.track_id in focus)
        if self.has_existence and cf.extracted is not None and cf.posterior is not None:
            self._sample(
                paths.extraction_threshold(self.tracker, class_name),
                max(cf.extracted.threshold, self.show_min_existence),
                f"{class_name} shown as a track above",
                THRESHOLD_COLOR,
            )
        for e in drawn:
            self._track_z[e.track_id] = float(e.translation_m[2])
        worthy = self._draw_prior(class_name, cf)
        self._draw_associations(class_name, cf, worthy)
        self._record_posterior(class_name, cf)
        if self.focus_tracks:
            self._record_steps(cf, estimates)
        self._story(class_name, cf, estimates)
        self._draw_tracks(class_name, drawn, {e.track_id for e in estimates})
        return {e.track_id for e in estimates}

    def _draw_prior(self, class_name: str, cf: _ClassFrame) -> set[int]:
        """Predicted means (tracks vs candidates) and gates; returns the ids of the tracks worth a gate."""
        if cf.predicted is None:
            return set()
        ids = np.asarray(cf.predicted.track_ids, dtype=np.int64)
        existence = np.asarray(cf.predicted.existence, dtype=np.float64)
        focused = np.isin(ids, list(self.focus_tracks)) if self.focus_tracks else np.zeros(ids.size, dtype=bool)
        worthy = (existence >= self.gate_min_existence) | focused
        xy = np.asarray(cf.predicted.mean, dtype=np.float64).reshape(-1, 4)[:, :2]
        if self.log_predicted:
            for path, sel in (
                (paths.predicted(self.tracker, class_name), np.flatnonzero(worthy & ~focused)),
                (paths.predicted_focus(self.tracker, class_name), np.flatnonzero(focused)),
            ):
                if sel.size == 0:
                    continue
                self._put(
                    path,
                    rr.Points3D,
                    sel.size,
                    static={"show_labels": False},
                    build=self._predicted_points,
                    xy=xy[sel],
                    z=self._z_of(ids[sel]),
                    ids=ids[sel],
                    existence=existence[sel],
                )
        if (~worthy).any():
            sel = np.flatnonzero(~worthy)
            self._put(
                paths.candidates_world(self.tracker, class_name),
                rr.Points3D,
                sel.size,
                static={"show_labels": False},
                build=self._candidate_points,
                xy=xy[sel],
                ids=ids[sel],
                existence=existence[sel],
            )
        if self.has_existence:  # a track-logic tracker has no candidates (every existence is 1)
            self._sample(
                paths.candidate_count(self.tracker, class_name), float((~worthy).sum()), f"{class_name} candidates"
            )
        gated = cf.gated
        if gated is not None:
            gids = np.asarray(gated.track_ids, dtype=np.int64)
            id_list = ids.tolist()
            if np.array_equal(gids, ids) and len(set(id_list)) == len(id_list):  # the usual case: same tracks
                drawn = worthy
            else:
                lookup = dict(zip(id_list, worthy.tolist(), strict=True))  # focused tracks count as worthy
                drawn = np.array([lookup.get(t, True) for t in gids.tolist()], dtype=bool)
            if drawn.any():
                n = int(drawn.sum())
                self._put(
                    paths.gates(self.tracker, class_name),
                    rr.LineStrips3D,
                    n,
                    build=self._gate_outlines,
                    center_xy=np.asarray(gated.center_xy, dtype=np.float64)[drawn],
                    cov=np.asarray(gated.innovation_cov, dtype=np.float64)[drawn],
                    threshold=np.full(n, gated.threshold, dtype=np.float64),
                    z=self._z_of(gids[drawn]),
                    ids=gids[drawn],
                )
            return set(gids[drawn].tolist())
        return set(ids[worthy].tolist())

    # Row builders (``viz.rows.Build``): the elementwise part of drawing, run once per entity over all its rows.
    def _predicted_points(self, raw: dict[str, np.ndarray]) -> dict[str, object]:
        """Points3D of predicted means: xy (N, 2) at height z (N,), coloured by track, labelled with existence."""
        n = raw["ids"].size
        return {
            "positions": lift_xy(raw["xy"], raw["z"]),
            "colors": self._track_colors(raw["ids"]),
            "radii": np.full(n, PREDICTED_POINT_RADIUS_M, dtype=np.float32),
            "labels": _labels("%d predicted r=%.2f", raw["ids"], raw["existence"]),
        }

    def _candidate_points(self, raw: dict[str, np.ndarray]) -> dict[str, object]:
        """Points3D of candidates' predicted means (N, 2), grey, at ``gate_z_m``."""
        n = raw["ids"].size
        return {
            "positions": lift_xy(raw["xy"], self.gate_z_m),
            "colors": np.full(n, CANDIDATE_COLOR, dtype=np.uint32),
            "radii": np.full(n, CANDIDATE_POINT_RADIUS_M, dtype=np.float32),
            "labels": _labels("candidate %d, r=%.3f", raw["ids"], raw["existence"]),
        }

    def _gate_outlines(self, raw: dict[str, np.ndarray]) -> dict[str, object]:
        """LineStrips3D of gate ellipses {z : (z - c)^T S^-1 (z - c) = threshold} (``ellipse_outline``) of
        centres (N, 2) and innovation covariances S (N, 2, 2), at height z (N,), in the track's colour."""
        n = raw["ids"].size
        outline = np.empty((n, self.gate_points + 1, 2), dtype=np.float64)
        for threshold in np.unique(raw["threshold"]).tolist():
            rows = raw["threshold"] == threshold
            outline[rows] = ellipse_outline(raw["center_xy"][rows], raw["cov"][rows], threshold, self.gate_points)
        return {
            "strips": lift_xy(outline, raw["z"][:, None]),
            "colors": self._track_colors(raw["ids"]),
            "radii": np.full(n, GATE_LINE_RADIUS_M, dtype=np.float32),
        }

    def _association_lines(self, raw: dict[str, object]) -> dict[str, object]:
        """LineStrips3D of chosen pairs: lines (N, 2, 3) in their tracks' colours (ids (N,)), labelled."""
        n = len(raw["labels"])
        return {
            "strips": raw["lines"],
            "colors": self._track_colors(raw["ids"]),
            "radii": np.full(n, ASSOCIATION_RADIUS_M, dtype=np.float32),
            "labels": raw["labels"],
        }

    def _gated_pair_lines(self, raw: dict[str, object]) -> dict[str, object]:
        """LineStrips3D of gated pairs not chosen: lines (N, 2, 3), faint (``GATED_PAIR_KEEP``), labelled."""
        n = len(raw["labels"])
        return {
            "strips": raw["lines"],
            "colors": self._track_colors(raw["ids"], GATED_PAIR_KEEP),
            "radii": np.full(n, GATED_PAIR_RADIUS_M, dtype=np.float32),
            "labels": raw["labels"],
        }

    def _draw_associations(self, class_name: str, cf: _ClassFrame, worthy: set[int]) -> None:
        """Chosen (track, detection) lines in the track's colour, gated-but-rejected ones dimmed; per-track NIS
        and chosen-cost samples."""
        if cf.meas is None or cf.predicted is None or cf.assignment is None:
            return
        pos = {m: k for k, m in enumerate(np.asarray(cf.meas.meas_indices, dtype=np.int64).tolist())}
        xyz = np.asarray(cf.meas.xyz_m, dtype=np.float64).reshape(-1, 3)
        pred_row = {t: k for k, t in enumerate(np.asarray(cf.predicted.track_ids, dtype=np.int64).tolist())}
        pred_xy = np.asarray(cf.predicted.mean, dtype=np.float64).reshape(-1, 4)[:, :2]
        cost_of = _pair_cost_lookup(cf.cost)
        pairs = [
            (int(col.ref), int(row.ref))
            for row, col in cf.assignment.pairs
            if col.kind is AxisKind.TRACK and row.ref in pos and col.ref in pred_row
        ]
        if pairs:
            owners = [t for t, _ in pairs]
            meas_rows = np.array([pos[m] for _, m in pairs], dtype=np.int64)
            nis = _nis_of(cf.gated, owners, xyz[meas_rows, :2])
            labels = []
            for (t, m), nis_tm in zip(pairs, nis, strict=True):
                cost = cost_of(m, t)
                labels.append(f"{meas_name(m)} → {t} (cost {cost:.2f})")
                self._track_sample(paths.chosen_cost, class_name, t, cost, "chosen cost")
                if nis_tm is not None:
                    self._track_sample(paths.nis, class_name, t, nis_tm, "NIS")
            self._put(
                paths.associations(self.tracker, class_name),
                rr.LineStrips3D,
                len(pairs),
                static={"show_labels": False},
                build=self._association_lines,
                lines=_pair_lines(pred_xy, [pred_row[t] for t in owners], xyz, meas_rows),
                ids=np.array(owners, dtype=np.int64),
                labels=labels,
            )
        gated = cf.gated
        if gated is None:
            return
        chosen = set(pairs)
        gids = np.asarray(gated.track_ids, dtype=np.int64).tolist()
        gmeas = np.asarray(gated.meas_indices, dtype=np.int64).tolist()
        drawn = np.array([t in worthy for t in gids], dtype=bool).reshape(-1, 1)
        rows, cols = np.nonzero(np.asarray(gated.inside, dtype=bool) & drawn)  # candidates' gates are not drawn
        rejected = [
            (gids[k], gmeas[j])
            for k, j in zip(rows.tolist(), cols.tolist(), strict=True)
            if (gids[k], gmeas[j]) not in chosen and gmeas[j] in pos
        ]
        if rejected:
            rowners = [t for t, _ in rejected]
            self._put(
                paths.gated_pairs(self.tracker, class_name),
                rr.LineStrips3D,
                len(rejected),
                static={"show_labels": False},
                build=self._gated_pair_lines,
                lines=_pair_lines(
                    pred_xy, [pred_row[t] for t in rowners], xyz, np.array([pos[m] for _, m in rejected])
                ),
                ids=np.array(rowners, dtype=np.int64),
                labels=[f"{meas_name(m)} in gate of {t}, not chosen (cost {cost_of(m, t):.2f})" for t, m in rejected],
            )

    def _record_posterior(self, class_name: str, cf: _ClassFrame) -> None:
        """Existence samples and trail points of the Bernoullis worth following (r >= gate_min_existence,
        already reported, or focused); candidates only count."""
        post = cf.posterior
        if post is None:
            return
        ids = np.asarray(post.track_ids, dtype=np.int64)
        existence = np.asarray(post.existence, dtype=np.float64)
        mean = np.asarray(post.mean, dtype=np.float64).reshape(-1, 4)
        reported, focused = self._extracted_ids, self._focused
        id_list, r_list = ids.tolist(), existence.tolist()
        follow = [
            k
            for k, (t, r) in enumerate(zip(id_list, r_list, strict=True))
            if r >= self.gate_min_existence or t in reported or t in focused
        ]
        xy = mean[follow, :2].tolist()
        for k, (x, y) in zip(follow, xy, strict=True):
            t = id_list[k]
            if self.has_existence:
                self._track_sample(paths.existence, class_name, t, r_list[k], "existence")
            trail = self._trails.get(t)
            if trail is None:
                trail = self._trails[t] = deque(maxlen=TRAIL_FRAMES)
            trail.append((x, y, self._track_z.get(t, self.gate_z_m)))

    def _record_steps(self, cf: _ClassFrame, estimates: tuple[TrackEstimate, ...]) -> None:
        """The frame's ``TrackStep`` of every focused track this class predicted."""
        if cf.predicted is None:
            return
        ids = np.asarray(cf.predicted.track_ids, dtype=np.int64).tolist()
        mean = np.asarray(cf.predicted.mean, dtype=np.float64).reshape(-1, 4)
        prior_r = np.asarray(cf.predicted.existence, dtype=np.float64)
        post = {}
        if cf.posterior is not None:
            post = dict(
                zip(
                    np.asarray(cf.posterior.track_ids).tolist(),
                    np.asarray(cf.posterior.existence).tolist(),
                    strict=True,
                )
            )
        given = {}
        if cf.assignment is not None:
            given = {int(c.ref): int(r.ref) for r, c in cf.assignment.pairs if c.kind is AxisKind.TRACK}
        reported = {e.track_id for e in estimates}
        if cf.assignment is not None:
            born = _born_tracks(cf)  # a focused track started this frame was not predicted, but its detection counts
            if any(t in self.focus_tracks for t in (*ids, *born.values())):
                self.given[self._frame] = {
                    int(r.ref): destination(c, born.get(int(r.ref))) for r, c in cf.assignment.pairs
                }
        meas_xy = {}
        if cf.meas is not None:
            xyz = np.asarray(cf.meas.xyz_m, dtype=np.float64).reshape(-1, 3)
            meas_xy = {int(m): xyz[k, :2] for k, m in enumerate(np.asarray(cf.meas.meas_indices).tolist())}
        for k, t in enumerate(ids):
            if t not in self.focus_tracks:
                continue
            gated: list[tuple[int, float]] = []
            if cf.gated is not None:
                g = np.flatnonzero(np.asarray(cf.gated.track_ids) == t)
                if g.size:
                    inside = np.asarray(cf.gated.inside, dtype=bool)[g[0]]
                    for j in np.flatnonzero(inside).tolist():
                        m = int(np.asarray(cf.gated.meas_indices)[j])
                        nis = _nis_of(cf.gated, [t], meas_xy[m][None, :])[0] if m in meas_xy else math.nan
                        gated.append((m, float(nis) if nis is not None else math.nan))
            self.track_steps.setdefault(t, {})[self._frame] = TrackStep(
                float(prior_r[k]),
                (float(mean[k, 0]), float(mean[k, 1])),
                tuple(gated),
                given.get(t, -1),
                float(post.get(t, math.nan)),
                t in reported,
            )

    def _track_colors(self, track_ids: np.ndarray, keep: float = 1.0) -> np.ndarray:
        """(N,) packed colours of (N,) track ids, ``keep`` of each colour (``colors.faded``); with focus tracks,
        those take their involved colour (``involved_rgb``) and the others keep ``DIMMED_KEEP`` of theirs."""
        ids = np.asarray(track_ids, dtype=np.int64).reshape(-1)
        colors = packed_track_colors(ids) if keep == 1.0 else faded(packed_track_colors(ids), keep)
        if not self.focus_tracks:
            return colors
        others = ~np.isin(ids, list(self.focus_tracks))
        colors[others] = faded(packed_track_colors(ids[others]), keep * DIMMED_KEEP)
        for k in np.flatnonzero(~others).tolist():
            own = self._involved_packed[int(ids[k])]
            colors[k] = own if keep == 1.0 else faded(np.array([own], dtype=np.uint32), keep)[0]
        return colors

    def _draw_tracks(self, class_name: str, estimates: tuple[TrackEstimate, ...], shown: set[int]) -> None:
        """Each drawn track's box and trail on its own entity; ``shown``: the ones that count as reported tracks
        (the others are focused tracks below ``show_min_existence``, drawn for the focus only)."""
        if not estimates:
            return
        self._extracted_ids.update(shown)
        for e in estimates:
            key = (paths.track, class_name, e.track_id)
            path = self._track_paths.get(key)
            if path is None:
                path = self._track_paths[key] = paths.track(self.tracker, class_name, e.track_id)
            self._put(path, rr.Boxes3D, 1, build=self._track_boxes, estimate=[e])
            trail = self._trails.get(e.track_id, ())
            if len(trail) >= 2:
                self._put(path, rr.LineStrips3D, 1, build=self._trail_lines, trail=[list(trail)], ids=[e.track_id])

    def _trail_lines(self, raw: dict[str, list]) -> dict[str, object]:
        """LineStrips3D of tracks' trails (each a list of (x, y, z) points), in the track's colour
        (``viz.rows.Build``)."""
        return {
            "strips": raw["trail"],
            "colors": self._track_colors(np.array(raw["ids"], dtype=np.int64)),
            "radii": np.full(len(raw["ids"]), TRAIL_RADIUS_M, dtype=np.float32),
        }

    def _track_boxes(self, raw: dict[str, list[TrackEstimate]]) -> dict[str, object]:
        """Boxes3D of extracted tracks (``estimate_boxes``), in the track's colour, labelled with the track id
        (``viz.rows.Build``)."""
        estimates = raw["estimate"]
        boxes = estimate_boxes(estimates)
        n = len(estimates)
        return {
            "centers": boxes.centers_m,
            "half_sizes": 0.5 * boxes.sizes_xyz_m,
            "quaternions": boxes.quat_xyzw,
            "colors": self._track_colors(np.array([e.track_id for e in estimates], dtype=np.int64)),
            "class_ids": np.array([CLASS_IDS.get(e.class_name, 0) for e in estimates], dtype=np.uint16),
            "labels": [str(e.track_id) for e in estimates],
            "radii": np.full(n, TRACK_LINE_RADIUS_M, dtype=np.float32),
        }

    # The story log.
    def _story(self, class_name: str, cf: _ClassFrame, estimates: tuple[TrackEstimate, ...]) -> None:
        now = {e.track_id: e for e in estimates}
        known = self._extracted_ids
        for t, e in now.items():
            via = f"from {meas_name(e.meas_index)}" if e.meas_index >= 0 else "without a detection"
            if t not in known:
                self._text(class_name, f"track {t} confirmed ({self._r(e.existence)}{via})", "INFO")
            elif e.meas_index < 0:
                self._text(class_name, f"track {t} missed this frame, still reported{self._r_in(e.existence)}", "INFO")
        posterior_r: dict[int, float] = {}
        if cf.posterior is not None:
            posterior_r = dict(
                zip(
                    np.asarray(cf.posterior.track_ids).tolist(),
                    np.asarray(cf.posterior.existence).tolist(),
                    strict=True,
                )
            )
        self._story_focused(class_name, cf, posterior_r, known | set(now))
        pruned_ids = {p.track_id for p in cf.pruned}
        limit = max(cf.extracted.threshold if cf.extracted is not None else 0.0, self.show_min_existence)
        for t in sorted(self._reported - set(now) - pruned_ids):
            if t in posterior_r:
                self._text(
                    class_name,
                    f"track {t} no longer shown (r={posterior_r[t]:.2f} fell below {limit:.2f})"
                    if self.has_existence
                    else f"track {t} no longer shown (not output this frame)",
                    "WARN",
                )
        candidates_pruned = 0
        for p in cf.pruned:
            if p.track_id in known:
                self._text(
                    class_name,
                    f"track {p.track_id} ended: {p.reason.value}"
                    + (f" (last r={p.last_existence:.3g})" if self.has_existence else ""),
                    "WARN",
                )
            else:
                candidates_pruned += 1
            self._trails.pop(p.track_id, None)
        born = [(t, m) for b in cf.born for t, m in zip(_ints(b.track_ids), _ints(b.meas_indices), strict=True)]
        if born or candidates_pruned:
            names = ", ".join(meas_name(m) for _, m in born[:12]) + (" …" if len(born) > 12 else "")
            self._text(
                class_name,
                f"{len(born)} new candidates{' from ' + names if born else ''}; {candidates_pruned} candidates pruned",
                "DEBUG",
            )
        for m in cf.merged:
            if m.into_id in known or any(f in known for f in m.from_ids):
                weights = ", ".join(f"{w:.3g}" for w in m.weights)
                ids = ", ".join(str(i) for i in m.from_ids)
                self._text(class_name, f"merged {ids} into track {m.into_id} (weights {weights})", "INFO")
        for ev in cf.logic:
            if ev.action is not TrackLogicAction.DELETED:
                continue  # tentative is a candidate's birth; confirmation shows as "confirmed" above
            self._text(
                class_name,
                f"track {ev.track_id} {ev.action.value} ({ev.hits}/{ev.window} hits)",
                _LEVEL_BY_ACTION[ev.action],
            )
        if cf.assignment is not None and cf.meas is not None:
            to_tracks = sum(1 for _, c in cf.assignment.pairs if c.kind is AxisKind.TRACK)
            shown_missed = [t for t in cf.assignment.missed_track_ids if t in known]
            self._text(
                class_name,
                f"{len(cf.meas.meas_indices)} detections: {to_tracks} updated tracks, "
                f"{len(cf.assignment.pairs) - to_tracks} new or clutter; reported tracks missed: "
                f"{', '.join(map(str, shown_missed)) or 'none'}",
                "DEBUG",
            )

    def _story_focused(self, class_name: str, cf: _ClassFrame, posterior_r: dict[int, float], known: set[int]) -> None:
        """A focused track below the show floor still gets one INFO line per frame: a failure is often about a
        track the tracker kept but no longer reported (its low existence is the story)."""
        hidden = sorted((self._focused & set(posterior_r)) - known)
        if not hidden:
            return
        given = {}
        if cf.assignment is not None:
            given = {c.ref: r.ref for r, c in cf.assignment.pairs if c.kind is AxisKind.TRACK}
        started = {t: m for m, t in _born_tracks(cf).items()}
        for t in hidden:
            if t in started:
                via = f"started by {meas_name(started[t])}"
            else:
                via = f"given {meas_name(given[t])}" if t in given else "given no detection"
            self._text(
                class_name,
                f"track {t} (not shown, r < {self.show_min_existence:g}): {via}, r={existence_text(posterior_r[t])}"
                if self.has_existence
                else f"track {t} (not output): {via}",
                "INFO",
            )

    def _r(self, existence: float) -> str:
        """``r=0.97, `` for a story line, nothing for a tracker without existences."""
        return f"r={existence:.2f}, " if self.has_existence else ""

    def _r_in(self, existence: float) -> str:
        """`` (r=0.97)`` for a story line, nothing for a tracker without existences."""
        return f" (r={existence:.2f})" if self.has_existence else ""

    @property
    def _focused(self) -> set[int]:
        return self.focus_tracks or set()

    def _on_budget(self, event: BudgetReached) -> None:
        self._text(
            event.class_name,
            f"budget {event.budget} = {event.limit} reached (this frame needed {event.needed}); work was cut",
            "WARN",
        )

    def _story_close_calls(self, d: Decisions, born: dict[int, int]) -> None:
        """Close calls that involve a reported track (between candidates they are routine)."""
        for conflict in d.conflicts:
            for c in conflict.choices:
                reported = {
                    label.ref
                    for label in (c.chosen, c.alternative)
                    if label is not None and label.kind is AxisKind.TRACK
                } & self._extracted_ids
                if c.margin < CLOSE_CALL_MARGIN and c.alternative is not None and reported:
                    self._text(
                        d.class_name,
                        f"close call: {meas_name(c.meas.ref)} → {destination(c.chosen, born.get(c.meas.ref))} "
                        f"(cost {c.chosen_cost:.2f}) "
                        f"over {column_name(c.alternative)} ({c.alternative_cost:.2f}), margin {c.margin:.2f}",
                        "INFO",
                    )

    # The decision view.
    def _draw_decisions(
        self,
        decisions: list[Decisions],
        matrices: dict[str, CostMatrix],
        fallbacks: list[CostMatrix],
        hypotheses: list[GlobalHypotheses],
    ) -> None:
        doc = decisions_markdown(
            self.tracker,
            self._frame,
            decisions,
            fallbacks,
            focus_tracks=self.focus_tracks,
            reported=self._extracted_ids,
            hypotheses=hypotheses,
        )
        self._put(paths.decisions(self.tracker), rr.TextDocument, 1, text=[doc], media_type=["text/markdown"])
        grid = decision_grid(decisions, matrices, reported=self._extracted_ids, focus_tracks=self.focus_tracks)
        root = paths.decision_matrix(self.tracker)
        if grid.costs.size:
            n = grid.costs.size
            self._put(
                f"{root}/cells",
                rr.Boxes2D,
                n,
                static={"show_labels": True, "draw_order": 1.0},
                centers=grid.centers,
                half_sizes=np.full((n, 2), 0.47),
                colors=pack_rgba(cost_colors(grid.costs)),
                labels=grid.labels,
            )
            sel = np.flatnonzero(grid.chosen)
            if sel.size:
                self._put(
                    f"{root}/chosen",
                    rr.Boxes2D,
                    sel.size,
                    static={"draw_order": 2.0},
                    centers=grid.centers[sel],
                    half_sizes=np.full((sel.size, 2), 0.47),
                    colors=np.full(sel.size, CHOSEN_CELL_RGBA, dtype=np.uint32),
                    radii=np.full(sel.size, 0.05, dtype=np.float32),
                )
            k = len(grid.axis_labels)
            self._put(
                f"{root}/axes",
                rr.Points2D,
                k,
                static={"show_labels": True},
                positions=grid.axis_positions,
                radii=np.full(k, 0.01, dtype=np.float32),
                labels=grid.axis_labels,
            )

    # Tracker-specific plots.
    def _on_marginals(self, event: Marginals) -> None:
        probs = np.asarray(event.probs, dtype=np.float32)
        if probs.ndim != 2 or probs.size == 0:
            return
        kinds = "|".join(dict.fromkeys(label.kind.value for label in event.rows)) or "empty"
        col_kinds = "|".join(dict.fromkeys(label.kind.value for label in event.cols)) or "empty"
        self._show(
            paths.marginals(self.tracker, event.class_name),
            rr.Tensor(probs, dim_names=[kinds, col_kinds], value_range=(0.0, 1.0)),
        )

    def _on_hypotheses(self, event: GlobalHypotheses) -> None:
        """Kept for the decision document; log weights of the best MAX_HYPOTHESIS_SERIES hypotheses as one
        multi-line series per class (NaN where fewer are kept), each line named by class and rank."""
        self._class_frame(event.class_name).hypotheses = event
        w = np.full(MAX_HYPOTHESIS_SERIES, np.nan)
        top = np.asarray(event.log_weights, dtype=np.float64)[:MAX_HYPOTHESIS_SERIES]
        w[: top.size] = top
        path = paths.hypothesis_weights(self.tracker, event.class_name)
        series = self._multi.setdefault(path, ([f"{event.class_name} h{r}" for r in range(w.size)], [], [], []))
        names, frames, stamps, values = series
        frames.append(self._frame)
        stamps.append(self._timestamp_us)
        values.append(w)

    def _on_cardinality(self, event: Cardinality) -> None:
        pmf = np.asarray(event.pmf, dtype=np.float64)
        if pmf.size == 0:
            return
        self._show(paths.cardinality_pmf(self.tracker, event.class_name), rr.BarChart(pmf))
        expected = float(np.arange(pmf.size) @ pmf)
        self._sample(paths.cardinality_mean(self.tracker, event.class_name), expected, f"E[n] {event.class_name}")

    def _on_intensity(self, event: IntensityWeights) -> None:
        weights = np.asarray(event.weights, dtype=np.float64)
        self._sample(
            paths.intensity_total(self.tracker, event.class_name), float(weights.sum()), f"sum w {event.class_name}"
        )
        if weights.size:
            self._show(paths.intensity_weights(self.tracker, event.class_name), rr.BarChart(weights))


def _pair_cost_lookup(matrix: CostMatrix | None) -> Callable[[int, int], float]:
    """cost(meas index, track id): the matrix entry of that detection's row and that track's column, NaN when
    there is none or it is not finite (outside the gate)."""
    if matrix is None:
        return lambda m, t: math.nan
    cost = np.asarray(matrix.cost, dtype=np.float64)
    if cost.size == 0:
        return lambda m, t: math.nan
    row_of = {label.ref: i for i, label in enumerate(matrix.rows)}
    col_of = label_positions(matrix.cols).get(AxisKind.TRACK, {})

    def cost_of(m: int, t: int) -> float:
        i, j = row_of.get(m), col_of.get(t)
        if i is None or j is None:
            return math.nan
        value = float(cost[i, j])
        return value if math.isfinite(value) else math.nan

    return cost_of


def _nis_of(gated: Gated | None, track_ids: list[int], z_xy: np.ndarray) -> list[float | None]:
    """(z - H m)^T S^-1 (z - H m) of detection k (z_xy: (P, 2)) for track_ids[k], from that track's gate
    (its first row in ``gated``); None where the track has no gate."""
    if gated is None:
        return [None] * len(track_ids)
    ids = np.asarray(gated.track_ids, dtype=np.int64).tolist()
    first = dict(zip(reversed(ids), range(len(ids) - 1, -1, -1), strict=True))  # the first row of each id wins
    hit = [k for k, t in enumerate(track_ids) if t in first]
    out: list[float | None] = [None] * len(track_ids)
    if not hit:
        return out
    rows = np.array([first[track_ids[k]] for k in hit], dtype=np.int64)
    nu = np.asarray(z_xy, dtype=np.float64)[hit] - np.asarray(gated.center_xy, dtype=np.float64)[rows]
    x = np.linalg.solve(np.asarray(gated.innovation_cov, dtype=np.float64)[rows], nu[:, :, None])[:, :, 0]
    for k, value in zip(hit, np.vecdot(nu, x).tolist(), strict=True):  # the same dot kernel as nu @ x per pair
        out[k] = value
    return out


def _pair_lines(pred_xy: np.ndarray, pred_rows: list[int], xyz: np.ndarray, meas_rows: np.ndarray) -> np.ndarray:
    """(P, 2, 3) lines from each track's predicted BEV position (pred_xy: (K, 2), at its detection's height) to
    its detection (xyz: (M, 3))."""
    end = xyz[np.asarray(meas_rows, dtype=np.int64)]
    start = np.column_stack([pred_xy[np.asarray(pred_rows, dtype=np.int64)], end[:, 2]])
    return np.stack([start, end], axis=1)


def _born_tracks(cf: _ClassFrame) -> dict[int, int]:
    """Detection index -> the id of the track it started this frame."""
    return {m: t for b in cf.born for t, m in zip(_ints(b.track_ids), _ints(b.meas_indices), strict=True)}


def destination(column: AxisLabel, born_id: int | None) -> str:
    """Where a detection went, in words: ``column_name``, with the id of the track a "new" detection started."""
    name = column_name(column)
    return f"new track {born_id}" if column.kind is AxisKind.NEW_TRACK and born_id is not None else name


def _one_per_row(values: np.ndarray) -> dict[str, tuple[np.ndarray, np.ndarray]]:
    """The ``Scalars`` field of a series of (R,) values, one per row (``viz.rows.EntityRows``)."""
    return {"scalars": (values, np.ones(values.size, dtype=np.int64))}


def _labels(template: str, track_ids: np.ndarray, existence: np.ndarray) -> list[str]:
    """``template % (id, r)`` per track (Python scalars and %-formatting: formatting numpy scalars, or with
    ``str.format``, is several times slower)."""
    return [template % (t, r) for t, r in zip(track_ids.tolist(), existence.tolist(), strict=True)]


def _ints(values: np.ndarray) -> list[int]:
    """(N,) ids as Python ints (one ``tolist``: iterating a NumPy array makes a NumPy scalar per element)."""
    return np.asarray(values, dtype=np.int64).tolist()
