"""``TrackerLogger``: an ``EventSink`` that draws one tracker's introspection events in Rerun.

Per frame and class it shows predicted means, gate ellipses, the cost matrix (a heat map plus a markdown table
naming every row and column), the extracted tracks and, for the trackers that have them, PMBM hypothesis
weights, TO-PMB/JPDA marginals, the CPHD cardinality and PHD intensity weights. Births, prunings, assignments,
track-logic transitions and merges go to a text log. Per-track existence probabilities become time series:
under ``existence/`` for Bernoullis that were output as tracks at least once, under ``candidates/`` for those
that never were (the many short-lived births on clutter), so the default plot stays readable.

Cheap logging: per-frame entities are logged directly; text-log lines are buffered for the frame and sent as one
column chunk per class; time series are kept in memory and sent column-wise by ``finish()`` (one chunk per
series instead of one per point). An entity drawn in one frame and not redrawn in the next is cleared at the next
frame, so a class without tracks shows no boxes.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field

import numpy as np
import rerun as rr

from gnnpmb.events import (
    Assignment,
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
    Merged,
    Posterior,
    Predicted,
    Pruned,
    TrackLogic,
    TrackLogicAction,
)
from gnnpmb.gating import ellipse_outline
from viz import paths
from viz.colors import class_ids, pack_rgba, track_color, track_colors
from viz.geometry import estimate_boxes, lift_xy
from viz.scene import set_frame_time

TRACK_LINE_RADIUS_M = 0.06
GATE_LINE_RADIUS_M = 0.03
PREDICTED_POINT_RADIUS_M = 0.25
MAX_TABLE_CELLS = 600
"""Cost matrices with more cells than this are listed row by row (finite entries only) instead of as a table."""
MAX_HYPOTHESIS_SERIES = 10
"""Log weights are plotted for the best this many PMBM global hypotheses."""

_LEVEL_BY_ACTION = {
    TrackLogicAction.TENTATIVE: "DEBUG",
    TrackLogicAction.CONFIRMED: "INFO",
    TrackLogicAction.DELETED: "WARN",
}


def cost_heat(cost: np.ndarray) -> tuple[np.ndarray, tuple[float, float]]:
    """Heat map of an (R, C) cost matrix for a Tensor view: (R, C) float32 heat and its value range.

    heat = -cost (the log-likelihood ratio for the PMB family: brighter = more likely). Impossible entries
    (+inf cost, NaN) get a sentinel a quarter of the finite span below the lowest finite heat, and the value range
    starts at the sentinel, so gated-out cells are the darkest colour and never squash the colour map.
    """
    heat = -np.asarray(cost, dtype=np.float64)
    finite = np.isfinite(heat)
    if finite.any():
        lo, hi = float(heat[finite].min()), float(heat[finite].max())
    else:
        lo, hi = 0.0, 1.0
    if hi <= lo:
        hi = lo + 1.0
    sentinel = lo - 0.25 * (hi - lo)
    return np.where(finite, heat, sentinel).astype(np.float32), (sentinel, hi)


def compact_cost(event: CostMatrix) -> CostMatrix:
    """The matrix without columns in which every entry is impossible (tracks with no measurement in their gate:
    with many candidate Bernoullis most columns are), so the heat map shows what the solver chose between; the
    markdown table still names every column. The description says how many were hidden."""
    cost = np.asarray(event.cost)
    keep = np.isfinite(cost).any(axis=0)
    if keep.all():
        return event
    hidden = int((~keep).sum())
    return dataclasses.replace(
        event,
        cost=cost[:, keep],
        cols=tuple(c for c, k in zip(event.cols, keep.tolist(), strict=True) if k),
        description=f"{event.description} ({hidden} columns with no possible assignment hidden)",
    )


def axis_dim_name(labels: Sequence[AxisLabel]) -> str:
    """Name of a matrix dimension from the kinds of its labels, e.g. "meas" or "track|new"."""
    kinds = dict.fromkeys(label.kind.value for label in labels)
    return "|".join(kinds) or "empty"


def cost_markdown(event: CostMatrix) -> str:
    """Markdown naming every row and column of a cost matrix with its values.

    Up to MAX_TABLE_CELLS cells: a full table ("-" = impossible). Larger matrices (gating makes them sparse): one
    line per row listing only its finite entries.
    """
    cost = np.asarray(event.cost, dtype=np.float64)
    head = (
        f"**{event.class_name}**, hypothesis {event.hypothesis}: {event.description}; "
        f"{cost.shape[0]} rows x {cost.shape[1]} columns. The heat map shows -cost; darkest = impossible.\n\n"
    )
    cols = [str(c) for c in event.cols]
    finite = np.isfinite(cost)
    if cost.size <= MAX_TABLE_CELLS:
        shown = np.where(finite, cost, np.nan)
        lines = ["| | " + " | ".join(cols) + " |", "|---" * (len(cols) + 1) + "|"]
        for label, row in zip(event.rows, shown.tolist(), strict=True):
            cells = " | ".join(map("{:.2f}".format, row)).replace("nan", "-")
            lines.append(f"| **{label}** | {cells} |")
        return head + "\n".join(lines) + "\n"
    lines = []
    for label, row, ok in zip(event.rows, cost, finite, strict=True):
        idx = np.flatnonzero(ok)
        entries = ", ".join(f"{cols[j]} {v:.2f}" for j, v in zip(idx.tolist(), row[idx].tolist(), strict=True))
        lines.append(f"- **{label}**: {entries or 'nothing possible'}")
    return head + "\n".join(lines) + "\n"


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

    gate_z_m: height at which gates and predicted means of tracks with no known box height are drawn (global z;
    nuScenes ego poses have z = 0). gate_points: vertices per gate ellipse. log_predicted: draw the predicted
    means. gate_min_existence: gates are drawn for tracks whose predicted existence reaches it. Call
    ``finish()`` after the last frame: it sends the time series (existence, hypothesis weights, ...),
    which therefore appear in a live viewer at the end of the run.
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
    ) -> None:
        paths.tracker_root(tracker_name)  # rejects names that cannot be an entity-path segment
        self.stream = stream
        self.tracker = tracker_name
        self.gate_z_m = gate_z_m
        self.gate_points = gate_points
        self.log_predicted = log_predicted
        self.gate_min_existence = gate_min_existence
        self._prior_existence: dict[str, tuple[np.ndarray, np.ndarray]] = {}  # class -> (ids, existence)
        self._frame = -1  # current keyframe index; -1 before the first FrameStarted
        self._timestamp_us = 0
        self._live: set[str] = set()
        self._touched: set[str] = set()
        self._texts: dict[str, tuple[list[str], list[str]]] = {}
        self._series: dict[str, _Series] = {}
        self._track_z: dict[int, float] = {}
        self._existence_paths: dict[str, tuple[str, int]] = {}  # series path -> (class, track id)
        self._extracted_ids: set[int] = set()
        self._handlers: dict[type, Callable] = {
            FrameStarted: self._on_frame_started,
            Predicted: self._on_predicted,
            Gated: self._on_gated,
            CostMatrix: self._on_cost,
            Assignment: self._on_assignment,
            Born: self._on_born,
            Posterior: self._on_posterior,
            Pruned: self._on_pruned,
            Extracted: self._on_extracted,
            GlobalHypotheses: self._on_hypotheses,
            Marginals: self._on_marginals,
            Merged: self._on_merged,
            Cardinality: self._on_cardinality,
            IntensityWeights: self._on_intensity,
            TrackLogic: self._on_track_logic,
            BudgetReached: self._on_budget,
        }

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
        for path, series in self._series.items():
            if path in self._existence_paths and self._existence_paths[path][1] not in self._extracted_ids:
                path = paths.candidate_existence(self.tracker, *self._existence_paths[path])
            if series.color is None:
                self.stream.log(path, rr.SeriesLines(names=series.name), static=True)
            else:
                self.stream.log(path, rr.SeriesLines(names=series.name, colors=[series.color]), static=True)
            self.stream.send_columns(
                path,
                indexes=[
                    rr.TimeColumn("frame", sequence=series.frames),
                    rr.TimeColumn("timestamp", timestamp=np.array(series.timestamps_us, dtype="datetime64[us]")),
                ],
                columns=rr.Scalars.columns(scalars=np.asarray(series.values, dtype=np.float64)),
            )
        self._series.clear()
        self._existence_paths.clear()

    # Frame bookkeeping.
    def _on_frame_started(self, event: FrameStarted) -> None:
        if self._frame >= 0:
            self._close_frame()
        self._frame = event.frame_index
        self._timestamp_us = event.timestamp_us
        set_frame_time(self.stream, event.frame_index, event.timestamp_us)

    def _close_frame(self) -> None:
        """Send the frame's text lines; clear entities drawn last frame but not this one."""
        set_frame_time(self.stream, self._frame, self._timestamp_us)
        for path, (texts, levels) in self._texts.items():
            n = len(texts)
            self.stream.send_columns(
                path,
                indexes=[
                    rr.TimeColumn("frame", sequence=np.full(n, self._frame, dtype=np.int64)),
                    rr.TimeColumn("timestamp", timestamp=np.full(n, self._timestamp_us, dtype="datetime64[us]")),
                ],
                columns=rr.TextLog.columns(text=texts, level=levels),
            )
        self._texts.clear()
        for path in sorted(self._live - self._touched):
            self.stream.log(path, rr.Clear(recursive=False))
        self._live = self._touched
        self._touched = set()

    def _show(self, path: str, archetype: rr.AsComponents) -> None:
        self.stream.log(path, archetype)
        self._touched.add(path)

    def _text(self, class_name: str, text: str, level: str) -> None:
        texts, levels = self._texts.setdefault(paths.events(self.tracker, class_name), ([], []))
        texts.append(text)
        levels.append(level)

    def _sample(self, path: str, value: float, name: str = "") -> None:
        """Append one point to a time series at the current frame (a repeat in the same frame replaces it).
        A new series is named ``name`` (or the entity's last path part) and coloured by the viewer."""
        series = self._series.get(path)
        if series is None:
            series = self._series[path] = _Series(name or path.rsplit("/", 1)[-1], None)
        if series.frames and series.frames[-1] == self._frame:
            series.values[-1] = float(value)
            return
        series.frames.append(self._frame)
        series.timestamps_us.append(self._timestamp_us)
        series.values.append(float(value))

    def _z_of(self, track_ids: np.ndarray) -> np.ndarray:
        """(K,) last known box height of each track, gate_z_m for tracks never extracted."""
        return np.array([self._track_z.get(int(t), self.gate_z_m) for t in track_ids], dtype=np.float64)

    # Spatial events.
    def _on_predicted(self, event: Predicted) -> None:
        ids = np.asarray(event.track_ids)
        self._prior_existence[event.class_name] = (ids, np.asarray(event.existence, dtype=np.float64))
        if ids.size == 0 or not self.log_predicted:
            return
        self._show(
            paths.predicted(self.tracker, event.class_name),
            rr.Points3D(
                lift_xy(np.asarray(event.mean)[:, :2], self._z_of(ids)),
                colors=pack_rgba(track_colors(ids)),
                radii=PREDICTED_POINT_RADIUS_M,
                labels=[
                    f"{t} prior r={r:.2f}"
                    for t, r in zip(ids.tolist(), np.asarray(event.existence).tolist(), strict=True)
                ],
                show_labels=False,
            ),
        )

    def _on_gated(self, event: Gated) -> None:
        ids = np.asarray(event.track_ids)
        drawn = self._gate_worthy(event.class_name, ids)
        if not drawn.any():
            return
        ids = ids[drawn]
        outline = ellipse_outline(
            np.asarray(event.center_xy, dtype=np.float64)[drawn],
            np.asarray(event.innovation_cov, dtype=np.float64)[drawn],
            event.threshold,
            self.gate_points,
        )
        self._show(
            paths.gates(self.tracker, event.class_name),
            rr.LineStrips3D(
                lift_xy(outline, self._z_of(ids)[:, None]),
                colors=pack_rgba(track_colors(ids)),
                radii=GATE_LINE_RADIUS_M,
            ),
        )

    def _gate_worthy(self, class_name: str, ids: np.ndarray) -> np.ndarray:
        """(K,) bool: draw the gate of tracks whose predicted existence (from this frame's ``Predicted``) is at
        least ``gate_min_existence``; the many candidate Bernoullis born on clutter would hide everything else."""
        known_ids, existence = self._prior_existence.get(class_name, (np.zeros(0, dtype=np.int64), np.zeros(0)))
        if known_ids.size == 0:
            return np.ones(ids.size, dtype=bool)
        lookup = dict(zip(known_ids.tolist(), existence.tolist(), strict=True))
        return np.array([lookup.get(t, 1.0) >= self.gate_min_existence for t in ids.tolist()], dtype=bool)

    def _on_extracted(self, event: Extracted) -> None:
        for e in event.estimates:
            self._track_z[e.track_id] = float(e.translation_m[2])
            self._extracted_ids.add(e.track_id)
        if not event.estimates:
            return
        boxes = estimate_boxes(event.estimates)
        ids = np.array([e.track_id for e in event.estimates], dtype=np.int64)
        self._show(
            paths.tracks(self.tracker, event.class_name),
            rr.Boxes3D(
                centers=boxes.centers_m,
                sizes=boxes.sizes_xyz_m,
                quaternions=boxes.quat_xyzw,
                colors=pack_rgba(track_colors(ids)),
                class_ids=class_ids(np.array([e.class_name for e in event.estimates], dtype=object)),
                labels=[f"{e.track_id} {e.class_name} r={e.existence:.2f}" for e in event.estimates],
                radii=TRACK_LINE_RADIUS_M,
            ),
        )

    # Matrices.
    def _on_cost(self, event: CostMatrix) -> None:
        cost = np.asarray(event.cost)
        if cost.ndim != 2 or cost.size == 0:
            return
        shown = compact_cost(event)
        heat, value_range = cost_heat(np.asarray(shown.cost))
        self._show(
            paths.cost_matrix(self.tracker, event.class_name, event.hypothesis),
            rr.Tensor(heat, dim_names=[axis_dim_name(shown.rows), axis_dim_name(shown.cols)], value_range=value_range),
        )
        if event.hypothesis == 0:
            self._show(
                paths.cost_axes(self.tracker, event.class_name),
                rr.TextDocument(cost_markdown(event), media_type="text/markdown"),
            )

    def _on_marginals(self, event: Marginals) -> None:
        probs = np.asarray(event.probs, dtype=np.float32)
        if probs.ndim != 2 or probs.size == 0:
            return
        self._show(
            paths.marginals(self.tracker, event.class_name),
            rr.Tensor(probs, dim_names=[axis_dim_name(event.rows), axis_dim_name(event.cols)], value_range=(0.0, 1.0)),
        )
        self._text(
            event.class_name,
            f"marginals {probs.shape[0]}x{probs.shape[1]} by {event.method}, {event.iterations} iterations",
            "DEBUG",
        )

    # Text events.
    def _on_assignment(self, event: Assignment) -> None:
        pairs = ", ".join(f"{r}->{c}" for r, c in event.pairs) or "none"
        missed = ", ".join(str(t) for t in event.missed_track_ids) or "none"
        self._text(
            event.class_name,
            f"h{event.hypothesis} assignment, cost {event.total_cost:.3f}: {pairs}; missed tracks: {missed}",
            "DEBUG",
        )

    def _on_born(self, event: Born) -> None:
        mean = np.asarray(event.mean)
        for t, m, xy, r in zip(
            np.asarray(event.track_ids).tolist(),
            np.asarray(event.meas_indices).tolist(),
            mean.reshape(-1, 4)[:, :2].tolist(),
            np.asarray(event.existence).tolist(),
            strict=True,
        ):
            self._text(
                event.class_name, f"born track {t} from meas {m} at ({xy[0]:.1f}, {xy[1]:.1f}) r={r:.3f}", "INFO"
            )

    def _on_budget(self, event: BudgetReached) -> None:
        self._text(
            event.class_name,
            f"budget {event.budget} = {event.limit} reached (this frame needed {event.needed}); work was cut",
            "WARN",
        )

    def _on_pruned(self, event: Pruned) -> None:
        self._text(
            event.class_name,
            f"pruned track {event.track_id}: {event.reason.value} (last {event.last_existence:.3g})",
            "WARN",
        )

    def _on_merged(self, event: Merged) -> None:
        weights = ", ".join(f"{w:.3g}" for w in event.weights)
        self._text(
            event.class_name,
            f"merged {', '.join(str(i) for i in event.from_ids)} into {event.into_id} (weights {weights})",
            "DEBUG",
        )

    def _on_track_logic(self, event: TrackLogic) -> None:
        self._text(
            event.class_name,
            f"track {event.track_id} {event.action.value} ({event.hits}/{event.window} hits)",
            _LEVEL_BY_ACTION[event.action],
        )

    # Series and charts.
    def _on_posterior(self, event: Posterior) -> None:
        for t, r in zip(np.asarray(event.track_ids).tolist(), np.asarray(event.existence).tolist(), strict=True):
            path = paths.existence(self.tracker, event.class_name, t)
            if path not in self._series:
                self._series[path] = _Series(f"{t} {event.class_name}", track_color(t))
                self._existence_paths[path] = (event.class_name, t)
            self._sample(path, r)

    def _on_hypotheses(self, event: GlobalHypotheses) -> None:
        for rank, w in enumerate(np.asarray(event.log_weights)[:MAX_HYPOTHESIS_SERIES].tolist()):
            self._sample(paths.hypothesis_weight(self.tracker, event.class_name, rank), w, f"h{rank}")

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
