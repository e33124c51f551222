"""From a failure to its ``Finding``: what happened to the object and the tracks around it, and whose doing it was.

``explain_failure`` reads four independent sources and nothing else: the failure report (the devkit's matching
and how it evaluated each object and track, ``eval.evaluated``), the tracker's facts (its events, ``facts``), its
run (the detections it was given and the boxes it output) and the scene's annotations. The stated tests of
``findings`` decide the ``Blame``; the finding keeps the facts each test used, so the text (``words``) and the
checks (``claims``) read the same data.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Iterator, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from types import MappingProxyType

import numpy as np

from gnnpmb.data.boxes3d import containing_box, in_footprint
from gnnpmb.data.scene import SceneData
from gnnpmb.eval.evaluated import GtFrame, GtStatus, TrackEval
from gnnpmb.eval.failures import Failure, FailureKind, FailureReport
from gnnpmb.events import AxisKind, CostMatrix
from gnnpmb.explain import PairChoice
from gnnpmb.foreign import BoxOn
from gnnpmb.pipeline import FrameResult, TrackingRun
from gnnpmb.types import Boxes, TrackEstimate
from gnnpmb.why.counterfactual import would_take
from gnnpmb.why.facts import TrackerFacts, TrackStep, UseMode, Went
from gnnpmb.why.findings import (
    EVALUATED_OFFSET_M,
    FRAMES_BEFORE,
    NEAR_M,
    OFF_NEAR_M,
    Blame,
    Deciding,
    EvaluatedReach,
    FalseOutput,
    Finding,
    HypothesisSwitch,
    HypothesisTrack,
    KeyDecision,
    LostTrack,
    MatchedAway,
    Near,
    OffObject,
    OnObject,
    Origin,
    OtherRun,
    Rule,
    Sighting,
    covering,
)
from gnnpmb.why.untracked import untracked_by_token, untracked_detections, untracked_name_near, untracked_on

_ON_IT_RULES = (Rule.TRACK_DROPPED, Rule.NOT_COUNTED, Rule.COVERED_TWO)
"""The tests about tracks output on an object the evaluation still missed (``_Context.blame_uncovered``)."""

LOST_AND_TAKER = {
    FailureKind.ID_SWITCH: (0, 1),
    FailureKind.IDENTITY_THEFT: (1, 0),
    FailureKind.FRAGMENTATION: (0, None),
}
"""Per failure kind whose object a track lost: the positions in ``Failure.track_ids`` of that track and of the
track that took the object over (None: none did)."""


@dataclass(frozen=True, slots=True)
class Evidence:
    """What ``explain_failure`` reads: a tracker's failure report, facts and run on one scene; for a run known by
    its output only (a results file), how each of its boxes was placed on a detection, by (frame, track id)
    (``gnnpmb.foreign.box_on``)."""

    report: FailureReport
    facts: TrackerFacts
    run: TrackingRun
    boxes_on: Mapping[tuple[int, int], BoxOn] = field(default_factory=dict)
    detections_path: Path | None = None
    """The detection file the run read (None: simulated): its boxes of untracked names are read from it."""

    @property
    def tracker(self) -> str:
        return self.run.tracker


def explain_failure(
    failure_id: str,
    evidence: Evidence,
    scene: SceneData,
    others: Sequence[Evidence] = (),
    first_frame: int | None = None,
) -> Finding:
    """The ``Finding`` of the failure ``failure_id`` of ``evidence`` (raises KeyError for an unknown id).

    others: other trackers' evidence on the same detections (their failures at the same place become
    ``OtherRun`` evidence); first_frame: the first frame to look at (default ``FRAMES_BEFORE`` before the
    failure, within the run)."""
    failure = evidence.report.by_id(failure_id)
    if failure is None:
        raise KeyError(failure_id)
    start = first_frame if first_frame is not None else failure.frame_index - FRAMES_BEFORE
    ctx = _Context(evidence, scene, failure.frame_index, failure.class_name, start, failure)
    return ctx.finding(failure_id, others)


class _Context:
    """The failure, its sources and the frames looked at, with the lookups every part of a finding shares."""

    untracked: Mapping[str, Boxes] = MappingProxyType({})
    """Per sample token, the annotations of categories the evaluation does not track (``gnnpmb.why.untracked``)."""

    def __init__(
        self,
        evidence: Evidence,
        scene: SceneData,
        frame: int,
        class_name: str,
        first_frame: int,
        failure: Failure | None = None,
    ) -> None:
        self.evidence, self.scene = evidence, scene
        self.failure: Failure = failure  # type: ignore[assignment]  # only the finding's parts read it
        self.report, self.facts = evidence.report, evidence.facts
        self.frames: dict[int, FrameResult] = {fr.keyframe.index: fr for fr in evidence.run.frames}
        self.f = frame
        self.class_name = class_name
        self.window = range(max(min(self.frames), first_frame), frame + 1)
        self.threshold = self.report.threshold_of(self.class_name)
        self.untracked: Mapping[str, Boxes] = untracked_by_token(scene)

    # The object.
    def gt_xy(self, gt_id: str, frame: int) -> np.ndarray | None:
        """(2,) annotated BEV centre of ``gt_id`` at ``frame`` (None: not annotated there)."""
        gt = self.scene.keyframes[frame].gt
        hit = np.flatnonzero(gt.instance_id.astype(str) == gt_id) if len(gt) else np.zeros(0, int)
        return None if hit.size == 0 else np.asarray(gt.translation_m[hit[0], :2], dtype=np.float64)

    def points(self, gt_id: str, frame: int) -> int:
        gt = self.scene.keyframes[frame].gt
        hit = np.flatnonzero(gt.instance_id.astype(str) == gt_id)
        return int(self.scene.keyframes[frame].gt_num_pts[hit[0]]) if hit.size else 0

    def radar_points(self, gt_id: str, frame: int) -> int:
        """The radar returns among ``points`` (0 where the dataset gives none)."""
        kf = self.scene.keyframes[frame]
        hit = np.flatnonzero(kf.gt.instance_id.astype(str) == gt_id)
        return int(kf.gt_num_radar_pts[hit[0]]) if hit.size and kf.gt_num_radar_pts is not None else 0

    def near(
        self, frame: int, xy: np.ndarray, *, own: bool, kept_only: bool = True, neighbours: bool = False
    ) -> Near | None:
        """The nearest detection within ``NEAR_M`` of ``xy`` at ``frame``: any class and score (own False), or one of
        the failure's class (own True) that preprocessing kept (kept_only) or removed (not kept_only). Of any class,
        a detection that lies nearer no other annotated object comes first (``Near.on_other``); of the failure's
        class, one nearer another annotated object is that object's, not this one's, and is returned only when
        ``neighbours`` asks for those alone (dev set scene-0916 centerpoint: two pedestrians 0.78 m apart had one
        box, 0.28 m from one of them, and the other's miss was said to be the tracker's, who had no detection to
        keep it by)."""
        fr = self.frames.get(frame)
        if fr is None:
            return None
        boxes, kept = fr.detections.boxes, np.asarray(fr.detections.kept)
        if not len(boxes):
            return None
        d = np.hypot(*(boxes.translation_m[:, :2] - xy).T)
        ok = d < NEAR_M
        if own:
            ok &= (kept if kept_only else ~kept) & (boxes.class_name == self.class_name)
        if not ok.any():
            return None
        idx = np.flatnonzero(ok)
        other = self.nearer_object(frame, boxes.translation_m[idx, :2], d[idx])
        if own:  # its own, or (neighbours) only those nearer another object
            keep = [i for i in range(idx.size) if (other[i] is not None) == neighbours]
            if not keep:
                return None
            idx, other = idx[keep], [other[i] for i in keep]
        else:  # audit truth51 (world7, a rider): a box of another class on an object of that class is its
            other = [o if o is not None else self.of_its_class(frame, int(m)) for m, o in zip(idx, other, strict=True)]
        k = min(range(idx.size), key=lambda i: (other[i] is not None, d[idx[i]]))
        m = int(idx[k])
        return Near(m, str(boxes.class_name[m]), float(boxes.score[m]), float(d[m]), bool(kept[m]), other[k])

    def of_its_class(self, frame: int, meas: int) -> tuple[str, str, float] | None:
        """The nearest annotated object of detection ``meas``'s class within ``NEAR_M`` of it, when that class is
        not the failure's: the detection is that object's (the evaluation would match it there), not a sight of
        another class's object (world7: a rider annotated as a bicycle and a pedestrian on one spot; the bicycle's
        box was said to be the pedestrian seen as the wrong class)."""
        boxes, gt = self.frames[frame].detections.boxes, self.scene.keyframes[frame].gt
        c = str(boxes.class_name[meas])
        if c == self.class_name or not len(gt):
            return None
        d = np.hypot(*(gt.translation_m[:, :2] - boxes.translation_m[meas, :2]).T)
        mine = np.flatnonzero((gt.class_name == c) & (d < NEAR_M))
        if not mine.size:
            return None
        g = int(mine[np.argmin(d[mine])])
        return str(gt.instance_id[g]), c, float(d[g])

    def nearer_object(self, frame: int, xy_m: np.ndarray, own_m: np.ndarray) -> list[tuple[str, str, float] | None]:
        """For each of N detections at ``xy_m`` (N, 2), ``own_m`` (N,) from the object: the annotated object of a
        tracked class (id, class, m) nearest it when that one lies nearer than the object, else None."""
        gt = self.scene.keyframes[frame].gt
        if not len(gt):
            return [None] * len(own_m)
        d = np.hypot(*(gt.translation_m[None, :, :2] - xy_m[:, None, :]).transpose(2, 0, 1))  # (N, G)
        k = np.argmin(d, axis=1)
        return [
            (str(gt.instance_id[g]), str(gt.class_name[g]), float(d[i, g])) if d[i, g] < own_m[i] - 1e-6 else None
            for i, g in enumerate(k.tolist())
        ]

    def on_object(self, report: FailureReport, fr: FrameResult | None, xy: np.ndarray) -> tuple[OnObject, ...]:
        """The tracks of the failure's class output within ``NEAR_M`` of ``xy`` in ``fr``."""
        if fr is None:
            return ()
        threshold = report.threshold_of(self.class_name)
        out = []
        for e in fr.estimates:
            if e.class_name != self.class_name:
                continue
            d = float(np.hypot(e.translation_m[0] - xy[0], e.translation_m[1] - xy[1]))
            if d < NEAR_M:
                evaluated = report.track_evals.get(str(e.track_id))
                false_here = self.false_at(report, fr.keyframe.index, e.track_id)
                xy_m = (float(e.translation_m[0]), float(e.translation_m[1]))
                matched = evaluated.matched_at(fr.keyframe.index) if evaluated is not None else None
                there = self.gt_xy(matched, fr.keyframe.index) if matched is not None else None
                matched_m = None if there is None else math.dist(xy_m, (float(there[0]), float(there[1])))
                out.append(
                    OnObject(e.track_id, d, e.score, e.meas_index, evaluated, threshold, false_here, xy_m, matched_m)
                )
        return tuple(sorted(out, key=lambda o: o.distance_m))

    def sightings(self, gt_id: str) -> tuple[Sighting, ...]:
        out = []
        for f in self.window:
            xy = self.gt_xy(gt_id, f)
            if xy is None or f not in self.frames:
                continue
            own = self.near(f, xy, own=True)
            went = self.facts.destination(f, self.class_name, own.meas) if own is not None else None
            any_near = self.near(f, xy, own=False)
            box = self.in_box(f, gt_id) if any_near is None else None
            out.append(
                Sighting(
                    f,
                    self.points(gt_id, f),
                    self.report.gt_frame(gt_id, f),
                    any_near,
                    own,
                    went,
                    self.on_object(self.report, self.frames[f], xy),
                    self.near(f, xy, own=True, kept_only=False),
                    self.radar_points(gt_id, f),
                    box,
                    self.off_near(f, gt_id) if any_near is None and box is None else None,
                    neighbours_own=self.near(f, xy, own=True, neighbours=True),
                    untracked_name=self.untracked_name(f, xy) if any_near is None and box is None else None,
                )
            )
        return tuple(out)

    # The finding.
    def finding(self, failure_id: str, others: Sequence[Evidence]) -> Finding:
        failure, kind = self.failure, self.failure.kind
        gt_id = self.object_of()
        if kind in LOST_AND_TAKER and gt_id is not None:  # look back to where the lost track last had the object
            held = self.held_until(int(failure.track_ids[LOST_AND_TAKER[kind][0]]), gt_id)
            if held is not None:
                self.window = range(max(min(self.frames), min(self.window.start, held + 1)), self.window.stop)
        sightings = self.sightings(gt_id) if gt_id is not None else ()
        parts: dict = {}
        if kind in LOST_AND_TAKER:
            parts = self.lost_object(gt_id, sightings, self.involved(sightings))
        elif kind is FailureKind.FALSE_TRACK:
            parts = self.false_track()
        elif kind is FailureKind.MISS:
            parts = self.miss(sightings)
        elif kind is FailureKind.COALESCENCE:
            parts = self.coalescence(sightings)
        else:
            raise AssertionError(kind)
        if gt_id is not None and self.gt_xy(gt_id, self.f) is None:  # scored where it had no annotation
            parts["blame"] = (Blame(Rule.UNANNOTATED, (self.f,)), *parts.get("blame", ()))
        involved = self.involved(sightings)
        boxes_on = self.boxes_on(sightings, parts) if self.facts.output_only else ()
        return Finding(
            failure_id=failure_id,
            kind=kind,
            tracker=self.evidence.tracker,
            frame=self.f,
            class_name=self.class_name,
            gt_id=gt_id,
            track_ids=tuple(int(t) for t in failure.track_ids),
            window=(self.window.start, self.window.stop - 1),
            sightings=sightings,
            mode=self.facts.mode(self.class_name, self.window).value,
            has_existence=self.facts.has_existence,
            key_decisions=self.key_decisions(involved),
            others=self.others(others, gt_id),
            reach=self.reach(gt_id, parts["blame"]),
            boxes_on=boxes_on,
            unscored=any(c.class_name == self.class_name and c.threshold is None for c in self.report.classes),
            **parts,
        )

    def boxes_on(self, sightings: tuple[Sighting, ...], parts: dict) -> tuple[tuple[int, int, BoxOn], ...]:
        """For a run known by its output only: how each output box the finding names was placed on a detection,
        as (frame, track id, ``BoxOn``)."""
        named = {(s.frame, o.track_id) for s in sightings for o in s.on_it}
        lost: LostTrack | None = parts.get("lost")
        if lost is not None:
            named |= {(s.frame, lost.track_id) for s in lost.steps if s.output is not None}
        false: FalseOutput | None = parts.get("false_output")
        if false is not None and false.between is None:
            named.add((self.f, false.track_id))
        known = self.evidence.boxes_on
        return tuple((f, t, known[(f, t)]) for f, t in sorted(named) if (f, t) in known)

    def reach(self, gt_id: str | None, blame: tuple[Blame, ...]) -> EvaluatedReach | None:
        """With the blame ``INTERPOLATED``: the tracks within reach of the evaluated and of the annotated box."""
        if gt_id is None or not any(b.rule is Rule.INTERPOLATED for b in blame):
            return None
        return self.reach_of(self.report.gt_frame(gt_id, self.f), gt_id)

    def reach_of(self, g: GtFrame | None, gt_id: str | None) -> EvaluatedReach | None:
        """The tracks within reach of the box the evaluation scored object ``gt_id`` at (``g``) and of its annotated
        box (None: it scored no box there). A track on the annotation that the evaluation matched there to another
        object whose box lies nearer the track is that object's, not one the interpolation put out of reach: with the
        box where it belongs the devkit would still match it there (independent audit truth46, dev set scene-0655
        centerpoint immortal miss:18, track 8 1.2 m from the annotation and 0.1 m from the pedestrian beside it)."""
        fr = self.frames.get(g.frame) if g is not None else None
        if g is None or g.evaluated_xy_m is None or fr is None:
            return None
        evaluated = self.on_object(self.report, fr, np.asarray(g.evaluated_xy_m))
        annotated = self.on_object(self.report, fr, np.asarray(g.annotated_xy_m))
        return EvaluatedReach(
            g.offset_m,
            tuple(o.track_id for o in evaluated),
            tuple(o.track_id for o in annotated if not self.neighbours(o, g.frame, gt_id)),
        )

    def neighbours(self, o: OnObject, frame: int, gt_id: str | None) -> bool:
        """Whether the evaluation matched track ``o`` at ``frame`` to an object other than ``gt_id`` whose
        evaluated box lies nearer the track than ``gt_id``'s annotation does."""
        other = o.evaluated.matched_at(frame) if o.evaluated is not None else None
        if other is None or other == gt_id or o.xy_m is None:
            return False
        g = self.report.gt_frame(other, frame)
        if g is None or g.evaluated_xy_m is None:
            return False
        return math.hypot(o.xy_m[0] - g.evaluated_xy_m[0], o.xy_m[1] - g.evaluated_xy_m[1]) < o.distance_m

    def involved(self, sightings: tuple[Sighting, ...]) -> set[int]:
        """The failure's own tracks and every track output on the object in the window."""
        return {int(t) for t in self.failure.track_ids} | {o.track_id for s in sightings for o in s.on_it}

    def object_of(self) -> str | None:
        """The failure's object: the missed one of a coalescence, the object of the others, and for a false track
        the object of its class nearest its box as evaluated within ``NEAR_M`` (None if none)."""
        failure = self.failure
        if failure.kind is FailureKind.COALESCENCE:
            return failure.gt_ids[1]
        if failure.gt_ids:
            return failure.gt_ids[0]
        box = next((b for b in failure.boxes if b.role == "false track"), None)
        if box is None:
            return None
        gt = self.scene.keyframes[self.f].gt
        mine = np.flatnonzero(gt.class_name == self.class_name) if len(gt) else np.zeros(0, int)
        if not mine.size:
            return None
        d = np.hypot(*(gt.translation_m[mine, :2] - np.asarray(box.translation_m[:2])).T)
        k = int(np.argmin(d))
        return str(gt.instance_id[mine[k]]) if d[k] < NEAR_M else None

    def estimate(self, track_id: int, frame: int) -> TrackEstimate | None:
        fr = self.frames.get(frame)
        return next((e for e in fr.estimates if e.track_id == track_id), None) if fr is not None else None

    def held_until(self, track_id: int, gt_id: str) -> int | None:
        """The last frame before the failure at which ``track_id`` was output within ``NEAR_M`` of the object."""
        for f in sorted((f for f in self.frames if f < self.f), reverse=True):
            e, xy = self.estimate(track_id, f), self.gt_xy(gt_id, f)
            if e is not None and xy is not None and np.hypot(*(np.asarray(e.translation_m[:2]) - xy)) < NEAR_M:
                return f
        return None

    def lost_object(self, gt_id: str, sightings: tuple[Sighting, ...], involved: set[int]) -> dict:
        """ID switch, identity theft, fragmentation: the lost track, the taker, the deciding choice or hypothesis
        switch, and the blame over the deciding frames."""
        lost_at, took_at = LOST_AND_TAKER[self.failure.kind]
        lost_id = int(self.failure.track_ids[lost_at])
        taker_id = int(self.failure.track_ids[took_at]) if took_at is not None else None
        held = self.held_until(lost_id, gt_id)
        deciding = tuple(range((held + 1) if held is not None else self.f, self.f + 1))
        lost = self.lost_track(lost_id, gt_id, held)
        taker = self.origin(taker_id) if taker_id is not None else None
        blame = self.blame_lost(sightings, deciding, lost)
        decision = self.deciding(lost_id, taker_id, involved) if taker_id is not None else None
        switch = self.switch({lost_id, *([taker_id] if taker_id is not None else [])}, deciding)
        return {
            "deciding": deciding,
            "blame": blame,
            "lost": lost,
            "taker": taker,
            "decision": decision,
            "switch": switch,
        }

    def lost_track(self, track_id: int, gt_id: str, held: int | None) -> LostTrack:
        steps = self.facts.steps(track_id, self.class_name)
        in_window = tuple(steps[f] for f in self.window if f in steps)
        off = None
        e, xy = self.estimate(track_id, self.f), self.gt_xy(gt_id, self.f)
        if e is not None and xy is not None:
            gap = float(np.hypot(*(np.asarray(e.translation_m[:2]) - xy)))
            if gap >= NEAR_M:
                earlier = []
                for s in in_window:
                    at, fr = self.gt_xy(gt_id, s.frame), self.frames.get(s.frame)
                    if s.frame >= self.f or at is None or fr is None:
                        continue
                    boxes = fr.detections.boxes
                    earlier += [(s.frame, m) for m in s.used if np.hypot(*(boxes.translation_m[m, :2] - at)) >= NEAR_M]
                g = self.report.gt_frames.get(gt_id, {}).get(self.f)
                scored = None
                if g is not None and g.status is GtStatus.INTERPOLATED and g.evaluated_xy_m is not None:
                    scored = float(np.hypot(*(np.asarray(e.translation_m[:2]) - g.evaluated_xy_m)))
                off = OffObject(gap, e.meas_index, tuple(earlier), scored)
        elsewhere = tuple(f for f in self.window if f not in steps and self.has_column(f, track_id))
        evaluated = self.report.track_evals.get(str(track_id))
        finite = self.finite_elsewhere(track_id, steps)
        matched = self.matched_until(gt_id)
        away = matched_away(evaluated, gt_id, matched, self.f)
        nothing = tuple(
            (s.frame, m)
            for s in in_window
            for m in s.used
            if self.of_no_object(s.frame, m) and self.meas_part_of(s.frame, m) is None
        )
        return LostTrack(
            track_id, held, in_window, off, evaluated, self.threshold, elsewhere, finite, matched, away, nothing
        )

    def matched_until(self, gt_id: str) -> int | None:
        """The last frame before the failure at which the evaluation matched object ``gt_id`` to a track: it scored
        a box of the object there (annotated or interpolated) and had no MISS of it. The devkit matches every
        scored object it does not miss (CLEAR-MOT), and an ID switch, identity theft or fragmentation is about the
        track of that last match (its accumulator's memory), so for a lost object this is the lost track's last
        match on it (None: the evaluation matched it at no earlier frame, or evaluated no earlier frame)."""
        missed = {f.frame_index for f in self.report.of_kind(FailureKind.MISS) if gt_id in f.gt_ids}
        first = self.report.frames[0] if self.report.frames is not None else 0
        scored = [
            x
            for x, g in self.report.gt_frames.get(gt_id, {}).items()
            if first <= x < self.f and g.evaluated_xy_m is not None and x not in missed
        ]
        # frames the object has no annotation at (it left view and came back): the devkit scores a box it
        # interpolated there and its accumulator's matches are the only record of them
        unannotated = [
            x
            for ev in self.report.track_evals.values()
            for x, g in ev.matches
            if g == gt_id and first <= x < self.f and x not in self.report.gt_frames.get(gt_id, {})
        ]
        return max(scored + unannotated, default=None)

    def finite_elsewhere(self, track_id: int, steps: Mapping[int, TrackStep]) -> tuple[tuple[int, int], ...]:
        """(frame, detection) pairs of the window that track ``track_id`` could not take in its step's matrix (an
        infinite cost) but another hypothesis's matrix gave a finite cost."""
        out = []
        for f in self.window:
            cf, step = self.facts.frames.get(f, {}).get(self.class_name), steps.get(f)
            if cf is None or step is None:
                continue
            for m in cf.costs.values():
                cols = [k for k, c in enumerate(m.cols) if c.kind is AxisKind.TRACK and int(c.ref) == track_id]
                for i, r in enumerate(m.rows) if cols else ():
                    own = step.column_cost(int(r.ref))
                    if own is not None and not math.isfinite(own) and math.isfinite(float(m.cost[i, cols[0]])):
                        out.append((f, int(r.ref)))
        return tuple(sorted(set(out)))

    def has_column(self, frame: int, track_id: int) -> bool:
        """Whether any cost matrix of ``frame`` (any hypothesis) has a column of track ``track_id``."""
        cf = self.facts.frames.get(frame, {}).get(self.class_name)
        matrices = cf.costs.values() if cf is not None else ()
        return any(c.kind is AxisKind.TRACK and int(c.ref) == track_id for m in matrices for c in m.cols)

    def origin(self, track_id: int) -> Origin:
        """Where ``track_id`` came from: the detection that started it and when; its false frames before the
        failure (the evaluation matched it to no object)."""
        steps = self.facts.steps(track_id, self.class_name)
        born = next(((f, s.born_from) for f, s in sorted(steps.items()) if s.born_from is not None), None)
        since = self.facts.existed_since(track_id, self.class_name, self.f)
        if born is None or (since is not None and since < born[0]):
            # started in a PMBM hypothesis other than the best (no Born event names it), or before the facts
            born = (since if since is not None else min(steps, default=-1), -1)
        false = tuple(
            sorted(
                {
                    f.frame_index
                    for f in self.report.of_kind(FailureKind.FALSE_TRACK)
                    if str(track_id) in f.track_ids and f.frame_index < self.f
                }
            )
        )
        if self.failure.kind is not FailureKind.IDENTITY_THEFT:
            false = ()
        gt_id = self.failure.gt_ids[0] if self.failure.gt_ids else None
        victim = self.failure.track_ids[1] if len(self.failure.track_ids) > 1 else None
        held = self.victim_held(gt_id, victim, false)
        no_object, part = self.no_object_part(born[0], born[1])
        return Origin(track_id, born[0], born[1], false, held, no_object, part)

    def victim_held(self, gt_id: str | None, victim: str | None, frames: tuple[int, ...]) -> bool:
        """Whether at each of ``frames`` (a thief's false frames) the evaluation matched object ``gt_id`` to track
        ``victim``: it scored and did not miss the object, and the victim's match there was the object (audit
        truth52, world8 scene-0655 cphd identity_theft:1: the object was track 27's at frame 16 and the victim's,
        track 55's, only from frame 17, yet "the evaluation still gave GT 1defa4 to track 55" at frames 16-18)."""
        if not frames or gt_id is None or victim is None:
            return False
        ev = self.report.track_evals.get(str(victim))
        return ev is not None and all(
            not self.missed_at(gt_id, x)
            and self.evaluated_at(gt_id, x)
            and not self.false_at(self.report, x, int(victim))
            and ev.matched_at(x) == gt_id
            for x in frames
        )

    def _meas_xy(self, frame: int, meas: int) -> np.ndarray | None:
        """(2,) the centre of detection ``meas`` of ``frame``; None when there is no such detection or frame."""
        fr = self.frames.get(frame)
        if meas < 0 or fr is None or meas >= len(fr.detections.boxes.score):
            return None
        return fr.detections.boxes.translation_m[meas, :2]

    def of_no_object(self, frame: int, meas: int) -> bool:
        """Whether detection ``meas`` of ``frame`` lay farther than ``NEAR_M`` from every annotated object of a
        tracked class (False when unknown: no such detection or frame)."""
        xy = self._meas_xy(frame, meas)
        if xy is None:
            return False
        gt = self.scene.keyframes[frame].gt
        return not len(gt) or bool(np.hypot(*(gt.translation_m[:, :2] - xy).T).min() >= NEAR_M)

    def meas_part_of(self, frame: int, meas: int) -> tuple[str, str, float] | None:
        """``part_of`` for detection ``meas`` of ``frame`` (None when unknown)."""
        xy = self._meas_xy(frame, meas)
        return None if xy is None else self.part_at(frame, xy)

    def untracked_name(self, frame: int, xy: np.ndarray) -> tuple[str, float, float] | None:
        """The nearest box of an untracked detection name within ``NEAR_M`` of ``xy`` at ``frame`` in the run's
        detection file (``gnnpmb.why.untracked``; None: none, or no file)."""
        path = getattr(self.evidence, "detections_path", None)
        if path is None:
            return None
        tokens = tuple(str(k.sample_token) for k in self.scene.keyframes)
        kf = self.scene.keyframes[frame]
        centres = [kf.gt.translation_m[:, :2]] if len(kf.gt) else []
        if (others := self.untracked.get(str(kf.sample_token))) is not None and len(others):
            centres.append(others.translation_m[:, :2])
        around = np.concatenate(centres) if centres else np.zeros((0, 2))
        around = around[np.hypot(*(around - xy).T) > 1e-6]  # the object itself
        return untracked_name_near(untracked_detections(path, tokens), str(kf.sample_token), xy, around)

    def part_at(self, frame: int, xy: np.ndarray) -> tuple[str, str, float] | None:
        """``part_of`` at ``frame``, else the annotation of an untracked category the point lies on (its class is
        the category; audit truth52, world8: car boxes on an ambulance were "detections of no tracked object")."""
        kf = self.scene.keyframes[frame]
        return part_of(kf.gt, xy) or untracked_on(self.untracked.get(getattr(kf, "sample_token", "")), xy)

    def no_object_part(self, frame: int, meas: int) -> tuple[bool, tuple[str, str, float] | None]:
        """(``of_no_object``, and for such a detection ``meas_part_of``): whether it lay near no annotated object,
        and the long object it lay on part of, if any."""
        no_object = self.of_no_object(frame, meas)
        return no_object, self.meas_part_of(frame, meas) if no_object else None

    def coasted_from(self, track_id: int, gt_id: str) -> tuple[int, int] | None:
        """(frame, detection) of the last box before the failure that track ``track_id`` was output on, when that
        detection lay within ``NEAR_M`` of object ``gt_id`` and nearer it than any other annotated object: a track
        of another class that coasted on with the object it was fed by, not onto it (audit truth51, world7: a car
        detected as a truck at every other frame left a truck track on it); None otherwise."""
        for x in sorted((x for x in self.frames if x < self.f), reverse=True):
            e = self.estimate(track_id, x)
            if e is None or e.meas_index < 0:
                continue
            xy, at = self._meas_xy(x, e.meas_index), self.gt_xy(gt_id, x)
            if xy is None or at is None:
                return None
            d = float(np.hypot(*(xy - at)))
            if d >= NEAR_M or self.nearer_object(x, xy[None, :], np.array([d]))[0] is not None:
                return None
            return x, int(e.meas_index)
        return None

    def drifted_off(
        self, track_id: int, xy_m: np.ndarray, dropped: bool = False
    ) -> tuple[str, float, int, GtFrame | None] | None:
        """``FalseOutput.drifted_from`` of track ``track_id``'s box at ``xy_m`` (BEV, m) at the failure frame: the
        object of its class nearest the track's latest earlier box that lay within ``NEAR_M`` of one, when that
        object is annotated at the failure frame between ``NEAR_M`` and ``OFF_NEAR_M`` from ``xy_m``. dropped: the
        box at ``xy_m`` is one the evaluation interpolated in place of the track's own box there, which it dropped
        (beyond the class range); that own box counts too, at the failure frame (audit truth53, world9: a
        pedestrian's track on it at 40.0 m was "last within 2 m of it at frame 19")."""
        for x in sorted((x for x in self.frames if x < self.f or (dropped and x == self.f)), reverse=True):
            e = self.estimate(track_id, x)
            gt = self.scene.keyframes[x].gt
            if e is None or not len(gt):
                continue
            mine = np.flatnonzero(gt.class_name == self.class_name)
            d = np.hypot(*(gt.translation_m[mine, :2] - np.asarray(e.translation_m[:2])).T)
            if not mine.size or d.min() >= NEAR_M:
                continue
            gt_id = str(gt.instance_id[mine[np.argmin(d)]])
            at = self.gt_xy(gt_id, self.f)
            if at is None:
                return None
            now = float(np.hypot(*(at - xy_m)))
            return (gt_id, now, x, self.report.gt_frame(gt_id, self.f)) if now < OFF_NEAR_M else None
        return None

    def own_detections(self, frame: int, gt_id: str) -> tuple[int, ...]:
        """The kept detections of the class within ``NEAR_M`` of object ``gt_id`` at ``frame`` that lie nearer it
        than any other annotated object (a detector without NMS gives one object two: audit truth50, world6)."""
        xy, fr = self.gt_xy(gt_id, frame), self.frames.get(frame)
        if xy is None or fr is None or not len(fr.detections.boxes.score):
            return ()
        boxes = fr.detections.boxes
        d = np.hypot(*(boxes.translation_m[:, :2] - np.asarray(xy)[:2]).T)
        ok = (d < NEAR_M) & fr.detections.kept & (boxes.class_name == self.class_name)
        idx = np.flatnonzero(ok)
        other = self.nearer_object(frame, boxes.translation_m[idx, :2], d[idx])
        return tuple(
            int(m)
            for m, o in zip(idx.tolist(), other, strict=True)
            if o is None and self.untracked_nearer(frame, boxes.translation_m[m, :2], float(d[m])) is None
        )

    def untracked_nearer(self, frame: int, xy: np.ndarray, own_m: float) -> tuple[str, str, float] | None:
        """The annotation of an untracked category nearest ``xy`` at ``frame`` when it lies nearer than ``own_m``
        (id, category, m), else None: a pedestrian box on a stroller beside its pusher is the stroller's (audit
        truth52, world8: "the detector gave it two pedestrian detections" counted it as the pusher's)."""
        kf = self.scene.keyframes[frame]
        hit = untracked_on(self.untracked.get(getattr(kf, "sample_token", "")), xy)
        return hit if hit is not None and hit[2] < own_m - 1e-6 else None

    def off_near(self, frame: int, gt_id: str) -> Near | None:
        """The nearest detection of the class within ``OFF_NEAR_M`` of object ``gt_id`` at ``frame`` (kept or not)
        that lies nearer it than any other annotated object (None: none)."""
        xy, fr = self.gt_xy(gt_id, frame), self.frames.get(frame)
        if xy is None or fr is None or not len(fr.detections.boxes.score):
            return None
        boxes = fr.detections.boxes
        d = np.hypot(*(boxes.translation_m[:, :2] - xy).T)
        idx = np.flatnonzero((d < OFF_NEAR_M) & (boxes.class_name == self.class_name))
        other = self.nearer_object(frame, boxes.translation_m[idx, :2], d[idx])
        mine = [int(m) for m, o in zip(idx.tolist(), other, strict=True) if o is None]
        if not mine:
            return None
        m = min(mine, key=lambda m: d[m])
        return Near(m, str(boxes.class_name[m]), float(boxes.score[m]), float(d[m]), bool(fr.detections.kept[m]))

    def in_box(self, frame: int, gt_id: str) -> Near | None:
        """The nearest detection of ``frame`` whose centre lies inside object ``gt_id``'s box (None: none)."""
        gt, fr = self.scene.keyframes[frame].gt, self.frames.get(frame)
        k = np.flatnonzero(gt.instance_id == gt_id) if len(gt) else np.zeros(0, int)
        if fr is None or not k.size or not len(fr.detections.boxes.score):
            return None
        boxes = fr.detections.boxes
        xy = boxes.translation_m[:, :2]
        others = np.hypot(*(gt.translation_m[None, :, :2] - xy[:, None, :]).transpose(2, 0, 1)).min(axis=1)
        inside = in_footprint(gt, int(k[0]), xy) & (others >= NEAR_M)  # not another object's detection
        if not inside.any():
            return None
        d = np.hypot(*(boxes.translation_m[:, :2] - gt.translation_m[k[0], :2]).T)
        m = int(np.flatnonzero(inside)[np.argmin(d[inside])])
        return Near(m, str(boxes.class_name[m]), float(boxes.score[m]), float(d[m]), bool(fr.detections.kept[m]))

    def blame_lost(self, sightings: tuple[Sighting, ...], deciding: tuple[int, ...], lost: LostTrack) -> tuple:
        seen = {s.frame: s for s in sightings}
        no_det, other_class, unused, not_output = [], [], [], []
        for f in deciding:
            s = seen.get(f)
            if s is None:
                continue
            step = lost.step(f)
            if s.undetected:
                if s.points > 0:
                    no_det.append(f)
            elif s.nearest_own is None and s.seen.class_name != self.class_name:
                other_class.append(f)
            own = s.nearest_own
            if own is None and s.seen is not None and s.seen.class_name == self.class_name:
                own = s.seen  # of its class, dropped by preprocessing
            if own is not None and (step is None or own.meas not in step.used):
                unused.append(f)
            if step is None or step.output is None:
                not_output.append(f)
        covering: list[Blame] = []
        at = seen.get(self.f)
        if self.failure.kind is FailureKind.FRAGMENTATION and at is not None:  # missed here though tracks were on it
            covering = [b for b in self.blame_uncovered(at) if b.rule in _ON_IT_RULES]
        elif at is not None and lost.off is None and any(o.track_id == lost.track_id for o in at.on_it):
            covering = [Blame(Rule.TWO_TRACKS, (self.f,))]  # still on it, yet the evaluation took the other track
        return (
            self.evaluation_blame()
            + _blames(
                (Rule.NO_DETECTION, no_det),
                (Rule.OTHER_CLASS, other_class),
                (Rule.DETECTION_UNUSED, unused),
                (Rule.NOT_OUTPUT, not_output),
                (Rule.OFF_OBJECT, [self.f] if lost.off is not None else []),
            )
            + tuple(covering)
        )

    def evaluation_blame(self, least_offset_m: float = EVALUATED_OFFSET_M) -> tuple[Blame, ...]:
        """The evaluation's tests at the failure frame for the finding's object (a coalescence's is its first
        missed one: its other objects are not what the finding is about): its box was interpolated
        ``least_offset_m`` or more from the annotation, or out of reach of a counted track on the annotation."""
        out = []
        for gt_id in self.failure.gt_ids[1:2] if self.failure.kind is FailureKind.COALESCENCE else self.failure.gt_ids:
            g = self.report.gt_frame(gt_id, self.f)
            if g is None:
                continue
            if g.status is GtStatus.INTERPOLATED and (g.offset_m >= least_offset_m or self.put_out_of_reach(g, gt_id)):
                out.append(Blame(Rule.INTERPOLATED, (self.f,)))
        return tuple(dict.fromkeys(out))

    def put_out_of_reach(self, g: GtFrame, gt_id: str) -> bool:
        """Whether the object's interpolated box ``g`` lies ``NEAR_M`` or more from a counted track of the class
        output within ``NEAR_M`` of the annotation (however near the interpolation is to the annotation, it decided
        the match: dev set scene-0757 megvii prob3dmot fragmentation:18, a track 1.8 m from the annotation and 2.1 m
        from a box interpolated 0.3 m from it)."""
        fr = self.frames.get(self.f)
        if g.evaluated_xy_m is None or fr is None:
            return False
        on = {
            o.track_id
            for o in self.on_object(self.report, fr, np.asarray(g.annotated_xy_m))
            if o.counted and not self.neighbours(o, self.f, gt_id)
        }
        near = {o.track_id for o in self.on_object(self.report, fr, np.asarray(g.evaluated_xy_m))}
        return bool(on - near)

    def deciding(self, lost_id: int, taker_id: int, involved: set[int]) -> Deciding | None:
        """The solver's last choice up to the failure that sent a detection to the taker (or started it) while an
        involved track (the lost one, or one in between) was the next best, or by a close call."""
        best = None
        for f, c, born in self.choices():
            went, is_born = _went(c.chosen, born.get(int(c.meas.ref)))
            if went != taker_id or c.alternative is None or c.alternative.kind is not AxisKind.TRACK:
                continue
            if c.alternative.ref in involved or c.close_call:
                best = (f, c, went, is_born)
        if best is None:
            return None
        f, c, went, is_born = best
        compared = {label.ref for label in (c.chosen, c.alternative) if label is not None}
        frame = self.facts.frame(f, self.class_name)
        matrix, assignment = frame.cost, frame.assignment
        lost = None if lost_id in compared else lost_id
        in_gate, lost_would = False, None
        if lost is not None:  # said only of a track with a column in the matrix: its cost for the detection
            entry = _entry(matrix, int(c.meas.ref), lost)
            lost = None if entry is None else lost
            in_gate = entry is not None and math.isfinite(entry)
            if in_gate and assignment is not None:
                lost_would = would_take(matrix, assignment, int(c.meas.ref), lost_id)
        would = None
        if matrix is not None and assignment is not None and c.alternative is not None:
            would = would_take(matrix, assignment, int(c.meas.ref), int(c.alternative.ref))
        took = self.took(f, int(c.alternative.ref))
        no_object, part = self.no_object_part(f, int(c.meas.ref))
        return Deciding(f, c, went, is_born, lost, in_gate, would, lost_would, took, no_object, part)

    def switch(self, tracks: set[int], deciding: tuple[int, ...]) -> HypothesisSwitch | None:
        """A PMBM hypothesis switch in the deciding frames: the best hypothesis descends from another prior
        hypothesis than the previous best (the latest such frame)."""
        for f in reversed(deciding):
            h = self.facts.hypotheses(f, self.class_name)
            if h is None or not h.switched:
                continue
            before = self.facts.hypotheses(f - 1, self.class_name)
            weights = before.weights if before is not None else ()
            parent_w = weights[h.best_parent] if h.best_parent < len(weights) else float("nan")
            rows = []
            for t in sorted(tracks):
                step = self.facts.steps(t, self.class_name).get(f)
                rows.append(
                    HypothesisTrack(
                        t,
                        self.facts.existed_since(t, self.class_name, f),
                        step.decided_existence if step is not None else None,
                        step.prior_existence if step is not None else None,
                        h.existence_in(0, t),
                        step.marginal_existence if step is not None else None,
                    )
                )
            return HypothesisSwitch(f, h.best_parent, parent_w, weights[0] if weights else float("nan"), tuple(rows))
        return None

    def false_track(self) -> dict:
        t = int(self.failure.track_ids[0])
        e = self.estimate(t, self.f)
        ev = self.report.track_evals.get(str(t))
        interpolated = e is None or (ev is not None and self.f in ev.interpolated)
        between = None
        if not interpolated:
            xy = np.asarray(e.translation_m[:2])
        else:  # no box of the tracker's was kept here: the evaluation interpolated the track between two of its
            box = next(b for b in self.failure.boxes if b.role == "false track")
            xy = np.asarray(box.translation_m[:2])
            kept = ev.kept if ev is not None else ()
            before, after = around(kept, self.f)
            between = (before, after) if before is not None and after is not None else None
            e = None  # the box scored is not the tracker's
        fr = self.frames.get(self.f)
        on = None
        if e is not None and e.meas_index >= 0 and fr is not None:
            m, boxes = e.meas_index, fr.detections.boxes
            on = Near(
                m,
                str(boxes.class_name[m]),
                float(boxes.score[m]),
                float(np.hypot(*(boxes.translation_m[m, :2] - xy))),
                bool(fr.detections.kept[m]),
            )
        gt = self.scene.keyframes[self.f].gt
        d = np.hypot(*(gt.translation_m[:, :2] - xy).T) if len(gt) else np.zeros(0)
        mine = np.flatnonzero(gt.class_name == self.class_name) if len(gt) else np.zeros(0, int)
        nearest_own = nearest_any = None
        matched = None
        twins: tuple[int, ...] = ()
        came: tuple[int, int] | None = None
        drifted = None
        if mine.size and d[mine].min() < NEAR_M:
            k = int(mine[np.argmin(d[mine])])
            gt_id = str(gt.instance_id[k])
            nearest_own = (gt_id, float(d[k]), self.report.gt_frame(gt_id, self.f))
            matched = self.matched_to(gt_id)
        if d.size and d.min() < NEAR_M:
            k = int(np.argmin(d))
            nearest_any = (str(gt.instance_id[k]), str(gt.class_name[k]), float(d[k]))
        near_detection = self.detection_near(on, xy) if nearest_any is None and on is not None else None
        blame: list[Blame] = []
        if interpolated:
            blame.append(Blame(Rule.TRACK_INTERPOLATED, (self.f,)))
            if self.estimate(t, self.f) is not None:
                blame.append(Blame(Rule.TRACK_DROPPED, (self.f,)))  # output, but beyond the range: dropped
        if nearest_own is not None:
            g = nearest_own[2]
            if g is None or g.status in (GtStatus.NO_BOX, GtStatus.BEYOND_RANGE):
                blame.append(Blame(Rule.NO_EVAL_BOX, (self.f,)))
            elif g.status is GtStatus.INTERPOLATED and np.hypot(*(np.asarray(g.evaluated_xy_m) - xy)) >= NEAR_M:
                blame.append(Blame(Rule.INTERPOLATED, (self.f,)))
            else:
                twins = self.own_detections(self.f, nearest_own[0])
                if len(twins) >= 2:  # the detector's first, as its other tests (whose doing, in order)
                    blame.append(Blame(Rule.TWO_DETECTIONS, (self.f,)))
                blame.append(Blame(Rule.TWO_TRACKS, (self.f,)))
        elif e is None:
            pass  # no box of the tracker's here
        elif on is None:
            came = self.coasted_from(t, nearest_any[0]) if nearest_any is not None else None
            if came is not None:  # audit truth51 (world7): the track was on the object, fed by its wrong-class boxes
                blame.append(Blame(Rule.OTHER_CLASS, (came[0],)))
            blame.append(Blame(Rule.COASTED, (self.f,)))
        elif nearest_any is not None:
            blame.append(Blame(Rule.OTHER_CLASS, (self.f,)))
        elif near_detection is not None:  # its detection was the object's (truth54)
            blame.append(Blame(Rule.OFF_OBJECT, (self.f,)))
        else:
            blame.append(Blame(Rule.DETECTION_OF_NOTHING, (self.f,)))
        if nearest_any is None and on is None and (interpolated or e is not None):  # a box on no detection
            drifted = self.drifted_off(t, xy, dropped=any(b.rule is Rule.TRACK_DROPPED for b in blame))
        output = FalseOutput(
            t,
            on,
            (float(xy[0]), float(xy[1])),
            between,
            nearest_own,
            nearest_any,
            matched,
            self.report.track_evals.get(str(t)),
            self.threshold,
            nearest_own is not None and self.missed_at(nearest_own[0], self.f),
            step.use if (step := self.facts.steps(t, self.class_name).get(self.f)) is not None else None,
            self.part_at(self.f, xy) if nearest_any is None else None,
            twins if len(twins) >= 2 else (),
            came,
            drifted,
            self.untracked_nearer(self.f, xy, nearest_own[1]) if nearest_own is not None else None,
            near_detection,
            self.kept_around(nearest_own[0]) if any(b.rule is Rule.NO_EVAL_BOX for b in blame) else None,
        )
        return {"deciding": (self.f,), "blame": tuple(blame), "false_output": output}

    def detection_near(self, on: Near, xy: np.ndarray) -> tuple[str, str, float, float] | None:
        """The nearest annotated object of a tracked class within ``NEAR_M`` of detection ``on`` at this frame (id,
        class, the detection's distance, the box's at ``xy``), when the box itself lies farther than that."""
        fr, gt = self.frames.get(self.f), self.scene.keyframes[self.f].gt
        if fr is None or not len(gt):
            return None
        d = np.hypot(*(gt.translation_m[:, :2] - fr.detections.boxes.translation_m[on.meas, :2]).T)
        k = int(np.argmin(d))
        if d[k] >= NEAR_M:
            return None
        box = float(np.hypot(*(gt.translation_m[k, :2] - xy)))
        return (str(gt.instance_id[k]), str(gt.class_name[k]), float(d[k]), box)

    def kept_around(self, gt_id: str) -> tuple[int | None, int | None]:
        """The last frame before this one and the first after it at which the evaluation kept the object's
        annotated box (None: none on that side): the ends its interpolation would join."""
        return around((x for x, g in self.report.gt_frames.get(gt_id, {}).items() if g.dropped is None), self.f)

    @staticmethod
    def false_at(report: FailureReport, frame: int, track_id: int) -> bool:
        """Whether the evaluation matched track ``track_id`` to no object at ``frame`` (a false track there)."""
        return any(
            f.frame_index == frame and str(track_id) in f.track_ids for f in report.of_kind(FailureKind.FALSE_TRACK)
        )

    def evaluated_at(self, gt_id: str, frame: int) -> bool:
        """Whether the evaluation had a box of object ``gt_id`` at ``frame`` (annotated or interpolated)."""
        g = self.report.gt_frame(gt_id, frame)
        return g is not None and g.evaluated_xy_m is not None

    def missed_at(self, gt_id: str, frame: int) -> bool:
        """Whether the evaluation matched object ``gt_id`` to no track at ``frame`` (a miss there)."""
        return any(f.frame_index == frame and gt_id in f.gt_ids for f in self.report.of_kind(FailureKind.MISS))

    def matched_to(self, gt_id: str) -> int | None:
        """The track the evaluation matched object ``gt_id`` to at the failure frame: the one counted track of the
        class output within ``NEAR_M`` of its evaluated box that was no false track there, the object not missed
        (None: none, or more than one could have been)."""
        g = self.report.gt_frame(gt_id, self.f)
        if not self.evaluated_at(gt_id, self.f) or self.missed_at(gt_id, self.f):
            return None
        others = [
            o
            for o in self.on_object(self.report, self.frames.get(self.f), np.asarray(g.evaluated_xy_m))
            if o.counted and not o.false_here and o.track_id != int(self.failure.track_ids[0])
        ]
        if self.interpolated_track_here():
            return None  # the evaluation filled in a box of a track of the class here: it may have matched that one
        return others[0].track_id if len(others) == 1 else None  # of two or more, which one is not known here

    def interpolated_track_here(self) -> bool:
        """Whether the evaluation interpolated a box at the failure frame for a track of the class other than the
        failure's (the devkit fills a track's gaps between its kept boxes; that box is in no output here)."""
        own = self.failure.track_ids[0]
        filled = {t for t, ev in self.report.track_evals.items() if self.f in ev.interpolated and t != own}
        if not filled:
            return False
        return any(
            str(e.track_id) in filled and e.class_name == self.class_name
            for fr in self.frames.values()
            for e in fr.estimates
        )

    def miss(self, sightings: tuple[Sighting, ...]) -> dict:
        """A miss is the evaluation's doing where its interpolated box lies ``NEAR_M`` or more from the annotation
        (a track on the object would be out of reach) or put a counted track out of reach; a box nearer the
        annotation would still have been matched by a counted track on the object, so the interpolation did not
        make the miss (demo scene-0103 gnnpmb miss:11, a box 1.3 m off where the track on the object was not
        counted: "the evaluation's and the tracker's doing", said as if the box had cost the match)."""
        s = next((s for s in sightings if s.frame == self.f), None)
        blame = list(self.evaluation_blame(least_offset_m=NEAR_M))
        if s is not None:
            blame += self.blame_uncovered(s)
        return {"deciding": (self.f,), "blame": tuple(blame)}

    def blame_uncovered(self, s: Sighting) -> list[Blame]:
        """The tests for an object no counted track covered at frame ``s.frame`` (a miss, a coalescence's
        missed object)."""
        f = (s.frame,)
        out = []
        if s.undetected and (s.points > 0 or not s.on_it):  # unseen: no track carried it either
            out.append(Blame(Rule.NO_DETECTION if s.points > 0 else Rule.UNSEEN, f))
        elif s.nearest_own is None and s.seen is not None and s.seen.class_name != self.class_name:
            out.append(Blame(Rule.OTHER_CLASS, f))
        dropped = [o for o in s.on_it if o.evaluated is not None and s.frame not in o.evaluated.kept]
        if dropped:
            out.append(Blame(Rule.TRACK_DROPPED, f))
        if any(not o.counted for o in s.on_it if o not in dropped):
            out.append(Blame(Rule.NOT_COUNTED, f))
        # matched to another object while this one was in reach; not where the tracker received no detection of
        # this one's class of its own while it was visible (two objects given one box, or none, or one of another
        # class): then no track of the class could have covered both
        if not (s.nearest_own is None and s.points > 0) and covering(s, self.reach_of(s.evaluated, self.object_of())):
            out.append(Blame(Rule.COVERED_TWO, f))
        own = s.nearest_own
        if own is None and s.seen is not None and s.seen.class_name == self.class_name:
            out.append(Blame(Rule.DETECTION_UNUSED, f))  # preprocessing dropped it
        elif own is not None:
            on_ids = {o.track_id for o in s.on_it}
            went = s.went
            if went is None or went.track_id < 0 or went.went is Went.NO_OUTPUT:  # NO_OUTPUT: a box beside it
                out.append(Blame(Rule.DETECTION_UNUSED, f))
            elif went.track_id not in on_ids:
                out.append(Blame(Rule.NOT_OUTPUT, f))
        return out

    def coalescence(self, sightings: tuple[Sighting, ...]) -> dict:
        s = next((s for s in sightings if s.frame == self.f), None)
        blame = list(self.evaluation_blame())
        if s is not None:
            uncovered = self.blame_uncovered(s)
            blame += uncovered
            if (
                s.went is not None
                and s.went.went is not Went.NO_OUTPUT
                and s.went.track_id == int(self.failure.track_ids[0])
            ):
                blame.append(Blame(Rule.COVERED_TWO, (self.f,)))
        t = int(self.failure.track_ids[0])
        ev = self.report.track_evals.get(str(t))
        if ev is not None and self.f in ev.interpolated:  # the box matched is the evaluation's, not the tracker's
            blame.insert(0, Blame(Rule.TRACK_INTERPOLATED, (self.f,)))
            if self.estimate(t, self.f) is not None:
                blame.insert(1, Blame(Rule.TRACK_DROPPED, (self.f,)))  # output, but beyond the range: dropped
        covered = self.failure.gt_ids[:1]  # the object the evaluation matched the track to (failures docstring)
        return {"deciding": (self.f,), "blame": tuple(dict.fromkeys(blame)), "covered": covered}

    def key_decisions(self, involved: set[int]) -> tuple[KeyDecision, ...]:
        """Choices up to the failure that sent a detection elsewhere while an involved track was its next best,
        or gave one to an involved track by a close call (on the tracker's own cost scale)."""
        out = []
        for f, c, born in self.choices():
            alt = c.alternative
            alt_involved = alt is not None and alt.kind is AxisKind.TRACK and alt.ref in involved
            chosen_involved = c.chosen.kind is AxisKind.TRACK and c.chosen.ref in involved
            if (alt_involved and not chosen_involved) or (chosen_involved and c.close_call):
                went, is_born = _went(c.chosen, born.get(int(c.meas.ref)))
                took = self.took(f, int(alt.ref)) if alt is not None and alt.kind is AxisKind.TRACK else None
                out.append(KeyDecision(f, c, went, is_born, took))
        return tuple(out)

    def took(self, f: int, track_id: int) -> int | None:
        """The detection track ``track_id`` was assigned at frame ``f`` (None: none, or not an assignment)."""
        use = self.facts.use(f, self.class_name)
        step = use.tracks.get(track_id) if use is not None and use.mode is UseMode.ASSIGNED else None
        return None if step is None else step.dominant

    def choices(self) -> Iterator[tuple[int, PairChoice, dict[int, int]]]:
        """(frame, choice, the frame's detection -> track born of it) of every conflict's choice in the window."""
        for f in self.window:
            d = self.facts.decisions(f, self.class_name)
            if d is None:
                continue
            born = self.facts.frame(f, self.class_name).born_of()
            for conflict in d.conflicts:
                yield from ((f, c, born) for c in conflict.choices)

    def others(self, others: Sequence[Evidence], gt_id: str | None) -> tuple[OtherRun, ...]:
        """How other trackers fared at the same place: a failure of the same kind on the same object (or, for a
        false track, at the same place) at the same frame, and their tracks output on the object."""
        out = []
        for ev in others:
            if ev.tracker == self.evidence.tracker:
                continue
            fr = next((fr for fr in ev.run.frames if fr.keyframe.index == self.f), None)
            xy = self.gt_xy(gt_id, self.f) if gt_id is not None else None
            if xy is None and self.failure.boxes:
                xy = np.asarray(self.failure.boxes[0].translation_m[:2])
            kinds = SAME_FAILURE.get(self.failure.kind, {self.failure.kind})
            failed = any(
                f.kind in kinds and f.frame_index == self.f and _same_place(f, gt_id, xy, self.class_name)
                for f in ev.report.failures
            )
            on_it = self.on_object(ev.report, fr, xy) if xy is not None else ()
            place = (float(xy[0]), float(xy[1])) if xy is not None else None
            missed = gt_id is not None and any(
                f.kind is FailureKind.MISS and f.frame_index == self.f and gt_id in f.gt_ids for f in ev.report.failures
            )
            matched = next(
                (
                    int(t)
                    for t, e in ev.report.track_evals.items()
                    if gt_id is not None and e.matched_at(self.f) == gt_id
                ),
                None,
            )
            switched = gt_id is not None and any(
                f.kind in SWITCHES and f.frame_index == self.f and _same_place(f, gt_id, xy, self.class_name)
                for f in ev.report.failures
            )
            unscored = any(c.class_name == self.class_name and c.threshold is None for c in ev.report.classes)
            out.append(
                OtherRun(ev.tracker, failed, on_it, place, ev.facts.output_only, missed, matched, switched, unscored)
            )
        return tuple(out)


