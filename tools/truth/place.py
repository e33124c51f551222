"""Where a false track's box lay among the annotations, and the devkit's interpolation of an object, checked
against the annotation files and the devkit's own boxes.

* "C GT H lies D m away": H is annotated at the finding's frame with class C, D m (as printed, one decimal) from
  the false box (as the accumulator scored it, else as submitted), and no other annotation of class C is nearer;
* "no C GT lies within 2 m, but GT K H does (D m)": no annotation of class C within 2 m of the box, and H is
  annotated there with class K, D m away;
* "… from frames L and R, weighting the two ends the wrong way round (nuscenes-devkit issue #1141): weighted the
  right way the box would lie D m from the annotation": L and R are the nearest frames before and after the
  finding's frame at which the devkit kept the object's box; the box interpolated linearly in time between those
  two annotations lies D m from the annotation, and the devkit's own box lies at least 0.05 m from it;
* "at frame x track T was (still) output D m from the annotated object, but the evaluation scored the object at a
  box it interpolated O m from the annotation, out of the track's reach": T's submitted box lies D m from the
  annotation (under 2 m), the devkit did not keep the annotation there and scored a box O m from it, 2 m or more
  from T's box; misleading where the devkit matched T there to another object whose box lies nearer T than the
  annotation (T was that object's: with the box where it belongs the devkit would match T there still);
  and ", and weighted the right way it would still lie E m from the track" follows it exactly where the devkit's
  swap moved the box and the box interpolated the right way lies E m (2 m or more) from T's;
* "…, and no track carried it through": no submitted box of the object's class lies within 2 m of its annotation;
* "at frame x track T was output D m from GT H(, on mN): beyond the evaluation's 2 m, so it no longer matched the
  object": T's submitted box lies D m (2 m or more) from H's annotation and 2 m or more from the box the devkit
  scored H at; "…, on mN, E m from the box the evaluation interpolated for it": the devkit did not keep H's
  annotation there and scored a box E m (under 2 m) from T's;
* a false box on detection mN "…: a detection of no tracked object": no annotation of a tracked class lies within
  2 m of mN either; "…within 2 m of the box, but mN lay D m from C GT H: the track's box lay E m from that
  object": mN lies D m from H, of class C, and the box E m (audit truth54, dev set scene-0103 pointpillars jpda
  false_track:19: a bicycle detection 1.98 m from a bicycle called a detection of no tracked object);
* a false track's "C GT H lies D m away, but the evaluation has no box for it here (WHY)": the devkit neither kept
  H's annotation at the frame nor interpolated one; "it had no LiDAR or radar points" only of a box with none;
  "the evaluation keeps none of its boxes after frame L" / "before frame R" / "at any frame": L and R are the
  nearest frames before and after at which it kept H's box, and there is none on the other side (audit truth54,
  dev set: "no box of it both before and after this frame" of an object whose boxes it kept from the next frame
  on, misleading);
* a false track's "C GT H lies D m away, but the evaluation has it interpolated O m from the annotation, out of the
  track's reach" cites nuscenes-devkit issue #1141 as "(see …)" only where the box interpolated the right way lies
  within 2 m of the false box, says "weighted the right way (…) it would still lie E m from the track" only where it
  lies E m (2 m or more) from it, and cites nothing only where the devkit's box is the right way's (under 0.05 m).
"""

from __future__ import annotations

import math
import re

from gnnpmb.events import Assignment, AxisKind
from tools.truth.output import placed
from tools.truth.scene import NEAR_M, POINTS, points_problem

AWAY = re.compile(r"(\w+) GT (\w{6}) lies (\d+\.\d) m away")
OTHER_CLASS = re.compile(r"no (\w+) GT lies within 2 m, but GT (\w+) (\w{6}) does \((\d+\.\d) m\)")
SWAPPED = re.compile(
    r"from frames (\d+) and (\d+), weighting the two ends the wrong way round \(nuscenes-devkit issue #1141\): "
    r"weighted the right way the box would lie (\d+\.\d) m from the annotation"
)


