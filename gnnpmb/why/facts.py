"""The facts of one tracker run, kept from its events: ``FactSink`` collects, ``TrackerFacts`` answers.

``FactSink`` is an ``EventSink`` that keeps every event by frame and class (the arrays the tracker emitted, no
copies). Everything else is worked out on demand, per frame and class, from those events alone, and kept once
worked out:

* ``use(frame, class)``: how each track's update used the frame's detections (``FrameUse``), in the tracker's
  own terms: a hard assignment (GNN-PMB, GNN, greedy, PMBM's chosen hypothesis: share 1), association
  probabilities (JPDA, TO-PMB: the ``Marginals`` rows) or GM-PHD / CPHD update weights (``UpdateWeights``: the
  share of a track label's predicted weight each detection took); and where each detection went (``Destination``);
* ``decisions(frame, class)``: the solver's conflicts, choices and margins (``explain``), for trackers that choose
  one assignment from a cost matrix;
* ``steps(track, class)``: a track's ``TrackStep`` at every frame it lived;
* ``hypotheses(frame, class)``: PMBM's kept global hypotheses and the prior one the best came from.

Facts are about the events as emitted: nothing here re-runs tracker math.
"""

from __future__ import annotations

import enum
import math
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass, field

import numpy as np

from gnnpmb.events import (
    Assignment,
    AxisKind,
    Born,
    BudgetReached,
    Cardinality,
    CostMatrix,
    CostScale,
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
    PruneReason,
    TrackLogic,
    TrackLogicAction,
    UpdateWeights,
)
from gnnpmb.explain import Decisions, explain
from gnnpmb.foreign import NEAREST_M
from gnnpmb.types import TrackEstimate

USED_SHARE = 0.01
"""A track's update *used* a detection when the detection's share of the update is at least this (1 %): a soft
update that gave a detection less moved the track by less than a hundredth of the way to it."""


class UseMode(enum.Enum):
    """How a tracker's update uses detections."""

    ASSIGNED = "assigned"  # one detection or none per track (GNN-PMB, PMBM's chosen hypothesis, GNN, greedy)
    PROBABILITIES = "association probabilities"  # a mixture over detections (JPDA, TO-PMB)
    WEIGHTS = "update weights"  # the PHD intensity split over detections (GM-PHD, CPHD)
    OUTPUT = "output only"  # a results file: only the detection each output box sits on is known


@dataclass(frozen=True, slots=True)
class Use:
    """How one track's update used the frame's detections.

    shares: (detection source index, share) with share >= ``USED_SHARE``, largest first; missed: the share of
    the missed-detection hypothesis; mode: what a share is (1 or 0 for an assignment, a probability, or the
    fraction of the track's predicted PHD weight that went to the detection).
    """

    shares: tuple[tuple[int, float], ...]
    missed: float
    mode: UseMode

    @property
    def dominant(self) -> int | None:
        """The detection with the largest share, if its share outweighs the missed hypothesis (-1-free: None)."""
        if not self.shares or self.shares[0][1] <= self.missed:
            return None
        return self.shares[0][0]

    @property
    def used(self) -> tuple[int, ...]:
        """The detections the update used (share >= ``USED_SHARE``)."""
        return tuple(m for m, _ in self.shares)


class Went(enum.Enum):
    """Where a detection went."""

    TRACK = "track"  # an existing track took it (all of it, or its largest share)
    NEW_TRACK = "new track"  # it started a track (or a candidate Bernoulli) of its own
    NEW = "new"  # it started nothing that got an id this frame, or was clutter
    NOT_RECEIVED = "not received"  # below the score threshold or suppressed by NMS: the tracker never saw it
    NO_OUTPUT = "under no output box"  # output only: no box of the run sits on it (what its update did is unknown)


@dataclass(frozen=True, slots=True)
class Destination:
    """Where detection ``meas`` went: ``went``, the track (``track_id``: the one that took it or the one it
    started; -1 for none) and its share of the detection (1 for an assignment; a probability or PHD weight)."""

    meas: int
    went: Went
    track_id: int = -1
    share: float = 1.0


@dataclass(frozen=True, slots=True)
class FrameUse:
    """One class at one frame: each track's ``Use`` and each received detection's ``Destination``."""

    mode: UseMode
    tracks: Mapping[int, Use]
    destinations: Mapping[int, Destination]


