"""What the Why says the lost track did, checked against its raw events and the submission.

* "its existence went from A (frame x) to B (frame y)" / "its existence was A (frame x)" (a PHD's "weight"): the
  track's existence in the ``Posterior`` event of each named frame (a PHD label's heaviest ``IntensityWeights``
  component; rounded as printed), and none of the frames between above A (A is the highest);
* "it was not output at frames …": the submission has no box of the track at any of them;
* "its track logic deleted it at frame x (h of w hits)": a delete ``TrackLogic`` event of x names it, with those
  hits (without hits: a track-logic ``Pruned`` event, greedy's maximum age, also does); "it was pruned at frame x
  (reason)": a ``Pruned`` event of x with that reason; "it was merged into another component at frame x": a
  ``Merged`` event of x names it among the absorbed, or a ``Pruned`` one removes it as merged; "and it ended at
  frame x": one of the three;
* "at frame x it used mN (p P), mK (p Q) +n more": the track's row of the frame's ``Marginals`` (association
  probabilities): the detections with a share of at least 1 %, most likely first, with those probabilities;
  "was given mN": the frame's ``Assignment`` pairs mN with the track;
* "track T was last output on it at frame F" / "the evaluation last matched track T to it at frame F": the last
  frame before the failure's at which the devkit's accumulator matched the object (MATCH or SWITCH) is F, and to
  track T ("on it" reads as the evaluation's match; where the track was last within 2 m is the tracker's business);
  where the submission has no box of T at F (the devkit matched its interpolation) and the text does not say "(a box
  it interpolated for the track)", misleading;
  ", then (the evaluation) matched track T to C GT X at frames …( and to C GT Y at frames …)": after that frame,
  up to the failure's, the accumulator matched T to exactly those other objects at exactly those frames; and where
  it matched T to another object there and the text leaves that out, the last-match sentence is misleading (it
  reads as if T had followed the object, unmatched, since);
* "at frame F track T was still output on the object, but so was track U: two tracks on one object, and the
  evaluation matched the other": at F the accumulator matched the object to U, and T to no other object (else T
  was no spare second track, but another object's match: misleading); "at frame F track T was still output D m
  from it, but the evaluation matched track T to C GT X and track U to GT Y": at F it matched T to X and U to the
  object Y, and the submission's box of T lies D m from the object's annotation.
"""

from __future__ import annotations

import math
import re

import numpy as np

from gnnpmb.events import (
    Assignment,
    AxisKind,
    Cardinality,
    Extracted,
    Gated,
    IntensityWeights,
    Marginals,
    Merged,
    Posterior,
    Predicted,
    Pruned,
    PruneReason,
    TrackLogic,
    TrackLogicAction,
    UpdateWeights,
)
from tools.truth.printing import NUMBER, frames_of, printed

