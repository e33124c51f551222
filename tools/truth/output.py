"""A results file's boxes (a tracker known by its output only) as the Why places them on detections, checked
against the file's boxes and the detection file, with this checker's own placement rule:

a box sits on the detection of its class whose size, rotation and centre height it repeats (each number within
``SAME_BOX_TOL``; the nearest such), else on the nearest detection of its class within ``NEAREST_M`` (BEV), else
on none.

* "at frame x track T (C) was output on detection mN (K, score S; its box carries mN's size, heading and height)"
  / "…; mN is the nearest C detection, D m from its box (none carries …)" / "was output on no detection (…)";
* "at frame x it was output on mN" / "… on no detection" (the lost track), "its box had sat on detections 2 m or
  more from the object at frames x (mN), …";
* "at frame x mN (…) lay under track T's box" (the lowest id of the boxes on mN), "… lay under track T's box, which
  sat on another detection" (no box on mN; T's the nearest box of the class within ``NEAREST_M``, on another
  detection) / "lay under no output box" (no box on mN, none of its class within ``NEAREST_M``); the same of a
  miss's "detection mN … lay D m from C GT H and lay under …" and a coalescence's "its detection mN (…) lay under …";
* "track T was first output at frame x": the file's first box of T is at x.
"""

from __future__ import annotations

import math
import re

SAME_BOX_TOL = 1e-4
"""Float32 files round-trip within this (m, quaternion units): the checker's own copy."""
NEAREST_M = 0.5

ON = re.compile(
    r"at frame (\d+) track (\d+) \((\w+)\) was output on detection m(\d+) \((\w+), score (\d+\.\d+); (?:its box "
    r"carries m\d+'s size, heading and height|m\d+ is the nearest \w+ detection, (\d+\.\d+) m from its box \(none "
    r"carries its size, heading and height\))\)"
)
ON_NONE = re.compile(r"at frame (\d+) track (\d+) \((\w+)\) was output on no detection \(none of its class carries")
IT_ON = re.compile(r"at frame (\d+) it was output on (?:m(\d+)|no detection)")
SAT_ON = re.compile(r"its box had sat on detections 2 m or more from the object at frames? ((?:\d+ \(m\d+\)(?:, )?)+)")
UNDER = re.compile(
    r"(?:at frame (\d+) m(\d+) \([^()]*\)|at frame (\d+) detection m(\d+) \(score [\d.]+\) lay [\d.]+ m from \w+ "
    r"GT \w+ and|its detection m(\d+) \(score [\d.]+, [\d.]+ m away\)) lay under (?:track (\d+)'s box(, which sat on "
    r"another detection)?|no output box)"
)
FIRST = re.compile(r"track (\d+) was first output at frame (\d+)")


def placed(x: int, track: str, scene, ev) -> tuple[int, bool, float] | None:
    """(detection, repeats its box, BEV distance) that track's box at frame x sits on; None: none."""
    box = next((b for b in ev.boxes.get(x, []) if b[0] == track), None)
    geometry = ev.geometry.get((x, track))
    if box is None or geometry is None or x >= len(scene.detections):
        return None
    best = None
    for m, d in enumerate(scene.detections[x]):
        if d.class_name != box[1]:
            continue
        dist = math.hypot(d.xy_m[0] - box[2][0], d.xy_m[1] - box[2][1])
        same = len(d.box) == len(geometry)
        same = same and all(abs(a - b) <= SAME_BOX_TOL for a, b in zip(d.box, geometry, strict=True))
        if (same or dist < NEAREST_M) and (best is None or (not same, dist) < (not best[1], best[2])):
            best = (m, same, dist)
    return best


def check_output(text: str, c: str, lost: int | None, scene, ev, out, bad, frame: int = -1) -> None:
    """A results file's sentences (module docstring); ``lost``: the track the Why follows; ``frame``: the
    finding's (a coalescence's "its detection" is of that frame)."""
    if scene is None:
        return
    for m in ON.finditer(text):
        out.checked["output"] += 1
        x, meas = int(m[1]), int(m[4])
        got = placed(x, m[2], scene, ev)
        det = scene.detections[x][meas] if x < len(scene.detections) and meas < len(scene.detections[x]) else None
        same = m[7] is None
        ok = got is not None and got[0] == meas and got[1] == same and det is not None
        ok = ok and det.class_name == m[5] and f"{det.score:.2f}" == m[6]
        ok = ok and (same or f"{got[2]:.2f}" == m[7])
        if not ok:
            bad("output", m[0], f"the box sits on {got}")
    for m in ON_NONE.finditer(text):
        out.checked["output"] += 1
        got = placed(int(m[1]), m[2], scene, ev)
        if got is not None:
            bad("output", m[0], f"the box sits on {got}")
    for m in IT_ON.finditer(text):
        if lost is None:
            continue
        out.checked["output"] += 1
        got = placed(int(m[1]), str(lost), scene, ev)
        if (got[0] if got is not None else None) != (int(m[2]) if m[2] else None):
            bad("output", m[0], f"track {lost}'s box sits on {got}")
    for m in SAT_ON.finditer(text):
        for x, meas in re.findall(r"(\d+) \(m(\d+)\)", m[1]):
            out.checked["output"] += 1
            got = placed(int(x), str(lost), scene, ev)
            if got is None or got[0] != int(meas):
                bad("output", m[0], f"track {lost}'s box at frame {x} sits on {got}")
    for m in UNDER.finditer(text):
        out.checked["output"] += 1
        x = int(m[1] or m[3] or frame)
        meas = int(m[2] or m[4] or m[5])
        said = int(m[6]) if m[6] else None
        on = sorted(
            int(t) for t, cls, _ in ev.boxes.get(x, []) if cls == c and (p := placed(x, t, scene, ev)) and p[0] == meas
        )
        beside = None
        if not on and x < len(scene.detections) and meas < len(scene.detections[x]):
            d = scene.detections[x][meas].xy_m
            near = sorted(
                (math.hypot(xy[0] - d[0], xy[1] - d[1]), int(t))
                for t, cls, xy in ev.boxes.get(x, [])
                if cls == c and math.hypot(xy[0] - d[0], xy[1] - d[1]) < NEAREST_M
            )
            beside = near[0][1] if near else None
        truth = (on[0], False) if on else (beside, beside is not None)
        if (said, m[7] is not None) != truth:
            bad("output", m[0], f"the boxes on m{meas}: {on}; the nearest of its class within {NEAREST_M} m: {beside}")
    for m in FIRST.finditer(text):
        out.checked["output"] += 1
        t, x = m[1], int(m[2])
        first = min((f for f, ids in ev.submitted.items() if t in ids), default=None)
        if first != x:
            bad("output", m[0], f"the file's first box of track {t} is at frame {first}")