def matched_away(evaluated: TrackEval | None, gt_id: str, since: int | None, frame: int) -> tuple[MatchedAway, ...]:
    """The objects other than ``gt_id`` the evaluation matched a track to after frame ``since`` (the track's last
    match on ``gt_id``; None: none known, nothing said) up to ``frame``, each with its frames, by first frame, from
    the devkit's own matches (``evaluated``: the track as evaluated; None: not evaluated)."""
    if evaluated is None or since is None:
        return ()
    frames: dict[str, list[int]] = {}
    for x, g in evaluated.matches:
        if since < x <= frame and g != gt_id:
            frames.setdefault(g, []).append(x)
    return tuple(MatchedAway(g, tuple(xs)) for g, xs in frames.items())


def around(frames: Iterable[int], frame: int) -> tuple[int | None, int | None]:
    """The last of ``frames`` before ``frame`` and the first after it (None: none on that side)."""
    ordered = sorted(frames)
    return (
        next((x for x in reversed(ordered) if x < frame), None),
        next((x for x in ordered if x > frame), None),
    )


def object_frames(
    evidence: Evidence, scene: SceneData, class_name: str, gt_id: str, frames: range
) -> tuple[Sighting, ...]:
    """The object ``gt_id`` of ``class_name`` at each of ``frames`` as ``evidence``'s tracker saw it
    (``Sighting``): the tables of a focus document, one per tracker."""
    return _Context(evidence, scene, frames.stop - 1, class_name, frames.start).sightings(gt_id)


