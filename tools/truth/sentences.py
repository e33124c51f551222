"""Each sentence of a rendered finding that states a checkable fact, checked against the independent sources:
the devkit's matching (``devkit.EvalFacts``), the raw events (``rawevents.RawEvents``) and replays
(``replay``). The sentence is read from the text a user sees (``gnnpmb failures --why``); the finding is read only
for what the text abbreviates (full object ids, the frames a range stands for).

Classes of false statement (the issue's numbering):

* ``matched``: who the evaluation matched (or counted);
* ``gone``: a track said to be gone, or a detection outside a track's gate, against that frame's columns;
* ``counterfactual``: a "would have taken" / "would have cost more" replayed, a rival already taken, a stated
  threshold on the wrong side of the current value;
* ``misleading``: a margin other than the solver's (a capped one included), a greedy alternative already taken,
  a note meant for the viewer printed in the terminal, detections preprocessing removed left out of "had a
  detection within 2 m" unsaid, "did not have this failure" of a run that lost the object too, a bare percentage;

and beyond the issue's four: ``detector`` (scores, distances, points, detections in reach: ``detector``), ``other
run`` (``otherruns``), ``share`` (PHD percentages: ``shares``), ``output`` (a track's box on the object, its score,
against the submission), ``fields`` (a finding's typed fields: ``fields``). ``coverage`` says which clauses of a
text any pattern reads.
"""

from __future__ import annotations

import math
import re
from collections import Counter
from collections.abc import Iterator, Mapping
from dataclasses import dataclass, field, replace

import numpy as np

from gnnpmb.assign.hungarian import solve
from gnnpmb.events import AxisKind, Born, CostMatrix, Gated
from tools.truth import costs, detector, hypotheses, lost, otherruns, output, place, replay, shares
from tools.truth.devkit import EvalFacts
from tools.truth.printing import BECAUSE, frames_of
from tools.truth.rawevents import RawEvents
from tools.truth.scene import NEAR_M, SceneTruth

CLASSES = (
    "matched",
    "gone",
    "counterfactual",
    "misleading",
    "detector",
    "other run",
    "share",
    "output",
    "tracker",
    "cost",
    "hypothesis",
    "evaluation",
    "fields",
)


@dataclass(frozen=True)
class Contradiction:
    """A sentence found false: its class (``CLASSES``), the sentence, and what the sources say."""

    kind: str
    sentence: str
    truth: str


@dataclass(frozen=True)
class Context:
    """What the text abbreviates: the finding's class, frame, full object id, covered objects' ids, the taking
    track's false frames."""

    class_name: str
    frame: int
    gt_id: str | None
    covered: tuple[str, ...] = ()
    false_frames: tuple[int, ...] = ()
    taker: int | None = None
    kind: str = ""
    lost: int | None = None
    track: int | None = None
    """A false track's id (its box is the place the finding is about)."""


@dataclass
class Tally:
    """Sentences checked and contradictions per class; counterfactual replays checked and refuted."""

    checked: dict[str, int] = field(default_factory=lambda: dict.fromkeys(CLASSES, 0))
    found: list[Contradiction] = field(default_factory=list)
    replays: int = 0
    refuted: int = 0
    clauses: int = 0
    unchecked: Counter = field(default_factory=Counter)
    """Clauses of the texts, and the kinds (``clause_kind``) of those no pattern reads."""

    def add(self, other: Tally) -> None:
        for k, v in other.checked.items():
            self.checked[k] += v
        self.found += other.found
        self.replays += other.replays
        self.refuted += other.refuted
        self.clauses += other.clauses
        self.unchecked += other.unchecked


_NUM = r"[-\d.e+]+"
GONE = re.compile(r"at frame (\d+) m(\d+) \(score [\d.]+, [\d.]+ m from it; track (\d+) was gone\)")
OUTSIDE = re.compile(r"m(\d+) was outside the gate of track (\d+), which had the object")
WITHIN = re.compile(rf"Within d² ({_NUM}) \(instead of ({_NUM})\), track (\d+) would have taken m(\d+)")
ABOVE = re.compile(
    rf"With a predicted existence above ({_NUM}) \(instead of ({_NUM})\), track (\d+) would have taken m(\d+)"
)
NO_EXISTENCE = re.compile(r"No predicted existence would have given m(\d+) to track (\d+)")
EVEN_AT_ZERO = re.compile(
    r"Even with m(\d+) right on its prediction \(d² 0\), track (\d+) would (?:have cost more|not have taken it)"
)
RIVAL = re.compile(
    r"m(\d+) went to (.+?) \(cost [-\d.]+\) rather than track (\d+) \(cost [-\d.]+\): the lower cost wins"
)
RIVAL_TAKEN = re.compile(r"m(\d+) went to (.+?) \(cost [-\d.]+\); track (\d+) \(cost [-\d.]+\) went to m(\d+)")
COULD_NOT = re.compile(
    r"at frame (\d+) m(\d+) \(score [\d.]+, [\d.]+ m from it; track (\d+) could not take it: its column's cost for "
    r"it was infinite"
)
TEST_KIND = re.compile(
    r"at frame (\d+) m(\d+) \([^;]*; track (\d+) could not take it(?: in the hypothesis the tracker chose \(|: )"
    r"its column's cost (?:there|for it) was infinite,? \(?(outside its gate|beyond its ([^\n]+?) threshold)"
)


def _check_test_kind(m: re.Match, c: str, raw: RawEvents, out: Tally, bad) -> None:
    """The test an infinite cost is said to stand for: "outside its gate" where a ``Gated`` row of the track has
    the detection outside; "beyond its K threshold" where the frame's matrix has a cost threshold named K and no
    ``Gated`` row has the detection outside the track's gate (else the gate stopped it first)."""
    x, meas, t, kind, name = int(m[1]), int(m[2]), int(m[3]), m[4], m[5]
    outside = inside = False
    for e in raw.of_kind(x, c, Gated):
        refs = np.asarray(e.meas_indices).tolist()
        if meas not in refs:
            continue
        for k in np.flatnonzero(np.asarray(e.track_ids) == t).tolist():
            hit = bool(np.asarray(e.inside)[k, refs.index(meas)])
            inside, outside = inside or hit, outside or not hit
    named = {mat.scale.name for mat in raw.matrices(x, c) if mat.scale is not None and mat.scale.threshold is not None}
    # a threshold that is the gate's own test (a Mahalanobis distance of at most T: the gate d² < T², prob3dmot)
    gates = {float(e.threshold) for e in raw.of_kind(x, c, Gated)}
    same_test = any(
        mat.scale.name == name and any(math.isclose(mat.scale.threshold**2, g, rel_tol=1e-9) for g in gates)
        for mat in raw.matrices(x, c)
        if mat.scale is not None and mat.scale.threshold is not None
    )
    out.checked["gone"] += 1
    if kind == "outside its gate" and not (outside and not inside):
        bad("gone", m[0], f"the Gated rows of track {t} at frame {x}: outside {outside}, inside {inside}")
    elif name is not None and (name not in named or (outside and not inside and not same_test)):
        bad("gone", m[0], f"the frame's thresholds: {sorted(named)}; Gated outside {outside}, inside {inside}")