WENT_FROM = re.compile(rf"its (existence|weight) went from ({NUMBER}) \(frame (\d+)\) to ({NUMBER}) \(frame (\d+)\)")
WAS = re.compile(rf"its (existence|weight) was ({NUMBER}) \(frames? (\d+)(?:–(\d+))?\)")
NOT_OUTPUT = re.compile(r"it was not output at (frames? [\d–, ]*\d)")
DELETED = re.compile(
    r"its track logic deleted it at frame (\d+)(?: \((?:(\d+) of (\d+) hits|no hit in its last (\d+) frames)\))?"
)
PRUNED = re.compile(r"it was pruned at frame (\d+) \(([^)]+)\)")
MERGED = re.compile(r"it was merged into another component at frame (\d+)")
ENDED = re.compile(
    r"track (\d+) could not take it: its column's cost for it was infinite \([^)]*\), and it ended at frame (\d+)"
)
USED = re.compile(
    rf"at frame (\d+) it (used|was given) (m\d+(?: \(p {NUMBER}\))?(?:, m\d+(?: \(p {NUMBER}\))?)?)(?: \+(\d+) more)?"
)
GATE = re.compile(r"at frame (\d+) m(\d+) \(score [\d.]+, [\d.]+ m from it, in track (\d+)'s gate at NIS (\d+\.\d)\)")
STAYED = re.compile(r"track (\d+)'s (existence|weight) stayed below (\d+(?:\.\d+)?) \(the views draw tracks from")
AVERAGED = re.compile(
    r"(?:track (\d+)[^;:]*?|the evaluation counted the track: |track (\d+)'s (?:existence|weight) stayed below "
    r"[^;]*?counted it: )"
    r"its score averaged over (?:its (\d+) frames?|the (\d+) "
    r"of its (\d+) frames the evaluation kept \(within the class range\)), (\d+\.\d{3})"
)
LAST_ON_IT = re.compile(
    r"(?:track (\d+) was last output on it|the evaluation last matched track (\d+) to it) at frame (\d+)"
)
INTERPOLATED = " (a box it interpolated for the track)"
"""What follows "the evaluation last matched track T to it at frame F" where the submission has no box of T at F."""
AWAY = re.compile(
    r"then (?:the evaluation )?matched track (\d+) (to \w+ GT \w+ at frames? [\d–, ]*\d"
    r"(?: and to \w+ GT \w+ at frames? [\d–, ]*\d)*)"
)
AWAY_OBJECT = re.compile(r"to (\w+) GT (\w+) at (frames? [\d–, ]*\d)")
TWO_ON_ONE = re.compile(
    r"at frame (\d+) track (\d+) was still output on the object, but so was track ([\d, ]+): two tracks on one "
    r"object, and the evaluation matched the other"
)
MATCHED_BOTH = re.compile(
    r"at frame (\d+) track (\d+) was still output (\d+\.\d) m from it, but the evaluation matched track (\d+) to "
    r"(\w+) GT (\w+) and track (\d+) to GT (\w+)"
)
USED_SHARE = 0.01
"""The checker's own copy of the share from which an update is said to have used a detection."""


def _existence(raw, x: int, c: str, track: int) -> float | None:
    """The track's existence after the update of frame ``x``; a GM-PHD / CPHD label's weight is its heaviest
    ``IntensityWeights`` component (a PHD weight is an expected number and may exceed 1; the ``Posterior`` event
    holds min(w, 1))."""
    intensity = raw.last(x, c, IntensityWeights)
    if intensity is not None:
        mine = np.asarray(intensity.weights)[np.asarray(intensity.labels) == track]
        return float(mine.max()) if mine.size else None
    found = raw.last(x, c, Posterior)
    if found is None:
        return None
    ids = np.asarray(found.track_ids).tolist()
    return float(np.asarray(found.existence)[ids.index(track)]) if track in ids else None


def check_lost(text: str, c: str, lost: int | None, raw, ev, out, bad) -> None:
    """The lost track's story (module docstring); ``lost``: the track the Why follows (None: nothing checked)."""
    if lost is None:
        return
    for m in WENT_FROM.finditer(text):
        out.checked["tracker"] += 1
        (hi, x), (lo, y) = (m[2], int(m[3])), (m[4], int(m[5]))
        got = {f: _existence(raw, f, c, lost) for f in (x, y)}
        if any(v is None for v in got.values()) or printed(got[x]) != hi or printed(got[y]) != lo:
            bad("tracker", m[0], f"the update events give track {lost} {got}")
            continue
        between = [(f, v) for f in range(min(x, y), max(x, y) + 1) if (v := _existence(raw, f, c, lost)) is not None]
        above = [(f, round(v, 4)) for f, v in between if printed(v) != hi and v > float(hi)]
        if above:
            bad("tracker", m[0], f"its {m[1]} was higher between: {above}")
    for m in WAS.finditer(text):
        out.checked["tracker"] += 1
        frames = range(int(m[3]), int(m[4] or m[3]) + 1)
        got = {f: _existence(raw, f, c, lost) for f in frames}
        if any(v is None or printed(v) != m[2] for v in got.values()):
            bad("tracker", m[0], f"the update events give track {lost} {got}")
    for m in DELETED.finditer(text):
        out.checked["tracker"] += 1
        x = int(m[1])
        logic = [
            e for e in raw.of_kind(x, c, TrackLogic) if e.track_id == lost and e.action is TrackLogicAction.DELETED
        ]
        hits = (int(m[2]), int(m[3])) if m[2] else (0, int(m[4])) if m[4] else None
        aged = [p for p in raw.of_kind(x, c, Pruned) if p.track_id == lost and p.reason is PruneReason.TRACK_LOGIC]
        if not logic and (hits is not None or not aged):
            bad("tracker", m[0], f"no delete TrackLogic event (nor, without hits, a track-logic Pruned) of frame {x}")
        elif hits is not None and hits not in {(e.hits, e.window) for e in logic}:
            bad("tracker", m[0], f"the track logic counted {[(e.hits, e.window) for e in logic]}")
    for m in PRUNED.finditer(text):
        out.checked["tracker"] += 1
        reasons = [p.reason.value for p in raw.of_kind(int(m[1]), c, Pruned) if p.track_id == lost]
        if m[2] not in reasons:
            bad("tracker", m[0], f"the Pruned events of frame {m[1]} give track {lost} {reasons}")
    for m in MERGED.finditer(text):
        out.checked["tracker"] += 1
        if not _merged(raw, int(m[1]), c, lost):
            bad("tracker", m[0], f"no Merged event of frame {m[1]} absorbed track {lost}")
    for m in ENDED.finditer(text):
        out.checked["tracker"] += 1
        t, x = int(m[1]), int(m[2])
        if not (raw.deleted(x, c, t) or _merged(raw, x, c, t)):
            bad("tracker", m[0], f"no event of frame {x} ends track {t}")
    for m in USED.finditer(text):
        _check_used(m, c, lost, raw, out, bad)


