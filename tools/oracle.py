"""The truth oracle: every claim of every finding checked against facts gathered apart from the explanation code.

For a tracker on a scene and detector preset, the oracle runs the tracker once with a plain ``ListSink`` beside the
fact sink, evaluates it, explains every failure (``gnnpmb.why``), renders each finding, and checks each claim
(``gnnpmb.why.claims``) against three independent sources:

* the tracker's **submission** (the boxes it output: which detection each sits on, found by its size, heading and
  height, which a box takes from its detection; positions);
* its **raw events** (assignments, association probabilities, PHD update weights, births, prunings, hypotheses),
  read here with code of its own, not ``why.facts``;
* the devkit's **evaluation**, recomputed here (its range and point filters, its interpolation, its averaged
  scores) and the failure report's matching;

plus the scene's annotations and the detections. A rendered sentence with a ``?`` placeholder is a contradiction
too. ``uv run python -m tools.oracle`` checks every tracker on every demo scene and preset and prints the count of
claims checked and contradictions found per tracker; ``tests/gnnpmb/why/test_oracle.py`` runs it on the
evaluation split.

A results file of another tracker (``--results NAME=FILE.json``) has no events: its findings are checked against
the file itself, read here (its boxes, the detection each sits on by the rule of ``gnnpmb.foreign``, re-applied
with code of its own), the detections and the devkit.
"""

from __future__ import annotations

import argparse
import sys
from collections import defaultdict
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from gnnpmb.eval.evaluated import GtStatus
from gnnpmb.eval.failures import FailureKind
from gnnpmb.events import (
    Assignment,
    AxisKind,
    Born,
    CostMatrix,
    FrameStarted,
    Gated,
    GlobalHypotheses,
    IntensityWeights,
    ListSink,
    Marginals,
    Posterior,
    Pruned,
    TrackLogic,
    TrackLogicAction,
    UpdateWeights,
)
from gnnpmb.why.claims import Claim, claims
from gnnpmb.why.findings import EVALUATED_OFFSET_M, NEAR_M, Finding, Rule

ATOL = 1e-6
USED_SHARE = 0.01
"""The oracle's own copy of the share from which an update *used* a detection (``why.facts.USED_SHARE``)."""


@dataclass
class Sources:
    """What the oracle checks against, for one tracker run on one scene: frames (index -> FrameResult), results
    (submission boxes by sample token), events by (frame, class) and kind, the report, the devkit's evaluation
    recomputed (``Devkit``), the scene, and other trackers' reports by name. keeps_detection_box: the tracker's output
    boxes carry their detections' size, heading and height (False for a box-filtering tracker, whose box can only
    be tied to a detection through its raw events)."""

    scene: Any
    frames: Mapping[int, Any]
    results: Mapping[str, Sequence[Mapping[str, Any]]]
    events: Mapping[tuple[int, str], Mapping[type, list]]
    report: Any
    devkit: Devkit
    others: Mapping[str, Any] = field(default_factory=dict)
    keeps_detection_box: bool = True
    output_only: bool = False
    """A results file: ``results`` is the file's, and what an update used is where its boxes sit."""

    def box(self, frame: int, track: int) -> Mapping[str, Any] | None:
        token = self.scene.keyframes[frame].sample_token
        return next((b for b in self.results.get(token, ()) if b["tracking_id"] == str(track)), None)

    def points(self, frame: int, gt_id: str) -> int:
        keyframe = self.scene.keyframes[frame]
        hit = np.flatnonzero(keyframe.gt.instance_id.astype(str) == gt_id)
        return int(keyframe.gt_num_pts[hit[0]]) if hit.size else 0

    def gt_xy(self, frame: int, gt_id: str) -> np.ndarray | None:
        gt = self.scene.keyframes[frame].gt
        hit = np.flatnonzero(gt.instance_id.astype(str) == gt_id) if len(gt) else []
        return None if len(hit) == 0 else np.asarray(gt.translation_m[hit[0], :2], dtype=float)

    def of(self, frame: int, class_name: str, kind: type) -> list:
        return self.events.get((frame, class_name), {}).get(kind, [])

    def one(self, frame: int, class_name: str, kind: type):
        found = self.of(frame, class_name, kind)
        return found[-1] if found else None


@dataclass
class Devkit:
    """The devkit's evaluation of one scene, recomputed: (frame, gt id) -> status and evaluated xy; track id ->
    (kept frames, averaged score); the class thresholds of the report."""

    gt: dict[tuple[int, str], tuple[GtStatus, tuple[float, float] | None]]
    tracks: dict[str, tuple[tuple[int, ...], float | None]]