BETWEEN = re.compile(r"(?:^|; )from frames (\d+) and (\d+)(?=[;.]|$)", re.M)
TRACK_BETWEEN = re.compile(
    r"at frame (\d+) track (\d+) \((\w+)\) was not output: the evaluation interpolated it between its boxes at "
    r"frames (\d+) and (\d+), and that box matched no object"
)
PREDICTED = re.compile(
    r"at frame (\d+) track (\d+) \((\w+)\) was output on no detection this frame \(a predicted box\)"
)


OUT_OF_REACH = re.compile(
    r"at frame (\d+) track (\d+) was (?:still )?output (\d+\.\d) m from the annotated object, but the evaluation "
    r"scored the object at a box it interpolated (\d+\.\d) m from the annotation, out of the track's reach"
    r"(?:, and weighted the right way it would still lie (\d+\.\d) m from the track)?"
)
NOT_CARRIED = "and no track carried it through"


def check_out_of_reach(text: str, c: str, x: int, gt_id: str | None, scene, ev, out, bad) -> None:
    """A track on the annotated object out of the reach of the devkit's interpolated box, and "no track carried it
    through" (module docstring), at the finding's frame ``x``."""
    a = scene.objects[x].get(gt_id) if scene is not None and gt_id is not None and x < len(scene.objects) else None
    if a is None:
        return
    for m in OUT_OF_REACH.finditer(text):
        out.checked["evaluation"] += 1
        y, t = int(m[1]), m[2]
        at = scene.objects[y].get(gt_id) if y < len(scene.objects) else None
        box = next((xy for tt, _, xy in ev.boxes.get(y, []) if tt == t), None)
        scored = ev.evaluated_gt.get((y, gt_id))
        if at is None or box is None or scored is None or (y, gt_id) in ev.kept_gt:
            bad("evaluation", m[0], f"no box of track {t}, or the devkit scored the annotation itself at {y}")
            continue
        on, off, away = math.dist(box, at.xy_m), math.dist(scored, at.xy_m), math.dist(box, scored)
        if not (on < NEAR_M and f"{on:.1f}" == m[3] and f"{off:.1f}" == m[4] and away >= NEAR_M):
            said = f"box {on:.2f} m from the annotation, {away:.2f} m from the devkit's ({off:.2f} off)"
            bad("evaluation", m[0], said)
            continue
        other = ev.matched_gt(c, y, t)
        elsewhere = ev.evaluated_gt.get((y, other)) if other is not None and other != gt_id else None
        out.checked["misleading"] += 1
        if elsewhere is not None and math.dist(box, elsewhere) < on:
            bad(
                "misleading",
                m[0],
                f"the devkit matched track {t} to GT {other[:6]}, {math.dist(box, elsewhere):.2f} m away",
            )
            continue
        right = _right_way(scene, ev, gt_id, y)
        if right is not None and math.dist(right, scored) >= 0.05:  # the swap moved it: out of reach weighted so?
            still = math.dist(right, box)
            out.checked["misleading"] += 1
            if (m[5] is None) != (still < NEAR_M) or (m[5] is not None and f"{still:.1f}" != m[5]):
                bad("misleading", m[0], f"weighted the right way the box lies {still:.2f} m from the track")
        elif m[5] is not None:
            bad("misleading", m[0], "the devkit's box is the one weighted the right way")
    if NOT_CARRIED in text:
        out.checked["output"] += 1
        near = [t for t, cls, xy in ev.boxes.get(x, []) if cls == c and math.dist(xy, a.xy_m) < NEAR_M]
        if near:
            bad("output", NOT_CARRIED, f"tracks {near} were output within 2 m of it at frame {x}")


OF_NOTHING = re.compile(
    r"at frame (\d+) track (\d+) \(\w+\) was output (?:on|[\d.]+ m from) detection m(\d+) \([^()]*\)[^;]*; no object "
    r"of a tracked class lies within 2 m(?:: a detection of no tracked object| of the box, but m\d+ lay ([\d.]+) m "
    r"from (\w+) GT (\w{6}): the track's box lay ([\d.]+) m from that object, beyond the evaluation's 2 m)"
)