def check_gates(text: str, c: str, raw, out, bad) -> None:
    """ "mN (…, in track T's gate at NIS V)": the frame's ``Gated`` event has mN inside T's gate at that d²."""
    for m in GATE.finditer(text):
        x, meas, t = int(m[1]), int(m[2]), int(m[3])
        out.checked["tracker"] += 1
        g = raw.last(x, c, Gated)
        rows = np.flatnonzero(np.asarray(g.track_ids) == t) if g is not None else []
        cols = np.flatnonzero(np.asarray(g.meas_indices) == meas) if g is not None else []
        if len(rows) == 0 or len(cols) == 0 or not bool(np.asarray(g.inside)[rows[0], cols[0]]):
            bad("tracker", m[0], f"the Gated event of frame {x} does not have m{meas} inside track {t}'s gate")
        elif f"{float(np.asarray(g.d2)[rows[0], cols[0]]):.1f}" != m[4]:
            bad("tracker", m[0], f"its d² is {float(np.asarray(g.d2)[rows[0], cols[0]]):.3f}")


def check_averaged(text: str, track: int | None, ev, out, bad) -> None:
    """ "its score averaged over its N frames, S" / "over the K of its N frames the evaluation kept …": the devkit
    kept the track's box at K (N) frames and averaged S over them; N the file's boxes of the track."""
    for m in AVERAGED.finditer(text):
        t = m[1] or m[2] or (str(track) if track is not None else None)
        if t is None:
            continue
        out.checked["matched"] += 1
        kept, score = ev.averaged.get(t, (0, float("nan")))
        submitted = sum(t in ids for ids in ev.submitted.values())
        said_kept, said_all = (int(m[3]), int(m[3])) if m[3] else (int(m[4]), int(m[5]))
        if (kept, submitted) != (said_kept, said_all) or f"{score:.3f}" != m[6]:
            bad("matched", m[0], f"the devkit kept {kept} of its {submitted} boxes and averaged {score:.4f}")


def check_stayed_below(text: str, c: str, raw, ev, out, bad) -> None:
    """ "track T's existence stayed below E (…)": its ``Posterior`` existence at every frame the submission has its
    box is below E; "weight" of a GM-PHD / CPHD label (its frames have ``IntensityWeights``), "existence" of any other
    track (else ``misleading``)."""
    for m in STAYED.finditer(text):
        out.checked["tracker"] += 1
        t, below = int(m[1]), float(m[3])
        phd = any(raw.of_kind(x, c, IntensityWeights) for x in ev.submitted if str(t) in ev.submitted[x])
        out.checked["misleading"] += 1
        if (m[2] == "weight") != phd:
            bad("misleading", m[0], f"a {'PHD label has a weight' if phd else 'track has an existence'}, not a {m[2]}")
        above = {
            x: v
            for x in sorted(ev.submitted)
            if str(t) in ev.submitted[x] and (v := _existence(raw, x, c, t)) is not None
        }
        above = {x: round(v, 3) for x, v in above.items() if v >= below}
        if above:
            bad("tracker", m[0], f"its existence at frames it was output: {above}")