class Ending(enum.Enum):
    """Why a track left the tracker."""

    PRUNED = "pruned"  # existence or weight below the pruning threshold, absent from every hypothesis, capped
    DELETED = "deleted by its track logic"  # M/N logic, greedy's max age
    MERGED = "merged into another component"


@dataclass(frozen=True, slots=True)
class TrackEnd:
    """How a track ended at a frame: ``ending``; reason: the tracker's ``PruneReason``; last: the existence or
    weight it last had; hits / window: the M/N logic's count at deletion (-1 when not a track-logic deletion)."""

    ending: Ending
    reason: PruneReason
    last: float
    hits: int = -1
    window: int = -1


@dataclass(frozen=True, slots=True)
class TrackStep:
    """One track at one frame, as the tracker's events show it.

    prior_existence: predicted existence (None: not predicted, e.g. born this frame; 1 for trackers without
    existences); decided_existence: its existence in the prior hypothesis its detection was decided in (PMBM, when
    that is not the most likely prior hypothesis; else None); marginal_existence: PMBM's existence over all kept
    hypotheses after the update (None for other trackers); predicted_xy_m: its predicted BEV position; gated:
    (detection, d2) inside its gate, nearest first; use: how its update used the detections (None: no update
    reported for it); born_from: the detection that started it this frame; posterior_existence: after the update
    (GM-PHD / CPHD: its label's heaviest weight, an expected number that may exceed 1; None if it ended); output:
    its box in the tracker's output (None: not output); ended: how it ended (None: it lives on); column:
    (detection, cost) of its column in the cost matrix the frame was decided over (+inf: it could not take that
    detection; None: it had no column), on that matrix's ``column_scale``.
    """

    frame: int
    prior_existence: float | None
    predicted_xy_m: tuple[float, float] | None
    gated: tuple[tuple[int, float], ...]
    use: Use | None
    born_from: int | None
    posterior_existence: float | None
    output: TrackEstimate | None
    ended: TrackEnd | None = None
    decided_existence: float | None = None
    marginal_existence: float | None = None
    column: tuple[tuple[int, float], ...] | None = None
    column_scale: CostScale | None = None

    @property
    def used(self) -> tuple[int, ...]:
        return self.use.used if self.use is not None else ()

    def column_cost(self, meas: int) -> float | None:
        """Its column's cost for detection ``meas`` in the matrix the frame was decided over (+inf: it could not
        take it); None when it had no column or the matrix no row for the detection."""
        return next((c for m, c in self.column or () if m == meas), None)


@dataclass(frozen=True, slots=True)
class HypothesisFrame:
    """PMBM's hypotheses of one class after one frame's update: the best kept posterior came from prior
    hypothesis ``best_parent`` (0: the previous best); weights (H,) normalised; members[h] its track ids;
    existence[h] their existences; parents[h] the prior hypothesis of each."""

    best_parent: int
    weights: tuple[float, ...]
    members: tuple[tuple[int, ...], ...]
    existence: tuple[tuple[float, ...], ...]
    parents: tuple[int, ...]

    @property
    def switched(self) -> bool:
        """Whether the best hypothesis descends from another prior hypothesis than the previous best."""
        return self.best_parent != 0

    def holding(self, track_id: int) -> tuple[int, ...]:
        """The hypotheses that hold ``track_id``."""
        return tuple(h for h, ids in enumerate(self.members) if track_id in ids)

    def existence_in(self, h: int, track_id: int) -> float | None:
        ids = self.members[h]
        return self.existence[h][ids.index(track_id)] if track_id in ids else None