CHOICE = re.compile(
    r"frame (\d+): (?:close call: )?m(\d+)(?: \(score [\d.]+\))? → ([^(]+?) \([^()]*\) "
    r"(?:over (track \d+|new|a new track|missed \d+) \([^()]*(?:\([^()]*\)[^()]*)*\)"
    r"(?:, which took m(\d+) \(the lower total wins\))?|\(no other\)), margin (inf|\d+\.\d+)"
    r"((?: [a-zA-Z]+)? or more)?"
)
UNDERCUT = re.compile(
    r"frame (\d+): m(\d+)(?: \(score [\d.]+\))? → [^(\n]+? \([^()\n]*\), not (?:track (\d+) \([^()\n]*\): the "
    r"solver matched every pair before dropping those past [^\n]+?, and gave track \d+ to a detection whose pair it "
    r"dropped|the cheapest on these costs: the solver matched every pair before dropping those past)"
)
UNDERCUT_TOL = 1e-9
THEFT = re.compile(
    r"track (\d+) had been a false track at [^(]+\(matched to no object: the evaluation still gave GT (\w+) to "
    r"track (\d+)\)"
)
COVERED = re.compile(
    r"tracks? ([\d, ]+) lay within \d m of it and (?:was|were) counted, but the evaluation matched (?:it|each) to "
    r"another"
)
COALESCED = re.compile(
    r"at frame (\d+) track (\d+) (?:(was not output|was output, but (?:its box lay (?:[\d.]+ m from the ego vehicle, "
    r"beyond the evaluation's \d+ m range|in a bike rack) and was dropped|the evaluation dropped its box)); the box "
    r"the evaluation interpolated for it in its place )?was matched to "
    r"(GT \w+(?:, GT \w+)*) and also lay within"
)
ALSO_NEAR = re.compile(
    r"at frame (\d+) track (\d+) .{0,200}?and also lay within 2 m of GT (\w{6}), (?:which no counted track "
    r"covered|which the evaluation matched to no track((?:,| and) (?:though counted )?track \d+ lay [\d.]+ m from it "
    r"\(matched to GT \w{6}\))*)"
)
"""A coalescence's second object: matched to no track; every other counted track the submission has within 2 m of
its annotation that the devkit matched to another object named, with that object (audit truth54, dev set
scene-0061 centerpoint jpda: "which no counted track covered" said of a pedestrian with counted track 72 0.9 m
from it, matched to a third pedestrian)."""
ALSO_ITEM = re.compile(r"track (\d+) lay ([\d.]+) m from it \(matched to GT (\w{6})\)")
MATCHED_INSTEAD = re.compile(r"the evaluation matched it to another track \(track (\d+)\)")
NOT_COUNTED = re.compile(
    r"track (\d+) was output on it(?: \(score [\d.]+\))?, but [^:]*?: the evaluation did not count it"
)
ON_IT = re.compile(r"track (\d+) was (not )?output on it(?: \(score ([\d.]+)\))?")
VIEWER_ONLY = ("too low to be shown here",)
NOTHING_NEAR = re.compile(r"no object of a tracked class lies within 2 m")
NO_TRACK_NEAR = re.compile(r"no (\w+) track was output within 2 m of it")
COUNTED_AT = re.compile(
    r"the evaluation counted the track: its score averaged [^:]*?, is at least the (\w+) threshold (\d+\.\d+)"
)
OUTPUT_AT = re.compile(r"at frame (\d+) track (\d+) (?:\(\w+\) )?was (?:still )?output (?:on|[\d.]+ m from)")
LAST_OUTPUT = re.compile(r"track (\d+) was last output on it at frame (\d+)")
UNANNOTATED = re.compile(
    r"at frame (\d+) \w+ GT (\w{6}) had no annotation, though it had some before and after: the evaluation scored a "
    r"box it interpolated between them there"
)
"""A failure at a keyframe the object had no annotation at (``Rule.UNANNOTATED``)."""
OFF_AFTER = re.compile(
    r"(?:track (\d+) was last output on it|the evaluation last matched track (\d+) to it) at frame \d+"
    r"(?: \(a box it interpolated for the track\))?"
    r"(?: \(output farther than 2 m from it at (frames? [\d–, ]*\d)\))?"
    r"(?: \(it was not annotated at (frames? [\d–, ]*\d): the evaluation scored (?:boxes|a box) it interpolated\))?"
)
"""A lost track's last frame on the object, then where it was output away from the annotation and the frames
without one."""
STARTED_NEW = re.compile(
    r"at frame (\d+) (?:detection )?m(\d+) \([^()]*(?:\([^()]*\)[^()]*)*\)(?: lay [\d.]+ m from \w+ GT \w+ and started|"
    r" →) new track (\d+)"
)
STARTED = re.compile(r"track (\d+) had been started at frame (\d+) by m(\d+)")
# the object's own detection and the track it went to or started (a miss's or a coalescence's)
WENT_TO = re.compile(
    r"(?:its detection m\d+ \(score [\d.]+, [\d.]+ m away\)|detection m\d+ \(score [\d.]+\) lay [\d.]+ m from \w+ GT "
    r"\w+ and) (?:started new track|went to track) (\d+)"
)