def key_decisions(
    evidence: Evidence, scene: SceneData, class_name: str, involved: set[int], frames: range
) -> tuple[KeyDecision, ...]:
    """Choices in ``frames`` that sent a detection away from one of ``involved`` while it was the next best, or
    gave one to an involved track by a close call (``_Context.key_decisions``)."""
    return _Context(evidence, scene, frames.stop - 1, class_name, frames.start).key_decisions(involved)


SWITCHES = frozenset({FailureKind.ID_SWITCH, FailureKind.IDENTITY_THEFT})
"""The devkit's SWITCH of an object: an ID switch, or a theft (a switch whose new track had been false)."""
SAME_FAILURE = {FailureKind.ID_SWITCH: SWITCHES, FailureKind.IDENTITY_THEFT: SWITCHES}
"""Kinds that are one failure for another run: both are the devkit's SWITCH of the object (a theft is a switch whose
new track had been false), so a run with either did not 'not fail here'."""


def _same_place(f: Failure, gt_id: str | None, xy: np.ndarray | None, class_name: str) -> bool:
    """Whether failure ``f`` is about the object ``gt_id`` (a coalescence's missed object: the one it matched
    there, it kept: dev set scene-1077 pointpillars, gnn's coalescence missing pedestrian a2d371 was said to be
    jpda's too, whose coalescence matched a2d371 and missed its neighbour), or, without one (or when ``f`` names no
    object: a false track), is of ``class_name`` and lies within ``NEAR_M`` of ``xy`` (a false car is not a false
    bicycle: dev set scene-0655, immortal's false car beside gnnpmb's false bicycle)."""
    if gt_id is not None and f.gt_ids:
        return gt_id in (f.gt_ids[1:] if f.kind is FailureKind.COALESCENCE else f.gt_ids)
    if xy is None or f.class_name != class_name:
        return False
    return any(np.hypot(*(np.asarray(b.translation_m[:2]) - xy)) < NEAR_M for b in f.boxes)


