"""A finding's typed fields (what ``gnnpmb failures --why --json`` writes, as ``gnnpmb.why.claims`` lists them one
assertion at a time) checked against the checker's own sources, as the text's sentences are: the files
(``scene.SceneTruth``: detections in file order, annotations, points, ego poses), the raw events
(``rawevents.RawEvents``), the devkit's bookkeeping (``devkit.EvalFacts``: its kept and interpolated boxes, averaged
scores, per-frame matches) and, for a results file, where its boxes sit (``output.placed``). The text names only
some of these fields; the JSON writes them all (every sighting's detections and destination, every step's gate,
update and existence, the blame's frames).

One check per claim kind (``CLAIM_KINDS``); the stated tests of the blame (``why.findings.Rule``) are recomputed
frame by frame from the same sources. Each failed check is a ``Contradiction`` of class ``fields``.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping

import numpy as np

from gnnpmb.events import (
    Assignment,
    AxisKind,
    Born,
    CostMatrix,
    Gated,
    GlobalHypotheses,
    IntensityWeights,
    Marginals,
    Posterior,
    Pruned,
    TrackLogic,
    TrackLogicAction,
    UpdateWeights,
)
from tools.truth.devkit import EvalFacts
from tools.truth.output import NEAREST_M, placed
from tools.truth.rawevents import RawEvents
from tools.truth.scene import NEAR_M, SceneTruth

ATOL = 1e-6
USED_SHARE = 0.01
"""The checker's own copy of the share from which an update used a detection."""
EVALUATED_OFFSET_M = 0.5
"""The checker's own copy of the offset from which an interpolated box is 'far' from the annotation (the rule
``INTERPOLATED``)."""
CLASS_RANGE_M = {
    "car": 50.0,
    "truck": 50.0,
    "bus": 50.0,
    "trailer": 50.0,
    "pedestrian": 40.0,
    "motorcycle": 40.0,
    "bicycle": 40.0,
}
"""The devkit's ``tracking_nips_2019`` class ranges (its config file), copied here."""


class Sources:
    """What the fields are checked against, for one run on one scene: the files, the raw events (None: a results
    file), the devkit's bookkeeping of this run and of the other runs (by name); keeps_detection_box: the tracker's
    boxes repeat the size, heading and height of the detection that updated them (False: a box filter's do not)."""

    def __init__(
        self,
        scene: SceneTruth,
        raw: RawEvents | None,
        ev: EvalFacts,
        others: Mapping[str, EvalFacts] | None = None,
        keeps_detection_box: bool = True,
    ) -> None:
        self.scene, self.raw, self.ev = scene, raw, ev
        self.others = dict(others or {})
        self.keeps_detection_box = keeps_detection_box

    @property
    def output_only(self) -> bool:
        return self.raw is None

    def box(self, x: int, track: int) -> tuple[str, tuple[float, float]] | None:
        """(class, centre) of the submission's box of ``track`` at frame ``x``; None: none."""
        return next(((c, xy) for t, c, xy in self.ev.boxes.get(x, []) if t == str(track)), None)

    def gt_xy(self, x: int, gt_id: str | None) -> np.ndarray | None:
        a = self.scene.objects[x].get(gt_id) if gt_id is not None and 0 <= x < len(self.scene.objects) else None
        return None if a is None else np.asarray(a.xy_m, dtype=float)

    def points(self, x: int, gt_id: str) -> int:
        a = self.scene.objects[x].get(gt_id)
        return a.points if a is not None else 0

    def near(self, x: int, xy: np.ndarray) -> tuple[np.ndarray, list[int]]:
        d = self.scene.distances(x, (float(xy[0]), float(xy[1])))
        return d, np.flatnonzero(d < NEAR_M).tolist()

    def one(self, x: int, c: str, kind: type):
        return self.raw.last(x, c, kind) if self.raw is not None else None

    def carries(self, x: int, track: int, m: int) -> bool:
        """Whether the track's box at ``x`` repeats detection ``m``'s size, heading and height."""
        g, det = self.ev.geometry.get((x, str(track))), self.scene.detections[x][m].box
        return g is not None and len(g) == len(det) and all(abs(a - b) < ATOL for a, b in zip(g, det, strict=True))

    def status(self, x: int, gt_id: str) -> tuple[str | None, tuple[float, float] | None]:
        """How the devkit scored the object at ``x`` (the ``GtStatus`` values) and the centre it scored."""
        a = self.scene.objects[x].get(gt_id) if 0 <= x < len(self.scene.objects) else None
        if a is None:
            return None, None
        xy = self.ev.evaluated_gt.get((x, gt_id))
        if (x, gt_id) in self.ev.kept_gt:
            return "scored", xy
        if xy is not None:
            return "interpolated", xy
        ego = self.scene.ego_xy_m[x] if self.scene.ego_xy_m is not None else None
        far = ego is not None and math.hypot(a.xy_m[0] - ego[0], a.xy_m[1] - ego[1]) >= CLASS_RANGE_M[a.class_name]
        return ("beyond the class range" if far else "no box"), None

    def kept_frames(self, track: int) -> tuple[int, ...]:
        return self.ev.kept_frames.get(str(track), ())