def check_text(
    text: str,
    ctx: Context,
    raw: RawEvents | None,
    ev: EvalFacts,
    tracker: str = "",
    scene: SceneTruth | None = None,
    others: Mapping[str, EvalFacts] | None = None,
) -> Tally:
    """Every checkable sentence of ``text`` (one finding's rendered lines); raw None for a results file; scene: the
    files' own detections and annotations (None: detector sentences unchecked); others: other runs' devkit facts
    by tracker name."""
    out = Tally()

    def bad(kind: str, sentence: str, truth: str) -> None:
        out.found.append(Contradiction(kind, sentence, truth))

    c = ctx.class_name
    out.clauses, out.unchecked = coverage(text)
    _check_eval(text, ctx, ev, out, bad, scene)
    if scene is not None:
        detector.check_detector(text, ctx.gt_id, ctx.frame, c, scene, raw, out, bad, ev.evaluated_gt)
    otherruns.check_others(text, ctx.kind, c, ctx.frame, ctx.gt_id, others or {}, scene, out, bad)
    where = _place(ctx, ev, scene)
    otherruns.check_other_false_tracks(text, c, ctx.frame, where, others or {}, out, bad)
    otherruns.check_other_unscored(text, c, others or {}, out, bad)
    otherruns.check_own_unscored(text, ctx.kind, c, ev, out, bad)
    if ctx.gt_id is None:
        place.check_place(text, c, ctx.frame, where, scene, out, bad)
        place.check_coasted(text, scene, ev, out, bad, raw)
    place.check_swapped(text, ctx.frame, ctx.gt_id, scene, ev, out, bad)
    place.check_reach_1141(text, ctx.frame, _place(replace(ctx, gt_id=None), ev, scene), scene, ev, out, bad)
    place.check_interpolated(text, ctx.frame, ctx.gt_id, ev, out, bad)
    place.check_out_of_reach(text, c, ctx.frame, ctx.gt_id, scene, ev, out, bad)
    place.check_no_box(text, ctx.frame, scene, ev, out, bad)
    place.check_of_nothing(text, scene, ev, out, bad)
    place.check_off(text, scene, ev, out, bad)
    place.check_none_of_its_own(text, ctx.frame, scene, out, bad)
    check_dropped(text, ctx, ev, out, bad)
    out.checked["misleading"] += 2
    if "?" in text:
        bad("misleading", text[max(0, text.index("?") - 60) : text.index("?") + 1], "a placeholder in the text")
    if "cause unknown" in text:
        bad("misleading", "cause unknown", "no stated test held")
    if scene is not None and ctx.gt_id is None and where is not None:
        for m in NOTHING_NEAR.finditer(text):
            out.checked["detector"] += 1
            here = scene.objects[ctx.frame] if ctx.frame < len(scene.objects) else {}
            near = [k[:6] for k, a in here.items() if math.hypot(a.xy_m[0] - where[0], a.xy_m[1] - where[1]) < 2.0]
            if near:
                bad("detector", m[0], f"annotated objects within 2 m of track {ctx.track}'s box: {near}")
            _part_of(text[m.end() :], where, ctx.frame, m[0], scene, out, bad)
            _check_drifted(text[m.end() :], ctx, where, scene, ev, out, bad)
    if scene is not None:
        _check_twins(
            text, ctx.frame, scene, (raw.received(ctx.frame, c) or None) if raw is not None else None, out, bad
        )
    for phrase in VIEWER_ONLY:
        if phrase in text:
            out.checked["misleading"] += 1
            bad("misleading", phrase, "a note about the viewer printed where nothing is shown")
    for m in COUNTED_AT.finditer(text):
        out.checked["matched"] += 1
        if ev.thresholds.get(m[1]) is None or abs(ev.thresholds[m[1]] - float(m[2])) > 0.0005 + 1e-9:
            bad("matched", m[0], f"the devkit's best-MOTA threshold for {m[1]} is {ev.thresholds.get(m[1])}")
    if scene is not None and ctx.gt_id is not None:
        for m in NO_TRACK_NEAR.finditer(text):
            a = scene.objects[ctx.frame].get(ctx.gt_id) if ctx.frame < len(scene.objects) else None
            if a is None:
                continue
            out.checked["detector"] += 1
            near = [
                t
                for t, cls, xy in ev.boxes.get(ctx.frame, [])
                if cls == m[1] and math.hypot(xy[0] - a.xy_m[0], xy[1] - a.xy_m[1]) < 2.0
            ]
            if near:
                bad("detector", m[0], f"the submission has {m[1]} tracks {near} within 2 m at frame {ctx.frame}")
    if scene is not None and ctx.gt_id is not None:
        _check_on_it(text, ctx, scene, ev, out, bad)
    said_output = [(int(m[1]), m[2], m[0]) for m in OUTPUT_AT.finditer(text)]
    said_output += [(int(m[2]), m[1], m[0]) for m in LAST_OUTPUT.finditer(text)]
    for x, t, sentence in said_output:
        out.checked["misleading"] += 1
        if t not in ev.submitted.get(x, set()):
            bad("misleading", sentence, f"the submission has no box of track {t} at frame {x} (an interpolation)")
    if scene is not None and ctx.gt_id is not None:
        for m in LAST_OUTPUT.finditer(text):
            later = _output_on_after(scene, ev, m[1], ctx.gt_id, int(m[2]), ctx.frame)
            out.checked["output"] += 1
            if later:
                bad("output", m[0], f"the submission's box of track {m[1]} lay within 2 m of the annotation at {later}")
    if scene is not None and ctx.gt_id is not None:
        _check_off_and_unannotated(text, ctx.gt_id, scene, ev, out, bad)
        for m in UNANNOTATED.finditer(text):
            out.checked["evaluation"] += 1
            x, have = int(m[1]), [y for y, objs in enumerate(scene.objects) if ctx.gt_id in objs]
            if not ctx.gt_id.startswith(m[2]) or x in have or not have or not have[0] < x < have[-1]:
                bad("evaluation", m[0], f"the object is annotated at frames {have}")
            elif (x, ctx.gt_id) not in ev.evaluated_gt:
                bad("evaluation", m[0], f"the devkit scored no box of the object at frame {x}")
    lost.check_not_output(text, ctx.lost, ev, out, bad)
    lost.check_last_match(text, c, ctx.frame, ctx.gt_id, ev, out, bad)
    lost.check_two_tracks(text, c, ctx.frame, ctx.gt_id, scene, ev, out, bad)
    lost.check_averaged(text, ctx.track, ev, out, bad)
    if raw is None:  # a results file: where its boxes sit
        output.check_output(text, c, ctx.lost, scene, ev, out, bad, ctx.frame)
        return out
    started = [(int(m[2]), int(m[1]), int(m[3]), m[0]) for m in STARTED.finditer(text)]
    started += [(int(m[1]), int(m[3]), int(m[2]), m[0]) for m in STARTED_NEW.finditer(text)]
    for x, t, meas, sentence in started:
        out.checked["misleading"] += 1
        born = {
            (int(a), int(b)) for e in raw.of_kind(x, c, Born) for a, b in zip(e.track_ids, e.meas_indices, strict=True)
        }
        if (t, meas) not in born:
            bad(
                "misleading",
                sentence,
                f"no Born event of frame {x} starts track {t} from m{meas} (born: {sorted(born)})",
            )
    for m in GONE.finditer(text):
        x, meas, t = int(m[1]), int(m[2]), int(m[3])
        out.checked["gone"] += 1
        if not raw.gone(x, c, t):
            cost = raw.entry(x, c, meas, t)
            bad("gone", m[0], f"track {t} had a column at frame {x} (cost for m{meas}: {cost})")
    for m in COULD_NOT.finditer(text):
        x, meas, t = int(m[1]), int(m[2]), int(m[3])
        out.checked["gone"] += 1
        if not raw.could_not_take(x, c, meas, t):
            bad("gone", m[0], f"(m{meas}, track {t}) at frame {x}: cost {raw.entry(x, c, meas, t)}")
    for m in TEST_KIND.finditer(text):
        _check_test_kind(m, c, raw, out, bad)
    for b in BECAUSE.finditer(text):
        x, para = int(b[1]), b[2]
        for m in OUTSIDE.finditer(para):
            meas, t = int(m[1]), int(m[2])
            out.checked["gone"] += 1
            if t not in raw.columns(x, c):
                bad("gone", m[0], f"track {t} had no column at frame {x} (gone or deleted)")
            elif not raw.could_not_take(x, c, meas, t):
                bad("gone", m[0], f"(m{meas}, track {t}) cost {raw.entry(x, c, meas, t)}: inside")
        _check_counterfactuals(x, para, c, raw, out, bad)
    for m in CHOICE.finditer(text):
        _check_choice(m, c, raw, out, bad)
    for m in UNDERCUT.finditer(text):
        _check_undercut(m, c, raw, out, bad)
    _check_lead_and_no_object(text, ctx.frame, scene, out, bad, raw, c)
    if scene is not None:
        _check_used_no_object(text, scene, out, bad)
    shares.check_shares(text, c, ctx.lost, raw, out, bad)
    lost.check_lost(text, c, ctx.lost, raw, ev, out, bad)
    lost.check_used_away(text, c, ctx.lost, ctx.gt_id, scene, raw, out, bad)
    lost.check_gates(text, c, raw, out, bad)
    lost.check_stayed_below(text, c, raw, ev, out, bad)
    costs.check_costs(text, c, raw, scene, out, bad)
    hypotheses.check_hypotheses(text, c, raw, out, bad)
    return out


LEAD = re.compile(r"(then|the deciding choice was earlier), frame (\d+): (?:close call: )?m(\d+)\b")
"""A lost object's deciding choice as a Why introduces it: "then" reads as after the frames told before it (which
run up to the failure's frame), "earlier" as before the failure's frame."""
NO_OBJECT = re.compile(
    r"(?:track \d+ had been started at frame (\d+) by m(\d+)|\bm(\d+) at frame (\d+) was)"
    r"(,? a detection of (no object|part of \w+ GT (\w+)|(\w+(?:\.\w+)+ \w{6}) \())?"
)
"""A thief's starting detection, or a deciding detection said of no object: of no object exactly when no annotation
of a tracked class lies within 2 m of it (audit truth49, world5: a false bus that took a real bus's ID)."""