@dataclass(slots=True)
class ClassFrame:
    """The events of one class at one frame, by kind (filled while the frame is emitted)."""

    meas: MeasurementsReceived | None = None
    predicted: Predicted | None = None
    gated: Gated | None = None
    costs: dict[int, CostMatrix] = field(default_factory=dict)
    assignment: Assignment | None = None
    marginals: Marginals | None = None
    weights: UpdateWeights | None = None
    born: list[Born] = field(default_factory=list)
    pruned: list[Pruned] = field(default_factory=list)
    merged: list[Merged] = field(default_factory=list)
    logic: list[TrackLogic] = field(default_factory=list)
    posterior: Posterior | None = None
    extracted: Extracted | None = None
    hypotheses: GlobalHypotheses | None = None
    cardinality: Cardinality | None = None
    intensity: IntensityWeights | None = None
    budgets: list[BudgetReached] = field(default_factory=list)

    @property
    def cost(self) -> CostMatrix | None:
        """The cost matrix the frame's assignment was chosen over: that of the assignment's prior hypothesis (PMBM's
        best posterior may come from another prior hypothesis than the first); hypothesis 0's without one."""
        return self.costs.get(self.assignment.hypothesis if self.assignment is not None else 0)

    def born_of(self) -> dict[int, int]:
        """Detection source index -> the id of the track it started this frame."""
        return {
            m: t
            for b in self.born
            for t, m in zip(np.asarray(b.track_ids).tolist(), np.asarray(b.meas_indices).tolist(), strict=True)
        }


_LISTS = {Born: "born", Pruned: "pruned", Merged: "merged", TrackLogic: "logic", BudgetReached: "budgets"}
_ONE = {
    MeasurementsReceived: "meas",
    Predicted: "predicted",
    Gated: "gated",
    Assignment: "assignment",
    Marginals: "marginals",
    UpdateWeights: "weights",
    Posterior: "posterior",
    Extracted: "extracted",
    GlobalHypotheses: "hypotheses",
    Cardinality: "cardinality",
    IntensityWeights: "intensity",
}


class FactSink:
    """Keeps every event of one tracker's run by frame and class (``TrackerFacts`` reads them).

    Put it before the viewer's logger in a ``TeeSink``: the logger reads the facts of a frame when it closes it.
    has_existence: False for a tracker whose tracks have no existence probability (its events carry 1);
    output_only: the run is known by its output alone (a results file, ``gnnpmb.foreign``).
    """

    enabled = True

    def __init__(self, tracker: str, *, has_existence: bool = True, output_only: bool = False) -> None:
        self.facts = TrackerFacts(tracker, has_existence=has_existence and not output_only, output_only=output_only)

    def emit(self, event: Event) -> None:
        self.facts.add(event)