def check_of_nothing(text: str, scene, ev, out, bad) -> None:
    """A false box on a detection with no object within 2 m of the box (module docstring)."""
    for m in OF_NOTHING.finditer(text):
        x, t, j = int(m[1]), m[2], int(m[3])
        if scene is None or x >= len(scene.detections) or j >= len(scene.detections[x]):
            continue
        out.checked["detector"] += 1
        d = scene.detections[x][j].xy_m
        near = sorted((_d(a.xy_m, d), k, a.class_name) for k, a in scene.objects[x].items())
        if m[4] is None:
            if near and near[0][0] < NEAR_M:
                bad("detector", m[0], f"m{j} lies {near[0][0]:.3f} m from {near[0][2]} GT {near[0][1][:6]}")
            continue
        hit = scene.object_of(x, m[6])
        box = next((xy for tt, _, xy in ev.boxes.get(x, []) if tt == t), None)
        if hit is None or box is None or hit[1].class_name != m[5] or not near or near[0][1] != hit[0]:
            bad("detector", m[0], f"the annotations nearest m{j}: {near[:2]}")
        elif abs(_d(hit[1].xy_m, d) - float(m[4])) > 0.006 or abs(_d(hit[1].xy_m, box) - float(m[7])) > 0.006:
            bad("detector", m[0], f"m{j} {_d(hit[1].xy_m, d):.3f} m, the box {_d(hit[1].xy_m, box):.3f} m from it")


NO_BOX = re.compile(
    r"\w+ GT (\w{6}) lies \d+\.\d m away, but the evaluation has no box for it here \((it had no LiDAR or radar "
    r"points)?[^()]*?(?:, and (?:(it keeps no box of it both before and after this frame)|the evaluation keeps none "
    r"of its boxes (?:after frame (\d+)|before frame (\d+)|at any frame)[^()]*))?\): a track on it is false"
)


def check_no_box(text: str, x: int, scene, ev, out, bad) -> None:
    """A false track's "…, but the evaluation has no box for it here (WHY)" (module docstring) at frame ``x``."""
    for m in NO_BOX.finditer(text):
        hit = scene.object_of(x, m[1]) if scene is not None else None
        if hit is None:
            continue
        out.checked["evaluation"] += 1
        gt_id, a = hit
        if (x, gt_id) in ev.kept_gt or (x, gt_id) in ev.evaluated_gt:
            bad("evaluation", m[0], f"the devkit scored a box of GT {m[1]} at frame {x}")
            continue
        if m[2] is not None and a.points > 0:
            bad("evaluation", m[0], f"GT {m[1]} has {a.points} LiDAR and radar points at frame {x}")
        if m[3] is None and m[4] is None and m[5] is None and "at any frame" not in m[0]:
            continue
        kept = sorted(y for y, k in ev.kept_gt if k == gt_id)
        before = max((y for y in kept if y < x), default=None)
        after = min((y for y in kept if y > x), default=None)
        out.checked["misleading"] += 1
        said = (int(m[4]) if m[4] else None, int(m[5]) if m[5] else None)
        if m[3] is not None or said != (before, after):
            bad("misleading", m[0], f"the devkit kept its box last before frame {x} at {before}, first after {after}")


NONE_OF_ITS_OWN = re.compile(rf"the detector gave GT (\w{{6}}) no detection of its own within 2 m \({POINTS}\)")


def _d(a: tuple[float, float], b: tuple[float, float]) -> float:
    return math.hypot(a[0] - b[0], a[1] - b[1])


def check_place(text: str, c: str, x: int, place, scene, out, bad) -> None:
    """The annotations around a false box at ``place`` (None: nothing checked) at frame ``x``."""
    if place is None or scene is None or x >= len(scene.objects):
        return
    here = scene.objects[x]
    for m in AWAY.finditer(text):
        out.checked["detector"] += 1
        hit = scene.object_of(x, m[2])
        own = sorted((_d(a.xy_m, place), k[:6]) for k, a in here.items() if a.class_name == c)
        if hit is None or hit[1].class_name != m[1] or f"{_d(hit[1].xy_m, place):.1f}" != m[3]:
            bad("detector", m[0], f"the {c} annotations' distances from the box: {own[:3]}")
        elif own and own[0][1] != m[2] and own[0][0] < _d(hit[1].xy_m, place) - 1e-9:
            bad("detector", m[0], f"GT {own[0][1]} lies nearer ({own[0][0]:.2f} m)")
    for m in OTHER_CLASS.finditer(text):
        out.checked["detector"] += 1
        own = [k[:6] for k, a in here.items() if a.class_name == m[1] and _d(a.xy_m, place) < NEAR_M]
        hit = scene.object_of(x, m[3])
        if own:
            bad("detector", m[0], f"{m[1]} annotations within 2 m: {own}")
        elif hit is None or hit[1].class_name != m[2] or f"{_d(hit[1].xy_m, place):.1f}" != m[4]:
            bad("detector", m[0], f"GT {m[3]} is {hit[1] if hit else 'not annotated here'}")