def _check_lead_and_no_object(
    text: str, frame: int, scene: SceneTruth | None, out: Tally, bad, raw: RawEvents | None = None, c: str = ""
) -> None:
    """The deciding choice's lead word against the failure's frame; "a detection of no object" (said, or left
    unsaid of a thief's start or a deciding detection) against the annotations within ``NEAR_M``; the track a
    deciding choice gave the detection to, started by a detection of no object (``raw``'s ``Born``), must say so or
    be said to have been a false track (audit truth50, world5 gnn id_switch:1)."""
    deciding = []
    for m in LEAD.finditer(text):
        x = int(m[2])
        out.checked["misleading"] += 1
        if (m[1] == "then") != (x >= frame):
            bad("misleading", m[0], f"the deciding choice is at frame {x}, the failure at frame {frame}")
        deciding.append((x, int(m[3]), m))
    if scene is None:
        return
    said = {}
    for m in NO_OBJECT.finditer(text):
        x, meas = (int(m[1]), int(m[2])) if m[1] is not None else (int(m[4]), int(m[3]))
        said[(x, meas)] = said.get((x, meas), False) or m[5] is not None
        between = text.startswith(" instead of", m.end())  # a track between the two (``_where_from``): not the thief
        if (m[1] is not None and not between) or m[5] is not None:
            _no_object(x, meas, m[5] is not None, m[0], scene, out, bad, m[7], m[8])
    for x, meas, m in deciding:
        if (x, meas) not in said:
            _no_object(x, meas, False, m[0], scene, out, bad)
        chosen = re.match(r" → \**track (\d+)", text[m.end() :])
        born = raw.birth(c, int(chosen[1])) if raw is not None and chosen is not None else None
        if born is None or born[0] >= x or not _of_nothing(scene, *born):
            continue
        t = chosen[1]
        out.checked["misleading"] += 1
        if (
            f"track {t} had been started at frame {born[0]}" not in text
            and f"track {t} had been a false track" not in text
        ):
            bad("misleading", m[0], f"track {t} was started at frame {born[0]} by m{born[1]}, of no object: unsaid")


def _of_nothing(scene: SceneTruth, x: int, meas: int) -> bool:
    """Detection ``meas`` of frame ``x`` lies ``NEAR_M`` or more from every annotated object and inside none's box
    (an annotation of an untracked category counts: a box on an ambulance is the ambulance's)."""
    if x >= len(scene.detections) or meas >= len(scene.detections[x]):
        return False
    xy = scene.detections[x][meas].xy_m
    far = all(math.dist(a.xy_m, xy) >= NEAR_M for a in scene.objects[x].values())
    return far and not scene.inside(x, xy) and not scene.untracked_on(x, xy)  # truth52: an ambulance's box


USED_NOTHING = re.compile(
    r"((?:m\d+ \(frames? [\d–, ]*\d\)(?:, | and )?)+) (?:was a detection|were detections) of no object"
)
"""The detections a lost track's soft updates used that were of no object (audit truth50, world5)."""
SOFT_USE = re.compile(
    r"at frame (\d+) it (?:used (m\d+(?: \([^)]*\))?(?:, m\d+(?: \([^)]*\))?)?)|took \d+ % of its weight from (m\d+))"
)


def _check_used_no_object(text: str, scene: SceneTruth, out: Tally, bad) -> None:
    """Each detection said of no object among a soft update's, against the annotations; each a soft update used
    that was of no object (``_of_nothing``) and not said so: misleading (the false bus's detection read as a sight
    of the bus)."""
    said = set()
    for m in USED_NOTHING.finditer(text):
        for item in re.finditer(r"m(\d+) \((frames? [\d–, ]*\d)\)", m[1]):
            for x in frames_of(item[2]):
                said.add((x, int(item[1])))
                _no_object(x, int(item[1]), True, m[0], scene, out, bad)
    for m in SOFT_USE.finditer(text):
        x = int(m[1])
        for meas in (int(k) for k in re.findall(r"m(\d+)", m[2] or m[3])):
            if _of_nothing(scene, x, meas):
                out.checked["misleading"] += 1
                if (x, meas) not in said:
                    bad("misleading", m[0], f"m{meas} at frame {x} is a detection of no object: unsaid")


def _no_object(
    x: int,
    meas: int,
    said: bool,
    sentence: str,
    scene: SceneTruth,
    out: Tally,
    bad,
    part: str | None = None,
    untracked: str | None = None,
) -> None:
    """``said``: "a detection of no object", of ``part`` of an object (its short id) or of an ``untracked``
    category's annotation ("category id") was said of ``meas``."""
    if x >= len(scene.detections) or meas >= len(scene.detections[x]):
        return
    out.checked["detector"] += 1
    xy = scene.detections[x][meas].xy_m
    near = min((math.dist(a.xy_m, xy) for a in scene.objects[x].values()), default=math.inf)
    if said and near < NEAR_M:
        bad("detector", sentence, f"m{meas} at frame {x} lies {near:.2f} m from an annotated object")
    elif not said and near >= NEAR_M:
        bad("misleading", sentence, f"m{meas} at frame {x} lies {near:.2f} m from every annotated object: unsaid")
    elif said:
        tail = f"part of GT {part}" if part is not None else f"{untracked} (" if untracked is not None else ""
        _part_of(tail, xy, x, sentence, scene, out, bad)


def _part_of(tail: str, xy, frame: int, sentence: str, scene: SceneTruth, out: Tally, bad) -> None:
    """A point said to lie within 2 m of no object, ``tail`` the text after it: misleading where it lies inside an
    annotated object's box and ``tail`` does not start by saying so; wrong where it names an object whose box does
    not contain it."""
    inside = scene.inside(frame, tuple(xy))
    said = re.match(r"(?:, but (?:the detection|the box) lies on |, a detection of )?part of (\w+ )?GT (\w+)", tail)
    out.checked["misleading"] += 1
    if said is None and inside:
        bad("misleading", sentence, f"inside the box of {[k[:6] for k in inside]} at frame {frame}: unsaid")
    elif said is not None and not any(k.startswith(said[2]) for k in inside):
        bad("detector", sentence, f"not inside GT {said[2]}'s box at frame {frame} (inside {[k[:6] for k in inside]})")
    if inside:
        return
    on = scene.untracked_on(frame, tuple(xy))  # audit truth52 (world8): a car box on an ambulance
    named = re.match(r"(?:, but (?:the detection|the box) lies on |, a detection of )?(\w+(?:\.\w+)+ \w{6}) \(", tail)
    out.checked["misleading"] += 1
    if named is None and on:
        bad("misleading", sentence, f"on {on} at frame {frame} (a category the evaluation does not track): unsaid")
    elif named is not None and named[1] not in on:
        bad("detector", sentence, f"not on {named[1]} at frame {frame} (on {on})")