class TrackerFacts:
    """The facts of one tracker run (module docstring): events by frame and class, and what follows from them."""

    def __init__(self, tracker: str, *, has_existence: bool = True, output_only: bool = False) -> None:
        self.tracker = tracker
        self.has_existence = has_existence
        self.output_only = output_only
        """Only the run's output is known (``UseMode.OUTPUT``): nothing here speaks of its update."""
        self.frames: dict[int, dict[str, ClassFrame]] = {}
        """Frame index -> class -> its events."""
        self.started: dict[int, FrameStarted] = {}
        self._frame = -1
        # What was worked out, by frame then class (a frame's entries go when it gets another event).
        self._use: dict[int, dict[str, FrameUse | None]] = {}
        self._decisions: dict[int, dict[str, Decisions | None]] = {}
        self._hypotheses: dict[int, dict[str, HypothesisFrame | None]] = {}
        self._steps: dict[tuple[int, str], dict[int, TrackStep]] = {}
        self._origins: dict[str, dict[int, tuple[int, int]]] = {}

    def add(self, event: Event) -> None:
        """File one event under the current frame (a ``FrameStarted`` opens a frame)."""
        if isinstance(event, FrameStarted):
            self._frame = event.frame_index
            self.started[event.frame_index] = event
            self.frames.setdefault(event.frame_index, {})
            self._forget(event.frame_index)
            return
        kind = type(event)
        if kind is not CostMatrix and kind not in _LISTS and kind not in _ONE:
            raise TypeError(f"TrackerFacts cannot keep {kind.__name__}")
        if self._frame < 0:
            raise RuntimeError(f"{type(event).__name__} emitted before the first FrameStarted")
        by_class = self.frames[self._frame]
        cf = by_class.get(event.class_name)
        if cf is None:
            cf = by_class[event.class_name] = ClassFrame()
        if kind is CostMatrix:
            cf.costs[event.hypothesis] = event
        elif kind in _LISTS:
            getattr(cf, _LISTS[kind]).append(event)
        else:
            setattr(cf, _ONE[kind], event)
        self._forget(self._frame)

    def _forget(self, frame: int) -> None:
        """Drop what was worked out for ``frame`` (it has new events) and every track history (they span it)."""
        for cache in (self._use, self._decisions, self._hypotheses):
            cache.pop(frame, None)
        if self._steps:
            self._steps.clear()
        self._origins.clear()

    # What the events say, per frame and class.
    def frame(self, frame: int, class_name: str) -> ClassFrame | None:
        return self.frames.get(frame, {}).get(class_name)

    @property
    def frame_indices(self) -> list[int]:
        return sorted(self.frames)

    def use(self, frame: int, class_name: str) -> FrameUse | None:
        """How the tracker's update of ``class_name`` at ``frame`` used the detections (module docstring); None
        when the frame had no update event for the class."""
        known = self._use.setdefault(frame, {})
        if class_name not in known:
            cf = self.frame(frame, class_name)
            read = output_use if self.output_only else frame_use
            known[class_name] = None if cf is None else read(cf)
        return known[class_name]

    def mode(self, class_name: str, frames: range) -> UseMode:
        """How the tracker's update used detections in ``frames`` (assignment without any update event; output only
        for a run known by its output)."""
        if self.output_only:
            return UseMode.OUTPUT
        for f in frames:
            use = self.use(f, class_name)
            if use is not None and use.tracks:
                return use.mode
        return UseMode.ASSIGNED

    def destination(self, frame: int, class_name: str, meas: int) -> Destination | None:
        """Where detection ``meas`` went at ``frame`` (None: the tracker of the class did not receive it)."""
        use = self.use(frame, class_name)
        return None if use is None else use.destinations.get(meas)

    def decisions(self, frame: int, class_name: str) -> Decisions | None:
        """The solver's decisions (``explain``) over the cost matrix the frame's assignment was chosen on; None for
        a tracker that chooses no assignment (JPDA, PHD) or a frame without one."""
        known = self._decisions.setdefault(frame, {})
        if class_name not in known:
            cf = self.frame(frame, class_name)
            ok = cf is not None and cf.cost is not None and cf.assignment is not None and cf.marginals is None
            known[class_name] = explain(cf.cost, cf.assignment) if ok else None
        return known[class_name]

    def hypotheses(self, frame: int, class_name: str) -> HypothesisFrame | None:
        """PMBM's hypotheses of the class after ``frame``'s update (None for other trackers)."""
        known = self._hypotheses.setdefault(frame, {})
        if class_name not in known:
            cf = self.frame(frame, class_name)
            h = cf.hypotheses if cf is not None else None
            if h is None:
                known[class_name] = None
            else:
                log_w = np.asarray(h.log_weights, dtype=np.float64)
                weights = np.exp(log_w - np.logaddexp.reduce(log_w)) if log_w.size else log_w
                parent = cf.assignment.hypothesis if cf.assignment is not None else 0
                known[class_name] = HypothesisFrame(parent, tuple(weights.tolist()), h.members, h.existence, h.parents)
        return known[class_name]

    def existed_since(self, track_id: int, class_name: str, upto: int) -> int | None:
        """The first frame up to ``upto`` after whose update a kept PMBM hypothesis held ``track_id`` (None: never,
        or not PMBM) — in any hypothesis, not only the best."""
        for f in self.frame_indices:
            if f > upto:
                break
            h = self.hypotheses(f, class_name)
            if h is not None and h.holding(track_id):
                return f
        return None

    def origin(self, track_id: int, class_name: str) -> tuple[int, int] | None:
        """(frame, detection source index) of the birth that started ``track_id``: what names the same track in
        runs that number their tracks differently (None: no ``Born`` event names it, e.g. a GM-PHD label)."""
        if class_name not in self._origins:
            found: dict[int, tuple[int, int]] = {}
            for f in self.frame_indices:
                cf = self.frame(f, class_name)
                for m, t in (cf.born_of() if cf is not None else {}).items():
                    found.setdefault(t, (f, m))
            self._origins[class_name] = found
        return self._origins[class_name].get(track_id)

    def output(self, frame: int, class_name: str) -> tuple[TrackEstimate, ...]:
        cf = self.frame(frame, class_name)
        return cf.extracted.estimates if cf is not None and cf.extracted is not None else ()

    # One track over time.
    def steps(self, track_id: int, class_name: str) -> dict[int, TrackStep]:
        """Frame -> the track's ``TrackStep`` at every frame it appears in the events."""
        key = (track_id, class_name)
        if key not in self._steps:
            self._steps[key] = {
                f: step for f in self.frame_indices if (step := self._step(track_id, class_name, f)) is not None
            }
        return self._steps[key]

    def _step(self, t: int, class_name: str, f: int) -> TrackStep | None:
        cf = self.frame(f, class_name)
        if cf is None:
            return None
        prior_r = xy = None
        if cf.predicted is not None:  # a GM-PHD / CPHD label has a row per component: its heaviest one
            row = _heaviest_row(cf.predicted.track_ids, cf.predicted.existence, t)
            if row is not None:
                prior_r = float(cf.predicted.existence[row])
                xy = (float(cf.predicted.mean[row, 0]), float(cf.predicted.mean[row, 1]))
        gated: tuple[tuple[int, float], ...] = ()
        if cf.gated is not None:
            row = _row_of(cf.gated.track_ids, t)
            if row is not None:
                inside = np.flatnonzero(np.asarray(cf.gated.inside)[row])
                d2 = np.asarray(cf.gated.d2)[row, inside]
                order = np.argsort(d2, kind="stable")
                refs = np.asarray(cf.gated.meas_indices)[inside][order]
                gated = tuple(zip(refs.tolist(), d2[order].tolist(), strict=True))
                if xy is None:
                    xy = (float(cf.gated.center_xy[row, 0]), float(cf.gated.center_xy[row, 1]))
        frame_use = self.use(f, class_name)
        use = frame_use.tracks.get(t) if frame_use is not None else None
        born = {track: m for m, track in cf.born_of().items()}
        posterior_r = None
        if cf.posterior is not None:
            row = _row_of(cf.posterior.track_ids, t)
            if row is not None:
                posterior_r = float(cf.posterior.existence[row])
        if cf.intensity is not None:  # GM-PHD / CPHD: the label's heaviest weight, not the Posterior's min(w, 1)
            mine = np.asarray(cf.intensity.weights)[np.asarray(cf.intensity.labels) == t]
            if mine.size:
                posterior_r = float(mine.max())
        output = next((e for e in self.output(f, class_name) if e.track_id == t), None)
        ended = _ending(cf, t)
        if prior_r is None and posterior_r is None and output is None and ended is None and t not in born:
            return None
        hyp = self.hypotheses(f, class_name)
        decided = marginal = None
        if hyp is not None:
            marginal = _marginal(hyp, t)
            if hyp.best_parent != 0:
                decided = _decided_existence(cf, t)
        column = scale = None
        matrix = cf.cost
        if matrix is not None:
            cols = [k for k, c in enumerate(matrix.cols) if c.kind is AxisKind.TRACK and c.ref == t]
            if cols:
                refs = [int(r.ref) for r in matrix.rows]
                column = tuple(zip(refs, np.asarray(matrix.cost)[:, cols[0]].tolist(), strict=True))
                scale = matrix.scale
        return TrackStep(
            frame=f,
            prior_existence=prior_r,
            predicted_xy_m=xy,
            gated=gated,
            use=use,
            born_from=born.get(t),
            posterior_existence=posterior_r if ended is None else None,
            output=output,
            ended=ended,
            decided_existence=decided,
            marginal_existence=marginal,
            column=column,
            column_scale=scale,
        )

    def track_ids(self, class_name: str, frames: Iterable[int] | None = None) -> set[int]:
        """Every track id of ``class_name`` named in a predicted, posterior or output set (of ``frames``)."""
        out: set[int] = set()
        for f in self.frame_indices if frames is None else frames:
            cf = self.frame(f, class_name)
            if cf is None:
                continue
            for ev in (cf.predicted, cf.posterior):
                if ev is not None:
                    out.update(np.asarray(ev.track_ids).tolist())
            out.update(e.track_id for e in self.output(f, class_name))
        return out


