"""Sentences about what the detector gave, checked against the detection file and the annotations themselves
(``scene.SceneTruth``), and, for what the tracker kept, the tracker's own ``MeasurementsReceived`` events.

Each pattern names a detection ``mN`` with its score and distance from the object, says the detector gave no
detection near an object (and how many points the object had), or lists the frames at which the object had a
detection of its class within reach. The last must count every detection the file has there: a detection the
tracker's preprocessing removed (score threshold or NMS) is either in the stated frames or stated apart; leaving it
out without saying so is the issue's class 4 ("misleading").
"""

from __future__ import annotations

import math
import re

import numpy as np

from tools.truth.printing import frames_of
from tools.truth.rawevents import RawEvents
from tools.truth.scene import NEAR_M, POINTS, SceneTruth, points_problem

_F = r"[\d.]+"
_FRAMES = r"frames? [\d–, ]*\d"
SCORE_AT = re.compile(rf"at frame (\d+) detection m(\d+) \(score ({_F})\) lay ({_F}) m from (\w+) GT (\w+)")
NO_DETECTION = re.compile(
    rf"at frame (\d+) the detector gave no detection( of a tracked class)? within 2 m of (\w+) GT (\w+) \({POINTS} in "
    r"its box\)"
)
WRONG_CLASS = re.compile(
    rf"at frame (\d+) the detector gave no (\w+) detection(?: of its own)? within 2 m of \w+ GT (\w+) \({POINTS} in "
    rf"its box\), but "
    rf"a (\w+) detection, m(\d+) \(score ({_F})\), ({_F}) m away"
)
NONE_ANY = re.compile(
    rf"at ({_FRAMES}) the detector gave no detection of (any|a tracked) class within 2 m, though it had {POINTS}"
)
HIDDEN = re.compile(
    rf"at ({_FRAMES}) (?:\w+ GT (\w+)|it) had no LiDAR or radar points \(no detector could see it\) and no detection"
    r"( of a tracked class)? within 2 m"
)
UNUSED = re.compile(rf"at frame (\d+) m(\d+) \((?:(\w+), )?score ({_F}), ({_F}) m from it")
OUTPUT_ON = re.compile(
    rf"at frame (\d+) track \d+ \((\w+)\) was output (?:on|{_F} m from) detection m(\d+) \((\w+), score ({_F})\)"
)
USED_ONE = re.compile(
    rf"at frame (\d+) track (\d+) \((\w+)\) was output {_F} m from detection m(\d+) \([^)]*\), the one its update used"
)
"""A false track's box off the detection its update used: of a soft update, that detection must carry most of it."""
ITS_DETECTION = re.compile(rf"its detection m(\d+) \(score ({_F}), ({_F}) m away\)")
OTHER_CLASS = re.compile(rf"at ({_FRAMES}) the detector saw it only as another class \(([^)]*)\)")
OTHER_ITEM = re.compile(rf"(\w+) m(\d+) ({_F}) m away")
NOT_ITS_OWN = re.compile(
    rf"at ({_FRAMES}) (?:the detector gave (?:\w+ GT (\w+) \([\d,–]+ LiDAR and (?:[\d,–]+ )?radar points in its "
    rf"box\) )?|(?:\w+ GT (\w+)|it) had no LiDAR or radar points \(no detector could see it\) and )no detection of "
    rf"its own within 2 m "
    rf"\(((?:[^()]|\([^()]*\))*)\)"
)
"""Detections within 2 m of an object, each nearer another annotated object: ``(at frame 3 car m4, 1.8 m away, lay
0.1 m from car GT 26e63e; ...)``."""
ITS_OWN_ITEM = re.compile(rf"(?:at frame (\d+) )?(\w+) m(\d+), ({_F}) m away, lay ({_F}) m from \w+ GT (\w+)")
EGO = re.compile(
    rf"(?:it|the object) lies ({_F}) m from the ego vehicle, (inside|beyond) the evaluation's ({_F}) m range"
)
INTERPOLATED_AT = re.compile(
    rf"the evaluation scored (?:it|GT \w{{6}}) at a box it interpolated, ({_F}) m from the annotation"
)
PRESENCE = re.compile(
    rf"in the (\d+) recorded frames up to (\d+) \(([\d–, ]+)\), GT (\w+) had an? (\w+) detection "
    rf"(?:of its own )?(?:the tracker kept )?within 2 m at ({_FRAMES}|no frame)(?: only)?"
    rf"(?:,? and at ({_FRAMES}) only one? (?:that )?(?:its )?preprocessing removed[^,]*)?"
    rf"(?:, and at ({_FRAMES}) only one nearer another annotated object)?"
)