COASTED = re.compile(
    r"at frame (\d+) track (\d+) \((\w+)\) was output on no detection this frame \(a predicted box\); no \w+ GT lies "
    r"within 2 m, but GT (\w+) (\w{6}) does \((\d+\.\d) m\): the track coasted (onto it|on with it from m(\d+) at "
    r"frame (\d+), a \w+ detection of it: the detector gave it the wrong class)"
)


def _fed_last(x: int, track: str, c: str, scene, ev, raw) -> tuple[int, int] | None:
    """(frame, detection) of the last detection before ``x`` that track ``track`` (class ``c``) was output on: the
    later of its box repeating a detection's box (a PHD's soft update has no pair) and the raw events' last
    assignment pair or birth naming it (a box filter's box repeats no detection's); None: none."""
    seen = None
    for y in range(x - 1, -1, -1):
        p = placed(y, track, scene, ev) if any(b[0] == track for b in ev.boxes.get(y, [])) else None
        if p is not None and p[1]:
            seen = (y, p[0])
            break
    if raw is None:
        return seen
    for y in range(x - 1, seen[0] if seen is not None else -1, -1):
        pairs = [
            int(r.ref)
            for a in raw.of_kind(y, c, Assignment)
            for r, col in a.pairs
            if r.kind is AxisKind.MEASUREMENT and col.kind is AxisKind.TRACK and str(col.ref) == track
        ]
        born = [m for m, t in raw.born(y, c).items() if str(t) == track]
        if pairs or born:
            return y, (pairs or born)[-1]
    return seen


def _fed_by(x: int, track: str, c: str, short: str, scene, ev, raw) -> tuple[int, int] | None:
    """``_fed_last``, when that detection lies within 2 m of object ``short`` and nearer it than any other annotated
    object; None otherwise."""
    fed = _fed_last(x, track, c, scene, ev, raw)
    if fed is None:
        return None
    y, m = fed
    hit = scene.object_of(y, short)
    d = scene.detections[y][m].xy_m
    if hit is None or _d(hit[1].xy_m, d) >= NEAR_M or scene.owner(y, m, hit[1].xy_m) is not None:
        return None
    return fed


def check_coasted(text: str, scene, ev, out, bad, raw=None) -> None:
    """A false track's predicted box on an object of another class: "the track coasted onto it" where the track's
    last box sat on a detection of that object is misleading (audit truth51, world7: a car seen as a truck at
    every other frame; the truck track had been on it all along); "coasted on with it from mK at frame y" must
    name that box's detection and frame."""
    if scene is None:
        return
    for m in COASTED.finditer(text):
        out.checked["misleading"] += 1
        fed = _fed_by(int(m[1]), m[2], m[3], m[5], scene, ev, raw)
        if m[7] == "onto it":
            if fed is not None:
                bad("misleading", m[0], f"its last box (frame {fed[0]}) sat on m{fed[1]}, a detection of GT {m[5]}")
        elif fed is not None and fed != (int(m[9]), int(m[8])):  # None: a box filter's boxes repeat none
            bad("detector", m[0], f"its last box's detection of the object: {fed}")


def _right_way(scene, ev, gt_id: str, x: int) -> tuple[float, float] | None:
    """The object's box at ``x`` interpolated linearly in time between its annotations at the frames the devkit
    kept around x (None: no such ends)."""
    ends = _ends(ev, gt_id, x)
    a, b = (scene.objects[f].get(gt_id) for f in ends) if ends is not None else (None, None)
    if a is None or b is None:
        return None
    left, right = ends
    w = (ev.stamps[x] - ev.stamps[left]) / (ev.stamps[right] - ev.stamps[left])
    return a.xy_m[0] + w * (b.xy_m[0] - a.xy_m[0]), a.xy_m[1] + w * (b.xy_m[1] - a.xy_m[1])