def _row_of(ids: np.ndarray, t: int) -> int | None:
    hit = np.flatnonzero(np.asarray(ids) == t)
    return int(hit[0]) if hit.size else None


def _heaviest_row(ids: np.ndarray, weights: np.ndarray, t: int) -> int | None:
    """The row of ``t`` with the largest weight (a track's only row; a PHD label's heaviest component)."""
    hit = np.flatnonzero(np.asarray(ids) == t)
    return int(hit[np.argmax(np.asarray(weights)[hit])]) if hit.size else None


def _ending(cf: ClassFrame, t: int) -> TrackEnd | None:
    """How track ``t`` ended in this frame's events, None if it did not."""
    for p in cf.pruned:
        if p.track_id == t:
            if p.reason is PruneReason.TRACK_LOGIC:
                logic = next((e for e in cf.logic if e.track_id == t and e.action is TrackLogicAction.DELETED), None)
                hits, window = (logic.hits, logic.window) if logic is not None else (-1, -1)
                return TrackEnd(Ending.DELETED, p.reason, p.last_existence, hits, window)
            ending = Ending.MERGED if p.reason is PruneReason.MERGED else Ending.PRUNED
            return TrackEnd(ending, p.reason, p.last_existence)
    for e in cf.logic:
        if e.track_id == t and e.action is TrackLogicAction.DELETED:
            return TrackEnd(Ending.DELETED, PruneReason.TRACK_LOGIC, 1.0, e.hits, e.window)
    return None


