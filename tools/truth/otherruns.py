"""Sentences about how another tracker on the same detections fared at the failure, checked against the devkit
bookkeeping of that other run (``devkit.EvalFacts`` of its results, built the same way as the first run's).

By failure kind, at the failure's frame x, for the object: a miss is the devkit's MISS of it (no match at x); an
ID switch or identity theft is a SWITCH event of it at x; a fragmentation is a match at x after none at x - 1 and
one before, and one again after. "Did not fail here: its track T was output on the object and counted" holds when
the other run's submission has T's box within 2 m of the object's annotation at x and T passes the class threshold
(and no such failure); it misleads where that run's evaluation matched the object at x to none of the named tracks
(they were matched elsewhere, or to nothing, and the object to another track or missed). "Did not match the
object here: its track T was output on the object and counted, but the evaluation matched track T to C GT X (to
no object)" and "did not fail here: the evaluation matched the object to its track M" are checked against that
run's matches. "Did not have this failure" said of a run that had no track matched to the object at x is the
issue's class 4: that run lost the object too; "did not fail here" / "did not have this failure" of a run whose
devkit events have a SWITCH of the object at x is false ("switched the object's track here instead" is checked
against those events and the track matched); "did not have this failure" of a run whose evaluation matched the
object at x (a box it interpolated for a track not output there included) misleads: the track is named instead.
"""

from __future__ import annotations

import math
import re
from collections.abc import Iterator, Mapping, Sequence

from tools.truth.devkit import EvalFacts
from tools.truth.fields import failed_here
from tools.truth.scene import NEAR_M

OTHER = re.compile(
    r"(\w+) on the same detections (failed here too|switched the object's track here instead(?:: the evaluation "
    r"matched the object to its track (?:\d+))?|did not have this failure|had no counted track on the object "
    r"here either|did not fail here: its tracks? ([\d, ]+) (?:was|were) output on the object and counted"
    r"|did not fail here: the evaluation matched the object to its track (\d+)"
    r"|did not match the object here: its tracks? ([\d, ]+) (?:was|were) output on the object and counted, but the "
    r"evaluation matched (track \d+ to (?:\w+ GT \w+|no object)(?: and track \d+ to (?:\w+ GT \w+|no object))*)"
    r"|did not match the object here: its tracks? ([\d, ]+) (?:was|were) output on the (?:\w+|objects) beside it and "
    r"counted: the evaluation matched (track \d+ to \w+ GT \w+, [\d.]+ m from the track \([\d.]+ m from this one\)"
    r"(?: and track \d+ to \w+ GT \w+, [\d.]+ m from the track \([\d.]+ m from this one\))*))"
)
BESIDE = re.compile(r"track (\d+) to (\w+) GT (\w+), ([\d.]+) m from the track \(([\d.]+) m from this one\)")
REACH_NOTE = " (the box it scored for this object, interpolated"
"""What follows "but the evaluation matched track T to ..." where the box the devkit scored for the object lay out
of the 2 m of each named track."""
MATCHED_TO = re.compile(r"track (\d+) to (?:(\w+) GT (\w+)|no object)")
LOST_KINDS = ("id_switch", "identity_theft", "fragmentation")


def _named_runs(
    pattern: re.Pattern, text: str, others: Mapping[str, EvalFacts]
) -> Iterator[tuple[re.Match, EvalFacts]]:
    """Each match of ``pattern`` in ``text`` whose first group names one of the ``others`` runs, with its facts."""
    for m in pattern.finditer(text):
        if (ev := others.get(m[1])) is not None:
            yield m, ev