DRIFTED = re.compile(
    r"(?: of it)?: the track's (?:predicted )?box lies ([\d.]+) m from (\w+) GT (\w+), which it was last within 2 m "
    r"of at frame (\d+)(; the evaluation has no box for that one here \((it had no LiDAR or radar points)?[^()]*\)|"
    r"; that one is beyond the evaluation's \d+ m range here, so it has no box for it)?"
)
"""A false track's box that ran off the object of its class it had been on (``FalseOutput.drifted_from``)."""
DRIFTED_HERE = re.compile(
    r"(?: of it)?: the box the evaluation interpolated lies ([\d.]+) m from (\w+) GT (\w+), though the track's own "
    r"box here, the one the evaluation dropped, lay within 2 m of it()"
    r"(; the evaluation has no box for that one here \((it had no LiDAR or radar points)?[^()]*\)|"
    r"; that one is beyond the evaluation's \d+ m range here, so it has no box for it)?"
)
"""The same, where the evaluation dropped the track's own box on the object at the failure frame (beyond the class
range) and the box it interpolated in its place lies off it (audit truth53, world9)."""
DRIFT_LOOKBACK = 8
"""Frames before a false track's failure in which its box within 2 m of an object of its class counts as having
been on that object (a finding's window, ``why.findings.FRAMES_BEFORE``)."""
DRIFT_NEAR_M = 6.5
"""How far off that object the box may now lie for the drift to be worth saying (``why.findings.OFF_NEAR_M``)."""


def _track_xy(ev: EvalFacts, frame: int, track: int | None) -> tuple[float, float] | None:
    return next((xy for t, _, xy in ev.boxes.get(frame, []) if t == str(track)), None)


DROPPED = re.compile(
    r"track (\d+) was output on it, but its box (?:there lies ([\d.]+) m from the ego vehicle, beyond the "
    r"evaluation's ([\d.]+) m range|there lies in a bike rack|(lies beyond the evaluation's range for the class"
    r"( \(or in a bike rack\))?)): the evaluation dropped that box"
)
LAY_BEYOND = re.compile(
    r"at frame (\d+) track (\d+)[^;]*? but its box lay ([\d.]+) m from the ego vehicle, beyond the evaluation's "
    r"(\d+) m range"
)
"""A box the devkit dropped beyond the class range, said of a false track, a coalescence or a lost track (the
devkit's own distance of the track's box there, at or beyond the range)."""


def check_dropped(text: str, ctx: Context, ev: EvalFacts, out: Tally, bad) -> None:
    """ "track T was output on it, but its box there ...: the evaluation dropped that box": the devkit's filter
    dropped T's box at the frame, for the reason said: at or beyond the class range at the devkit's own ego
    distance of that box, else a bike rack. The old hedge ("beyond the evaluation's range for the class (or in a
    bike rack)") is misleading: the reason is known, and the object's own distance said after it could lie on
    the other side of the range (dev set scene-0757 pointpillars pmbm, frame 37: the motorcycle 39.8 m away,
    inside its 40 m range, the track's box 40.1 m, beyond it)."""
    for m in DROPPED.finditer(text):
        out.checked["evaluation"] += 1
        track = m[1]
        d = ev.pred_ego_m.get((ctx.frame, track))
        if d is None or ctx.frame in ev.kept_frames.get(track, ()):
            bad("evaluation", m[0], f"the devkit kept track {track}'s box at frame {ctx.frame} (or it has none)")
            continue
        r = detector.RANGE_M[ctx.class_name]
        if m[5] is not None:  # the old hedge (audit truth53, world9: of a car's box too, a filter never applied to it)
            bad("misleading", m[0], f"its box lies {d:.2f} m from the ego vehicle, the range is {r:g} m: say which")
        elif m[4] is not None and d < r:
            bad("evaluation", m[0], f"its box lies {d:.2f} m from the ego vehicle, inside the {r:g} m range")
        elif m[2] is not None and (abs(float(m[2]) - d) > 0.05 + 1e-9 or float(m[3]) != r or d < r):
            bad("evaluation", m[0], f"the devkit's ego distance of the box is {d:.2f} m; the range is {r:g} m")
        elif m[2] is None and m[4] is None and d >= r:
            bad("evaluation", m[0], f"the box lies {d:.2f} m from the ego vehicle, beyond the {r:g} m range")
    for m in LAY_BEYOND.finditer(text):
        out.checked["evaluation"] += 1
        x, track, said = int(m[1]), m[2], float(m[3])
        d, r = ev.pred_ego_m.get((x, track)), detector.RANGE_M[ctx.class_name]
        if d is None or x in ev.kept_frames.get(track, ()) or d < r or float(m[4]) != r or abs(said - d) > 0.05 + 1e-9:
            bad("evaluation", m[0], f"the devkit's ego distance of track {track}'s box at frame {x}: {d}, range {r:g}")


def _check_drifted(tail: str, ctx: Context, xy, scene: SceneTruth, ev: EvalFacts, out: Tally, bad) -> None:
    """After "no object of a tracked class lies within 2 m" of a false track's box (``tail``: the text after it):
    where the submission has the track's box within 2 m of an object of its class at an earlier frame of the
    window, and that object lies less than 6.5 m from the box now, unsaid is misleading ("a box where no tracked
    object was" of a track that followed a bicycle with no sensor points and ran 2.1 m past it: dev set scene-0916
    centerpoint gnnpmb false_track:14); said, the distance, the object and the frame must be the submission's."""
    said = DRIFTED.match(tail) or DRIFTED_HERE.match(tail)
    last: tuple[int, str] | None = None
    # the track's own box at the failure frame counts where the devkit dropped it (audit truth53, world9); unsaid is
    # judged over the window, a said frame against every earlier frame (dev set scene-1077 pointpillars immortal
    # false_track:33 at frame 35: track 90's box 1.84 m from car a1a72a at frame 26, nine frames back, is true)
    dropped_here = ctx.frame not in ev.kept_frames.get(str(ctx.track), (ctx.frame,))
    oldest = -1 if said is not None else max(-1, ctx.frame - 1 - DRIFT_LOOKBACK)
    for y in range(ctx.frame - (0 if dropped_here else 1), oldest, -1):
        at = _track_xy(ev, y, ctx.track)
        mine = [
            (math.dist(a.xy_m, at), k)
            for k, a in (scene.objects[y].items() if at is not None and y < len(scene.objects) else ())
            if a.class_name == ctx.class_name
        ]
        if mine and min(mine)[0] < NEAR_M:
            last = (y, min(mine)[1])
            break
    now = scene.objects[ctx.frame].get(last[1]) if last is not None and ctx.frame < len(scene.objects) else None
    out.checked["misleading"] += 1
    if said is None:
        # a box on no detection: the predicted one's words, or an interpolated one's (" of it" and the clause's end)
        on_nothing = tail.startswith(": the tracker output a box where") or re.match(r" of it(;|$)", tail)
        if on_nothing and now is not None and math.dist(now.xy_m, xy) < DRIFT_NEAR_M:
            bad(
                "misleading",
                tail[:80],
                f"track {ctx.track} was within 2 m of GT {last[1][:6]} at frame {last[0]}, "
                f"{math.dist(now.xy_m, xy):.1f} m from its box now: unsaid",
            )
        return
    d, cls, gt, frame = float(said[1]), said[2], said[3], int(said[4] or ctx.frame)
    if last is None or not last[1].startswith(gt) or last[0] != frame or cls != ctx.class_name or now is None:
        bad("detector", said[0], f"the track's box was last within 2 m of an object of its class at {last}")
    elif abs(math.dist(now.xy_m, xy) - d) > 0.05 + 1e-9:
        bad("detector", said[0], f"the box lies {math.dist(now.xy_m, xy):.2f} m from GT {gt}")
    elif said[5] is not None and (ctx.frame, last[1]) in ev.evaluated_gt:  # "no box" of a box the devkit scored
        bad("evaluation", said[0], f"the devkit scored a box of GT {gt} at frame {ctx.frame}")
    elif said[6] is not None and now.points > 0:
        bad("detector", said[0], f"GT {gt} has {now.points} LiDAR and radar points at frame {ctx.frame}")