def _marginal(hyp: HypothesisFrame, t: int) -> float:
    """sum_h w_h r_h(t) over the kept hypotheses (0 where one does not hold the track)."""
    total = 0.0
    for w, ids, existence in zip(hyp.weights, hyp.members, hyp.existence, strict=True):
        if t in ids:
            total += w * existence[ids.index(t)]
    return total


def _decided_existence(cf: ClassFrame, t: int) -> float | None:
    """Track ``t``'s predicted existence in the cost matrix its frame's assignment was chosen over (PMBM: the best
    posterior's parent hypothesis)."""
    matrix = cf.cost
    if matrix is None or matrix.terms is None or matrix.terms.existence is None:
        return None
    col = matrix.terms.column_of(t)
    return None if col is None else float(matrix.terms.existence[col])


def frame_use(cf: ClassFrame) -> FrameUse | None:
    """How the update of one class and frame used its detections (``TrackerFacts.use``), from the richest event
    it emitted: ``Marginals`` (a soft update), else ``UpdateWeights`` (PHD), else ``Assignment``."""
    received = np.asarray(cf.meas.meas_indices).tolist() if cf.meas is not None else []
    born = cf.born_of()
    if cf.marginals is not None:
        return _from_marginals(cf.marginals, received, born)
    if cf.weights is not None:
        return _from_weights(cf.weights, born)
    if cf.assignment is not None:
        return _from_assignment(cf, received, born)
    if not received:
        return None
    return FrameUse(UseMode.ASSIGNED, {}, {m: _new(m, born) for m in received})


def output_use(cf: ClassFrame) -> FrameUse | None:
    """An output-only run (``UseMode.OUTPUT``): each output track "used" the detection its box sits on
    (``TrackEstimate.meas_index``; share 1, none: missed 1); a detection went to the track whose box sits on it
    (the lowest id when several do), else under no output box: ``track_id`` then names the nearest box of the
    class within ``foreign.NEAREST_M`` of it (a box that sat on another detection), -1 for none."""
    if cf.extracted is None:
        return None
    tracks: dict[int, Use] = {}
    destinations: dict[int, Destination] = {}
    for e in sorted(cf.extracted.estimates, key=lambda e: e.track_id):
        on = e.meas_index >= 0
        tracks[e.track_id] = Use(((e.meas_index, 1.0),) if on else (), 0.0 if on else 1.0, UseMode.OUTPUT)
        if on:
            destinations.setdefault(e.meas_index, Destination(e.meas_index, Went.TRACK, e.track_id))
    received = np.asarray(cf.meas.meas_indices).tolist() if cf.meas is not None else []
    boxes = sorted(cf.extracted.estimates, key=lambda e: e.track_id)
    for j, m in enumerate(received):
        if m not in destinations:
            destinations[m] = Destination(m, Went.NO_OUTPUT, _box_beside(boxes, np.asarray(cf.meas.xyz_m)[j, :2]))
    return FrameUse(UseMode.OUTPUT, tracks, destinations)


def _box_beside(boxes: Sequence[TrackEstimate], xy_m: np.ndarray) -> int:
    """The track whose box centre lies nearest ``xy_m`` (2,), BEV, within ``foreign.NEAREST_M``; -1: none."""
    near = [(math.dist(e.translation_m[:2], xy_m), e.track_id) for e in boxes]
    near = [x for x in near if x[0] < NEAREST_M]
    return min(near)[1] if near else -1