def used_of(src: Sources, x: int, c: str, track: int) -> tuple[tuple[tuple[int, float], ...], float] | None:
    """(detection, share) >= ``USED_SHARE`` and the missed share of the track's update at ``x`` from the raw events
    (Marginals, else a PHD's UpdateWeights, else the Assignment); a results file: the detection its box sits on."""
    if src.output_only:
        if src.box(x, track) is None:
            return None
        p = placed(x, str(track), src.scene, src.ev)
        return (((p[0], 1.0),), 0.0) if p is not None else ((), 1.0)
    marg = src.one(x, c, Marginals)
    if marg is not None:
        rows = [i for i, r in enumerate(marg.rows) if r.ref == track]
        if not rows:
            return None
        p = np.asarray(marg.probs)[rows[0]]
        shares = [(int(col.ref), float(p[k])) for k, col in enumerate(marg.cols) if col.kind is AxisKind.MEASUREMENT]
        missed = sum(float(p[k]) for k, col in enumerate(marg.cols) if col.kind is AxisKind.MISSED)
        return tuple(sorted(((m, v) for m, v in shares if v >= USED_SHARE), key=lambda s: (-s[1], s[0]))), missed
    w = src.one(x, c, UpdateWeights)
    if w is not None:
        rows = np.flatnonzero(np.asarray(w.labels) == track)
        if not rows.size:
            return None
        det, miss = np.asarray(w.detected)[rows[0]], float(np.asarray(w.missed)[rows[0]])
        total = miss + float(det.sum())
        shares = [(int(m), float(det[j] / total)) for j, m in enumerate(np.asarray(w.meas_indices).tolist())]
        return tuple(sorted(((m, v) for m, v in shares if v >= USED_SHARE), key=lambda s: (-s[1], s[0]))), miss / total
    a = src.one(x, c, Assignment)
    if a is None:
        return None
    for row, col in a.pairs:
        if col.kind is AxisKind.TRACK and col.ref == track:
            return ((int(row.ref), 1.0),), 0.0
    return ((), 1.0) if track in a.missed_track_ids else None


def went_of(src: Sources, x: int, c: str, meas: int) -> tuple[str, int, float] | None:
    """Where detection ``meas`` went at ``x``: (went, track, share) from the raw events; a results file: the
    lowest-numbered track whose box sits on it, else 'under no output box' with the nearest box of its class within
    ``NEAREST_M`` (one that sat on another detection; -1: none)."""
    if src.output_only:
        boxes = src.ev.boxes.get(x, [])
        on = sorted(
            int(t)
            for t, cls, _ in boxes
            if cls == c and (p := placed(x, t, src.scene, src.ev)) is not None and p[0] == meas
        )
        if on:
            return ("track", on[0], 1.0)
        d = src.scene.detections[x][meas].xy_m
        near = sorted((math.hypot(xy[0] - d[0], xy[1] - d[1]), int(t)) for t, cls, xy in boxes if cls == c)
        return ("under no output box", near[0][1] if near and near[0][0] < NEAREST_M else -1, 1.0)
    born = src.raw.born(x, c)

    def new(share: float) -> tuple[str, int, float]:
        return ("new track", born[meas], share) if meas in born else ("new", -1, share)

    marg = src.one(x, c, Marginals)
    if marg is not None:
        cols = [k for k, col in enumerate(marg.cols) if col.kind is AxisKind.MEASUREMENT and col.ref == meas]
        if not cols:
            return new(1.0)
        column = np.asarray(marg.probs)[:, cols[0]]
        p_new = max(0.0, 1.0 - float(column.sum()))
        k = int(np.argmax(column)) if column.size else -1
        if k >= 0 and column[k] > p_new:
            return "track", int(marg.rows[k].ref), float(column[k])
        return new(p_new)
    w = src.one(x, c, UpdateWeights)
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
    a = src.one(x, c, Assignment)
    if a is not None:
        for row, col in a.pairs:
            if row.ref == meas:
                return ("track", int(col.ref), 1.0) if col.kind is AxisKind.TRACK else new(1.0)
    return new(1.0)