def check_not_output(text: str, lost: int | None, ev, out, bad) -> None:
    """ "it was not output at frames …" of the lost track, against the submission (a results file's too)."""
    for m in NOT_OUTPUT.finditer(text) if lost is not None else ():
        out.checked["tracker"] += 1
        output = [x for x in frames_of(m[1]) if str(lost) in ev.submitted.get(x, set())]
        if output:
            bad("tracker", m[0], f"the submission has track {lost}'s box at frames {output}")


def _merged(raw, x: int, c: str, track: int) -> bool:
    """A ``Merged`` event of x absorbed the track, or a ``Pruned`` one removed it as merged."""
    if any(p.track_id == track and p.reason is PruneReason.MERGED for p in raw.of_kind(x, c, Pruned)):
        return True
    return any(track in e.from_ids and e.into_id != track for e in raw.of_kind(x, c, Merged))


def _check_used(m: re.Match, c: str, lost: int, raw, out, bad) -> None:
    x = int(m[1])
    said = [(int(a), b or None) for a, b in re.findall(rf"m(\d+)(?: \(p ({NUMBER})\))?", m[3])]
    more = int(m[4] or 0)
    if m[2] == "was given":
        a = raw.last(x, c, Assignment)
        if a is None:
            return
        out.checked["tracker"] += 1
        given = [int(r.ref) for r, k in a.pairs if k.kind is AxisKind.TRACK and int(k.ref) == lost]
        if [s for s, _ in said] != given or more:
            bad("tracker", m[0], f"the assignment of frame {x} gave track {lost} {given}")
        return
    marg = raw.last(x, c, Marginals)
    if marg is None:
        return
    out.checked["tracker"] += 1
    rows = [i for i, r in enumerate(marg.rows) if int(r.ref) == lost]
    if not rows:
        bad("tracker", m[0], f"the Marginals of frame {x} have no row of track {lost}")
        return
    p = np.asarray(marg.probs)[rows[0]]
    shares = sorted(
        ((int(k.ref), float(p[j])) for j, k in enumerate(marg.cols) if k.kind is AxisKind.MEASUREMENT),
        key=lambda s: (-s[1], s[0]),
    )
    used = [(d, v) for d, v in shares if v >= USED_SHARE]
    ok = [d for d, _ in used[:2]] == [d for d, _ in said] and max(0, len(used) - 2) == more
    ok = ok and all(v is None or f"{q:.2f}" == v for (_, q), (_, v) in zip(used, said, strict=False))
    if not ok:
        bad("tracker", m[0], f"the Marginals of frame {x} give track {lost} {[(d, round(v, 3)) for d, v in used]}")


def _short(object_id: str) -> str:
    """The checker's own copy of how the text shortens an object id (first 6 characters of a long token)."""
    return object_id if len(object_id) <= 8 else object_id[:6]


def _last_match(ev, class_name: str, frame: int, gt_id: str | None) -> int | None:
    """The last frame before ``frame`` at which the accumulator matched object ``gt_id`` (MATCH or SWITCH)."""
    return max(
        (x for (c, x), pairs in ev.gt_to_track.items() if c == class_name and x < frame and pairs.get(gt_id)),
        default=None,
    )


def _matched_away(ev, class_name: str, track: str, gt_id: str | None, since: int, frame: int) -> dict[str, list[int]]:
    """Short object id -> the frames after ``since`` up to ``frame`` at which the accumulator matched ``track`` to
    that object, other than ``gt_id``."""
    away: dict[str, list[int]] = {}
    for x in range(since + 1, frame + 1):
        g = ev.matched_gt(class_name, x, track)
        if g is not None and g != gt_id:
            away.setdefault(_short(g), []).append(x)
    return away