def _new(m: int, born: Mapping[int, int], share: float = 1.0) -> Destination:
    t = born.get(m)
    return Destination(m, Went.NEW_TRACK, t, share) if t is not None else Destination(m, Went.NEW, -1, share)


def _from_assignment(cf: ClassFrame, received: list[int], born: Mapping[int, int]) -> FrameUse:
    assignment = cf.assignment
    tracks: dict[int, Use] = {}
    destinations: dict[int, Destination] = {}
    for row, col in assignment.pairs:
        m = int(row.ref)
        if col.kind is AxisKind.TRACK:
            tracks[int(col.ref)] = Use(((m, 1.0),), 0.0, UseMode.ASSIGNED)
            destinations[m] = Destination(m, Went.TRACK, int(col.ref))
        else:
            destinations[m] = _new(m, born)
    for t in assignment.missed_track_ids:
        tracks.setdefault(int(t), Use((), 1.0, UseMode.ASSIGNED))
    for m in received:
        destinations.setdefault(m, _new(m, born))
    return FrameUse(UseMode.ASSIGNED, tracks, destinations)


def _from_marginals(marg: Marginals, received: list[int], born: Mapping[int, int]) -> FrameUse:
    """Rows: tracks; columns: [MISSED, detections...] (JPDA, TO-PMB; rows sum to 1)."""
    probs = np.asarray(marg.probs, dtype=np.float64)
    cols = list(marg.cols)
    missed_col = next((k for k, c in enumerate(cols) if c.kind is AxisKind.MISSED), None)
    meas_cols = [(k, int(c.ref)) for k, c in enumerate(cols) if c.kind is AxisKind.MEASUREMENT]
    tracks: dict[int, Use] = {}
    for i, row in enumerate(marg.rows):
        shares = sorted(
            ((m, float(probs[i, k])) for k, m in meas_cols if probs[i, k] >= USED_SHARE), key=lambda x: (-x[1], x[0])
        )
        missed = float(probs[i, missed_col]) if missed_col is not None else 0.0
        tracks[int(row.ref)] = Use(tuple(shares), missed, UseMode.PROBABILITIES)
    destinations: dict[int, Destination] = {}
    track_ids = [int(r.ref) for r in marg.rows]
    for k, m in meas_cols:
        column = probs[:, k] if probs.size else np.zeros(0)
        p_new = max(0.0, 1.0 - float(column.sum()))
        best = int(np.argmax(column)) if column.size else -1
        if best >= 0 and column[best] > p_new:
            destinations[m] = Destination(m, Went.TRACK, track_ids[best], float(column[best]))
        else:
            destinations[m] = _new(m, born, p_new)
    for m in received:
        destinations.setdefault(m, _new(m, born))
    return FrameUse(UseMode.PROBABILITIES, tracks, destinations)


def _from_weights(w: UpdateWeights, born: Mapping[int, int]) -> FrameUse:
    """GM-PHD / CPHD: a label's share of detection j is detected[k, j] / (missed[k] + sum_j detected[k, j]); a
    detection went to the label that took most of it, or to its birth component, whichever holds more."""
    detected = np.asarray(w.detected, dtype=np.float64)
    missed = np.asarray(w.missed, dtype=np.float64)
    refs = np.asarray(w.meas_indices).tolist()
    labels = np.asarray(w.labels).tolist()
    tracks: dict[int, Use] = {}
    for i, t in enumerate(labels):
        total = float(missed[i] + detected[i].sum())
        if total <= 0.0 or t < 0:
            continue
        shares = sorted(
            ((m, float(detected[i, j] / total)) for j, m in enumerate(refs) if detected[i, j] / total >= USED_SHARE),
            key=lambda x: (-x[1], x[0]),
        )
        tracks[t] = Use(tuple(shares), float(missed[i] / total), UseMode.WEIGHTS)
    destinations: dict[int, Destination] = {}
    birth = np.asarray(w.birth, dtype=np.float64)
    for j, m in enumerate(refs):
        column = detected[:, j] if detected.size else np.zeros(0)
        best = int(np.argmax(column)) if column.size else -1
        if best >= 0 and column[best] > birth[j] and labels[best] > 0:
            destinations[m] = Destination(m, Went.TRACK, labels[best], float(column[best]))
        else:
            destinations[m] = _new(m, born, float(birth[j]))
    return FrameUse(UseMode.WEIGHTS, tracks, destinations)