def _update_of(src: Sources, x: int, c: str, track: int) -> int | None:
    """The detection a box filter's track was born from or updated with at ``x`` (Born, Assignment); None."""
    for b in src.raw.of_kind(x, c, Born):
        hit = np.flatnonzero(np.asarray(b.track_ids) == track)
        if hit.size:
            return int(np.asarray(b.meas_indices)[hit[0]])
    used = used_of(src, x, c, track)
    return used[0][0][0] if used is not None and used[0] else None


def failed_here(ev: EvalFacts, kind: str, c: str, x: int, gt_id: str | None, place) -> bool | None:
    """Whether a run (its devkit bookkeeping ``ev``) had a failure of ``kind`` at frame ``x`` on object ``gt_id``
    of class ``c`` (a false track: a false positive of class ``c`` within ``NEAR_M`` of ``place``); None: a kind the
    bookkeeping does not decide here."""
    pairs = ev.gt_to_track.get((c, x), {})
    if kind in ("id_switch", "identity_theft"):
        return gt_id is not None and gt_id in ev.switches.get((c, x), set())
    if kind == "miss":
        return gt_id is not None and gt_id in pairs and pairs[gt_id] is None
    if kind == "false_track":  # a false track of the class within reach of the place (near the object, if named)
        return place is not None and bool(ev.false_near(x, place, c))
    if gt_id is None:
        return False
    if kind == "fragmentation":
        steps = sorted(f for (cc, f), p in ev.gt_to_track.items() if cc == c and gt_id in p)
        missed = {f: ev.gt_to_track[(c, f)][gt_id] is None for f in steps}
        if x not in missed or not missed[x]:
            return False
        before = [f for f in steps if f < x]
        return bool(before) and not missed[before[-1]] and any(not missed[f] for f in steps if f > x)
    if kind == "coalescence":  # the object missed beside a matched one (matched itself, the run kept it)
        return gt_id in _coalesced(ev, c, x) and gt_id in pairs and pairs[gt_id] is None
    return None


def _coalesced(ev: EvalFacts, c: str, x: int) -> set[str]:
    """The objects of a coalescence at ``x``: each missed object within ``NEAR_M`` of a matched object whose track's
    scored box lies within ``NEAR_M`` of it too, and those matched objects."""
    pairs, at = ev.gt_to_track.get((c, x), {}), ev.pred_xy.get((c, x), {})
    out: set[str] = set()

    def xy(g: str):
        return ev.evaluated_gt.get((x, g))

    for o, h in pairs.items():
        if h is not None or xy(o) is None:
            continue
        near = [
            (math.dist(xy(o), xy(b)), b)
            for b, t in pairs.items()
            if t is not None
            and xy(b) is not None
            and t in at
            and math.dist(xy(o), xy(b)) < NEAR_M
            and math.dist(xy(o), at[t]) < NEAR_M
        ]
        if near:
            out |= {o, min(near)[1]}
    return out