def check_last_match(text: str, class_name: str, frame: int, gt_id: str | None, ev, out, bad) -> None:
    """The sentences "track T was last output on it at frame F" and "the evaluation last matched track T to it at
    frame F" against the devkit's last MATCH or SWITCH of object ``gt_id`` before ``frame``, and the clause ", then
    matched track T to …" (or its absence) against the devkit's matches of T after it (module docstring)."""
    for m in LAST_ON_IT.finditer(text):
        t, said = m[1] or m[2], int(m[3])
        out.checked["matched"] += 1
        last = _last_match(ev, class_name, frame, gt_id)
        track = ev.matched_track(class_name, last, gt_id) if last is not None else None
        if (last, track) != (said, t):
            bad(
                "matched",
                m[0],
                f"the devkit last matched the object before frame {frame} at frame {last} (to track {track})",
            )
            continue
        out.checked["misleading"] += 1
        if m[2] is not None and t not in ev.submitted.get(said, set()) and not text[m.end() :].startswith(INTERPOLATED):
            bad(
                "misleading",
                m[0],
                f"left unsaid: the submission has no box of track {t} at frame {said} (the devkit matched its "
                "interpolation)",
            )
        away = _matched_away(ev, class_name, t, gt_id, last, frame)
        told = [a for a in AWAY.finditer(text) if a[1] == t]
        out.checked["misleading"] += 1
        if away and not told:
            bad(
                "misleading",
                m[0],
                f"left unsaid: after frame {last} the devkit matched track {t} to other objects {away}",
            )
        for a in told:
            out.checked["matched"] += 1
            said_away = {g: frames_of(frames) for cls, g, frames in AWAY_OBJECT.findall(a[2]) if cls == class_name}
            if said_away != away or len(AWAY_OBJECT.findall(a[2])) != len(said_away):
                bad("matched", a[0], f"after frame {last} the devkit matched track {t} to {away}")


def check_two_tracks(text: str, class_name: str, frame: int, gt_id: str | None, scene, ev, out, bad) -> None:
    """ "… two tracks on one object, and the evaluation matched the other" and "… but the evaluation matched track T
    to C GT X and track U to GT Y" against the accumulator's matches at that frame (module docstring)."""
    for m in TWO_ON_ONE.finditer(text):
        x, t = int(m[1]), m[2]
        named = {u.strip() for u in m[3].split(",")}
        out.checked["matched"] += 1
        matched = ev.matched_track(class_name, x, gt_id or "")
        if matched not in named:
            bad("matched", m[0], f"the devkit matched the object at frame {x} to track {matched}")
        other = ev.matched_gt(class_name, x, t)
        out.checked["misleading"] += 1
        if other is not None and other != gt_id:
            bad("misleading", m[0], f"at frame {x} the devkit matched track {t} to another object, GT {_short(other)}")
    for m in MATCHED_BOTH.finditer(text):
        x, t, distance, t2, cls, g, u, g2 = int(m[1]), m[2], float(m[3]), m[4], m[5], m[6], m[7], m[8]
        out.checked["matched"] += 1
        got_t, got_u = ev.matched_gt(class_name, x, t2), ev.matched_track(class_name, x, gt_id or "")
        if (
            t2 != t
            or cls != class_name
            or got_t is None
            or _short(got_t) != g
            or got_u != u
            or _short(gt_id or "") != g2
        ):
            bad("matched", m[0], f"at frame {x} the devkit matched track {t2} to {got_t} and the object to {got_u}")
        a = scene.objects[x].get(gt_id or "") if scene is not None and x < len(scene.objects) else None
        box = next((xy for tt, _, xy in ev.boxes.get(x, []) if tt == t), None)
        if a is None or box is None:
            continue
        out.checked["output"] += 1
        d = math.hypot(box[0] - a.xy_m[0], box[1] - a.xy_m[1])
        if abs(d - distance) > 0.05 + 1e-9 or d >= 2.0:
            bad("output", m[0], f"the submission's box of track {t} lies {d:.2f} m from the annotation")