def _class_range() -> dict[str, float]:
    from nuscenes.eval.common.config import config_factory

    return dict(config_factory("tracking_nips_2019").class_range)


RANGE_M = _class_range()
"""The devkit's evaluation range per class (``tracking_nips_2019``), metres from the ego pose."""


def _close(printed: str, value: float) -> bool:
    """Whether ``value`` prints as ``printed`` (its decimals), a rounding ulp allowed."""
    decimals = len(printed.split(".")[1]) if "." in printed else 0
    return abs(float(printed) - value) <= 0.5 * 10.0**-decimals + 1e-9


def _says_in_box(after: str) -> bool:
    """Whether the clause goes on (``after``: the text that follows it) to name detections inside the box."""
    return after.startswith(", but") and "lay inside its box" in after.split(";")[0]


def _check_in_box(said: bool, frames: list[int], short: str, sentence: str, scene: SceneTruth, out, bad) -> None:
    """ "No detection within 2 m" of an object a detection lay inside the box of (a 16 m truck seen as two boxes,
    each 3-5 m from its centre: audit truth50, world6): misleading unless the sentence goes on to say so; said of
    frames with none inside: wrong."""
    inside = {}
    for x in frames:
        hit = scene.object_of(x, short)
        if hit is not None and (ms := scene.in_box(x, hit[0])):
            inside[x] = ms
    out.checked["misleading"] += 1
    if inside and not said:
        bad("misleading", sentence, f"detections inside its box, beyond {NEAR_M} m of its centre, unsaid: {inside}")
    elif said and not inside:
        bad("detector", sentence, "no detection lies inside its box")


UNTRACKED_NAMED = re.compile(
    rf", but an? (\w+) box \(score ({_F})\) ({_F}) m away: the detector gave it a class no tracker takes"
)
"""A miss whose only box within 2 m has a name no tracker takes (audit truth52, world8: a car seen only as a
construction vehicle was "missed")."""


def _untracked_unsaid(after: str, x: int, short: str, scene: SceneTruth, out) -> tuple[str, str] | None:
    """(kind, truth) where the file's boxes of an untracked name that are object ``short``'s at frame ``x`` (within
    2 m, nearer it than any other annotation) go unnamed in ``after`` (the text after "no detection of a tracked
    class within 2 m of ..."), or where the box it names is none of them; None: the text holds. A detection inside
    its box is told first."""
    hit = scene.object_of(x, short)
    if hit is None or scene.in_box(x, hit[0]) or not after.startswith((": the detector missed it", ", but")):
        return None
    own, said = scene.untracked_own(x, hit[0]), UNTRACKED_NAMED.match(after)
    if not own and said is None:
        return None
    out.checked["misleading"] += 1
    if said is None:
        return "misleading", f"the file's untracked boxes of it, unsaid: {own}"
    if f"{said[1]} {said[2]}" not in own:
        return "detector", f"{said[1]} {said[2]} is not its own untracked box (its own: {own})"
    return None


OFF_NEAR_M = 6.5
"""A miss with a detection of its class this near (beyond ``NEAR_M``), nearer it than any other annotated object,
must name it (audit truth51, world7: a car's box moved 3-6 m for one frame was told as "the detector missed it")."""
OFF = re.compile(
    rf"the nearest (\w+) detection, m(\d+) \(score ({_F})\), lay ({_F}) m away, nearer it than any other annotated "
    r"object: the detector missed it or placed its box that far off"
)