def _ends(ev, gt_id: str, x: int) -> tuple[int, int] | None:
    """The frames before and after x nearest it at which the devkit kept the object's box (its interpolation's
    ends)."""
    kept = sorted(f for f, g in ev.kept_gt if g == gt_id)
    before, after = [f for f in kept if f < x], [f for f in kept if f > x]
    return (before[-1], after[0]) if before and after else None


def check_interpolated(text: str, x: int, gt_id: str | None, ev, out, bad) -> None:
    """ "from frames L and R" (the object's interpolation) and a false track's interpolated box: "at frame x track
    T (C) was not output: the evaluation interpolated it between its boxes at frames L and R, and that box matched
    no object" (no box of T at x, boxes at L and R, the accumulator scored one at x, matched to nothing)."""
    for m in BETWEEN.finditer(text) if gt_id is not None else ():
        out.checked["evaluation"] += 1
        if _ends(ev, gt_id, x) != (int(m[1]), int(m[2])):
            bad("evaluation", m[0], f"the devkit's kept neighbours of frame {x}: {_ends(ev, gt_id, x)}")
    for m in TRACK_BETWEEN.finditer(text):
        out.checked["evaluation"] += 1
        y, t, c, left, right = int(m[1]), m[2], m[3], int(m[4]), int(m[5])
        has = [f for f in (y, left, right) if t in ev.submitted.get(f, set())]
        scored = t in ev.pred_xy.get((c, y), {})
        if has != [left, right] or not scored or ev.matched_gt(c, y, t) is not None:
            bad("evaluation", m[0], f"boxes at {has}, scored at {y}: {scored}, matched {ev.matched_gt(c, y, t)}")
    for m in PREDICTED.finditer(text):
        out.checked["output"] += 1
        if m[2] not in ev.submitted.get(int(m[1]), set()):
            bad("output", m[0], f"the submission has no box of track {m[2]} at frame {m[1]}")


def check_none_of_its_own(text: str, x: int, scene, out, bad) -> None:
    """A coalescence's "the detector gave GT H no detection of its own within 2 m (N LiDAR and radar points)": every
    detection within 2 m of H's annotation at x lies nearer another annotated object (its own, as ``owner`` has
    it; dev set scene-0916 megvii: two detections 0.07 and 0.13 m from GT c1ad9f, one of them 1.96 m from H), and
    H has N points."""
    for m in NONE_OF_ITS_OWN.finditer(text) if scene is not None else ():
        out.checked["detector"] += 1
        hit = scene.object_of(x, m[1])
        near = scene.near(x, hit[1].xy_m) if hit is not None else None
        own = [j for j in near if scene.owner(x, j, hit[1].xy_m) is None] if hit is not None else None
        if hit is None or own:
            bad("detector", m[0], f"its own detections within 2 m: {own}; points {hit[1].points if hit else None}")
        elif (problem := points_problem([hit[1]], m[2], m[3])) is not None:
            bad(problem[0], m[0], problem[1])


def check_swapped(text: str, x: int, gt_id: str | None, scene, ev, out, bad) -> None:
    """The #1141 note about object ``gt_id`` at frame ``x``."""
    if gt_id is None or scene is None:
        return
    for m in SWAPPED.finditer(text):
        out.checked["evaluation"] += 1
        left, right = int(m[1]), int(m[2])
        kept = sorted(f for f, g in ev.kept_gt if g == gt_id)
        before = [f for f in kept if f < x]
        after = [f for f in kept if f > x]
        if not before or not after or (before[-1], after[0]) != (left, right):
            bad("evaluation", m[0], f"the devkit kept the object's box at frames {kept}")
            continue
        a, b, here = (scene.objects[f].get(gt_id) for f in (left, right, x))
        scored = ev.evaluated_gt.get((x, gt_id))
        if a is None or b is None or here is None or scored is None:
            bad("evaluation", m[0], "the object is not annotated at both ends and here, or not scored")
            continue
        w = (ev.stamps[x] - ev.stamps[left]) / (ev.stamps[right] - ev.stamps[left])
        right_way = (a.xy_m[0] + w * (b.xy_m[0] - a.xy_m[0]), a.xy_m[1] + w * (b.xy_m[1] - a.xy_m[1]))
        if f"{_d(right_way, here.xy_m):.1f}" != m[3]:
            bad("evaluation", m[0], f"interpolated in time the box lies {_d(right_way, here.xy_m):.2f} m away")
        elif _d(right_way, scored) < 0.05:
            bad("evaluation", m[0], "the devkit's box is the one interpolated the right way")