TWO_ON_ONE = re.compile(
    r"(\w+) GT (\w+) lies [\d.]+ m away and the evaluation matched it to another track(?: \(track \d+\))?: two "
    r"tracks on one object(?:; the detector gave it (?:two|\d+) \w+ detections within 2 m \(((?:m\d+(?:, )?)+)\))?"
)
"""A false track beside the object's matched one, and the detections of its class the detector gave the object."""


def _check_twins(text: str, frame: int, scene: SceneTruth, received: set[int] | None, out: Tally, bad) -> None:
    """ "Two tracks on one object": where the detector gave the object two or more detections of its class within
    2 m that the tracker received (``received``; None: any), each nearer it than any other annotated object (a
    detector without NMS, audit truth50 world6), unsaid is misleading (the tracker's doing alone); said, the
    named detections must be exactly those."""
    for m in TWO_ON_ONE.finditer(text):
        hit = scene.object_of(frame, m[2])
        if hit is None:
            continue
        out.checked["misleading"] += 1
        own = [j for j in scene.near(frame, hit[1].xy_m, m[1]) if scene.owner(frame, j, hit[1].xy_m) is None]
        own = [j for j in own if received is None or j in received]
        own = [j for j in own if scene.untracked_owner(frame, j, hit[1].xy_m) is None]  # truth52: a stroller's
        said = [int(x) for x in re.findall(r"m(\d+)", m[3] or "")]
        if len(own) >= 2 and not said:
            bad("misleading", m[0], f"the detector gave GT {m[2]} {len(own)} {m[1]} detections of its own: unsaid")
        elif said and sorted(said) != sorted(own):
            bad("detector", m[0], f"its own {m[1]} detections within 2 m at frame {frame}: {own}")


def _patterns() -> list[re.Pattern]:
    """Every pattern a checker reads a sentence with, each once; not ``BECAUSE``, which only cuts a paragraph out
    (it matches the whole paragraph, so counting it, or a module's import of it, would read every clause)."""
    mods = (detector, otherruns, shares, lost, place, costs, hypotheses, output)
    found = [v for v in globals().values() if isinstance(v, re.Pattern)]
    found += [v for mod in mods for v in vars(mod).values() if isinstance(v, re.Pattern)]
    return list({id(p): p for p in found if p is not BECAUSE}.values())


def clause_kind(clause: str) -> str:
    """A clause with its numbers, ids and class names blanked, cut to its first words: what kind of sentence."""
    text = re.sub(r"\b[0-9a-f]{6}\b", "H", clause)
    text = re.sub(r"\d+(\.\d+)?", "N", text)
    text = re.sub(r"\b(car|truck|bus|trailer|bicycle|motorcycle|pedestrian)\b", "C", text)
    return " ".join(text.split()[:7])


def coverage(text: str) -> tuple[int, Counter]:
    """(clauses, Counter of unchecked clause kinds): a Why paragraph's clauses are its "; " parts, a Because
    paragraph's its sentences; a clause is checked when a checker pattern's match overlaps it."""
    spans = [m.span() for p in _patterns() for m in p.finditer(text)]
    clauses: list[tuple[int, int]] = []
    for line in re.finditer(r"[^\n]+", text):
        head = line[0].find("): ")
        start = line.start() + (head + 3 if head >= 0 else 0)
        sep = r"; " if line[0].startswith("Why") else r"\. (?=[A-Z])"
        for part in re.finditer(rf"(?:(?!{sep}).)+", text[start : line.end()]):
            if part[0].strip(" ."):
                clauses.append((start + part.start(), start + part.end()))
    unchecked = Counter(clause_kind(text[a:b]) for a, b in clauses if not any(s < b and e > a for s, e in spans))
    return len(clauses), unchecked


def _neighbours(ev: EvalFacts, scene: SceneTruth | None, ctx: Context, other: str, box) -> bool:
    """Whether the object ``other`` the devkit matched a track (box ``box``) to was scored nearer the track than the
    finding's object is annotated: the track was that object's, and one track for two objects holds however far the
    devkit's box of this one lay (with it where it belongs the devkit would still match the track there)."""
    a = scene.objects[ctx.frame].get(ctx.gt_id or "") if scene is not None and ctx.frame < len(scene.objects) else None
    at = ev.evaluated_gt.get((ctx.frame, other))
    return a is not None and at is not None and math.dist(box, at) < math.dist(box, a.xy_m)


def _check_eval(text: str, ctx: Context, ev: EvalFacts, out: Tally, bad, scene: SceneTruth | None = None) -> None:
    c = ctx.class_name
    for m in THEFT.finditer(text):
        taker, victim = m[1], m[3]
        out.checked["matched"] += 1
        wrong = [x for x in ctx.false_frames if ev.matched_track(c, x, ctx.gt_id or "") != victim]
        if wrong:
            got = {x: ev.matched_track(c, x, ctx.gt_id or "") for x in wrong}
            bad("matched", m[0], f"the devkit matched the object at those frames to {got}")
        stolen = [x for x in ctx.false_frames if ev.matched_gt(c, x, taker) is not None]
        if stolen:
            bad("matched", m[0], f"track {taker} was matched at frames {stolen}")
    for m in COVERED.finditer(text):
        for t in (s.strip() for s in m[1].split(",")):
            out.checked["matched"] += 1
            got = ev.matched_gt(c, ctx.frame, t)
            scored = ev.evaluated_gt.get((ctx.frame, ctx.gt_id or ""))
            box = ev.pred_xy.get((c, ctx.frame), {}).get(t)
            if got is None or got == ctx.gt_id:
                bad("matched", m[0], f"the devkit matched track {t} at frame {ctx.frame} to {got}")
            elif (
                scored is not None
                and box is not None
                and math.dist(scored, box) >= 2.0
                and not _neighbours(ev, scene, ctx, got, box)
            ):
                bad(
                    "misleading",
                    m[0],
                    f"the devkit scored the object {math.dist(scored, box):.2f} m from track {t}'s box: out of its "
                    "reach, so its match elsewhere did not take this object from it",
                )
    for m in COALESCED.finditer(text):
        x, t = int(m[1]), m[2]
        if m[3] is not None:  # the box matched is one the devkit interpolated: the track's own was not kept there
            out.checked["matched"] += 1
            output = t in ev.submitted.get(x, set())
            if x in ev.kept_frames.get(t, ()) or output != m[3].startswith("was output"):
                bad("matched", m[0], f"track {t} at frame {x}: submitted {output}, kept by the devkit's filters")
        for g in ctx.covered:
            out.checked["matched"] += 1
            got = ev.matched_track(c, x, g)
            if got != t:
                bad("matched", m[0], f"the devkit matched GT {g[:6]} at frame {x} to {got}")
    if scene is not None:
        _check_also_near(text, c, ev, scene, out, bad)
    for m in MATCHED_INSTEAD.finditer(text):
        out.checked["matched"] += 1
        got = ev.matched_track(c, ctx.frame, ctx.gt_id or "")
        if got != m[1]:
            bad("matched", m[0], f"the devkit matched the object at frame {ctx.frame} to {got}")
    for m in NOT_COUNTED.finditer(text):
        out.checked["matched"] += 1
        if m[1] in ev.counted.get(c, set()):
            bad("matched", m[0], f"track {m[1]} passes the {c} threshold {ev.thresholds.get(c)}")