def _check_off(after: str, x: int, c: str, short: str, sentence: str, scene: SceneTruth, out, bad) -> None:
    """ "no detection ... within 2 m of C GT H (...)" followed (``after``) by the nearest detection of class C
    within ``OFF_NEAR_M`` that lies nearer H than any other annotated object, or, where there is none, by ": the
    detector missed it" (or by a detection inside the box, checked apart)."""
    hit = scene.object_of(x, short)
    if hit is None or not after.startswith((": the detector missed it", "; the nearest")) or scene.in_box(x, hit[0]):
        return  # a detection inside its box comes first (``_check_in_box``)
    d = scene.distances(x, hit[1].xy_m)
    off = [
        k
        for k in np.flatnonzero(d < OFF_NEAR_M).tolist()
        if scene.detections[x][k].class_name == c and scene.owner(x, k, hit[1].xy_m) is None
    ]
    best = min(off, key=lambda k: d[k]) if off else None
    said = OFF.match(after, 2) if after.startswith("; ") else None
    out.checked["misleading"] += 1
    if said is None:
        if best is not None:
            bad("misleading", sentence, f"{c} m{best} lies {d[best]:.2f} m from it, nearer it than any other object")
        return
    out.checked["detector"] += 1
    k = int(said[2])
    if best is None or k != best or said[1] != c:
        bad("detector", said[0], f"the nearest {c} detection of its own within {OFF_NEAR_M} m is {best}")
    elif not _close(said[3], scene.detections[x][k].score) or not _close(said[4], float(d[k])):
        bad("detector", said[0], f"the file's m{k}: score {scene.detections[x][k].score:.4f}, {d[k]:.3f} m away")