REACH_1141 = re.compile(
    r"GT (\w{6}) lies \d+\.\d m away, but the evaluation has it interpolated \d+\.\d m from the annotation, out of "
    r"the track's reach( \(see nuscenes-devkit issue #1141\)|, and weighted the right way \(nuscenes-devkit issue "
    r"#1141\) it would still lie (\d+\.\d) m from the track)?"
)


def check_reach_1141(text: str, x: int, place, scene, ev, out, bad) -> None:
    """A false track's interpolated object and what nuscenes-devkit issue #1141 did to it (module docstring), the
    false box at ``place``."""
    for m in REACH_1141.finditer(text) if place is not None and scene is not None else ():
        out.checked["misleading"] += 1
        hit = scene.object_of(x, m[1])
        scored = ev.evaluated_gt.get((x, hit[0])) if hit is not None else None
        right_way = _right_way(scene, ev, hit[0], x) if hit is not None else None
        if right_way is None or scored is None:
            bad("misleading", m[0], "no interpolation of the object the devkit scored here")
            continue
        swapped, reach = _d(right_way, scored) >= 0.05, _d(right_way, place)
        if m[3] is not None:
            ok = swapped and reach >= NEAR_M and f"{reach:.1f}" == m[3]
        else:
            ok = swapped and reach < NEAR_M if m[2] is not None else not swapped
        if not ok:
            bad("misleading", m[0], f"weighted the right way the box lies {reach:.2f} m from the track ({swapped=})")


OFF = re.compile(
    r"at frame (\d+) track (\d+) was output (\d+\.\d) m from GT (\w{6})(?:, on m\d+)?(?:: beyond the evaluation's 2 m, "
    r"so it no longer matched the object|, (\d+\.\d) m from the box the evaluation interpolated for it|"
    r"(, but its box lay (?:[\d.]+ m from the ego vehicle, beyond the evaluation's \d+ m range|in a bike rack): the "
    r"evaluation dropped it and had no box of the track to match to the object))"
)


def check_off(text: str, scene, ev, out, bad) -> None:
    """A lost track output 2 m or more from its object at the failure's frame (module docstring)."""
    for m in OFF.finditer(text) if scene is not None else ():
        out.checked["evaluation"] += 1
        x, t = int(m[1]), m[2]
        hit = scene.object_of(x, m[4])
        box = next((xy for tt, _, xy in ev.boxes.get(x, []) if tt == t), None)
        scored = ev.evaluated_gt.get((x, hit[0])) if hit is not None else None
        if hit is None or box is None:
            bad("evaluation", m[0], f"no annotation of GT {m[4]} or no box of track {t} at frame {x}")
            continue
        gap, reach = _d(box, hit[1].xy_m), _d(box, scored) if scored is not None else math.inf
        ok = f"{gap:.1f}" == m[3] and gap >= NEAR_M
        kept = ev.kept_frames.get(t, ())  # audit truth53 (world9): the devkit dropped its box and had none there
        no_box = bool(ev.kept_frames) and x not in kept and not (min(kept, default=x) < x < max(kept, default=x))
        if no_box != (m[6] is not None):
            bad("evaluation", m[0], f"the devkit {'had no' if no_box else 'kept or interpolated a'} box of track {t}")
            continue
        if m[5] is None and m[6] is None:
            ok = ok and reach >= NEAR_M
        elif m[5] is not None:
            ok = ok and (x, hit[0]) not in ev.kept_gt and f"{reach:.1f}" == m[5] and reach < NEAR_M
        if not ok:
            bad("evaluation", m[0], f"box {gap:.2f} m from the annotation, {reach:.2f} m from the devkit's box")