def _check_also_near(text: str, c: str, ev: EvalFacts, scene: SceneTruth, out: Tally, bad) -> None:
    """``ALSO_NEAR``: the object matched to no track at the frame, the named tracks and no other left unsaid."""
    for m in ALSO_NEAR.finditer(text):
        x, t = int(m[1]), m[2]
        hit = scene.object_of(x, m[3])
        if hit is None:
            continue
        gt_id, a = hit
        out.checked["matched"] += 1
        if ev.matched_track(c, x, gt_id) is not None:
            bad("matched", m[0], f"the devkit matched GT {m[3]} at frame {x} to track {ev.matched_track(c, x, gt_id)}")
        near = {
            k: math.dist(xy, a.xy_m)
            for k, cls, xy in ev.boxes.get(x, [])
            if cls == c and k != t and k in ev.counted.get(c, set()) and math.dist(xy, a.xy_m) < NEAR_M
        }
        near = {k: d for k, d in near.items() if (g := ev.matched_gt(c, x, k)) is not None and g != gt_id}
        said = {i[1]: i for i in ALSO_ITEM.finditer(m[4] or "")}
        for k, i in said.items():
            out.checked["matched"] += 1
            g = ev.matched_gt(c, x, k)
            if k not in near or f"{near[k]:.1f}" != i[2] or g is None or not g.startswith(i[3]):
                bad("matched", i[0], f"counted tracks within 2 m matched elsewhere: {near}; track {k} matched to {g}")
        out.checked["misleading"] += 1
        if set(near) - set(said):
            unsaid = {k: f"{d:.2f} m, matched to {(ev.matched_gt(c, x, k) or '')[:6]}" for k, d in near.items()}
            bad("misleading", m[0], f"counted tracks within 2 m of GT {m[3]} left unsaid: {unsaid}")


def _place(ctx: Context, ev: EvalFacts, scene: SceneTruth | None) -> tuple[float, float] | None:
    """Where a finding is: its object's annotation, else its false track's box as the accumulator scored it (an
    interpolation where the devkit made one), else as the submission has it."""
    if ctx.gt_id is not None:
        a = scene.objects[ctx.frame].get(ctx.gt_id) if scene is not None and ctx.frame < len(scene.objects) else None
        return a.xy_m if a is not None else None
    if ctx.track is None:
        return None
    scored = ev.pred_xy.get((ctx.class_name, ctx.frame), {}).get(str(ctx.track))
    if scored is not None:
        return scored
    return next((xy for t, _, xy in ev.boxes.get(ctx.frame, []) if t == str(ctx.track)), None)


def _check_on_it(text: str, ctx: Context, scene: SceneTruth, ev: EvalFacts, out: Tally, bad) -> None:
    """ "track T was (not) output on it (score S)" at the finding's frame: T's box in the submission within 2 m of
    the object's annotation, with that score."""
    a = scene.objects[ctx.frame].get(ctx.gt_id or "") if ctx.frame < len(scene.objects) else None
    if a is None:
        return
    near = {
        t
        for t, cls, xy in ev.boxes.get(ctx.frame, [])
        if cls == ctx.class_name and math.hypot(xy[0] - a.xy_m[0], xy[1] - a.xy_m[1]) < 2.0
    }
    for m in WENT_TO.finditer(text):  # a track not on the object, left unsaid, reads as covering it
        out.checked["misleading"] += 1
        if m[1] not in near and f"track {m[1]} was not output on it" not in text:
            bad("misleading", m[0], f"track {m[1]} has no box within 2 m of the object at frame {ctx.frame}, unsaid")
    for m in ON_IT.finditer(text):
        out.checked["output"] += 1
        if (m[1] in near) == bool(m[2]):
            bad("output", m[0], f"the submission's {ctx.class_name} boxes within 2 m at frame {ctx.frame}: {near}")
        elif m[3] is not None and abs(ev.scores.get((ctx.frame, m[1]), math.nan) - float(m[3])) > 0.005 + 1e-9:
            bad("output", m[0], f"its box's score is {ev.scores.get((ctx.frame, m[1]))}")


def _check_counterfactuals(x: int, para: str, c: str, raw: RawEvents, out: Tally, bad) -> None:
    found = raw.deciding(x, c)

    def setup(meas: int, t: int):
        if found is None:
            return None
        mat, a = found
        row, col = replay.row_of(mat, meas), replay.track_col(mat, t)
        return None if row is None or col is None else (mat, a, row, col)

    def verdict(sentence: str, holds: bool | None, truth: str) -> None:
        out.checked["counterfactual"] += 1
        out.replays += 1
        if not holds:
            out.refuted += 1
            bad("counterfactual", sentence, truth)

    def stated_against(pattern: re.Pattern) -> Iterator[tuple[re.Match, float, float, int, int, CostMatrix, int, int]]:
        """Each sentence "… VALUE (instead of NOW), track T would have taken mN" with the deciding matrix of
        (mN, track T) and their row and column; one without such a matrix is refuted here."""
        for m in pattern.finditer(para):
            value, now, t, meas = float(m[1]), float(m[2]), int(m[3]), int(m[4])
            s = setup(meas, t)
            if s is None:
                verdict(m[0], False, f"no matrix of frame {x} has m{meas} and track {t}")
            else:
                yield m, value, now, t, meas, s[0], s[2], s[3]

    for m, stated, now, t, meas, mat, row, col in stated_against(WITHIN):
        if stated >= now:
            verdict(m[0], False, f"the stated d² {stated} is not below the current {now}")
            continue
        verdict(
            m[0], replay.replay_d2(mat, row, col, stated), f"re-solved at d² {stated}, m{meas} does not go to track {t}"
        )
    for m, stated, now, t, meas, mat, row, col in stated_against(ABOVE):
        if stated <= now:
            verdict(m[0], False, f"the stated existence {stated} is not above the current {now}")
            continue
        holds = replay.replay_existence(mat, row, col, min(stated * (1 + replay.ABOVE), 1.0))
        verdict(m[0], holds, f"re-solved with existence just above {stated}, m{meas} does not go to track {t}")
    extremes = (  # "mN would not have gone to track T even with …": re-solved at that extreme, it still does not
        (NO_EXISTENCE, lambda mat, row, col: replay.replay_existence(mat, row, col, 1.0 - 1e-9), "with existence 1"),
        (EVEN_AT_ZERO, lambda mat, row, col: replay.replay_d2(mat, row, col, 0.0), "at d² 0"),
    )
    for pattern, replayed, extreme in extremes:
        for m in pattern.finditer(para):
            meas, t = int(m[1]), int(m[2])
            if (s := setup(meas, t)) is not None:
                mat, _, row, col = s
                verdict(m[0], replayed(mat, row, col) is False, f"{extreme}, m{meas} goes to track {t}")
    for m in RIVAL_TAKEN.finditer(para):
        meas, t, k = int(m[1]), int(m[3]), int(m[4])
        if found is None:
            continue
        out.checked["counterfactual"] += 1
        other = [int(r.ref) for r, col in found[1].pairs if col.kind is AxisKind.TRACK and int(col.ref) == t]
        if other != [k]:
            bad("counterfactual", m[0], f"the assignment of frame {x} gave track {t} to {other}")
    for m in RIVAL.finditer(para):
        meas, t = int(m[1]), int(m[3])
        if found is None:
            continue
        mat, a = found
        out.checked["counterfactual"] += 1
        other = [int(r.ref) for r, col in a.pairs if col.kind is AxisKind.TRACK and int(col.ref) == t]
        if other and other[0] != meas:
            bad("counterfactual", m[0], f"the assignment of frame {x} gave track {t} to m{other[0]}")