def check_detector(
    text: str, gt_id: str | None, frame: int, class_name: str, scene: SceneTruth, raw, out, bad, evaluated=None
) -> None:
    """Every detector sentence of ``text`` (``out``: the ``Tally``; ``bad(kind, sentence, truth)``); evaluated: the
    devkit's scored object boxes, (frame, object id) -> (x, y) (``devkit.EvalFacts.evaluated_gt``)."""

    def gt_xy(x: int, short: str | None = None):
        if x >= len(scene.objects):
            return None
        key = gt_id if short is None or (gt_id or "").startswith(short) else None
        if key is not None and key in scene.objects[x]:
            return scene.objects[x][key]
        hit = scene.object_of(x, short) if short else None
        return hit[1] if hit else None

    def det(x: int, m: int):
        dets = scene.detections[x] if x < len(scene.detections) else []
        return dets[m] if m < len(dets) else None

    def score_distance(sentence: str, x: int, m: int, score: str, dist: str | None, ann, cls: str | None = None):
        out.checked["detector"] += 1
        d = det(x, m)
        if d is None or ann is None:
            bad("detector", sentence, f"the file has no detection m{m} at frame {x} (or no such object)")
            return
        true_d = float(((d.xy_m[0] - ann.xy_m[0]) ** 2 + (d.xy_m[1] - ann.xy_m[1]) ** 2) ** 0.5)
        if not _close(score, d.score) or (dist is not None and not _close(dist, true_d)):
            bad("detector", sentence, f"the file's m{m}: score {d.score:.4f}, {true_d:.3f} m from the object")
        elif cls is not None and d.class_name != cls:
            bad("detector", sentence, f"the file's m{m} is a {d.class_name}")

    for m in SCORE_AT.finditer(text):
        x = int(m[1])
        score_distance(m[0], x, int(m[2]), m[3], m[4], gt_xy(x, m[6]))
    for m in UNUSED.finditer(text):
        x = int(m[1])
        score_distance(m[0], x, int(m[2]), m[4], m[5], gt_xy(x), m[3])
    for m in ITS_DETECTION.finditer(text):
        score_distance(m[0], frame, int(m[1]), m[2], m[3], gt_xy(frame))
    for m in OUTPUT_ON.finditer(text):
        x = int(m[1])
        out.checked["detector"] += 1
        d = det(x, int(m[3]))
        if d is None or d.class_name != m[4] or not _close(m[5], d.score):
            bad("detector", m[0], f"the file's m{m[3]} at frame {x}: {d}")

    def wrong_points(sentence: str, anns: list, said: str, radar_said: str | None) -> bool:
        """Whether the points said of ``anns`` are wrong (reported; a sum that hides radar returns is reported as
        misleading and the sentence's other facts still checked)."""
        problem = points_problem(anns, said, radar_said)
        if problem is not None:
            bad(problem[0], sentence, problem[1])
        return problem is not None and problem[0] != "misleading"

    for m in USED_ONE.finditer(text) if raw is not None else ():
        share = _soft_share(raw, int(m[1]), m[3], int(m[2]), int(m[4]))
        out.checked["misleading"] += 1
        if share is not None and share < 0.5:
            bad("misleading", m[0], f"a soft update: m{m[4]} carried {share:.2f} of track {m[2]}'s")
    for m in NO_DETECTION.finditer(text):
        x, ann = int(m[1]), gt_xy(int(m[1]), m[4])
        out.checked["detector"] += 1
        if ann is None:
            bad("detector", m[0], f"no annotation of GT {m[4]} at frame {x}")
        elif scene.near(x, ann.xy_m):
            bad("detector", m[0], f"detections within {NEAR_M} m: {scene.near(x, ann.xy_m)}")
        elif wrong_points(m[0], [ann], m[5], m[6]):
            continue
        elif not m[2] and scene.untracked_near(x, ann.xy_m):
            bad("detector", m[0], f"the file has {scene.untracked_near(x, ann.xy_m)} within {NEAR_M} m (untracked)")
        elif (problem := _untracked_unsaid(text[m.end() :], x, m[4], scene, out)) is not None:
            bad(problem[0], m[0], problem[1])
        else:
            _check_in_box(_says_in_box(text[m.end() :]), [x], m[4], m[0], scene, out, bad)
            _check_off(text[m.end() :], x, m[3], m[4], m[0], scene, out, bad)
    for m in WRONG_CLASS.finditer(text):
        x, ann = int(m[1]), gt_xy(int(m[1]), m[3])
        out.checked["detector"] += 1
        near = scene.near(x, ann.xy_m, m[2]) if ann else []
        mine = [j for j in near if scene.owner(x, j, ann.xy_m) is None] if ann else []  # a neighbour's is not its own
        if ann is None or mine or (bool(near) != (" of its own " in m[0])):  # "of its own" iff a neighbour's lay near
            points = ann.points if ann else None
            bad("detector", m[0], f"{m[2]} detections within reach: {near}, its own {mine}; points {points}")
        elif wrong_points(m[0], [ann], m[4], m[5]):
            continue
        elif (o := scene.claimant(x, int(m[7]), ann.xy_m, m[2])) is not None:
            bad("detector", m[0], f"m{m[7]} is GT {o[0][:6]}'s ({o[1]:.2f} m): that object's detection")
        score_distance(m[0], x, int(m[7]), m[8], m[9], ann, m[6])
    for m in NONE_ANY.finditer(text):
        out.checked["detector"] += 1
        anns = {x: a for x in frames_of(m[1]) if (a := gt_xy(x)) is not None}
        seen = {x: scene.near(x, a.xy_m) for x, a in anns.items()}
        if m[2] == "any":
            seen = {x: [*v, *scene.untracked_near(x, anns[x].xy_m)] for x, v in seen.items()}
        if any(seen.values()):
            bad("detector", m[0], f"detections within {NEAR_M} m by frame: {seen}")
        elif not wrong_points(m[0], list(anns.values()), m[3], m[4]) and gt_id is not None:
            _check_in_box(_says_in_box(text[m.end() :]), list(anns), gt_id[:6], m[0], scene, out, bad)
    for m in HIDDEN.finditer(text):
        out.checked["detector"] += 1
        wrong = {}
        for x in frames_of(m[1]):
            a = gt_xy(x, m[2])
            near = [] if a is None else [*scene.near(x, a.xy_m), *([] if m[3] else scene.untracked_near(x, a.xy_m))]
            if a is None or a.points != 0 or near:
                wrong[x] = None if a is None else (a.points, near)
        if wrong:
            bad("detector", m[0], f"(points, detections within reach) by frame: {wrong}")
    for m in NOT_ITS_OWN.finditer(text):
        frames, short = frames_of(m[1]), m[2] or m[3]
        out.checked["detector"] += 1
        owners = {}
        for x in frames:
            a = gt_xy(x, short)
            owners[x] = (
                {j: scene.claimant(x, j, a.xy_m, class_name) for j in scene.near(x, a.xy_m)} if a is not None else None
            )
        if any(o is None or None in o.values() for o in owners.values()):
            bad("detector", m[0], f"within 2 m by frame, each detection's nearer object (None: the object's): {owners}")
            continue
        for item in ITS_OWN_ITEM.finditer(m[4]):
            out.checked["detector"] += 1
            x = int(item[1]) if item[1] else frames[0]
            a, d, o = gt_xy(x, short), det(x, int(item[3])), owners.get(x, {}).get(int(item[3]))
            if d is None or a is None or o is None or d.class_name != item[2] or not o[0].startswith(item[6]):
                bad("detector", item[0], f"m{item[3]} at frame {x}: {d}, nearer {o}")
            elif not _close(item[4], math.dist(d.xy_m, a.xy_m)) or not _close(item[5], o[1]):
                away = math.dist(d.xy_m, a.xy_m)
                bad("detector", item[0], f"m{item[3]} lies {away:.2f} m away, {o[1]:.2f} m from the other object")
    for m in OTHER_CLASS.finditer(text):
        frames = frames_of(m[1])
        for item in OTHER_ITEM.finditer(m[2]):
            out.checked["detector"] += 1
            ok = False
            for x in frames:
                d, a = det(x, int(item[2])), gt_xy(x)
                if d is not None and a is not None and d.class_name == item[1] and d.class_name != class_name:
                    dist = ((d.xy_m[0] - a.xy_m[0]) ** 2 + (d.xy_m[1] - a.xy_m[1]) ** 2) ** 0.5
                    ok = ok or (
                        _close(item[3], dist)
                        # none of its class that is its own (one nearer another object is that one's)
                        and all(scene.owner(x, j, a.xy_m) is not None for j in scene.near(x, a.xy_m, class_name))
                        and scene.claimant(x, int(item[2]), a.xy_m, class_name) is None  # this object's
                    )
            if not ok:
                bad("detector", item[0], f"no frame of {frames} has it so with no {class_name} detection in reach")
    for m in PRESENCE.finditer(text):
        _check_presence(m, gt_id, class_name, scene, raw, out, bad)
    a = gt_xy(frame)
    for m in EGO.finditer(text):
        out.checked["detector"] += 1
        if a is None or scene.ego_xy_m is None:
            bad("detector", m[0], f"no annotation of the object at frame {frame}")
            continue
        ex, ey = scene.ego_xy_m[frame]
        d = ((a.xy_m[0] - ex) ** 2 + (a.xy_m[1] - ey) ** 2) ** 0.5
        r = RANGE_M[class_name]
        if not _close(m[1], d) or float(m[3]) != r or (m[2] == "inside") != (d < r):
            bad("detector", m[0], f"{d:.2f} m from the ego pose; the devkit's {class_name} range is {r:g} m")
        elif float(m[1]) == r:  # audit truth53 (world9): "40.0 m ..., inside the 40 m range" says neither side
            bad("misleading", m[0], f"{d:.3f} m from the ego pose, printed as the {r:g} m range itself")
    for m in INTERPOLATED_AT.finditer(text):
        out.checked["matched"] += 1
        box = evaluated.get((frame, gt_id or "")) if evaluated is not None else None
        if a is None or box is None:
            bad("matched", m[0], f"the devkit scored no box of the object at frame {frame}")
        elif not _close(m[1], ((box[0] - a.xy_m[0]) ** 2 + (box[1] - a.xy_m[1]) ** 2) ** 0.5):
            bad("matched", m[0], f"the devkit's box lies {box} against the annotation {a.xy_m}")


