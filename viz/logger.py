"""``TrackerLogger``: an ``EventSink`` that draws one tracker's introspection events in Rerun so a failure can be
explained from the picture. It only draws: what the events mean (which detection each track's update used,
the solver's decisions, the story) comes from the tracker's facts (``gnnpmb.why.facts``, ``gnnpmb.why.story``).

Per frame and class:

* **which detection went to which track**: a line from each track's predicted position to each detection its
  update used, in the track's colour (``associations``: an assignment, or every detection with a share of an
  association probability or PHD weight, labelled with it); detections inside a gate that the update did not
  use as dimmed lines (``gated_pairs``); detections are named ``m<idx>`` everywhere (labels, lines, tables, log);
* **why**: the decision view (``viz.decisions``): per conflict the chosen pair, its cost, the best alternative
  and the margin, as a document and as a labelled cost grid with the chosen cells outlined;
* **what happened before**: one entity per extracted track (``tracks/<class>/<id>``: its box and a trail of its
  last ``TRAIL_FRAMES`` positions), per-track series (existence, normalised innovation of the detection that
  dominated its update, chosen cost) and the story log per class (``gnnpmb.why.story``).

Candidate Bernoullis (predicted existence below ``gate_min_existence``, the many births on clutter) get no gate,
no box and no own series: their predicted means go to one hidden-by-default entity per class and their number to
one series per class. Time series are collected and sent column-wise by ``finish()`` (one chunk per series).
A frame is drawn when it closes (the next ``FrameStarted``, or ``finish``), from the facts of all its events.
"""

from __future__ import annotations

import math
from collections import deque
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np
import rerun as rr

from gnnpmb.events import (
    AxisKind,
    Cardinality,
    CostMatrix,
    Event,
    FrameStarted,
    Gated,
    GlobalHypotheses,
    IntensityWeights,
    Marginals,
    label_positions,
)
from gnnpmb.explain import Decisions
from gnnpmb.gating import ellipse_outline
from gnnpmb.types import TrackEstimate
from gnnpmb.why.facts import ClassFrame, TrackerFacts, UseMode
from gnnpmb.why.story import StoryLine, Storyteller
from gnnpmb.why.words import SHOW_MIN_EXISTENCE, meas_name, share_text
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
from viz.decisions import cost_colors, decision_grid, decisions_markdown
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
FLUSH_FRAMES = 10
"""Default cadence: story lines and spatial rows are sent column-wise every this many frames (and at the end),
so a live viewer sees them within seconds; a saved recording passes ``flush_frames=None`` (only at the end: one
chunk per entity)."""
_STATIC_ROW = np.zeros(1, dtype=np.int64)
"""The one row of static data (``viz.rows.send_entities(static=True)`` ignores its time)."""
CANDIDATE_COLOR = int(pack_rgba(np.array([[160, 160, 160]], dtype=np.uint8))[0])