def check_claim(what: str, x: int, v: tuple, f, src: Sources) -> str:  # noqa: C901 (one branch per claim kind)
    """'' when claim ``what`` at frame ``x`` with values ``v`` of finding ``f`` holds, else what the sources say."""
    c = f.class_name
    match what:
        case "points":
            return "" if src.points(x, v[0]) == v[1] else f"the annotation has {src.points(x, v[0])} points"
        case "no detection near" | "detection near" | "nearest own" | "no own near":
            xy = src.gt_xy(x, v[0])
            if xy is None:
                return "no annotation of the object there"
            d, near = src.near(x, xy)
            dets = src.scene.detections[x]
            if what == "no detection near":
                return "" if not near else f"detections within {NEAR_M} m: {near}"
            if what == "detection near":
                m, owner = v[1], {j: src.scene.claimant(x, j, tuple(xy), c) for j in near}
                owner = {j: o[0] if o is not None else None for j, o in owner.items()}
                own = [j for j in near if owner[j] is None]  # the detections nearer this object than any other
                if not near or min(own or near, key=lambda j: d[j]) != m:
                    return "not the nearest detection within reach (of this object's, where it has one)"
                if owner[m] != v[5]:
                    return f"the detection lies nearer GT {owner[m]}" if owner[m] else "the detection is the object's"
                ok = dets[m].class_name == v[2] and abs(dets[m].score - v[3]) < ATOL and abs(d[m] - v[4]) < ATOL
                return "" if ok else "class, score or distance differ"
            # of its class and its own: one that lies nearer another annotated object is that one's (a neighbour's
            # box, dev set scene-0916 centerpoint frame 27: two pedestrians 0.78 m apart, one box)
            own = [j for j in _own_near(src, x, xy, c) if dets[j].class_name == c]
            if src.raw is not None:  # kept: the tracker received it after its preprocessing
                got = src.raw.received(x, c)
                own = [j for j in own if j in got]
            elif what == "no own near":
                return ""  # a results file's run: what preprocessing kept is no fact of the file
            if what == "no own near":
                return "" if not own else f"received {c} detections within reach: {own}"
            if src.raw is None:
                return "" if v[1] in own else "no detection of its class within reach"
            return "" if own and min(own, key=lambda j: d[j]) == v[1] else "not the nearest received one of its class"
        case "went":
            got = went_of(src, x, v[0], v[1])
            if got is None:
                return "the events do not say"
            return "" if got[0] == v[2] and got[1] == v[3] and abs(got[2] - v[4]) < ATOL else f"events say {got}"
        case "output":
            return _check_output(x, v, src)
        case "not output":
            return "" if src.box(x, v[0]) is None else "in the submission"
        case "output near":
            box, xy = src.box(x, v[0]), src.gt_xy(x, v[1])
            if box is None or xy is None:
                return "no box or no object"
            d = math.hypot(box[1][0] - xy[0], box[1][1] - xy[1])
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
            return "" if abs(float(np.asarray(post.existence)[rows[0]]) - v[2]) < ATOL else "existence differs"
        case "ended":
            pruned = [p for p in src.raw.of_kind(x, v[0], Pruned) if p.track_id == v[1]]
            logic = [
                e
                for e in src.raw.of_kind(x, v[0], TrackLogic)
                if e.track_id == v[1] and e.action is TrackLogicAction.DELETED
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
            return "" if pairs == {(m, d2) for m, d2 in v[2]} else f"gate holds {sorted(pairs)}"
        case "born":
            born = {
                (int(t), int(m))
                for b in src.raw.of_kind(x, v[0], Born)
                for t, m in zip(np.asarray(b.track_ids), np.asarray(b.meas_indices), strict=True)
            }
            return "" if (v[1], v[2]) in born else "no such birth"
        case "held since":

            def holds(y: int) -> bool:
                h = src.one(y, v[0], GlobalHypotheses)
                return h is not None and any(v[1] in ids for ids in h.members)

            return "" if holds(x) and not any(holds(y) for y in range(x)) else "not first held there"
        case "chosen":
            return _check_chosen(x, v, src)
        case "parent":
            a = src.one(x, v[0], Assignment)
            return "" if a is not None and a.hypothesis == v[1] else "the assignment's hypothesis differs"
        case "averaged score":
            kept, average = src.kept_frames(v[0]), src.ev.averaged.get(str(v[0]), (0, None))[1]
            ok = average is not None and abs(average - v[1]) < 1e-9 and tuple(kept) == tuple(v[2])
            return "" if ok else f"devkit: {average} over {kept}"
        case "evaluated":
            status, xy = src.status(x, v[0])
            said = v[1].value if hasattr(v[1], "value") else v[1]
            if status != said:
                return f"devkit status {status}"
            if (xy is None) != (v[2] is None) or (xy is not None and math.dist(xy, v[2]) > ATOL):
                return "evaluated box differs"
            return ""
        case "kept around":
            kept = sorted(y for y, k in src.ev.kept_gt if k == v[0])
            got = (max((y for y in kept if y < x), default=None), min((y for y in kept if y > x), default=None))
            return "" if got == (v[1], v[2]) else f"the devkit kept its box last before / first after at {got}"
        case "false at":
            false = {y for y in v[1] if str(v[0]) in src.ev.track_to_gt.get((c, y), {})}
            false = {y for y in false if src.ev.matched_gt(c, y, str(v[0])) is None}
            return "" if set(v[1]) <= false else f"matched (not false) at {sorted(set(v[1]) - false)}"
        case "other failed":
            other = src.others.get(v[0])
            if other is None:
                return ""
            failed = failed_here(other, v[1], c, x, v[2], v[3])
            return "" if failed is None or failed == v[4] else f"it {'did' if failed else 'did not'} fail"
        case "other matched":
            other = src.others.get(v[0])
            if other is None:
                return ""
            got = other.matched_track(c, x, v[1])
            return "" if got == (None if v[2] is None else str(v[2])) else f"its evaluation matched it to {got}"
        case "other switched":
            other = src.others.get(v[0])
            if other is None:
                return ""
            switched = v[1] in other.switches.get((c, x), set())
            return "" if switched == v[2] else f"its devkit events {'have' if switched else 'have no'} SWITCH of it"
        case "blame":
            return check_blame(v[0], v[1], f, src)
        case "deciding":
            held = None
            for y in range(x - 1, -1, -1):
                box, xy = src.box(y, v[0]), src.gt_xy(y, v[1])
                if box is not None and xy is not None and math.hypot(box[1][0] - xy[0], box[1][1] - xy[1]) < NEAR_M:
                    held = y
                    break
            expected = tuple(range((held + 1) if held is not None else x, x + 1))
            return "" if expected == tuple(v[2]) else f"the submission gives {expected}"
        case "matched away":
            return _check_matched_away(x, c, v, src.ev)
        case "output on":
            p = placed(x, str(v[0]), src.scene, src.ev)
            if p is None:
                return "its box sits on no detection"
            ok = p[0] == v[1] and ("same box" if p[1] else "nearest") == v[2] and abs(p[2] - v[3]) < ATOL
            return "" if ok else f"its box sits on {p}"
        case "first output":
            earlier = [y for y in range(x) if src.box(y, v[0]) is not None]
            return "" if src.box(x, v[0]) is not None and not earlier else f"output at frames {earlier} before"
    return f"unknown claim {what}"


def _check_matched_away(x: int, c: str, v: tuple, ev: EvalFacts) -> str:
    """'matched away' (track, gt, since, ((other gt, frames), ...)): the accumulator's last match of the object
    before ``x`` is at since, to the track, and its matches of the track after since up to ``x`` to other objects
    are exactly those."""
    track, gt, since, away = str(v[0]), v[1], v[2], v[3]
    last = max((y for (k, y), objs in ev.gt_to_track.items() if k == c and y < x and objs.get(gt)), default=None)
    if last != since or ev.matched_track(c, last, gt) != track:
        got = None if last is None else ev.matched_track(c, last, gt)
        return f"the devkit last matched the object before frame {x} at frame {last} (to track {got})"
    devkit: dict[str, list[int]] = {}
    for y in range(since + 1, x + 1):
        g = ev.matched_gt(c, y, track)
        if g is not None and g != gt:
            devkit.setdefault(g, []).append(y)
    said = {g: list(frames) for g, frames in away}
    return "" if said == devkit else f"the devkit matched track {track} to {devkit} after frame {since}"


def _check_output(x: int, v: tuple, src: Sources) -> str:
    """'output' (track, meas): the submission has the track's box at ``x``, on detection meas (-1: on none; None:
    on whatever)."""
    box = src.box(x, v[0])
    if box is None:
        return "not in the submission"
    if v[1] is None:
        return ""
    if src.output_only:
        p = placed(x, str(v[0]), src.scene, src.ev)
        on = p[0] if p is not None else -1
        return "" if on == v[1] else f"its box sits on detection {on}"
    dets = src.scene.detections[x]
    if v[1] >= len(dets):
        return f"the frame has no detection m{v[1]}"
    if not src.keeps_detection_box:
        took = _update_of(src, x, box[0], v[0])
        if v[1] >= 0:
            return "" if took == v[1] else f"its update took {took}, not that detection"
        return "" if took is None else f"its update took detection {took}"
    if v[1] >= 0:
        return "" if src.carries(x, v[0], v[1]) else "its box does not carry that detection"
    same = [m for m in range(len(dets)) if src.carries(x, v[0], m)]
    # A persistent false detection keeps its box from frame to frame: a track that kept that box while missed
    # looks the same. It was on that detection only if its update used it.
    used = used_of(src, x, box[0], v[0]) if same else None
    taken = [m for m in same if used is not None and m in [u for u, _ in used[0]]]
    return f"its box carries detection {taken[0]}, which its update used" if taken else ""


def _check_chosen(x: int, v: tuple, src: Sources) -> str:
    """'chosen' (class, meas, kind, ref, cost, alternative kind, ref, cost): the frame's assignment gave the detection
    that column at that cost in its matrix, and the alternative is the row's next cheapest (for a greedy matcher,
    among the columns no other detection took)."""
    a = src.one(x, v[0], Assignment)
    if a is None:
        return "no assignment"
    m = next((k for k in src.raw.of_kind(x, v[0], CostMatrix) if k.hypothesis == a.hypothesis), None)
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
        if not m.scale.optimal:
            taken = {(col.kind, col.ref) for r, col in a.pairs if r.ref != v[1]}
            row[[n for n, col in enumerate(m.cols) if (col.kind, col.ref) in taken]] = np.inf
        if abs(float(m.cost[i, k]) - v[7]) > ATOL or float(m.cost[i, k]) > np.delete(row, j).min() + ATOL:
            return "the alternative is not the row's next cheapest"
    return ""


def check_blame(rule, frames: tuple[int, ...], f, src: Sources) -> str:  # noqa: C901 (one branch per rule)
    """The stated test of ``rule`` (``why.findings.Rule``) recomputed at each of ``frames`` from the sources."""
    name = rule.name
    c = f.class_name
    false_track = f.false_output.track_id if f.false_output is not None else None
    for x in frames:
        xy = src.gt_xy(x, f.gt_id)
        if name == "UNANNOTATED":  # no annotation there, one before and one after (the devkit interpolates between)
            have = [y for y in range(len(src.scene.objects)) if (f.gt_id or "") in src.scene.objects[y]]
            if xy is not None or not any(y < x for y in have) or not any(y > x for y in have):
                return f"the object is annotated at frame {x}, or not on both sides of it"
        elif name in ("NO_DETECTION", "UNSEEN"):  # none of its own: each one within reach lies nearer another object
            if xy is None or _own_near(src, x, xy, c):
                return f"a detection of the object lies within reach at frame {x}"
            hidden = src.points(x, f.gt_id) == 0
            if hidden != (name == "UNSEEN"):
                return f"the object {'had no' if hidden else 'had'} points at frame {x}"
        elif name == "OTHER_CLASS" and f.false_output is None:  # the object's own detections: another class only
            mine = _own_near(src, x, xy, c) if xy is not None else []
            if not mine or any(src.scene.detections[x][j].class_name == c for j in mine):
                return f"no detection of the object's own of another class only at frame {x}"
        elif name == "NOT_OUTPUT" and f.lost is not None:
            if src.box(x, f.lost.track_id) is not None:
                return f"track {f.lost.track_id} was output at frame {x}"
        elif name == "OFF_OBJECT" and f.lost is None:  # a false box on a detection of an object (audit truth54)
            on = f.false_output.on if f.false_output is not None else None
            box = src.box(x, false_track) if false_track is not None else None
            if on is None or box is None or on.meas >= len(src.scene.detections[x]):
                return "no box on a detection"
            det = src.scene.detections[x][on.meas].xy_m
            objs = src.scene.objects[x].values()
            if not any(math.dist(a.xy_m, det) < NEAR_M for a in objs):
                return "its detection lies within reach of no object"
            if any(math.dist(a.xy_m, box[1]) < NEAR_M for a in objs):
                return "the track's box lies within reach of an object"
        elif name == "DETECTION_OF_NOTHING":  # the detection itself lies within reach of no object (audit truth54)
            on = f.false_output.on if f.false_output is not None else None
            if on is not None and on.meas < len(src.scene.detections[x]):
                det = src.scene.detections[x][on.meas].xy_m
                if any(math.dist(a.xy_m, det) < NEAR_M for a in src.scene.objects[x].values()):
                    return "its detection lies within reach of an object"
        elif name == "OFF_OBJECT":
            box = src.box(x, f.lost.track_id)
            if box is None or xy is None or math.hypot(box[1][0] - xy[0], box[1][1] - xy[1]) < NEAR_M:
                return "the track was within reach"
        elif name == "INTERPOLATED" and f.false_output is not None:
            status, at = src.status(x, f.gt_id)
            far = at is not None and math.dist(at, f.false_output.output_xy_m) >= NEAR_M
            if status != "interpolated" or not far:
                return "the evaluation's box of the object is within the track's reach"
        elif name == "INTERPOLATED":
            # a miss: a box interpolated nearer than 2 m would still match a counted track on the annotation
            least_m = NEAR_M if f.kind.value == "miss" else EVALUATED_OFFSET_M
            if f.gt_id is None or not _interpolated_decided(src, x, c, f.gt_id, least_m):
                return "the evaluation scored no far interpolated box, nor one out of a counted track's reach"
        elif name == "DETECTION_UNUSED":
            if xy is None:
                return f"no annotation at frame {x}"
            d, near = src.near(x, xy)
            own = [j for j in near if src.scene.detections[x][j].class_name == c]
            if not own:
                return f"no detection of its class within reach at frame {x}"
            if f.lost is not None:
                used = used_of(src, x, c, f.lost.track_id)
                nearest = min(own, key=lambda j: d[j])
                if used is not None and nearest in [m for m, _ in used[0]]:
                    return f"track {f.lost.track_id} used m{nearest} at frame {x}"
        elif name == "TRACK_DROPPED" and (false_track is not None or f.kind.value == "coalescence"):
            t = false_track if false_track is not None else f.track_ids[0]
            on = _boxes_on(src, x, c, xy) if false_track is None else []  # a coalescence: or a track on its object
            if (src.box(x, t) is None or x in src.kept_frames(t)) and all(x in src.kept_frames(int(u)) for u in on):
                return "the track's box was not dropped there"
        elif name == "TRACK_INTERPOLATED":
            t = false_track if false_track is not None else f.track_ids[0]
            if x in src.kept_frames(t):
                return "the evaluation kept the track's own box there"
        elif name == "TRACK_DROPPED":
            on = _boxes_on(src, x, c, xy)
            if not any(x not in src.kept_frames(int(t)) for t in on):
                return "no track box on it was dropped"
        elif name == "TWO_DETECTIONS":  # a second track on an object the detector gave two boxes of its class
            gt_id = f.false_output.nearest_own[0] if f.false_output and f.false_output.nearest_own else f.gt_id
            at = src.gt_xy(x, gt_id) if gt_id is not None else None
            near = _own_near(src, x, at, c) if at is not None else []
            own = [j for j in near if src.scene.detections[x][j].class_name == c]
            if len(own) < 2:
                return f"fewer than two {c} detections of the object's own within reach at frame {x}: {own}"
        elif name == "TWO_TRACKS" and f.lost is not None:
            on = _boxes_on(src, x, c, xy)
            if str(f.lost.track_id) not in on or len(on) < 2:
                return "not two tracks on the object"
        elif name == "COVERED_TWO" and f.kind.value in ("miss", "fragmentation"):
            at = src.status(x, f.gt_id)[1]  # the box the devkit scored the object at: only it decides a match
            taken = []
            for t in _counted_on(src, x, c, xy):
                box, other = next(p for tt, _, p in src.ev.boxes[x] if tt == t), src.ev.matched_gt(c, x, t)
                if at is None or other in (None, f.gt_id):
                    continue
                there = src.status(x, other)[1]  # matched to an object scored nearer it than this one's annotation
                if math.dist(box, at) < NEAR_M or (there is not None and math.dist(box, there) < math.dist(box, xy)):
                    taken.append(t)
            if not taken:
                return "no counted track within reach of the box the evaluation scored was matched to another object"
        elif name == "NO_EVAL_BOX":
            gt_id = f.false_output.nearest_own[0] if f.false_output and f.false_output.nearest_own else f.gt_id
            if src.status(x, gt_id)[0] in ("scored", "interpolated"):
                return "the evaluation has a box"
    if name == "NO_DETECTION" and f.lost is not None:  # complete: every deciding frame without a detection
        # of its own (one of its class nearer another object is that one's: two pedestrians given one box)
        gaps = [
            x
            for x in f.deciding
            if (xy := src.gt_xy(x, f.gt_id)) is not None and not _own_near(src, x, xy, c) and src.points(x, f.gt_id) > 0
        ]
        if tuple(gaps) != tuple(frames):
            return f"frames without a detection of the object's own: {gaps}"
    return ""


def _own_near(src: Sources, x: int, xy: np.ndarray, c: str) -> list[int]:
    """The detections within reach of the object (of class ``c``) at ``xy`` that are its own: nearer it than any
    other annotated object and, of another class, within reach of no object of theirs (``SceneTruth.claimant``)."""
    return [j for j in src.near(x, xy)[1] if src.scene.claimant(x, j, (float(xy[0]), float(xy[1])), c) is None]


def _interpolated_decided(src: Sources, x: int, c: str, gt_id: str, least_m: float) -> bool:
    """Whether the devkit scored object ``gt_id`` at ``x`` at an interpolated box ``least_m`` or more from its
    annotation, or 2 m or more from a counted track's box within 2 m of the annotation."""
    status, at = src.status(x, gt_id)
    xy = src.gt_xy(x, gt_id)
    if status != "interpolated" or xy is None:
        return False
    if math.dist(at, xy) >= least_m:
        return True
    counted = _counted_on(src, x, c, xy)
    return any(math.dist(next(p for tt, _, p in src.ev.boxes[x] if tt == t), at) >= NEAR_M for t in counted)


def _counted_on(src: Sources, x: int, c: str, xy: np.ndarray) -> list[str]:
    """The track boxes of class ``c`` on the place ``xy`` at ``x`` (``_boxes_on``) kept at ``x`` whose averaged
    score passes the class threshold: the tracks the evaluation counted there."""
    threshold = src.ev.thresholds.get(c) or 0.0
    return [
        t
        for t in _boxes_on(src, x, c, xy)
        if x in src.kept_frames(int(t)) and src.ev.averaged.get(t, (0, -math.inf))[1] >= threshold
    ]


def _boxes_on(src: Sources, x: int, c: str, xy: np.ndarray | None) -> list[str]:
    """The track ids of the submission's boxes of class ``c`` within ``NEAR_M`` of ``xy`` at ``x``."""
    if xy is None:
        return []
    return [t for t, cls, p in src.ev.boxes.get(x, []) if cls == c and math.hypot(p[0] - xy[0], p[1] - xy[1]) < NEAR_M]


def check_fields(f, src: Sources, out, bad: Callable[[str, str, str], None]) -> None:
    """Every claim of finding ``f`` (``gnnpmb.why.claims``) against ``src``; each failure is a ``fields``
    contradiction naming the claim."""
    from gnnpmb.why.claims import claims

    out.checked["fields"] += 1
    if not f.blame:
        bad("fields", f"{f.failure_id}: blame ()", "no stated test held (cause unknown)")
    for claim in claims(f):
        out.checked["fields"] += 1
        problem = check_claim(claim.what, claim.frame, claim.values, f, src)
        if problem:
            bad("fields", f"{f.failure_id}: {claim.what} at {claim.frame} {claim.values}", problem)