STORY_SHOWN = re.compile(
    r"frame (\d+): track (\d+) (?:no longer (?:shown|output) \(|fell below the display threshold \(|confirmed \(|"
    r"output again \(|back above the display threshold \()([rw])=(\d+\.\d+)"
)
STORY_HIDDEN = re.compile(
    r"frame (\d+): track (\d+) \((?:not shown, [rw] < [\d.]+|output; [rw] below the display threshold [\d.]+|not "
    r"output)\): [^\n]*?, ([rw])=(\d+(?:\.\d+)?)\n"
)
STORY_COPY = re.compile(r"frame (\d+): track (\d+) confirmed \(a copy of track (\d+)'s component, ([rw])=(\d+\.\d+)")
STORY_OUTPUT = re.compile(
    r"frame (\d+): track (\d+) (?:(no longer shown|\(not shown)|(no longer output|\(not output)|(fell below the "
    r"display threshold \([^)]*\), still output|\(output;|output again|back above the display threshold))"
)

STORY_FELL = re.compile(r"frame (\d+): track (\d+) no longer output \([rw]=(\d+\.\d+) fell below (\d+\.\d+|inf)\)")
STORY_MAP = re.compile(
    r"frame (\d+): track (\d+) no longer output \([rw]=\d+\.\d+; the MAP cardinality (?:(\d+) kept the \d+ heaviest "
    r"components, the lightest at w=(\d+\.\d+)|was 0)\)"
)


def check_no_longer_output(section: str, c: str, raw, out, bad) -> None:
    """ "track T no longer output (r=V fell below L)": a threshold fixed beforehand, so no CPHD (whose output is the
    MAP cardinality's heaviest components: ``Cardinality`` events), and V below L. "…; the MAP cardinality n kept
    the n heaviest components, the lightest at w=W)" / "…; the MAP cardinality was 0)": a CPHD frame, n the argmax
    of its cardinality pmf and the number of the class's estimates, W the lightest weight among them."""
    if raw is None:
        return
    for m in STORY_FELL.finditer(section):
        x = int(m[1])
        out.checked["misleading"] += 1
        if raw.last(x, c, Cardinality) is not None:
            bad("misleading", m[0], "a CPHD outputs its MAP cardinality's heaviest components: no fixed threshold")
        elif not float(m[3]) < float(m[4]):
            bad("misleading", m[0], f"{m[3]} is not below {m[4]}")
    for m in STORY_MAP.finditer(section):
        x = int(m[1])
        out.checked["tracker"] += 1
        pmf, extracted = raw.last(x, c, Cardinality), raw.last(x, c, Extracted)
        if pmf is None or extracted is None:
            bad("tracker", m[0], f"no Cardinality or Extracted event of {c} at frame {x}")
            continue
        n_map, ids = int(np.argmax(np.asarray(pmf.pmf))), [e.track_id for e in extracted.estimates]
        said = 0 if m[3] is None else int(m[3])
        weights = [w for t in ids if (w := _existence(raw, x, c, t)) is not None]
        lightest_ok = said == 0 or (weights and abs(min(weights) - float(m[4])) < 0.006)
        if said != n_map or said != len(ids) or not lightest_ok:
            bad("tracker", m[0], f"MAP cardinality {n_map}, {len(ids)} estimates, weights {sorted(weights)[:3]}")