@dataclass(slots=True)
class _Series:
    """One scalar time series being collected: frame indices, timestamps (us), values, and its style."""

    name: str
    color: tuple[int, int, int] | None
    frames: list[int] = field(default_factory=list)
    timestamps_us: list[int] = field(default_factory=list)
    values: list[float] = field(default_factory=list)


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
    series (flat lines at 1, a chunk pair per track) and no existence in the story. existence_word: what the
    series' legend calls the value (``weight`` for a PHD filter). facts: the tracker's facts,
    fed by a ``why.facts.FactSink`` placed before this logger in a ``TeeSink`` (None: the logger keeps and feeds
    its own). Call ``finish()`` after the last frame: it sends what is buffered and the time series.
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
        facts: TrackerFacts | None = None,
        label_tracks: bool = True,
        existence_word: str = "existence",
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
        self.label_tracks = label_tracks
        """Show every track's id label; False: ids stay data a click away and only the labels a full recording
        notes (``viz.opening.LabelNotes``: its failures at that frame) are shown."""
        self.flush_frames = flush_frames
        self.has_existence = has_existence
        self.existence_word = existence_word
        """What its per-track value is called in the plot's legend (``viz.blueprint.existence_word``)."""
        self.facts = facts if facts is not None else TrackerFacts(tracker_name, has_existence=has_existence)
        """What the tracker did (``why.facts``): the logger draws from it."""
        self._feeds_facts = facts is None
        self.storyteller = Storyteller(self.facts, show_min=show_min_existence, involved=frozenset(focus_tracks or ()))
        self.involved_rgb = involved_track_colors(focus_tracks or (), CLASS_COLORS.get(focus_class or ""))
        """Focus track id -> its RGB (``colors.involved_track_colors``), in every view and plot."""
        packed = pack_rgba(np.array(list(self.involved_rgb.values()), dtype=np.uint8).reshape(-1, 3))
        self._involved_packed = dict(zip(self.involved_rgb, packed.tolist(), strict=True))
        self._rows = RowBuffer(stream, clock)
        self._buffered: set[str] = set()
        self._drawing = True
        self.has_gates = False
        """Whether the tracker gates (a ``Gated`` event came): greedy matches within a distance instead."""
        self.story: list[StoryLine] = []
        """Every story line logged (``why.story.StoryLine``)."""
        self.sent_series: dict[str, tuple[np.ndarray, np.ndarray]] = {}
        """With ``focus_tracks``: series path -> (K,) frames and (K,) values of every time series ``finish`` sent
        (the focus view places its plots' legends from them)."""
        self._frame = -1  # current keyframe index; -1 before the first FrameStarted
        self._timestamp_us = 0
        self._live: set[str] = set()
        self._touched: set[str] = set()
        self._texts: dict[str, tuple[list[int], list[int], list[str], list[str]]] = {}
        self._frames_since_text_flush = 0
        self._series: dict[str, _Series] = {}
        self._multi: dict[str, tuple[list[str], list[int], list[int], list[np.ndarray]]] = {}
        self._track_z: dict[int, float] = {}
        self._trails: dict[int, deque[tuple[float, float, float]]] = {}
        self._extracted_ids: set[int] = set()  # tracks extracted at least once
        self._track_series: dict[str, tuple[str, int]] = {}  # series path -> (class, track id)
        self._track_paths: dict[tuple[Callable, str, int], str] = {}  # (paths function, class, track id) -> path

    @property
    def _focused(self) -> set[int]:
        return self.focus_tracks or set()

    @property
    def reported_ever(self) -> set[int]:
        """Ids of the tracks output at least once so far (the others are candidates)."""
        return self._extracted_ids

    def emit(self, event: Event) -> None:
        if self._feeds_facts:
            self.facts.add(event)
        elif self._frame < 0 and not isinstance(event, FrameStarted):
            raise RuntimeError(f"{type(event).__name__} emitted outside a frame (before FrameStarted or after finish)")
        if isinstance(event, FrameStarted):
            self._on_frame_started(event)
        elif self._frame < 0:
            raise RuntimeError(f"{type(event).__name__} emitted outside a frame (before FrameStarted or after finish)")
        elif isinstance(event, Gated):
            self.has_gates = True

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
        decisions: list[Decisions] = []
        matrices: dict[str, CostMatrix] = {}
        fallbacks: list[CostMatrix] = []
        classes = self.facts.frames.get(self._frame, {})
        hypotheses = [cf.hypotheses for cf in classes.values() if cf.hypotheses is not None]
        for class_name, cf in classes.items():
            self._draw_class(class_name, cf)
            self._draw_family(class_name, cf)
            if self._drawing and cf.cost is not None and cf.assignment is not None and cf.marginals is None:
                d = self.facts.decisions(self._frame, class_name)
                if d is None:
                    fallbacks.append(cf.cost)
                else:
                    decisions.append(d)
                    matrices[class_name] = cf.cost
        for line in self.storyteller.frame_lines(self._frame):
            self._text(line)
        if decisions or fallbacks:
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

    def _text(self, line: StoryLine) -> None:
        if not self._drawing:
            return
        self.story.append(line)
        path = paths.events(self.tracker, line.class_name)
        frames, stamps, texts, levels = self._texts.setdefault(path, ([], [], [], []))
        frames.append(line.frame)
        stamps.append(self._timestamp_us)
        texts.append(line.text)
        levels.append(line.level)

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
    def _draw_class(self, class_name: str, cf: ClassFrame) -> set[int]:
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
        if self.facts.output_only:  # no posterior: the trail follows the output boxes
            self._record_output(drawn)
        for p in cf.pruned:
            self._trails.pop(p.track_id, None)
        self._draw_tracks(class_name, drawn, {e.track_id for e in estimates})
        return {e.track_id for e in estimates}

    def _draw_prior(self, class_name: str, cf: ClassFrame) -> set[int]:
        """Predicted means (tracks vs candidates) and gates; returns the ids of the tracks worth a gate."""
        if cf.predicted is None:
            return set()
        ids = np.asarray(cf.predicted.track_ids, dtype=np.int64)
        existence = np.asarray(cf.predicted.existence, dtype=np.float64)
        focused = np.isin(ids, list(self.focus_tracks)) if self.focus_tracks else np.zeros(ids.size, dtype=bool)
        worthy = (existence >= self.gate_min_existence) | focused
        xy = np.asarray(cf.predicted.mean, dtype=np.float64).reshape(-1, 4)[:, :2]
        lighter = _lighter(ids, existence)
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
                    lighter=lighter[sel],
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
                lighter=lighter[sel],
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
            "labels": self._point_labels("%d predicted {}=%.2f", raw),
        }

    def _candidate_points(self, raw: dict[str, np.ndarray]) -> dict[str, object]:
        """Points3D of candidates' predicted means (N, 2), grey, at ``gate_z_m``."""
        n = raw["ids"].size
        return {
            "positions": lift_xy(raw["xy"], self.gate_z_m),
            "colors": np.full(n, CANDIDATE_COLOR, dtype=np.uint32),
            "radii": np.full(n, CANDIDATE_POINT_RADIUS_M, dtype=np.float32),
            "labels": self._point_labels("candidate %d, {}=%.3f", raw),
        }

    def _point_labels(self, template: str, raw: dict[str, np.ndarray]) -> list[str]:
        """``template`` with the run's symbol (``r``, or ``w`` for a PHD weight) per predicted point; a PHD
        component lighter than another of its label says whose it is instead (a track's id names its heaviest
        component, as the story and the focus text do)."""
        if self.existence_word != "weight":
            return _labels(template.format("r"), raw["ids"], raw["existence"])
        heaviest = _labels(template.format("w"), raw["ids"], raw["existence"])
        part = _labels("a lighter component of %d, w=%.3f", raw["ids"], raw["existence"])
        return [p if light else h for h, p, light in zip(heaviest, part, raw["lighter"].tolist(), strict=True)]

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

    def _draw_associations(self, class_name: str, cf: ClassFrame, worthy: set[int]) -> None:
        """A line from each track's prediction to each detection its update used (``why.facts.Use``: one for an
        assignment, every one with a share for association probabilities or PHD weights; shares below one half
        dimmed), gated detections it did not use dimmed; per-track samples of the NIS of the detection that
        dominated its update and, where the tracker chose from a cost matrix, the chosen cost."""
        use = self.facts.use(self._frame, class_name)
        if use is None or cf.meas is None or cf.predicted is None:
            return
        pos = {m: k for k, m in enumerate(np.asarray(cf.meas.meas_indices, dtype=np.int64).tolist())}
        xyz = np.asarray(cf.meas.xyz_m, dtype=np.float64).reshape(-1, 3)
        pred_ids = np.asarray(cf.predicted.track_ids, dtype=np.int64)
        # a PHD label can hold several components: the lines start at its heaviest, where the track's predicted
        # point and the focus's "<id> predicted" label stand (the last one was taken: dev set scene-0103 cphd
        # identity_theft:1, "m0 → 23" ran 6 m from 23's prediction, from a component of weight 0.004)
        lighter = _lighter(pred_ids, np.asarray(cf.predicted.existence, dtype=np.float64))
        pred_row = {t: k for k, t in enumerate(pred_ids.tolist()) if not lighter[k]}
        pred_xy = np.asarray(cf.predicted.mean, dtype=np.float64).reshape(-1, 4)[:, :2]
        cost_of = _pair_cost_lookup(cf.cost if cf.marginals is None else None)
        d2_of = _pair_d2_lookup(cf.gated)
        pairs, weak = [], []
        for t, u in use.tracks.items():
            if t not in pred_row:
                continue
            for m, share in u.shares:
                if m in pos:
                    (pairs if share >= 0.5 else weak).append((t, m, share))
            dominant = u.dominant
            if dominant is not None:
                cost = cost_of(dominant, t)
                if cost == cost:
                    self._track_sample(paths.chosen_cost, class_name, t, cost, "chosen cost")
                nis = d2_of(dominant, t)
                if nis == nis:
                    self._track_sample(paths.nis, class_name, t, nis, "NIS")
        for kept, path, build in (
            (pairs, paths.associations(self.tracker, class_name), self._association_lines),
            (weak, paths.weak_associations(self.tracker, class_name), self._gated_pair_lines),
        ):
            if not kept:
                continue
            owners = [t for t, _, _ in kept]
            labels = []
            for t, m, share in kept:
                cost = cost_of(m, t)
                extra = share_text(share, use.mode) if use.mode is not UseMode.ASSIGNED else ""
                extra = extra or (f"cost {cost:.2f}" if cost == cost else "")
                labels.append(f"{meas_name(m)} → {t}" + (f" ({extra})" if extra else ""))
            self._put(
                path,
                rr.LineStrips3D,
                len(kept),
                static={"show_labels": False},
                build=build,
                lines=_pair_lines(pred_xy, [pred_row[t] for t in owners], xyz, np.array([pos[m] for _, m, _ in kept])),
                ids=np.array(owners, dtype=np.int64),
                labels=labels,
            )
        gated = cf.gated
        if gated is None:
            return
        used = {(t, m) for t, m, _ in (*pairs, *weak)}
        gids = np.asarray(gated.track_ids, dtype=np.int64).tolist()
        gmeas = np.asarray(gated.meas_indices, dtype=np.int64).tolist()
        drawn = np.array([t in worthy for t in gids], dtype=bool).reshape(-1, 1)
        rows, cols = np.nonzero(np.asarray(gated.inside, dtype=bool) & drawn)  # candidates' gates are not drawn
        rejected = [
            (gids[k], gmeas[j])
            for k, j in zip(rows.tolist(), cols.tolist(), strict=True)
            if (gids[k], gmeas[j]) not in used and gmeas[j] in pos and gids[k] in pred_row
        ]
        if rejected:
            rowners = [t for t, _ in rejected]
            labels = []
            for t, m in rejected:
                cost = cost_of(m, t)
                why = f" (cost {cost:.2f})" if cost == cost else ""
                labels.append(f"{meas_name(m)} in gate of {t}, not used{why}")
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
                labels=labels,
            )

    def _record_posterior(self, class_name: str, cf: ClassFrame) -> None:
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
        heaviest: dict[int, int] = {}  # a GM-PHD / CPHD label has a row per component: its heaviest one's sample
        for k, t in enumerate(id_list):
            if t not in heaviest or r_list[k] > r_list[heaviest[t]]:
                heaviest[t] = k
        follow = [
            k
            for k in sorted(heaviest.values())
            if r_list[k] >= self.gate_min_existence or id_list[k] in reported or id_list[k] in focused
        ]
        xy = mean[follow, :2].tolist()
        for k, (x, y) in zip(follow, xy, strict=True):
            t = id_list[k]
            if self.has_existence:
                self._track_sample(paths.existence, class_name, t, r_list[k], self.existence_word)
            trail = self._trails.get(t)
            if trail is None:
                trail = self._trails[t] = deque(maxlen=TRAIL_FRAMES)
            trail.append((x, y, self._track_z.get(t, self.gate_z_m)))

    def _record_output(self, estimates: tuple[TrackEstimate, ...]) -> None:
        """Trail points of a run known by its output only: its box centres."""
        for e in estimates:
            trail = self._trails.get(e.track_id)
            if trail is None:
                trail = self._trails[e.track_id] = deque(maxlen=TRAIL_FRAMES)
            trail.append(tuple(float(v) for v in e.translation_m))

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
        } | ({} if self._labelled(estimates) else {"show_labels": np.zeros(n, dtype=bool)})

    def _labelled(self, estimates: list[TrackEstimate]) -> bool:
        """Whether a track's box shows its id: with ``label_tracks``, and in a focus recording only the focus's
        tracks (the others are dimmed boxes whose id is a click away; a run with no involved track labels none:
        it labelled all of them, 15 a frame, dev set scene-0103 ``--focus diff:introduced:1``)."""
        if not self.label_tracks:
            return False
        return self.focus_tracks is None or all(e.track_id in self.focus_tracks for e in estimates)

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
    def _draw_family(self, class_name: str, cf: ClassFrame) -> None:
        """The panels a tracker family declares: association probabilities, hypothesis weights, cardinality,
        intensity."""
        if cf.marginals is not None:
            self._draw_marginals(cf.marginals)
        if cf.hypotheses is not None:
            self._sample_hypotheses(cf.hypotheses)
        if cf.cardinality is not None:
            self._draw_cardinality(cf.cardinality)
        if cf.intensity is not None:
            self._draw_intensity(cf.intensity)

    def _draw_marginals(self, event: Marginals) -> None:
        probs = np.asarray(event.probs, dtype=np.float32)
        if probs.ndim != 2 or probs.size == 0:
            return
        kinds = "|".join(dict.fromkeys(label.kind.value for label in event.rows)) or "empty"
        col_kinds = "|".join(dict.fromkeys(label.kind.value for label in event.cols)) or "empty"
        self._show(
            paths.marginals(self.tracker, event.class_name),
            rr.Tensor(probs, dim_names=[kinds, col_kinds], value_range=(0.0, 1.0)),
        )

    def _sample_hypotheses(self, event: GlobalHypotheses) -> None:
        """Log weights of the best MAX_HYPOTHESIS_SERIES hypotheses as one multi-line series per class (NaN where
        fewer are kept), each line named by class and rank."""
        w = np.full(MAX_HYPOTHESIS_SERIES, np.nan)
        top = np.asarray(event.log_weights, dtype=np.float64)[:MAX_HYPOTHESIS_SERIES]
        w[: top.size] = top
        path = paths.hypothesis_weights(self.tracker, event.class_name)
        series = self._multi.setdefault(path, ([f"{event.class_name} h{r}" for r in range(w.size)], [], [], []))
        names, frames, stamps, values = series
        frames.append(self._frame)
        stamps.append(self._timestamp_us)
        values.append(w)

    def _draw_cardinality(self, event: Cardinality) -> None:
        pmf = np.asarray(event.pmf, dtype=np.float64)
        if pmf.size == 0:
            return
        self._show(paths.cardinality_pmf(self.tracker, event.class_name), rr.BarChart(pmf))
        expected = float(np.arange(pmf.size) @ pmf)
        self._sample(paths.cardinality_mean(self.tracker, event.class_name), expected, f"E[n] {event.class_name}")

    def _draw_intensity(self, event: IntensityWeights) -> None:
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