def part_of(gt: Boxes, xy_m: np.ndarray) -> tuple[str, str, float] | None:
    """The annotated object whose ground-plane box contains the point ``xy_m`` (the nearest centre of those): id,
    class and the point's distance to its centre; None: inside none. With no centre within ``NEAR_M`` such a
    point is on part of a long object, not on no object (audit truth50, world6: a 16 m truck seen as a cab box
    and a trailer box, each 3-5 m from its centre, was called "a detection of no object")."""
    hit = containing_box(gt, xy_m)
    if hit is None:
        return None
    k, dist_m = hit
    return str(gt.instance_id[k]), str(gt.class_name[k]), dist_m


def _entry(matrix: CostMatrix | None, meas: int, track: int) -> float | None:
    """Track ``track``'s cost for detection ``meas`` in ``matrix`` (+inf: it could not take it); None when the
    matrix has no column for the track (or no row for the detection)."""
    if matrix is None:
        return None
    rows = [i for i, r in enumerate(matrix.rows) if r.kind is AxisKind.MEASUREMENT and int(r.ref) == meas]
    cols = [k for k, col in enumerate(matrix.cols) if col.kind is AxisKind.TRACK and int(col.ref) == track]
    return float(np.asarray(matrix.cost)[rows[0], cols[0]]) if rows and cols else None


def _went(chosen, born_id: int | None) -> tuple[int, bool]:
    """(track id the detection went to or started (-1: none), whether it started it)."""
    if chosen.kind is AxisKind.TRACK:
        return int(chosen.ref), False
    return (born_id, True) if born_id is not None else (-1, True)


def _blames(*tests: tuple[Rule, list[int]]) -> tuple[Blame, ...]:
    """The held tests (those with frames), detector's before tracker's."""
    held = [Blame(t, tuple(frames)) for t, frames in tests if frames]
    return tuple(sorted(held, key=lambda b: list(type(b.party)).index(b.party)))