def check_story(section: str, c: str, raw, out, bad, submitted=None) -> None:
    """A focus document's story lines of one run (``section``): "track T confirmed (r=V, …)", "track T no longer
    output (r=V fell below …)", "track T fell below the display threshold (r=V < …), still output", "track T
    (output; r below the display threshold …): …, r=V", "track T (not output): …, r=V": V is the track's existence
    after frame x's update (a GM-PHD / CPHD label's heaviest ``IntensityWeights`` component), and the symbol is
    ``w`` for such a label, ``r`` for an existence (else ``misleading``). With the run's submission (``submitted``:
    frame -> track ids with a box there): "output" / "not output" as it has the track's box or not, and "not shown"
    of a track it output is ``misleading`` (the viewer's display threshold is not the submission's). "track T
    confirmed (a copy of track S's component, w=V, …)": T has no component of its own at x, S's weighs V (1.5 or
    more: two copies or more)."""
    if submitted is not None:
        for m in STORY_OUTPUT.finditer(section):
            x, t = int(m[1]), m[2]
            out.checked["output"] += 1
            boxed = t in submitted.get(x, set())
            if m[3] and boxed:  # "not shown": true of the view, misleading of a track output
                bad("misleading", m[0], f"the submission has a box of track {t} at frame {x}: it was output")
            elif (m[4] and boxed) or (m[5] and not boxed):
                bad("output", m[0], f"the submission {'has' if boxed else 'has no'} box of track {t} at frame {x}")
    if raw is None:
        return
    check_no_longer_output(section, c, raw, out, bad)
    for m in STORY_COPY.finditer(section):  # a GM-PHD copy: no component of its own, its source's weight
        x, t, source = int(m[1]), int(m[2]), int(m[3])
        out.checked["tracker"] += 1
        own, got = _existence(raw, x, c, t), _existence(raw, x, c, source)
        if own is not None or not _reads(got, m[5]) or got < 1.5:
            bad("tracker", m[0], f"track {t}'s own weight {own}; track {source}'s {got} (copies from 1.5)")
    found = [(m[0], int(m[1]), int(m[2]), m[3], m[4]) for m in STORY_SHOWN.finditer(section)]
    found += [(m[0].strip(), int(m[1]), int(m[2]), m[3], m[4]) for m in STORY_HIDDEN.finditer(section + "\n")]
    for sentence, x, t, symbol, said in found:
        out.checked["tracker"] += 1
        got = _existence(raw, x, c, t)
        if not _reads(got, said):
            bad("tracker", sentence, f"its existence (heaviest PHD component) after frame {x}: {got}")
        out.checked["misleading"] += 1
        if (symbol == "w") != bool(raw.of_kind(x, c, IntensityWeights)):
            bad(
                "misleading",
                sentence,
                f"'{symbol}=' of a {'PHD label' if symbol == 'r' else 'track with an existence'}",
            )


TRACK_TABLE = re.compile(
    r"Track (\d+), frame by frame:\n\n\| frame \| (r|weight) before update \| in gate \(NIS\) \| used \| (?:r|weight) "
    r"after \| output \|\n\|[-|]+\|\n((?:\|.*\|\n)+)"
)


def check_track_tables(section: str, c: str, raw, out, bad) -> None:
    """A focus document's per-track tables of one run: "r" / "weight" before and after each update against the raw
    events (the track's ``Predicted`` row, its ``Posterior`` existence; a GM-PHD / CPHD label's heaviest component,
    predicted and after ``IntensityWeights``), and the word: "weight" for such a label (else ``misleading``)."""
    if raw is None:
        return
    for table in TRACK_TABLE.finditer(section):
        t, word = int(table[1]), table[2]
        for row in table[3].strip().splitlines():
            cells = [x.strip() for x in row.strip("|").split("|")]
            x, before, after = int(cells[0]), cells[1].split(" ")[0], cells[4]
            phd = bool(raw.of_kind(x, c, IntensityWeights))
            out.checked["misleading"] += 1
            if (word == "weight") != phd:
                bad("misleading", f"Track {t}: {word} before update", f"{'a PHD label' if phd else 'an existence'}")
            predicted = [
                float(w)
                for e in raw.of_kind(x, c, Predicted)
                for i, w in zip(np.asarray(e.track_ids).tolist(), np.asarray(e.existence).tolist(), strict=True)
                if i == t
            ]
            if len(cells) == 6:  # "in gate (NIS)": "m15 (1.2), m3 (4.0)" or "nothing", against a Gated row of T
                _check_gate_cell(cells[2], raw, x, c, t, out, bad)
            for said, got in ((before, max(predicted) if predicted else None), (after, _existence(raw, x, c, t))):
                if said in ("—", "ended"):
                    continue
                out.checked["tracker"] += 1
                if not _reads(got, said):
                    bad("tracker", f"Track {t} at frame {x}: {said}", f"the raw events give {got}")


GATE_ITEM = re.compile(r"m(\d+) \((\d+\.\d)\)")


def _check_gate_cell(cell: str, raw, x: int, c: str, t: int, out, bad) -> None:
    """A table's gate cell: the detections inside track ``t``'s gate at frame x with their d² (one decimal),
    exactly those of one of its rows of the frame's ``Gated`` event (a PHD label has a row per component); "nothing"
    where a row of it gates none, or it has no row."""
    said = sorted((int(m), d2) for m, d2 in GATE_ITEM.findall(cell))
    rows = []
    for e in raw.of_kind(x, c, Gated):
        refs = np.asarray(e.meas_indices).tolist()
        for k in np.flatnonzero(np.asarray(e.track_ids) == t).tolist():
            inside = np.flatnonzero(np.asarray(e.inside)[k]).tolist()
            rows.append(sorted((int(refs[j]), f"{float(np.asarray(e.d2)[k, j]):.1f}") for j in inside))
    out.checked["tracker"] += 1
    if said not in rows and not (not said and not rows):
        bad("tracker", f"Track {t} at frame {x}: in gate {cell}", f"its Gated rows: {rows}")