def _check_choice(m: re.Match, c: str, raw: RawEvents, out: Tally, bad) -> None:
    x, meas, alt, took, printed, at_least = int(m[1]), int(m[2]), m[4], m[5], m[6], m[7] is not None
    found = raw.deciding(x, c)
    if found is None:
        return
    mat, a = found
    if took is not None:  # "over track U (...), which took mK": the assignment gave track U detection K
        t = int(alt.split()[1])
        out.checked["misleading"] += 1
        other = [int(r.ref) for r, k in a.pairs if k.kind is AxisKind.TRACK and int(k.ref) == t]
        if other != [int(took)]:
            bad("misleading", m[0], f"the assignment of frame {x} gave track {t} {other or 'no detection'}")
    row, col = replay.row_of(mat, meas), replay.chosen_col(mat, a, meas)
    if row is None or col is None:
        return
    if took is None and alt and alt.startswith("track ") and mat.scale.optimal:  # "over track U (cheaper), margin"
        t = int(alt.split()[1])
        other = [int(r.ref) for r, k in a.pairs if k.kind is AxisKind.TRACK and int(k.ref) == t]
        alt_col = replay.track_col(mat, t)
        out.checked["misleading"] += 1
        cost = np.asarray(mat.cost, dtype=float)
        if other and other[0] != meas and alt_col is not None and cost[row, alt_col] < cost[row, col]:
            bad("misleading", m[0], f"the cheaper track {t} took m{other[0]} in the same assignment: unsaid")
            return
    out.checked["misleading"] += 1
    if not mat.scale.optimal:
        if alt and alt.startswith("track "):
            t = int(alt.split()[1])
            other = [int(r.ref) for r, k in a.pairs if k.kind is AxisKind.TRACK and int(k.ref) == t]
            if other and other[0] != meas:
                bad("misleading", m[0], f"greedy: track {t} had been given m{other[0]}")
        return
    cheaper = _free_cheaper(mat, a, row, col)
    if cheaper is not None:  # the assignment is no optimum of this matrix: a margin measured on it says nothing
        bad("misleading", m[0], f"column {cheaper} was free and cheaper for m{meas} than the chosen one")
        return
    true = replay.margin(mat, row, col)
    if math.isnan(true):
        return
    shown = math.inf if printed == "inf" else float(printed)
    if at_least:  # "margin 5.00 or more"
        if true < shown - 0.006:
            bad("misleading", m[0], f"re-solved without the pair, the total rises by {true:.3f}")
        return
    if (math.isinf(true) and not math.isinf(shown)) or (math.isfinite(true) and abs(shown - true) > 0.006):
        bad("misleading", m[0], f"re-solved without the pair, the total rises by {true:.3f}")


def _used_cols(mat: CostMatrix, a) -> set[int]:
    return {k for r, _ in a.pairs if (k := replay.chosen_col(mat, a, int(r.ref))) is not None}


def _free_cheaper(mat: CostMatrix, a, row: int, col: int) -> int | None:
    """A column no detection took whose cost for ``row`` lies below the chosen ``col``'s (None: there is none)."""
    cost = np.asarray(mat.cost, dtype=float)
    used = _used_cols(mat, a)
    free = [k for k in range(cost.shape[1]) if k not in used and cost[row, k] < cost[row, col] - UNDERCUT_TOL]
    return free[0] if free else None


def _check_undercut(m: re.Match, c: str, raw: RawEvents, out: Tally, bad) -> None:
    """ "m11 → track 4 (...), not track 24 (...): the solver matched every pair before dropping those past the
    threshold, and gave track 24 to a detection whose pair it dropped": the matrix has a threshold and an optimal
    solver, track 24's column is free in the assignment and cheaper for m11 than the chosen one (the generic form:
    the assignment costs more than the matrix's optimum)."""
    x, meas, t = int(m[1]), int(m[2]), m[3]
    found = raw.deciding(x, c)
    if found is None:
        return
    mat, a = found
    row, col = replay.row_of(mat, meas), replay.chosen_col(mat, a, meas)
    if row is None or col is None:
        return
    out.checked["misleading"] += 1
    if not mat.scale.optimal or mat.scale.threshold is None:
        bad("misleading", m[0], "the matrix has no threshold dropped after an optimal solve")
        return
    if t is None:
        cost = np.asarray(mat.cost, dtype=float)
        chosen = sum(cost[replay.row_of(mat, int(r.ref)), replay.chosen_col(mat, a, int(r.ref))] for r, _ in a.pairs)
        _, best = solve(cost)
        if not chosen > best + UNDERCUT_TOL:
            bad("misleading", m[0], f"the assignment's total {chosen:.3f} is the matrix's optimum {best:.3f}")
        return
    k = replay.track_col(mat, int(t))
    if k is None or k in _used_cols(mat, a) or not mat.cost[row, k] < mat.cost[row, col] - UNDERCUT_TOL:
        bad("misleading", m[0], f"track {t}'s column at frame {x} is not a free one cheaper for m{meas}")


def _check_off_and_unannotated(text: str, gt_id: str, scene: SceneTruth, ev: EvalFacts, out: Tally, bad) -> None:
    """A lost track's "(output farther than 2 m from it at frames F)": the object was annotated at each of F and
    the submission's box of the track lay 2 m or more from the annotation; "(it was not annotated at frames G: ...)":
    the object had no annotation at any of G (world3: a track said far from an object that had no annotation there,
    which the devkit matched to its interpolated box)."""
    for m in OFF_AFTER.finditer(text):
        t, wrong = m[1] or m[2], {}
        if m[3]:
            out.checked["output"] += 1
        for x in frames_of(m[3]) if m[3] else ():
            a = scene.objects[x].get(gt_id) if x < len(scene.objects) else None
            box = next((xy for i, _, xy in ev.boxes.get(x, []) if i == t), None)
            if a is None or box is None or math.hypot(box[0] - a.xy_m[0], box[1] - a.xy_m[1]) < NEAR_M:
                wrong[x] = "no annotation" if a is None else "no box" if box is None else "within 2 m"
        if wrong:
            bad("output", m[0], f"track {t} by frame: {wrong}")
        if m[4]:
            out.checked["output"] += 1
            there = [x for x in frames_of(m[4]) if x < len(scene.objects) and gt_id in scene.objects[x]]
            if there:
                bad("output", m[0], f"the object was annotated at frames {there}")


def _output_on_after(scene: SceneTruth, ev: EvalFacts, t: str, gt_id: str, last: int, frame: int) -> list[int]:
    """The frames after ``last`` up to ``frame`` at which the submission's box of track ``t`` lay within 2 m of
    object ``gt_id``'s annotation ("last output on it at frame ``last``" is false there)."""
    later = []
    for x in range(last + 1, frame + 1):
        a = scene.objects[x].get(gt_id) if x < len(scene.objects) else None
        if a is None:
            continue
        if any(i == t and math.hypot(xy[0] - a.xy_m[0], xy[1] - a.xy_m[1]) < 2.0 for i, _, xy in ev.boxes.get(x, [])):
            later.append(x)
    return later


def check_choice_lines(text: str, c: str, raw: RawEvents | None, out: Tally, bad) -> None:
    """A focus document's key decisions and story close calls: each line's margin re-solved (as the Why's), its
    two values and a new-track column said as a threshold against the deciding matrix (``costs``)."""
    if raw is None:
        return
    for m in CHOICE.finditer(text):
        _check_choice(m, c, raw, out, bad)
    for m in UNDERCUT.finditer(text):
        _check_undercut(m, c, raw, out, bad)
    costs.check_thresholds(text, c, raw, out, bad)
    costs.check_choice_values(text, c, raw, out, bad)