def recompute_devkit(nusc, scene, results, cfg) -> Devkit:
    """The devkit's filters, interpolation and score averaging on ``scene``, run here from its own functions."""
    from nuscenes.eval.common.data_classes import EvalBoxes
    from nuscenes.eval.common.loaders import add_center_dist, filter_eval_boxes, load_gt_of_sample_tokens
    from nuscenes.eval.tracking.data_classes import TrackingBox
    from nuscenes.eval.tracking.loaders import create_tracks

    from gnnpmb.eval.failures import _split_with_scene
    from gnnpmb.eval.nuscenes_eval import quiet_devkit

    tokens = [k.sample_token for k in scene.keyframes]
    frame_of = {t: i for i, t in enumerate(tokens)}
    with quiet_devkit():
        gt = add_center_dist(nusc, load_gt_of_sample_tokens(nusc, tokens, TrackingBox, verbose=False))
        raw = {(frame_of[t], str(b.tracking_id)): b for t in tokens for b in gt[t]}  # the filter edits gt
        kept = filter_eval_boxes(nusc, gt, cfg.class_range)
        kept_ids = {(frame_of[t], str(b.tracking_id)) for t in tokens for b in kept[t]}
        tracks = create_tracks(kept, nusc, _split_with_scene(nusc, scene.name), True)
        pred = add_center_dist(nusc, EvalBoxes.deserialize({t: list(results.get(t, [])) for t in tokens}, TrackingBox))
        kept_pred = filter_eval_boxes(nusc, pred, cfg.class_range) if any(pred[t] for t in tokens) else pred
    (scene_tracks,) = tracks.values()
    stamp_frame = {nusc.get("sample", t)["timestamp"]: i for i, t in enumerate(tokens)}
    evaluated = {
        (stamp_frame[ts], str(b.tracking_id)): (float(b.translation[0]), float(b.translation[1]))
        for ts, boxes in scene_tracks.items()
        for b in boxes
    }
    out_gt = {}
    for (f, gt_id), box in raw.items():
        xy = evaluated.get((f, gt_id))
        if (f, gt_id) in kept_ids:
            status = GtStatus.SCORED
        elif xy is not None:
            status = GtStatus.INTERPOLATED
        else:
            status = GtStatus.BEYOND_RANGE if box.ego_dist >= cfg.class_range[box.tracking_name] else GtStatus.NO_BOX
        out_gt[(f, gt_id)] = (status, xy)
    scores: dict[str, list[tuple[int, float]]] = defaultdict(list)
    for t in tokens:
        for b in kept_pred[t]:
            scores[str(b.tracking_id)].append((frame_of[t], float(b.tracking_score)))
    out_tracks: dict[str, tuple[tuple[int, ...], float | None]] = {}
    for t in tokens:
        for b in results.get(t, ()):
            kept_t = scores.get(b["tracking_id"], [])
            out_tracks[b["tracking_id"]] = (
                tuple(f for f, _ in kept_t),
                float(np.mean([s for _, s in kept_t])) if kept_t else None,
            )
    return Devkit(out_gt, out_tracks)


# The oracle's own reading of the raw events.
def _box_update_of(src: Sources, frame: int, class_name: str, track: int) -> int | None:
    """The detection a box-filtering tracker's ``track`` was born from or updated with at ``frame`` (raw ``Born``
    and ``Assignment`` events), None if neither."""
    for born in src.events.get((frame, class_name), {}).get(Born, ()):
        hit = np.flatnonzero(np.asarray(born.track_ids) == track)
        if hit.size:
            return int(np.asarray(born.meas_indices)[hit[0]])
    used = used_of(src, frame, class_name, track)
    return used[0][0][0] if used is not None and used[0] else None


def used_of(
    src: Sources, frame: int, class_name: str, track: int
) -> tuple[tuple[tuple[int, float], ...], float] | None:
    """(detection, share) >= USED_SHARE and the missed share of ``track``'s update, from the raw events (a results
    file: the detection its box sits on)."""
    if src.output_only:
        box = src.box(frame, track)
        if box is None:
            return None
        placed = placed_on(src, frame, box)
        return (((placed[0], 1.0),), 0.0) if placed is not None else ((), 1.0)
    marg = src.one(frame, class_name, Marginals)
    if marg is not None:
        rows = [i for i, r in enumerate(marg.rows) if r.ref == track]
        if not rows:
            return None
        p = np.asarray(marg.probs)[rows[0]]
        shares = [(int(c.ref), float(p[k])) for k, c in enumerate(marg.cols) if c.kind is AxisKind.MEASUREMENT]
        missed = sum(float(p[k]) for k, c in enumerate(marg.cols) if c.kind is AxisKind.MISSED)
        return tuple(sorted(((m, v) for m, v in shares if v >= USED_SHARE), key=lambda x: (-x[1], x[0]))), missed
    w = src.one(frame, class_name, UpdateWeights)
    if w is not None:
        rows = np.flatnonzero(np.asarray(w.labels) == track)
        if not rows.size:
            return None
        det, miss = np.asarray(w.detected)[rows[0]], float(np.asarray(w.missed)[rows[0]])
        total = miss + float(det.sum())
        shares = [(int(m), float(det[j] / total)) for j, m in enumerate(np.asarray(w.meas_indices).tolist())]
        return tuple(sorted(((m, v) for m, v in shares if v >= USED_SHARE), key=lambda x: (-x[1], x[0]))), miss / total
    a = src.one(frame, class_name, Assignment)
    if a is None:
        return None
    for row, col in a.pairs:
        if col.kind is AxisKind.TRACK and col.ref == track:
            return ((int(row.ref), 1.0),), 0.0
    return ((), 1.0) if track in a.missed_track_ids else None