def check_others(
    text: str, kind: str, c: str, x: int, gt: str | None, others: Mapping[str, EvalFacts], scene, out, bad
) -> None:
    """Each other-run sentence of ``text`` about object ``gt`` (``out``: the ``Tally``; ``bad``)."""
    if gt is None:
        return
    for m, ev in _named_runs(OTHER, text, others):
        matched = ev.matched_track(c, x, gt)
        a = scene.objects[x].get(gt) if scene is not None and x < len(scene.objects) else None
        if kind == "false_track":  # near an object the evaluation had no box of: a false positive near it
            failed = None if a is None else failed_here(ev, kind, c, x, gt, a.xy_m)
        else:  # None: the evaluation scored no box of the object here (nothing to decide)
            failed = failed_here(ev, kind, c, x, gt, None) if gt in ev.gt_to_track.get((c, x), {}) else None
        out.checked["other run"] += 1
        said = m[2]
        switched = gt in ev.switches.get((c, x), set())
        if said.startswith("switched"):
            took = re.search(r"its track (\d+)", said)
            if not switched or (took is not None and matched != took[1]):
                bad("other run", m[0], f"{m[1]}'s devkit events at frame {x}: SWITCH {switched}, matched {matched}")
            continue
        if said.startswith(("did not fail here", "did not have this failure")) and switched:
            bad("other run", m[0], f"the devkit's events of {m[1]} have a SWITCH of the object at frame {x}")
            continue
        if said == "failed here too":
            if failed is False:
                bad("other run", m[0], f"the devkit's events of {m[1]} have no {kind} of the object at frame {x}")
        elif said.startswith("had no counted track"):
            if matched is not None:
                bad("other run", m[0], f"the devkit matched the object at frame {x} to {m[1]}'s track {matched}")
        elif said.startswith("did not fail here: the evaluation"):
            if failed or matched != m[4]:
                bad("other run", m[0], f"{m[1]}'s evaluation matched the object at frame {x} to track {matched}")
        elif said.startswith("did not match the object") and m[7] is not None:  # on a neighbour, matched there
            _check_beside(m, c, x, gt, ev, scene, out, bad)
        elif said.startswith("did not match the object"):  # on it and counted, but matched elsewhere or to nothing
            _check_matched_elsewhere(m, c, x, gt, ev, scene, out, bad)
        elif said.startswith("did not fail here"):  # its named tracks lay within reach of the object, counted
            named = {t.strip() for t in m[3].split(",")}
            near = _near(ev, c, x, gt, scene)
            if failed or not named <= near & ev.counted.get(c, set()):
                bad("other run", m[0], f"{m[1]}'s counted tracks within {NEAR_M} m at frame {x}: {sorted(near)}")
            elif matched not in named and gt in ev.gt_to_track.get((c, x), {}):
                out.checked["misleading"] += 1
                elsewhere = {t: ev.matched_gt(c, x, t) for t in sorted(named)}
                bad(
                    "misleading",
                    m[0],
                    f"{m[1]}'s evaluation matched the object at frame {x} to track {matched}, and {elsewhere}",
                )
        else:  # did not have this failure
            if failed:
                bad("other run", m[0], f"the devkit's events of {m[1]} have a {kind} of the object at frame {x}")
            elif matched is None and kind in LOST_KINDS:
                out.checked["misleading"] += 1
                bad("misleading", m[0], f"{m[1]} had no track matched to the object at frame {x}: it lost it too")
            elif matched is not None and kind != "false_track":  # the evaluation kept the object: say with which track
                out.checked["misleading"] += 1
                bad("misleading", m[0], f"{m[1]}'s evaluation matched the object at frame {x} to its track {matched}")


def _near(ev: EvalFacts, c: str, x: int, gt: str, scene) -> set[str]:
    """The other run's track ids of class ``c`` with a box within ``NEAR_M`` of the object's annotation at ``x``, or
    where it had none there (it left view and came back), of the box the devkit interpolated for it."""
    a = scene.objects[x].get(gt) if scene is not None and x < len(scene.objects) else None
    at = a.xy_m if a is not None else ev.evaluated_gt.get((x, gt))
    return {
        t
        for t, cls, xy in ev.boxes.get(x, [])
        if at is not None and cls == c and math.hypot(xy[0] - at[0], xy[1] - at[1]) < NEAR_M
    }