def _reads(got: float | None, said: str) -> bool:
    """Whether ``said`` prints ``got``: as ``printed`` does (one significant digit below 0.01), or with said's own
    decimals."""
    if got is None:
        return False
    digits = len(said.split(".")[1]) if "." in said and "e" not in said else 0
    return said == printed(got) or ("e" not in said and f"{got:.{digits}f}" == said)


USED_AWAY = re.compile(r"it had used detections 2 m or more from the object at frames? ((?:\d+ \(m\d+[^)]*\)(?:, )?)+)")
USED_ITEM = re.compile(r"(\d+) \(m(\d+)(?:, (?:p (\d\.\d+)|(\d+) % of its weight))?\)")


def check_used_away(text: str, c: str, lost: int | None, gt: str | None, scene, raw, out, bad) -> None:
    """ "it had used detections 2 m or more from the object at frames x (mN[, p P | Q % of its weight]), …": the
    lost track's update at x used mN (the frame's ``Assignment``, its ``Marginals`` row, or its share of the
    ``UpdateWeights``), with the share said where the update is soft (else ``misleading``), and mN lies 2 m or more
    from the object's annotation in the files."""
    if lost is None or gt is None or scene is None:
        return
    for m in USED_AWAY.finditer(text):
        for item in USED_ITEM.finditer(m[1]):
            x, meas = int(item[1]), int(item[2])
            out.checked["tracker"] += 1
            share, soft = _share(raw, x, c, lost, meas)
            a = scene.objects[x].get(gt) if x < len(scene.objects) else None
            d = scene.detections[x][meas] if x < len(scene.detections) and meas < len(scene.detections[x]) else None
            far = a is not None and d is not None and math.hypot(d.xy_m[0] - a.xy_m[0], d.xy_m[1] - a.xy_m[1]) >= 2.0
            if not share or not far:
                bad("tracker", item[0], f"track {lost}'s share of m{meas} at frame {x}: {share}; 2 m or more: {far}")
                continue
            out.checked["misleading"] += 1
            if item[3]:
                stated = f"{share:.2f}" == item[3]
            elif item[4]:
                stated = f"{100 * share:.0f}" == item[4]
            else:  # unsaid: right for an assignment only
                stated = not soft
            if not stated:
                bad("misleading", item[0], f"its share of m{meas} was {share:.3f} ({'soft' if soft else 'assigned'})")


def _share(raw, x: int, c: str, track: int, meas: int) -> tuple[float, bool]:
    """(the track's share of detection ``meas`` in frame x's update, whether the update is soft): 1 for an assigned
    pair, its ``Marginals`` probability, or its ``UpdateWeights`` share of its own weight; 0: not used."""
    for e in raw.of_kind(x, c, UpdateWeights):
        labels, refs = np.asarray(e.labels).tolist(), np.asarray(e.meas_indices).tolist()
        if track in labels and meas in refs:
            i = labels.index(track)
            total = float(e.missed[i] + np.asarray(e.detected)[i].sum())
            return (float(e.detected[i, refs.index(meas)]) / total if total > 0 else 0.0), True
    for e in raw.of_kind(x, c, Marginals):
        rows = [int(r.ref) for r in e.rows]
        cols = [k for k, col in enumerate(e.cols) if col.kind is AxisKind.MEASUREMENT and col.ref == meas]
        if track in rows and cols:
            return float(np.asarray(e.probs)[rows.index(track), cols[0]]), True
    pairs = {
        (int(r.ref), int(col.ref))
        for e in raw.of_kind(x, c, Assignment)
        for r, col in e.pairs
        if col.kind is AxisKind.TRACK
    }
    return (1.0 if (meas, track) in pairs else 0.0), False