def went_of(src: Sources, frame: int, class_name: str, meas: int) -> tuple[str, int, float] | None:
    """Where a detection went, from the raw events: (went, track, share); a results file: the track whose box sits
    on it (the lowest id), else under no output box."""
    if src.output_only:
        token = src.scene.keyframes[frame].sample_token
        on = sorted(
            int(b["tracking_id"])
            for b in src.results.get(token, ())
            if b["tracking_name"] == class_name and (p := placed_on(src, frame, b)) is not None and p[0] == meas
        )
        return ("track", on[0], 1.0) if on else ("under no output box", -1, 1.0)
    born = {
        int(m): int(t)
        for b in src.of(frame, class_name, Born)
        for t, m in zip(np.asarray(b.track_ids).tolist(), np.asarray(b.meas_indices).tolist(), strict=True)
    }

    def new(share: float) -> tuple[str, int, float]:
        return ("new track", born[meas], share) if meas in born else ("new", -1, share)

    marg = src.one(frame, class_name, Marginals)
    if marg is not None:
        cols = [k for k, c in enumerate(marg.cols) if c.kind is AxisKind.MEASUREMENT and c.ref == meas]
        if not cols:
            return new(1.0)
        column = np.asarray(marg.probs)[:, cols[0]]
        p_new = max(0.0, 1.0 - float(column.sum()))
        k = int(np.argmax(column)) if column.size else -1
        if k >= 0 and column[k] > p_new:
            return "track", int(marg.rows[k].ref), float(column[k])
        return new(p_new)
    w = src.one(frame, class_name, UpdateWeights)
    if w is not None:
        refs = np.asarray(w.meas_indices).tolist()
        if meas not in refs:
            return None
        j = refs.index(meas)
        column = np.asarray(w.detected)[:, j]
        k = int(np.argmax(column)) if column.size else -1
        label = int(np.asarray(w.labels)[k]) if k >= 0 else -1
        if k >= 0 and column[k] > float(np.asarray(w.birth)[j]) and label > 0:
            return "track", label, float(column[k])
        return new(float(np.asarray(w.birth)[j]))
    a = src.one(frame, class_name, Assignment)
    if a is not None:
        for row, col in a.pairs:
            if row.ref == meas:
                return ("track", int(col.ref), 1.0) if col.kind is AxisKind.TRACK else new(1.0)
    return new(1.0)


def placed_on(src: Sources, frame: int, box: Mapping[str, Any]) -> tuple[int, str, float] | None:
    """The detection a results file's box sits on, recomputed here: (index, how, BEV distance) of the detection of
    its class whose size, heading and height it carries (within ``foreign.SAME_BOX_TOL``; the nearest such), else
    the nearest of its class within ``foreign.NEAREST_M``; None: none."""
    from gnnpmb.foreign import NEAREST_M, SAME_BOX_TOL

    det = src.frames[frame].detections.boxes
    best: tuple[float, int, str] | None = None
    for m in range(len(det)):
        if det.class_name[m] != box["tracking_name"]:
            continue
        d = float(
            np.hypot(box["translation"][0] - det.translation_m[m, 0], box["translation"][1] - det.translation_m[m, 1])
        )
        same = (
            np.all(np.abs(np.asarray(box["size"]) - det.size_wlh_m[m]) <= SAME_BOX_TOL)
            and np.all(np.abs(np.asarray(box["rotation"]) - det.quat_wxyz[m]) <= SAME_BOX_TOL)
            and abs(box["translation"][2] - det.translation_m[m, 2]) <= SAME_BOX_TOL
        )
        rank = (0 if same else 1, d)
        if (same or d < NEAREST_M) and (best is None or rank < (best[0], best[1])):
            best = (rank[0], d, m)
    if best is None:
        return None
    return best[2], ("same box" if best[0] == 0 else "nearest"), best[1]


def _same_geometry(box: Mapping[str, Any], boxes, m: int) -> bool:
    """Whether submission ``box`` carries detection ``m``'s size, heading and height (what a track takes from the
    detection that updated it)."""
    return (
        np.allclose(box["size"], boxes.size_wlh_m[m], atol=ATOL)
        and np.allclose(box["rotation"], boxes.quat_wxyz[m], atol=ATOL)
        and abs(box["translation"][2] - boxes.translation_m[m, 2]) < ATOL
    )


@dataclass
class Verdict:
    """Claims checked and the contradictions found (each a line naming the finding and the claim)."""

    checked: int = 0
    contradictions: list[str] = field(default_factory=list)