def _check_matched_elsewhere(m: re.Match, c: str, x: int, gt: str, ev: EvalFacts, scene, out, bad) -> None:
    """ "Did not match the object here: its track T was output on the object and counted, but the evaluation matched
    track T to C GT X (or to no object)": the devkit scored the object at x and matched it to no track (a MISS), T's box
    lies within 2 m of its annotation and T passes the threshold, and the devkit matched T at x as said."""
    named = {t.strip() for t in m[5].split(",")}
    said = {t: (g if cls == c else "?") if g else None for t, cls, g in MATCHED_TO.findall(m[6])}
    if gt not in ev.gt_to_track.get((c, x), {}) or ev.matched_track(c, x, gt) is not None:
        bad("other run", m[0], f"{m[1]}'s evaluation matched the object at frame {x} to {ev.matched_track(c, x, gt)}")
    near = _near(ev, c, x, gt, scene)
    if not named <= near & ev.counted.get(c, set()):
        bad("other run", m[0], f"{m[1]}'s counted tracks within {NEAR_M} m at frame {x}: {sorted(near)}")
    box = ev.evaluated_gt.get((x, gt))
    a = scene.objects[x].get(gt) if scene is not None and x < len(scene.objects) else None
    tracks = {t: xy for t, cls, xy in ev.boxes.get(x, []) if cls == c and t in named}
    if box is not None and a is not None and tracks and math.dist(box, a.xy_m) > 1e-6:  # an interpolated box
        out.checked["misleading"] += 1
        out_of_reach = all(math.dist(xy, box) >= NEAR_M for xy in tracks.values())
        if out_of_reach != (REACH_NOTE in m.string[m.end() : m.end() + len(REACH_NOTE) + 2]):
            lay = {t: round(math.dist(xy, box), 2) for t, xy in tracks.items()}
            where = "out of" if out_of_reach else "within"
            bad("misleading", m[0], f"the box the devkit scored for the object lies {lay} m away: {where} their 2 m")
    got = {t: (g if len(g) <= 8 else g[:6]) if (g := ev.matched_gt(c, x, t)) else None for t in named}
    out.checked["other run"] += 1
    if said != got:
        bad("other run", m[0], f"{m[1]}'s evaluation matched them at frame {x} to {got}")
    beside = _beside_of(ev, c, x, gt, scene, named)
    out.checked["misleading"] += 1
    if beside:  # a named track lay nearer the neighbour it was matched to: the neighbour's, not on this object
        bad("misleading", m[0], f"{m[1]}'s tracks lay nearer the objects matched to them: {beside}: not on this one")


def _beside_of(ev: EvalFacts, c: str, x: int, gt: str, scene, named: set[str]) -> dict[str, tuple[str, float, float]]:
    """Of the other run's tracks ``named``, those the devkit matched at ``x`` to another object of class ``c`` whose
    annotation their box lies nearer than this object's: track -> (that object's id, distance to it, to this one)."""
    objects = scene.objects[x] if scene is not None and x < len(scene.objects) else {}
    a = objects.get(gt)
    out = {}
    for t, cls, xy in ev.boxes.get(x, []):
        g = ev.matched_gt(c, x, t) if t in named and cls == c else None
        if a is None or g is None or g == gt or (b := objects.get(g)) is None:
            continue
        if math.dist(xy, b.xy_m) < math.dist(xy, a.xy_m):
            out[t] = (g[:6], round(math.dist(xy, b.xy_m), 2), round(math.dist(xy, a.xy_m), 2))
    return out


def _check_beside(m: re.Match, c: str, x: int, gt: str, ev: EvalFacts, scene, out, bad) -> None:
    """ "Did not match the object here: its track T was output on the <class> beside it and counted: the evaluation
    matched track T to C GT X, D m from the track (E m from this one)": the devkit missed the object at x, T is
    counted, within 2 m of it, matched at x to X, and its box lies D m from X's annotation and E m from this one's,
    D < E."""
    named = {t.strip() for t in m[7].split(",")}
    out.checked["other run"] += 1
    if gt not in ev.gt_to_track.get((c, x), {}) or ev.matched_track(c, x, gt) is not None:
        bad("other run", m[0], f"{m[1]}'s evaluation matched the object at frame {x} to {ev.matched_track(c, x, gt)}")
    near = _near(ev, c, x, gt, scene)
    if not named <= near & ev.counted.get(c, set()):
        bad("other run", m[0], f"{m[1]}'s counted tracks within {NEAR_M} m at frame {x}: {sorted(near)}")
    beside = _beside_of(ev, c, x, gt, scene, named)
    for t, cls, g, d_track, d_this in BESIDE.findall(m[8]):
        got = beside.get(t)
        ok = cls == c and got is not None and got[0] == g[:6]
        if not ok or abs(got[1] - float(d_track)) > 0.051 or abs(got[2] - float(d_this)) > 0.051:
            bad("other run", m[0], f"{m[1]}'s track {t} at frame {x}: matched to and beside {got}")


FALSE_HERE = re.compile(
    r"(\w+) on the same detections (had a false (?:\w+ )?track here too|had no false (?:\w+ )?track here)"
)


UNSCORED = re.compile(
    r"(\w+) on the same detections reached no score threshold at the evaluation's lowest recall for (\w+)s: the "
    r"evaluation counted none of its \w+ tracks"
)


def check_other_unscored(text: str, c: str, others: Mapping[str, EvalFacts], out, bad) -> None:
    """ "Reached no score threshold at the evaluation's lowest recall": the other run's devkit evaluation of class
    ``c`` has no best-MOTA threshold (``devkit.EvalFacts.thresholds``), so it counted none of its tracks."""
    for m, ev in _named_runs(UNSCORED, text, others):
        out.checked["other run"] += 1
        if m[2] != c or c not in ev.thresholds or ev.thresholds[c] is not None:
            bad("other run", m[0], f"{m[1]}'s devkit evaluation of {c} has the threshold {ev.thresholds.get(c)}")