def _soft_share(raw: RawEvents, x: int, c: str, track: int, meas: int) -> float | None:
    """Detection ``meas``'s share of track ``track``'s update at ``x`` from the raw ``Marginals`` (JPDA, TO-PMB) or
    ``UpdateWeights`` (GM-PHD, CPHD) event; None: an assignment (no such event) or not in it."""
    from gnnpmb.events import AxisKind, Marginals, UpdateWeights

    mg = raw.last(x, c, Marginals)
    if mg is not None:
        rows = [i for i, r in enumerate(mg.rows) if r.kind is AxisKind.TRACK and int(r.ref) == track]
        cols = [j for j, k in enumerate(mg.cols) if k.kind is AxisKind.MEASUREMENT and int(k.ref) == meas]
        if rows and cols:
            return float(np.asarray(mg.probs)[rows[0], cols[0]])
        rows_t = [i for i, k in enumerate(mg.cols) if k.kind is AxisKind.TRACK and int(k.ref) == track]
        cols_m = [j for j, r in enumerate(mg.rows) if r.kind is AxisKind.MEASUREMENT and int(r.ref) == meas]
        return float(np.asarray(mg.probs)[cols_m[0], rows_t[0]]) if rows_t and cols_m else None
    w = raw.last(x, c, UpdateWeights)
    if w is None:
        return None
    labels, refs = np.asarray(w.labels).tolist(), np.asarray(w.meas_indices).tolist()
    if track not in labels or meas not in refs:
        return None
    k = labels.index(track)
    total = float(np.asarray(w.missed)[k] + np.asarray(w.detected)[k].sum())
    return float(np.asarray(w.detected)[k, refs.index(meas)]) / total if total > 0 else None