def check(finding: Finding, src: Sources, text: str = "") -> Verdict:
    """Every claim of ``finding`` against ``src``; ``text``: its rendered document, checked for placeholders."""
    v = Verdict()
    for c in claims(finding):
        v.checked += 1
        problem = _check(c, finding, src)
        if problem:
            v.contradictions.append(
                f"{finding.tracker} {finding.failure_id}: {c.what} at {c.frame} {c.values}: {problem}"
            )
    v.checked += 1
    if not finding.blame:
        v.contradictions.append(f"{finding.tracker} {finding.failure_id}: no stated test held (cause unknown)")
    v.checked += 1
    if "?" in text.replace("?url=", ""):
        v.contradictions.append(f"{finding.tracker} {finding.failure_id}: a '?' in the text")
    return v


def _near_detections(src: Sources, frame: int, xy: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    boxes = src.frames[frame].detections.boxes
    d = np.hypot(*(boxes.translation_m[:, :2] - xy).T) if len(boxes) else np.zeros(0)
    return d, np.flatnonzero(d < NEAR_M)


def _check(c: Claim, f: Finding, src: Sources) -> str:  # noqa: C901 (one branch per claim kind)
    v, x = c.values, c.frame
    match c.what:
        case "points":
            gt = src.scene.keyframes[x].gt
            k = np.flatnonzero(gt.instance_id.astype(str) == v[0])
            return "" if int(src.scene.keyframes[x].gt_num_pts[k[0]]) == v[1] else "points differ"
        case "no detection near" | "detection near" | "nearest own" | "no own near":
            xy = src.gt_xy(x, v[0])
            d, near = _near_detections(src, x, xy)
            det = src.frames[x].detections
            if c.what == "no detection near":
                return "" if near.size == 0 else f"detections within {NEAR_M} m: {near.tolist()}"
            if c.what == "detection near":
                m = v[1]
                if near.size == 0 or int(near[np.argmin(d[near])]) != m:
                    return "not the nearest detection within reach"
                ok = det.boxes.class_name[m] == v[2] and det.boxes.score[m] == v[3] and abs(d[m] - v[4]) < ATOL
                return "" if ok else "class, score or distance differ"
            own = [j for j in near.tolist() if det.kept[j] and det.boxes.class_name[j] == f.class_name]
            if c.what == "no own near":
                return "" if not own else f"kept {f.class_name} detections within reach: {own}"
            return "" if own and min(own, key=lambda j: d[j]) == v[1] else "not the nearest kept one of its class"
        case "went":
            got = went_of(src, x, v[0], v[1])
            if got is None:
                return "the events do not say"
            return "" if got[0] == v[2] and got[1] == v[3] and abs(got[2] - v[4]) < ATOL else f"events say {got}"
        case "output":
            box = src.box(x, v[0])
            if box is None:
                return "not in the submission"
            boxes = src.frames[x].detections.boxes
            if v[1] is None:  # output, on whatever
                return ""
            if src.output_only:
                placed = placed_on(src, x, box)
                on = placed[0] if placed is not None else -1
                return "" if on == v[1] else f"its box sits on detection {on}"
            if v[1] >= len(boxes):
                return f"the frame has no detection m{v[1]}"
            if not src.keeps_detection_box:
                took = _box_update_of(src, x, box["tracking_name"], v[0])
                if v[1] >= 0:
                    return "" if took == v[1] else f"its update took {took}, not that detection"
                return "" if took is None else f"its update took detection {took}"
            if v[1] >= 0:
                return "" if _same_geometry(box, boxes, v[1]) else "its box does not carry that detection"
            same = [m for m in range(len(boxes)) if _same_geometry(box, boxes, m)]
            if not same:
                return ""
            # A persistent false detection keeps its box from frame to frame: a track that kept that box while
            # missed looks the same. It was on that detection only if its update used it.
            cls = box["tracking_name"]
            used = used_of(src, x, cls, v[0])
            taken = [m for m in same if used is not None and m in [u for u, _ in used[0]]]
            return f"its box carries detection {taken[0]}, which its update used" if taken else ""
        case "not output":
            return "" if src.box(x, v[0]) is None else "in the submission"
        case "output near":
            box = src.box(x, v[0])
            xy = src.gt_xy(x, v[1])
            if box is None or xy is None:
                return "no box or no object"
            d = float(np.hypot(*(np.asarray(box["translation"][:2]) - xy)))
            if v[2] is None:
                return "" if d < NEAR_M else f"{d:.2f} m away"
            return "" if abs(d - v[2]) < ATOL else f"{d:.3f} m, not {v[2]:.3f}"
        case "used":
            got = used_of(src, x, v[0], v[1])
            if got is None:
                return "the events name no update of it"
            shares, missed = got
            same = len(shares) == len(v[2]) and all(
                a[0] == b[0] and abs(a[1] - b[1]) < ATOL for a, b in zip(shares, v[2], strict=True)
            )
            return "" if same and abs(missed - v[3]) < ATOL else f"events say {shares}, missed {missed}"
        case "existence":
            intensity = src.one(x, v[0], IntensityWeights)  # GM-PHD / CPHD: the label's heaviest weight
            if intensity is not None:
                mine = np.asarray(intensity.weights)[np.asarray(intensity.labels) == v[1]]
                if mine.size:
                    return "" if abs(float(mine.max()) - v[2]) < ATOL else "weight differs"
            post = src.one(x, v[0], Posterior)
            rows = np.flatnonzero(np.asarray(post.track_ids) == v[1]) if post is not None else []
            if len(rows) == 0:
                return "no posterior"
            return "" if abs(float(post.existence[rows[0]]) - v[2]) < ATOL else "existence differs"
        case "ended":
            pruned = [p for p in src.of(x, v[0], Pruned) if p.track_id == v[1]]
            logic = [
                e for e in src.of(x, v[0], TrackLogic) if e.track_id == v[1] and e.action is TrackLogicAction.DELETED
            ]
            if not pruned and not logic:
                return "no pruning or deletion event"
            if v[3] >= 0 and not any((e.hits, e.window) == (v[3], v[4]) for e in logic):
                return "hits differ"
            return ""
        case "gated":
            g = src.one(x, v[0], Gated)
            rows = np.flatnonzero(np.asarray(g.track_ids) == v[1]) if g is not None else []
            if len(rows) == 0:
                return "" if not v[2] else "no gate event"
            inside = np.flatnonzero(np.asarray(g.inside)[rows[0]])
            pairs = {(int(np.asarray(g.meas_indices)[j]), float(np.asarray(g.d2)[rows[0], j])) for j in inside}
            claimed = {(m, d2) for m, d2 in v[2]}
            return "" if pairs == claimed else f"gate holds {sorted(pairs)}"
        case "born":
            born = {
                (int(t), int(m))
                for b in src.of(x, v[0], Born)
                for t, m in zip(np.asarray(b.track_ids), np.asarray(b.meas_indices), strict=True)
            }
            return "" if (v[1], v[2]) in born else "no such birth"
        case "held since":

            def holds(frame: int) -> bool:
                h = src.one(frame, v[0], GlobalHypotheses)
                return h is not None and any(v[1] in ids for ids in h.members)

            earlier = [y for y in src.frames if y < x and holds(y)]
            return "" if holds(x) and not earlier else "not first held there"
        case "chosen":
            a = src.one(x, v[0], Assignment)
            if a is None:
                return "no assignment"
            m = next((k for k in src.of(x, v[0], CostMatrix) if k.hypothesis == a.hypothesis), None)
            pair = next(((r, col) for r, col in a.pairs if r.ref == v[1]), None)
            if m is None or pair is None:
                return "no matrix or no pair"
            if (pair[1].kind.value, int(pair[1].ref)) != (v[2], v[3]):
                return f"the assignment chose {pair[1]}"
            i = next(k for k, r in enumerate(m.rows) if r.ref == v[1])
            j = next(k for k, col in enumerate(m.cols) if col.kind.value == v[2] and col.ref == v[3])
            if abs(float(m.cost[i, j]) - v[4]) > ATOL:
                return "cost differs"
            if v[5] is not None:
                k = next(k for k, col in enumerate(m.cols) if col.kind.value == v[5] and col.ref == v[6])
                row = np.asarray(m.cost[i], dtype=float).copy()
                if not m.scale.optimal:  # a greedy matcher's alternative is a column no other detection took
                    taken = {(col.kind, col.ref) for r, col in a.pairs if r.ref != v[1]}
                    row[[n for n, col in enumerate(m.cols) if (col.kind, col.ref) in taken]] = np.inf
                others = np.delete(row, j)
                if abs(float(m.cost[i, k]) - v[7]) > ATOL or float(m.cost[i, k]) > others.min() + ATOL:
                    return "the alternative is not the row's next cheapest"
            return ""
        case "parent":
            a = src.one(x, v[0], Assignment)
            return "" if a is not None and a.hypothesis == v[1] else "the assignment's hypothesis differs"
        case "averaged score":
            kept, average = src.devkit.tracks.get(str(v[0]), ((), None))
            ok = average is not None and abs(average - v[1]) < 1e-9 and tuple(kept) == tuple(v[2])
            return "" if ok else f"devkit: {average} over {kept}"
        case "evaluated":
            status, xy = src.devkit.gt.get((x, v[0]), (None, None))
            if status is not v[1]:
                return f"devkit status {status}"
            if (xy is None) != (v[2] is None) or (xy is not None and np.hypot(xy[0] - v[2][0], xy[1] - v[2][1]) > ATOL):
                return "evaluated box differs"
            return ""
        case "false at":
            false = {
                g.frame_index for g in src.report.failures if g.kind.value == "false_track" and str(v[0]) in g.track_ids
            }
            return "" if set(v[1]) <= false else "not false there"
        case "other failed":
            report = src.others.get(v[0])
            if report is None:
                return ""

            def here(g) -> bool:
                if v[2] is not None:
                    return v[2] in g.gt_ids
                return v[3] is not None and any(
                    np.hypot(b.translation_m[0] - v[3][0], b.translation_m[1] - v[3][1]) < NEAR_M for b in g.boxes
                )

            failed = any(g.kind.value == v[1] and g.frame_index == x and here(g) for g in report.failures)
            return "" if failed == v[4] else f"it {'did' if failed else 'did not'} fail"
        case "deciding":
            held = None
            for y in sorted((y for y in src.frames if y < x), reverse=True):
                box, xy = src.box(y, v[0]), src.gt_xy(y, v[1])
                if box is not None and xy is not None and np.hypot(*(np.asarray(box["translation"][:2]) - xy)) < NEAR_M:
                    held = y
                    break
            expected = tuple(range((held + 1) if held is not None else x, x + 1))
            return "" if expected == tuple(v[2]) else f"the submission gives {expected}"
        case "blame":
            return _check_blame(v[0], v[1], f, src)
        case "output on":
            box = src.box(x, v[0])
            placed = placed_on(src, x, box) if box is not None else None
            if placed is None:
                return "its box sits on no detection"
            ok = placed[0] == v[1] and placed[1] == v[2] and abs(placed[2] - v[3]) < ATOL
            return "" if ok else f"its box sits on {placed}"
        case "first output":
            earlier = [y for y in range(x) if src.box(y, v[0]) is not None]
            return "" if src.box(x, v[0]) is not None and not earlier else f"output at frames {earlier} before"
    return f"unknown claim {c.what}"


def _check_blame(rule: Rule, frames: tuple[int, ...], f: Finding, src: Sources) -> str:
    """The stated test of ``rule`` (``why.findings``) recomputed at each frame from the sources."""
    for x in frames:
        xy = src.gt_xy(x, f.gt_id) if f.gt_id is not None else None
        match rule:
            case Rule.NO_DETECTION | Rule.UNSEEN:
                if xy is None or _near_detections(src, x, xy)[1].size:
                    return f"a detection lies within reach at frame {x}"
                hidden = src.points(x, f.gt_id) == 0
                if hidden != (rule is Rule.UNSEEN):
                    return f"the object {'had no' if hidden else 'had'} points at frame {x}"
            case Rule.NOT_OUTPUT:
                track = f.lost.track_id if f.lost is not None else None
                if track is not None and src.box(x, track) is not None:
                    return f"track {track} was output at frame {x}"
            case Rule.OFF_OBJECT:
                box = src.box(x, f.lost.track_id)
                if box is None or np.hypot(*(np.asarray(box["translation"][:2]) - xy)) < NEAR_M:
                    return "the track was within reach"
            case Rule.INTERPOLATED if f.false_output is not None:  # the object's evaluated box out of the track's reach
                status, at = src.devkit.gt.get((x, f.gt_id), (None, None))
                far = at is not None and np.hypot(*(np.asarray(at) - f.false_output.output_xy_m)) >= NEAR_M
                if status is not GtStatus.INTERPOLATED or not far:
                    return "the evaluation's box of the object is within the track's reach"
            case Rule.INTERPOLATED:
                status, at = src.devkit.gt.get((x, f.gt_id), (None, None))
                if status is not GtStatus.INTERPOLATED or np.hypot(*(np.asarray(at) - xy)) < EVALUATED_OFFSET_M:
                    return "the evaluation scored no far interpolated box"
            case Rule.DETECTION_UNUSED:
                d, near = _near_detections(src, x, xy)
                boxes = src.frames[x].detections.boxes
                own = [j for j in near.tolist() if boxes.class_name[j] == f.class_name]
                if not own:
                    return f"no detection of its class within reach at frame {x}"
                if f.lost is not None:
                    used = used_of(src, x, f.class_name, f.lost.track_id)
                    nearest = min(own, key=lambda j: d[j])
                    if used is not None and nearest in [m for m, _ in used[0]]:
                        return f"track {f.lost.track_id} used m{nearest} at frame {x}"
            case Rule.TRACK_DROPPED if f.false_output is not None or f.kind is FailureKind.COALESCENCE:
                t = f.false_output.track_id if f.false_output is not None else f.track_ids[0]
                kept, _ = src.devkit.tracks.get(str(t), ((), None))
                if src.box(x, t) is None or x in kept:
                    return "the track's box was not dropped there"
            case Rule.TRACK_INTERPOLATED:
                t = f.false_output.track_id if f.false_output is not None else f.track_ids[0]
                kept, _ = src.devkit.tracks.get(str(t), ((), None))
                if x in kept:
                    return "the evaluation kept the track's own box there"
            case Rule.TRACK_DROPPED:
                dropped = False
                for b in src.results.get(src.scene.keyframes[x].sample_token, ()):
                    if b["tracking_name"] != f.class_name or xy is None:
                        continue
                    if np.hypot(*(np.asarray(b["translation"][:2]) - xy)) < NEAR_M:
                        kept, _ = src.devkit.tracks.get(b["tracking_id"], ((), None))
                        dropped |= x not in kept
                if not dropped:
                    return "no track box on it was dropped"
            case Rule.TWO_TRACKS if f.lost is not None:
                near = [
                    b["tracking_id"]
                    for b in src.results.get(src.scene.keyframes[x].sample_token, ())
                    if b["tracking_name"] == f.class_name
                    and np.hypot(*(np.asarray(b["translation"][:2]) - xy)) < NEAR_M
                ]
                if str(f.lost.track_id) not in near or len(near) < 2:
                    return "not two tracks on the object"
            case Rule.COVERED_TWO if f.kind.value in ("miss", "fragmentation"):
                counted = [
                    b
                    for b in src.results.get(src.scene.keyframes[x].sample_token, ())
                    if b["tracking_name"] == f.class_name
                    and np.hypot(*(np.asarray(b["translation"][:2]) - xy)) < NEAR_M
                    and x in src.devkit.tracks.get(b["tracking_id"], ((), None))[0]
                    and src.devkit.tracks[b["tracking_id"]][1] >= (src.report.threshold_of(f.class_name) or 0.0)
                ]
                if not counted:
                    return "no counted track lies within reach"
            case Rule.NO_EVAL_BOX:
                gt_id = f.false_output.nearest_own[0] if f.false_output and f.false_output.nearest_own else f.gt_id
                status, _ = src.devkit.gt.get((x, gt_id), (None, None))
                if status in (GtStatus.SCORED, GtStatus.INTERPOLATED):
                    return "the evaluation has a box"
            case _:
                pass  # the other rules' facts are claimed and checked one by one above
    if rule is Rule.NO_DETECTION and f.lost is not None:  # complete: every deciding frame without a detection
        gaps = [
            x
            for x in f.deciding
            if (xy := src.gt_xy(x, f.gt_id)) is not None
            and x in src.frames
            and not _near_detections(src, x, xy)[1].size
            and src.points(x, f.gt_id) > 0
        ]
        if tuple(gaps) != tuple(frames):
            return f"frames without a detection: {gaps}"
    return ""


# Running it.
def sources(request, tracker: str, evidence: Mapping[str, Any], events: Sequence | None = None) -> Sources:
    """The independent sources of ``tracker``'s findings on ``request``'s scene: its submission (a results file:
    the file, read here), its raw events (``events``: the ones it emitted, e.g. a ``ListSink``'s; None: run it again
    to record them), the devkit's evaluation recomputed, the other trackers' reports."""
    from gnnpmb.data.nuscenes import open_nuscenes
    from gnnpmb.eval.nuscenes_eval import tracking_config
    from gnnpmb.eval.submission import run_results
    from gnnpmb.registry import tracker_keeps_detection_box
    from gnnpmb.stages.runs import track_run

    run = evidence[tracker].run
    spec = request.spec(tracker)
    if spec.results is not None:
        results = file_results(spec.results, request.scene, request.classes)
        events = []
    else:
        if events is None:
            listed = ListSink()
            track_run(request, tracker, listed)
            events = listed.events
        results = run_results(run)
    by: dict[tuple[int, str], dict[type, list]] = defaultdict(lambda: defaultdict(list))
    frame = -1
    for e in events:
        if isinstance(e, FrameStarted):
            frame = e.frame_index
        else:
            by[(frame, e.class_name)][type(e)].append(e)
    return Sources(
        request.scene,
        {fr.keyframe.index: fr for fr in run.frames},
        results,
        by,
        evidence[tracker].report,
        recompute_devkit(open_nuscenes(request.location), request.scene, results, tracking_config()),
        {t: ev.report for t, ev in evidence.items() if t != tracker},
        keeps_detection_box=spec.results is not None or tracker_keeps_detection_box(str(spec.tracker)),
        output_only=spec.results is not None,
    )


def file_results(path, scene, classes: Sequence[str]) -> dict[str, list[dict[str, Any]]]:
    """A results file's boxes of ``scene``'s samples and ``classes``, read here; ids that are not plain integers
    unique across classes numbered 1, 2, ... in order of appearance (as the run names them)."""
    import json
    import re

    data = json.loads(Path(path).read_bytes())["results"]
    tokens = [k.sample_token for k in scene.keyframes]
    boxes = {t: [dict(b) for b in data[t] if b["tracking_name"] in classes] for t in tokens}
    keys = list(dict.fromkeys((str(b["tracking_id"]), b["tracking_name"]) for t in tokens for b in boxes[t]))
    plain = all(re.fullmatch(r"0|[1-9][0-9]{0,14}", i) for i, _ in keys) and len({i for i, _ in keys}) == len(keys)
    number = {key: (key[0] if plain else str(k + 1)) for k, key in enumerate(keys)}
    for t in tokens:
        for b in boxes[t]:
            b["tracking_id"] = number[(str(b["tracking_id"]), b["tracking_name"])]
    return boxes


def run_one(request, tracker: str, others: Sequence[str] = ()) -> tuple[Verdict, int]:
    """Check every finding of ``tracker`` (a run of ``request``: a tracker or a results file) on ``request``'s scene;
    returns the verdict and the number of findings."""
    from gnnpmb.focus import resolve_focus
    from gnnpmb.stages.evaluation import find_reports
    from gnnpmb.stages.findings import all_evidence
    from gnnpmb.stages.runs import run_all
    from gnnpmb.why.findings import FRAMES_BEFORE
    from gnnpmb.why.reason import explain_failure
    from viz.focus_summary import focus_markdown

    runs = [r for r in run_all(request, record=True) if r.name in (tracker, *others)]
    reports, _ = find_reports(request, runs)
    evidence = all_evidence(request, runs, reports)
    src = sources(request, tracker, evidence, next(r for r in runs if r.name == tracker).events)
    verdict = Verdict()
    report = reports[tracker]
    rest = [evidence[t] for t in others]
    views = _views(request, evidence)
    estimates = {t: [fr.estimates for fr in ev.run.frames] for t, ev in evidence.items()}
    for fid, failure in zip(report.ids(), report.failures, strict=True):
        start = max(request.frame_range.start, failure.frame_index - FRAMES_BEFORE)
        finding = explain_failure(fid, evidence[tracker], request.scene, rest, first_frame=start)
        focus = resolve_focus(fid, request.scene, reports, estimates, request.frame_range)
        shown = focus.window(request.frame_range)
        text = focus_markdown(focus, finding, views, shown, request.scene)
        one = check(finding, src, text)
        verdict.checked += one.checked
        verdict.contradictions += one.contradictions
    return verdict, len(report.failures)


def _views(request, evidence: Mapping[str, Any]) -> dict[str, Any]:
    """What the focus document shows of each tracker, as a recording would (its story told from its facts)."""
    from gnnpmb.why.story import Storyteller
    from viz.focus_summary import TrackerView

    out = {}
    for t, ev in evidence.items():
        teller = Storyteller(ev.facts)
        story = tuple(line for f in ev.facts.frame_indices for line in teller.frame_lines(f))
        out[t] = TrackerView(ev, request.capabilities(t).has_gates, story, frozenset(teller.shown_ever))
    return out


def main(argv: Sequence[str] | None = None) -> int:
    from gnnpmb.data.demo import DEMO_SCENES
    from gnnpmb.data.demo_staged import STAGED_SCENES
    from gnnpmb.data.simdet_presets import PRESETS
    from gnnpmb.registry import TRACKER_NAMES
    from gnnpmb.stages.inputs import load_inputs
    from gnnpmb.stages.request import check_request

    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--scene", action="append", help="demo scenes (default: all)")
    parser.add_argument("--detector", action="append", help="presets (default: all; centerpoint with --results)")
    parser.add_argument("--tracker", action="append", help="trackers (default: all; none with --results)")
    parser.add_argument(
        "--results",
        action="append",
        metavar="NAME=FILE.json",
        help="check a results file's findings instead, on the scenes it covers (made on the given detections)",
    )
    parser.add_argument("--show", type=int, default=5, help="contradictions printed per tracker")
    args = parser.parse_args(argv)
    totals: dict[str, list[int]] = defaultdict(lambda: [0, 0, 0])
    shown: dict[str, list[str]] = defaultdict(list)
    jobs: list[tuple[str, str, list[str], list[str]]] = []  # (scene, detector, trackers, results)
    if args.results:
        covered = _covered_scenes(args.results, args.scene or list(DEMO_SCENES + STAGED_SCENES))
        jobs = [
            (scene, d, [], [r]) for r in args.results for scene in covered[r] for d in args.detector or ["centerpoint"]
        ]
    else:
        scenes = args.scene or list(DEMO_SCENES + STAGED_SCENES)
        jobs = [
            (s, d, [t], [])
            for s in scenes
            for d in args.detector or list(PRESETS)
            for t in args.tracker or TRACKER_NAMES
        ]
    for scene, detector, trackers, results in jobs:
        request = load_inputs(check_request(scene, trackers, results=results, detector=detector))
        name = request.trackers[0]
        verdict, n = run_one(request, name)
        t = totals[name]
        t[0] += n
        t[1] += verdict.checked
        t[2] += len(verdict.contradictions)
        shown[name] += verdict.contradictions
    print(f"{'tracker':8} {'findings':>9} {'claims':>8} {'contradictions':>15}")
    for tracker, (n, checked, bad) in totals.items():
        print(f"{tracker:8} {n:9d} {checked:8d} {bad:15d}")
        for line in shown[tracker][: args.show]:
            print(f"    {line}")
    return 1 if any(t[2] for t in totals.values()) else 0


def _covered_scenes(results: Sequence[str], scenes: Sequence[str]) -> dict[str, list[str]]:
    """Per ``NAME=FILE.json``, the ``scenes`` whose first sample the file holds."""
    import json

    from gnnpmb.data.nuscenes import resolve_dataroot, sample_tokens

    location = resolve_dataroot(None, None, tuple(scenes))
    first = {s: sample_tokens(location, [s])[0] for s in scenes}
    out = {}
    for spec in results:
        held = json.loads(Path(spec.split("=", 1)[1]).read_bytes())["results"]
        out[spec] = [s for s in scenes if first[s] in held]
    return out


if __name__ == "__main__":
    sys.exit(main())