OWN_UNSCORED = re.compile(
    r"outside the evaluation's counts: (\w+) reached no score threshold at its lowest recall for (\w+)s"
)


def check_own_unscored(text: str, kind: str, c: str, ev: EvalFacts, out, bad) -> None:
    """ "Outside the evaluation's counts: T reached no score threshold at its lowest recall for Cs": the run's own
    devkit evaluation of class ``c`` has no best-MOTA threshold, so it counted every object missed and no false
    track, switch or fragmentation; a failure of another kind there that does not say so reads as one the devkit
    counted (misleading)."""
    unscored = c in ev.thresholds and ev.thresholds[c] is None
    said = [m for m in OWN_UNSCORED.finditer(text) if m[2] == c]
    if kind in ("", "miss"):
        return
    out.checked["misleading"] += 1
    if unscored and not said:
        bad("misleading", kind, f"the devkit's evaluation of {c} reached no threshold: it counted no {kind} of it")
    for m in said if not unscored else ():
        bad("evaluation", m[0], f"the devkit's best-MOTA threshold of {c} is {ev.thresholds.get(c)}")


def check_other_false_tracks(text: str, c: str, x: int, place_xy_m, others: Mapping[str, EvalFacts], out, bad) -> None:
    """ "Had a false track here too / had no false track here": whether the other run's accumulator counted a track
    box of class ``c`` within ``NEAR_M`` of the place (the object, or the false box) as a false positive at frame
    x."""
    if place_xy_m is None:
        return
    for m, ev in _named_runs(FALSE_HERE, text, others):
        out.checked["other run"] += 1
        false = ev.false_near(x, place_xy_m, c)
        if bool(false) != m[2].startswith("had a false"):
            bad("other run", m[0], f"{m[1]}'s false positives within {NEAR_M} m at frame {x}: {false}")


TRACKS_NAMED = re.compile(r"\btracks? (\d+(?:(?:, | and )\d+)*)")
"""The tracks a clause about another run names (``its track 50``, ``its tracks 7, 9 were output``)."""


def check_involved(doc: str, track_ids: Mapping[str, Sequence[int]], out, bad) -> None:
    """A focus document's clauses about another run ("pmbm on the same detections did not fail here: the
    evaluation matched the object to its track 50"): every track they name is one of that run's involved tracks
    (``track_ids``, the focus target's: the tracks its views highlight and label), else ``misleading`` (the text
    names a track the views do not show among the involved)."""
    for name, ids in track_ids.items():
        for clause in re.finditer(rf"\b{re.escape(name)} on the same detections [^;\n]*", doc):
            named = {int(t) for said in TRACKS_NAMED.findall(clause[0]) for t in re.findall(r"\d+", said)}
            out.checked["misleading"] += 1
            if named - set(ids):
                bad("misleading", clause[0][:160], f"{name}'s involved tracks (highlighted in its views) are {ids}")


PART = re.compile(r"(\w[\w-]*): m(\d+)(?: →)? \*\*(new )?track (\d+)(?: \([^)]*\))?\*\*")
"""One run's destination in a "Where the trackers part" line: ``gnnpmb: m11 → **new track 104**``, ``phd: m9 →
**track 29 (98 % of m9)**``."""


def check_parting(doc: str, frame: int, class_name: str, raws: Mapping, out, bad) -> None:
    """Each "Where the trackers part" line of a focus document names places that differ by the runs' raw events,
    not by their numbering alone: a line where every run started a new track from the detection, or where every
    run's track was started by the same detection at the same frame (``RawEvents.birth``), is ``misleading``
    (dev set scene-0655 megvii gnnpmb beside pmbm: "m11 → new track 104 · m11 → new track 231"). A run without
    raw events (a results file) is not checked."""
    if "**Where the trackers part**" not in doc:
        return
    block = doc.split("**Where the trackers part**", 1)[1].split("\n\n", 2)[1]
    for line in (x for x in block.splitlines() if x.startswith("- ")):
        places = set()
        for name, _, new, track in PART.findall(line):
            raw = raws.get(name)
            if raw is None:
                break
            places.add("new" if new else raw.birth(class_name, int(track)) or (name, int(track)))
        else:
            if len(PART.findall(line)) == line.count(" · ") + 1:
                out.checked["misleading"] += 1
                if len(places) < 2:
                    bad("misleading", line[:160], f"at frame {frame} the runs went to the same place: {places}")