def _pair_d2_lookup(gated: Gated | None) -> Callable[[int, int], float]:
    """d2(meas index, track id): the squared Mahalanobis distance the tracker computed for that pair
    (``Gated.d2``, the track's first row), NaN when there is none."""
    if gated is None:
        return lambda m, t: math.nan
    row_of: dict[int, int] = {}
    for k, t in enumerate(np.asarray(gated.track_ids, dtype=np.int64).tolist()):
        row_of.setdefault(t, k)
    col_of = {m: j for j, m in enumerate(np.asarray(gated.meas_indices, dtype=np.int64).tolist())}
    d2 = np.asarray(gated.d2, dtype=np.float64)

    def d2_of(m: int, t: int) -> float:
        i, j = row_of.get(t), col_of.get(m)
        return math.nan if i is None or j is None else float(d2[i, j])

    return d2_of


def _pair_lines(pred_xy: np.ndarray, pred_rows: list[int], xyz: np.ndarray, meas_rows: np.ndarray) -> np.ndarray:
    """(P, 2, 3) lines from each track's predicted BEV position (pred_xy: (K, 2), at its detection's height) to
    its detection (xyz: (M, 3))."""
    end = xyz[np.asarray(meas_rows, dtype=np.int64)]
    start = np.column_stack([pred_xy[np.asarray(pred_rows, dtype=np.int64)], end[:, 2]])
    return np.stack([start, end], axis=1)


def _one_per_row(values: np.ndarray) -> dict[str, tuple[np.ndarray, np.ndarray]]:
    """The ``Scalars`` field of a series of (R,) values, one per row (``viz.rows.EntityRows``)."""
    return {"scalars": (values, np.ones(values.size, dtype=np.int64))}


def _lighter(ids: np.ndarray, weight: np.ndarray) -> np.ndarray:
    """(N,) bool: the row is not the heaviest of the rows with its id (the first of equal weights is), for (N,) ids
    and weights."""
    order = np.lexsort((np.arange(ids.size), -weight, ids))
    first = np.ones(ids.size, dtype=bool)
    first[1:] = ids[order][1:] != ids[order][:-1]
    out = np.ones(ids.size, dtype=bool)
    out[order[first]] = False
    return out


def _labels(template: str, track_ids: np.ndarray, existence: np.ndarray) -> list[str]:
    """``template % (id, r)`` per track (Python scalars and %-formatting: formatting numpy scalars, or with
    ``str.format``, is several times slower)."""
    return [template % (t, r) for t, r in zip(track_ids.tolist(), existence.tolist(), strict=True)]