def _check_presence(m: re.Match, gt_id, class_name: str, scene: SceneTruth, raw: RawEvents | None, out, bad) -> None:
    said_frames = frames_of(f"frames {m[3]}")
    first, last, cls = said_frames[0], said_frames[-1], m[5]
    stated = set(frames_of(m[6])) if m[6] != "no frame" else set()
    stated_removed = set(frames_of(m[7])) if m[7] else set()
    stated_neighbours = set(frames_of(m[8])) if m[8] else set()
    out.checked["misleading"] += 1
    annotated = [x for x in range(first, last + 1) if x < len(scene.objects) and (gt_id or "") in scene.objects[x]]
    if said_frames != annotated or int(m[1]) != len(annotated):
        # the recorded frames are the annotated ones: a span over frames without an annotation hides that it left
        bad("misleading", m[0], f"the object was annotated at frames {annotated} of {first}–{last}")
    any_near, kept_near, neighbours_only = set(), set(), set()
    for x in range(first, last + 1):
        a = scene.objects[x].get(gt_id or "") if x < len(scene.objects) else None
        if a is None:
            continue
        near = scene.near(x, a.xy_m, cls)
        mine = [j for j in near if scene.owner(x, j, a.xy_m) is None]  # one nearer another object is that one's
        if near and not mine:
            neighbours_only.add(x)
        if mine:
            any_near.add(x)
        if raw is not None and set(mine) & raw.received(x, cls):
            kept_near.add(x)
    if not stated_neighbours <= neighbours_only:
        bad("detector", m[0], f"only a neighbour's {cls} detection lay within {NEAR_M} m at {sorted(neighbours_only)}")
    out.checked["detector"] += 1
    if raw is None:
        if stated | stated_removed != any_near:
            bad("detector", m[0], f"the file has a {cls} detection within {NEAR_M} m at frames {sorted(any_near)}")
        return
    if stated != kept_near:
        bad("detector", m[0], f"the tracker received a {cls} detection within reach at frames {sorted(kept_near)}")
    elif stated_removed != any_near - kept_near:
        bad(
            "misleading",
            m[0],
            f"at frames {sorted(any_near - kept_near)} the file has a {cls} detection within {NEAR_M} m that "
            "preprocessing removed, not said",
        )
