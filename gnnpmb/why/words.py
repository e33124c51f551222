"""Findings in words: the one place an explanation becomes text (the focus document, ``gnnpmb failures --why``).

Every sentence is rendered from a ``Finding`` (or a decision's ``PairChoice``) and never parsed back. Numbers are
printed as the finding holds them; what a tracker's numbers mean follows its ``facts.UseMode`` (an assignment, an
association probability, a PHD weight) and its cost's ``events.CostScale`` (nats, metres).
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Sequence

from gnnpmb.eval.evaluated import Dropped, DroppedBox, GtFrame, GtStatus, TrackEval
from gnnpmb.eval.failures import FailureKind, short_id
from gnnpmb.events import AxisKind, AxisLabel, CostScale, PairTerms
from gnnpmb.explain import LINK_SLACK, PairChoice
from gnnpmb.foreign import NEAREST_M, BoxOn, OnHow
from gnnpmb.why.counterfactual import WouldTake
from gnnpmb.why.facts import Destination, Ending, TrackStep, UseMode, Went
from gnnpmb.why.findings import (
    EVALUATED_OFFSET_M,
    NEAR_M,
    FalseOutput,
    Finding,
    KeyDecision,
    LostTrack,
    Near,
    OnObject,
    OtherRun,
    Rule,
    Sighting,
    covering,
)
from gnnpmb.why.untracked import is_untracked, untracked_text

SHOW_MIN_EXISTENCE = 0.5
"""Extracted tracks are drawn (and called shown) from this existence on: the submission may hold far less likely
Bernoullis (a low extraction threshold with score = detection score x existence helps AMOTA)."""


# Names.
def meas_name(ref: int) -> str:
    """How every view names detection ``ref`` (its source index): ``m<ref>``."""
    return f"m{int(ref)}"


OFF_BOX_M = 0.25
"""A false track's box this far or farther from the detection its update used is not said to be "on" it (a filtering
tracker's box lies between its prediction and the detection: dev set scene-0553 centerpoint prob3dmot, 0.9 m)."""


def column_name(label: AxisLabel) -> str:
    """``track 802``, ``new`` (start a track / clutter) or ``missed``."""
    match label.kind:
        case AxisKind.TRACK:
            return f"track {label.ref}"
        case AxisKind.NEW_TRACK:
            return "new"
        case AxisKind.MISSED:
            return f"missed {label.ref}"
        case AxisKind.MEASUREMENT:
            return meas_name(label.ref)
    raise AssertionError(label.kind)


def existence_text(r: float) -> str:
    """An existence probability with two decimals, or one significant digit below 0.01 (``0.004``, ``4e-05``),
    so a small but non-zero existence does not read as 0.00."""
    return f"{r:.2f}" if r >= 0.01 or r == 0 else f"{r:.1g}"


def consecutive_runs(numbers: Iterable[int]) -> list[list[int]]:
    """``numbers`` in their order, cut where one is not the one before plus 1: [3, 4, 5, 9] -> [[3, 4, 5], [9]]."""
    runs: list[list[int]] = []
    for n in numbers:
        if runs and n == runs[-1][-1] + 1:
            runs[-1].append(n)
        else:
            runs.append([n])
    return runs


def frames_text(frames: Iterable[int]) -> str:
    """``frame 7``, ``frames 7, 13``, ``frames 12–14`` (consecutive runs joined)."""
    fs = sorted(set(frames))
    parts = [f"{r[0]}–{r[-1]}" if len(r) > 2 else ", ".join(map(str, r)) for r in consecutive_runs(fs)]
    return f"frame{'s' if len(fs) > 1 else ''} {', '.join(parts)}"


def plural(n: int, word: str) -> str:
    return f"{n} {word}{'s' if n != 1 else ''}"


def _span(values: Sequence[float]) -> str:
    lo, hi = min(values), max(values)
    return f"{lo:,.0f}" if lo == hi else f"{lo:,.0f}–{hi:,.0f}"


# Costs.
def hundredths_summing_to(values: list[float], total: float) -> list[float]:
    """``values`` rounded to hundredths so that they add up to ``total`` rounded to hundredths (largest
    remainder: each is rounded down, then the ones with the largest remainders get a hundredth more), so a
    reader adding the parts finds the total shown beside them."""
    scaled = [100.0 * v for v in values]
    down = [math.floor(x) for x in scaled]
    missing = round(100.0 * total) - sum(down)
    order = sorted(range(len(values)), key=lambda k: scaled[k] - down[k], reverse=True)
    for k in order[: max(0, min(missing, len(values)))]:
        down[k] += 1
    return [d / 100.0 for d in down]


def cost_breakdown(terms: PairTerms, meas: str) -> str:
    """A track's cost for detection ``meas`` in words: the nats its predicted existence, the uncertainty of its
    predicted position, the distance and the detection's score add, and the constant the tracker adds to every
    pair (``events.PairTerms``; the parts a tracker's cost does not have are left out)."""
    parts: list[tuple[float, str]] = []
    if terms.offset_text or terms.offset_nats:  # an unnamed constant is still a part: the parts add up to the cost
        parts.append((terms.offset_nats, f"for {terms.offset_text or 'a constant every pair of the matrix shares'}"))
    if terms.existence is not None:
        parts.append((terms.existence_nats, f"for its predicted existence {existence_text(terms.existence)}"))
    parts.append((terms.spread_nats, f"for the uncertainty of its predicted position (±{terms.spread_m:.1f} m)"))
    parts.append((terms.distance_nats, f"for the distance to {meas} (d² {terms.d2:.1f})"))
    if terms.score is not None:
        parts.append((terms.score_nats, f"for {meas}'s score {terms.score:.2f}"))
    if terms.box_nats:
        parts.append((terms.box_nats, f"for {meas}'s heading and size against its last box"))
    shown = hundredths_summing_to([v for v, _ in parts], terms.total_nats)
    return " + ".join(f"{v:.2f} {text}" for v, (_, text) in zip(shown, parts, strict=True))


def cost_brief(terms: PairTerms | None) -> str:
    """What a track's cost depended on, briefly: ``existence 0.62, ±1.2 m, d² 0.3`` ("" without terms)."""
    if terms is None:
        return ""
    existence = f"existence {existence_text(terms.existence)}, " if terms.existence is not None else ""
    return f"{existence}±{terms.spread_m:.1f} m, d² {terms.d2:.1f}"


def _brief(terms: PairTerms | None) -> str:
    return f" at {cost_brief(terms)}" if terms is not None else ""


def hits_text(hits: int, window: int) -> str:
    """A track-logic count: ``2 of 3 hits``, or ``no hit in its last 2 frames`` (a deletion by misses)."""
    return f"no hit in its last {window} frames" if hits == 0 else f"{hits} of {window} hits"


def cost_value(value: float, choice: PairChoice) -> str:
    """A cost in the tracker's own terms: ``6.76`` (nats), ``1.20 m``, or for a cost that is 1 - a similarity
    ``GIoU -0.21``."""
    scale = choice.scale
    if scale.similarity is not None:
        return f"{scale.similarity} {1.0 - value:.2f}"
    return f"{value:.2f}" if scale.unit == "nats" else f"{value:.2f} {scale.unit}"


def margin_value(value: float, choice: PairChoice) -> str:
    """A margin (a difference of costs) in the tracker's own terms: ``0.31`` (nats), ``0.20 m``, ``0.29 of
    GIoU``."""
    scale = choice.scale
    more = " or more" if math.isfinite(value) and value >= LINK_SLACK else ""  # ``explain`` caps margins there
    if scale.similarity is not None:
        return f"{value:.2f}{more} of {scale.similarity}"
    return f"{value:.2f}{more}" if scale.unit == "nats" else f"{value:.2f} {scale.unit}{more}"


def destination_text(went: int, born: bool, chosen: AxisLabel | None = None) -> str:
    """``new track 212``, ``track 26``, ``new`` (started nothing with an id, or clutter)."""
    if went < 0:
        return "new" if chosen is None else column_name(chosen)
    return f"new track {went}" if born else f"track {went}"


def choice_why(c: PairChoice, went: str | None = None, would: WouldTake | None = None) -> str | None:
    """Why a detection went to its chosen column rather than the track that was its next best: both costs, each
    track's taken apart (when the tracker's matrix says what they are made of), and, with ``would`` (the matrix
    re-solved, ``counterfactual``), what would have given that track the detection. went: how to name the chosen
    column ("new track 212"; default ``column_name``). None when the next best is not a track or its terms are
    unknown. When the assignment gave the next best another detection, the lower cost did not decide alone: the
    sentence says whose it was and that the lower total wins."""
    alt = c.alternative_terms
    if alt is None or c.alternative is None:
        return None
    meas = meas_name(c.meas.ref)
    other = column_name(c.alternative)
    if c.chosen.kind is AxisKind.NEW_TRACK:
        chosen = went if went and went.startswith("new track ") else "a new track"
    else:
        chosen = went or column_name(c.chosen)
    taken_by = would.taken_by if would is not None else None
    if taken_by is not None:
        head = (
            f"{meas} went to {chosen} (cost {c.chosen_cost:.2f}); {other} (cost {c.alternative_cost:.2f}) went to "
            f"{meas_name(taken_by)}: the lower total of the assignment wins"
        )
    else:
        head = f"{meas} went to {chosen} (cost {c.chosen_cost:.2f}) rather than {other} (cost {c.alternative_cost:.2f})"
        if would is not None:  # re-solved: the next best was free, so the lower cost decided
            head += ": the lower cost wins"
    lines = [head]
    if c.chosen_terms is not None:
        lines.append(
            f"{column_name(c.chosen).capitalize()}'s {c.chosen_cost:.2f} = {cost_breakdown(c.chosen_terms, meas)}"
        )
    lines.append(f"{other.capitalize()}'s {c.alternative_cost:.2f} = {cost_breakdown(alt, meas)}")
    if would is not None:
        lines.append(_would_have(would, other, meas))
    return ". ".join(lines)


def track_why(c: PairChoice, track_id: int, role: str = "", would: WouldTake | None = None) -> str | None:
    """What track ``track_id`` (neither the chosen nor the next best column of ``c``; ``role``: words after its
    name, e.g. ", which had the object,") would have cost for c's detection, taken apart, and (with ``would``)
    what would have given it the detection; None when the matrix does not say or has no such track."""
    if c.terms is None or c.row < 0:
        return None
    col = c.terms.column_of(track_id)
    if col is None:
        return None
    t = c.terms.pair(c.row, col)
    meas, name = meas_name(c.meas.ref), f"track {track_id}"
    cost = f"Track {track_id}{role} would have cost {t.total_nats:.2f} = {cost_breakdown(t, meas)}"
    return cost if would is None else f"{cost}. {_would_have(would, name, meas)}"


def _would_have(w: WouldTake, name: str, meas: str) -> str:
    """What re-solving the matrix says would have given ``meas`` to track ``name``: a predicted existence (PMB
    family) or a distance (GNN), on the safe side of the break-even (``counterfactual``)."""
    if w.kind == "existence":
        if w.needed is None:
            return f"No predicted existence would have given {meas} to {name}"
        needed, now = (
            (existence_text(w.needed), existence_text(w.now))
            if w.digits == 2
            else (f"{w.needed:.{w.digits}f}", f"{w.now:.{w.digits}f}")
        )
        return f"With a predicted existence above {needed} (instead of {now}), {name} would have taken {meas}"
    if w.needed is None:
        return f"Even with {meas} right on its prediction (d² 0), {name} would not have taken it"
    return f"Within d² {w.needed:.{w.digits}f} (instead of {w.now:.{w.digits}f}), {name} would have taken {meas}"


def choice_text(frame: int, c: PairChoice, went: int, born: bool, alternative_took: int | None = None) -> str:
    """One solver choice: ``frame 19: m2 (score 0.75) → **new track 315** (cost 6.75) over track 61 (7.06 at
    existence 0.05, ±2.6 m, d² 0.1), margin 0.31`` (costs on the tracker's scale); with ``alternative_took``,
    the detection the next best took in the same assignment: ``over track 20 (8.68 ...), which took m6 (the lower
    total wins), margin 2.01``."""
    other = "(no other)"
    if c.undercut:
        other = undercut_text(c, alternative_took)
    elif c.alternative is not None and (held := threshold_held(c.alternative, c.alternative_cost, c)) is not None:
        other = f"over a new track ({held})"
    elif c.alternative is not None:
        other = f"over {column_name(c.alternative)} ({cost_value(c.alternative_cost, c)}{_brief(c.alternative_terms)})"
        if alternative_took is not None:
            other += f", which took {meas_name(alternative_took)} (the lower total wins)"
    terms = c.chosen_terms or c.alternative_terms
    score = f" (score {terms.score:.2f})" if terms is not None and terms.score is not None else ""
    chosen = threshold_held(c.chosen, c.chosen_cost, c) or cost_named(c.chosen_cost, c)
    tail = f", {other}" if c.undercut else f" {other}, margin {margin_value(c.margin, c)}"
    went_to = destination_text(went, born, c.chosen)
    return f"frame {frame}: {meas_name(c.meas.ref)}{score} → **{went_to}** ({chosen}){tail}"


def undercut_text(c: PairChoice, alternative_took: int | None = None) -> str:
    """What an undercut choice (``explain``: the solver ran over every pair before its threshold dropped the
    pairs past it) passed over: ``not track 24 (GIoU -0.41): the solver matched every pair before dropping
    those past the GIoU threshold -0.50, and gave track 24 to a detection whose pair it dropped``. A free track
    column cheaper than the chosen one is left only so: an optimal solve would otherwise have taken it (dev set
    scene-0916 pointpillars simpletrack, frame 10, m11)."""
    threshold = c.scale.threshold  # set on every matrix an undercut choice comes from (``explain``)
    limit = threshold_name(threshold, c) if threshold is not None else "its threshold"
    dropped = f"the solver matched every pair before dropping those past {limit}"
    alt = c.alternative
    if alt is None or alt.kind is not AxisKind.TRACK or alternative_took is not None:
        return f"not the cheapest on these costs: {dropped}"
    name = column_name(alt)
    gave = f"and gave {name} to a detection whose pair it dropped"
    return f"not {name} ({cost_value(c.alternative_cost, c)}): {dropped}, {gave}"


def cost_named(value: float, c: PairChoice) -> str:
    """``cost 6.75`` / ``cost 1.20 m``; a similarity needs no word (``GIoU -0.21``)."""
    text = cost_value(value, c)
    return text if c.scale.similarity is not None else f"cost {text}"


def threshold_held(label: AxisLabel | None, value: float, c: PairChoice) -> str | None:
    """``the 3D IoU threshold 0.10`` / ``the distance threshold 2.00 m``: what a new-track column's entry is where
    the matrix has a cost threshold (``CostScale.threshold``: every new-track column holds it, so a detection
    starts a track unless a track is cheaper); None for any other column or scale, whose entry is a cost."""
    scale = c.scale
    if label is None or label.kind is not AxisKind.NEW_TRACK or scale.threshold is None:
        return None
    if not math.isclose(value, scale.threshold, rel_tol=1e-9, abs_tol=1e-12):
        return None
    return threshold_name(value, c)


def threshold_name(value: float, c: PairChoice) -> str:
    """``the GIoU threshold -0.50`` / ``the distance threshold 2.00 m``: a cost threshold ``value`` on the matrix's
    scale, as a similarity where the scale has one."""
    scale = c.scale
    if scale.similarity is not None:
        return f"the {scale.similarity} threshold {1.0 - value:.2f}"
    return f"the {scale.name} threshold {cost_value(value, c)}"


def key_text(k: KeyDecision) -> str:
    return choice_text(k.frame, k.choice, k.went, k.born, k.alternative_took)


# How an update used detections.
def share_text(share: float, mode: UseMode) -> str:
    """A detection's share of an update in the tracker's terms: nothing for an assignment (or a run known by its
    output only), ``p 0.93`` for an association probability, ``91 % of its weight`` for a PHD weight."""
    if mode in (UseMode.ASSIGNED, UseMode.OUTPUT):
        return ""
    if mode is UseMode.PROBABILITIES:
        return f"p {share:.2f}"
    return f"{100 * share:.0f} % of its weight"


def use_text(step: TrackStep) -> str:
    """``used m5``, ``used m5 (p 1.00)``, ``took 91 % of its weight from m2``, ``missed`` — what one update did;
    for a run known by its output only, where its box was: ``was output on m5``, ``was output on no detection``."""
    use = step.use
    if use is not None and use.mode is UseMode.OUTPUT:
        return f"was output on {meas_name(use.shares[0][0])}" if use.shares else "was output on no detection"
    if use is None or not use.shares:
        return "missed"
    verb = "was given" if use.mode is UseMode.ASSIGNED else "used"
    parts = []
    for m, share in use.shares[:2]:
        extra = share_text(share, use.mode)
        parts.append(f"{meas_name(m)}" + (f" ({extra})" if extra else ""))
    more = f" +{len(use.shares) - 2} more" if len(use.shares) > 2 else ""
    if use.mode is UseMode.WEIGHTS:
        m, share = use.shares[0]
        return f"took {100 * share:.0f} % of its weight from {meas_name(m)}{more}"
    return f"{verb} {', '.join(parts)}{more}"


def destination_name(d: Destination | None, mode: UseMode) -> str:
    """Where a detection went, as a table cell: ``track 26``, ``track 62 (p 1.00)``, ``new track 348``, ``new
    (started no track: a candidate or clutter)``, ``not received (dropped by preprocessing)``; for a run known by its
    output only, the box on it: ``under track 26's box``, ``under no output box``."""
    if mode is UseMode.OUTPUT:
        if d is not None and d.went is Went.NO_OUTPUT and d.track_id >= 0:  # beside a box placed on another one
            return f"under track {d.track_id}'s box, which sat on another detection"
        if d is None or d.went is not Went.TRACK:
            return "under no output box"
        return f"under track {d.track_id}'s box"
    if d is None or d.went is Went.NOT_RECEIVED:
        return "not received (dropped by preprocessing)"
    if d.went is Went.TRACK:
        extra = share_text(d.share, mode)
        if mode is UseMode.WEIGHTS:  # the detection's weight, not the track's: say whose
            return f"track {d.track_id} ({100 * d.share:.0f} % of {meas_name(d.meas)})"
        return f"track {d.track_id}" + (f" ({extra})" if extra else "")
    if d.went is Went.NEW_TRACK:
        return f"new track {d.track_id}"
    return "new (started no track: a candidate or clutter)"


def went_text(d: Destination | None, mode: UseMode) -> str:
    """Where a detection went, after its name: ``→ track 26``, ``→ new track 348``, ... (``destination_name``)."""
    name = destination_name(d, mode)
    return name if name.startswith(("not received", "under ")) else f"→ {name}"


def went_phrase(d: Destination | None, mode: UseMode) -> str:
    """Where a detection went, in a sentence: ``went to track 26``, ``started new track 348``, ``started no track
    (a candidate or clutter)``, ``was dropped by preprocessing``; output only: ``lay under track 26's box``."""
    if mode is UseMode.OUTPUT:
        return f"lay {destination_name(d, mode)}"
    if d is None or d.went is Went.NOT_RECEIVED:
        return "was dropped by preprocessing"
    if d.went is Went.NEW_TRACK:
        return f"started new track {d.track_id}"
    if d.went is Went.NEW:
        return "started no track (a candidate or clutter)"
    return f"went to {destination_name(d, mode)}"


def _existence_word(mode: UseMode) -> str:
    return "weight" if mode is UseMode.WEIGHTS else "existence"


# A finding.
def whose_text(f: Finding) -> str:
    """``the tracker's doing``, ``the detector's and the tracker's doing``."""
    names = [p.value + "'s" for p in f.parties]
    if not names:
        return "cause unknown"
    joined = names[0] if len(names) == 1 else ", ".join(names[:-1]) + " and " + names[-1]
    return f"{joined} doing"


def why_lines(f: Finding) -> list[str]:
    """The **Why** paragraph (and the **Because** one when a solver's choice decided it), as markdown lines."""
    match f.kind:
        case FailureKind.ID_SWITCH | FailureKind.IDENTITY_THEFT | FailureKind.FRAGMENTATION:
            parts = _lost_object(f)
        case FailureKind.FALSE_TRACK:
            parts = _false_track(f)
        case FailureKind.MISS:
            parts = _miss(f)
        case FailureKind.COALESCENCE:
            parts = _coalescence(f)
        case _:
            raise AssertionError(f.kind)
    if any(b.rule is Rule.UNANNOTATED for b in f.blame) and f.gt_id is not None:
        parts.insert(
            0,
            f"at frame {f.frame} {f.class_name} GT {short_id(f.gt_id)} had no annotation, though it had some before "
            "and after: the evaluation scored a box it interpolated between them there",
        )
    if f.unscored and f.kind is not FailureKind.MISS:  # the devkit counted every object missed and nothing else
        parts.append(
            f"outside the evaluation's counts: {f.tracker} reached no score threshold at its lowest recall for "
            f"{f.class_name}s"
        )
    parts += _others(f)
    lines = [f"**Why** ({f.tracker}, {whose_text(f)}): " + "; ".join(p for p in parts if p) + ".", ""]
    because = because_text(f)
    if because:
        lines += [because, ""]
    return lines


def evaluation_lines(f: Finding) -> list[str]:
    """A paragraph per object the evaluation scored at an interpolated box ``EVALUATED_OFFSET_M`` or more from its
    annotation (the blame ``INTERPOLATED``): where, why, and which tracks were within reach of each box."""
    if not any(b.rule is Rule.INTERPOLATED for b in f.blame) or f.gt_id is None:
        return []
    s = f.sighting(f.frame)
    g = s.evaluated if s is not None else None
    if g is None or g.evaluated_xy_m is None:
        return []
    why = f"its annotated box was dropped ({g.dropped.value if g.dropped else 'dropped'}), so the evaluation "
    why += "interpolated one" + _between(g)
    out = []
    r = f.reach
    if r is not None:

        def tracks(ids: tuple[int, ...]) -> str:
            return f"{f.tracker} track{'s' if len(ids) > 1 else ''} {', '.join(map(str, ids))}" if ids else "no track"

        if r.near_annotated and not r.near_evaluated:
            # the verdict names the evaluation alone only when the Why blames it alone (its header names the rest)
            lead = "**Verdict: the evaluation's doing.**" if len(f.parties) == 1 else "**The evaluation's part:**"
            out += [
                f"{lead} {tracks(r.near_annotated)} followed the annotated object, but "
                f"the evaluation scored it against a box {r.offset_m:.1f} m away.",
                "",
            ]
        reach = (
            f" Within {NEAR_M:.0f} m of the evaluated box: {tracks(r.near_evaluated)}. Within {NEAR_M:.0f} m of the "
            f"annotated box: {tracks(r.near_annotated)}."
        )
    else:
        reach = ""
    return out + [
        f"**GT {short_id(f.gt_id)} as evaluated**: at frame {f.frame} {why}; that box lies **{g.offset_m:.1f} m** "
        f"from the annotated one (the column beside the views labels both).{reach}",
        "",
    ]


def _between(g: GtFrame) -> str:
    """`` from frames 14 and 20, weighting the two ends the wrong way round (...): weighted the right way the box
    would lie 0.0 m from the annotation`` ("" without the ends)."""
    if g.between is None:
        return ""
    left, right = g.between
    text = f" from frames {left} and {right}"
    if g.unswapped_xy_m is not None and g.evaluated_xy_m is not None:
        off = math.hypot(g.unswapped_xy_m[0] - g.evaluated_xy_m[0], g.unswapped_xy_m[1] - g.evaluated_xy_m[1])
        if off >= 0.05:
            right_way = math.hypot(g.unswapped_xy_m[0] - g.annotated_xy_m[0], g.unswapped_xy_m[1] - g.annotated_xy_m[1])
            text += (
                f", weighting the two ends the wrong way round (nuscenes-devkit issue #1141): weighted the right way "
                f"the box would lie {right_way:.1f} m from the annotation"
            )
    return text


def _right_way_m(g: GtFrame | None, track_xy_m: tuple[float, float] | None) -> float | None:
    """How far from a track's box the interpolated box would lie weighted the right way (nuscenes-devkit issue
    #1141); None when the devkit's box is that one (its ends unknown, or the swap moved it under 0.05 m)."""
    if g is None or g.unswapped_xy_m is None or g.evaluated_xy_m is None or track_xy_m is None:
        return None
    ux, uy = g.unswapped_xy_m
    if math.hypot(ux - g.evaluated_xy_m[0], uy - g.evaluated_xy_m[1]) < 0.05:
        return None
    return math.hypot(ux - track_xy_m[0], uy - track_xy_m[1])


def _swap_reach(g: GtFrame | None, track_xy_m: tuple[float, float]) -> str:
    """What nuscenes-devkit issue #1141 did to a track out of reach of an interpolated box: `` (see ...)`` when the
    box weighted the right way lies within ``NEAR_M`` of the track, ``, and weighted the right way (...) it would
    still lie 2.6 m from the track`` when not (dev set scene-1094 megvii prob3dmot false_track:6), "" when the
    devkit's box is the one weighted the right way."""
    d = _right_way_m(g, track_xy_m)
    if d is None:
        return ""
    if d < NEAR_M:
        return " (see nuscenes-devkit issue #1141)"
    return f", and weighted the right way (nuscenes-devkit issue #1141) it would still lie {d:.1f} m from the track"


def _still_away(g: GtFrame | None, track_xy_m: tuple[float, float] | None) -> str:
    """``, and weighted the right way it would still lie 2.6 m from the track``: after "out of the track's reach",
    where the #1141 note before it names the swap but the box weighted the right way is out of reach too (dev set
    scene-1094 megvii prob3dmot miss:61); "" otherwise."""
    d = _right_way_m(g, track_xy_m)
    return (
        f", and weighted the right way it would still lie {d:.1f} m from the track"
        if d is not None and d >= NEAR_M
        else ""
    )


def because_text(f: Finding) -> str | None:
    """The deciding choice's costs taken apart, and the lost track's own cost when it was neither of the compared
    columns; None without a deciding choice whose next best was a track with known cost terms."""
    d = f.decision
    if d is None:
        return None
    why = choice_why(d.choice, destination_text(d.went, d.born, d.choice.chosen), d.would)
    if why is None:
        return None
    if d.lost is not None:  # the lost track had a column in the matrix (``Deciding``)
        if not d.lost_in_gate:
            why += (
                f". Track {d.lost}, which had the object, could not take {meas_name(d.choice.meas.ref)}: its "
                f"column's cost for it was infinite ({_failed_test(d.choice)})"
            )
        elif (lost_why := track_why(d.choice, d.lost, ", which had the object,", d.lost_would)) is not None:
            why += f". {lost_why}"
    back = f.frame - d.frame
    where = f"; the views open at frame {f.frame}: step back {plural(back, 'frame')} to see it" if back > 0 else ""
    return f"**Because** (frame {d.frame}{where}): {why}."


def _failed_test(c: PairChoice) -> str:
    """The test an infinite cost stands for on the matrix's scale: a gate, or the tracker's cost threshold."""
    return scale_test(c.scale)


def scale_test(scale: CostScale | None) -> str:
    """``outside its gate``, or ``beyond its distance threshold`` for a matrix with a cost threshold."""
    if scale is not None and scale.threshold is not None:
        return f"beyond its {scale.name} threshold"
    return "outside its gate"


def step_test(step: TrackStep) -> str:
    return scale_test(step.column_scale)


def _presence(f: Finding) -> str:
    """How often the object had a detection of its class within reach, over the window."""
    seen = [s for s in f.sightings]
    if not seen or f.gt_id is None:
        return ""
    detected = [s.frame for s in seen if s.nearest_own is not None]
    removed = [s.frame for s in seen if s.nearest_own is None and s.removed_own is not None]
    neighbours = [
        s.frame for s in seen if s.nearest_own is None and s.removed_own is None and s.neighbours_own is not None
    ]
    at = frames_text(detected) if detected else "no frame"
    only = " only" if 0 < len(detected) < len(seen) else ""
    kept = "the tracker kept " if removed else ""
    own = " of its own" if neighbours else ""
    also = (
        f", and at {frames_text(removed)} only one its preprocessing removed (score threshold or NMS)"
        if removed
        else ""
    )
    if neighbours:
        also += f", and at {frames_text(neighbours)} only one nearer another annotated object"
    # the frames it was annotated at: one span, or where it left view and came back, each run apart
    span = ", ".join(f"{r[0]}–{r[-1]}" if len(r) > 1 else f"{r[0]}" for r in consecutive_runs([s.frame for s in seen]))
    if len(seen) == 1:
        span = f"{seen[0].frame}–{seen[0].frame}"
    return (
        f"in the {len(seen)} recorded frames up to {f.frame} ({span}), GT "
        f"{short_id(f.gt_id)} had a {f.class_name} detection{own} {kept}within {NEAR_M:.0f} m at {at}{only}{also}"
    )


def _detector_gaps(f: Finding) -> list[str]:
    out = []
    by = {s.frame: s for s in f.sightings}
    for b in f.blame:
        if b.rule is Rule.NO_DETECTION:
            seen = [by[x] for x in b.frames if x in by]
            out.append(
                f"at {frames_text(b.frames)} the detector gave {no_detection(seen)}, though it had {points_text(seen)}"
                f"{_in_box_text(seen)}"
            )
        elif b.rule is Rule.OTHER_CLASS:
            seen = [by[x].seen for x in b.frames if x in by and by[x].seen is not None]
            what = ", ".join(f"{n.class_name} {meas_name(n.meas)} {n.distance_m:.2f} m away" for n in seen)
            out.append(f"at {frames_text(b.frames)} the detector saw it only as another class ({what})")
    return out


def _in_box_text(seen: Sequence[Sighting]) -> str:
    """``, but a detection lay inside its box, farther from its centre (truck m20 3.2 m at frame 13): the detector
    saw part of it``: the detections a "no detection within 2 m" hides (audit truth50, world6: a 16 m truck seen as
    two boxes)."""
    inside = [s for s in seen if s.in_box is not None]
    if not inside:
        return ""
    what = ", ".join(
        f"{s.in_box.class_name} {meas_name(s.in_box.meas)} {s.in_box.distance_m:.1f} m"
        + (f" at frame {s.frame}" if len(seen) > 1 else "")
        for s in inside[:3]
    )
    more = f" and at {len(inside) - 3} more frames" if len(inside) > 3 else ""
    lay = "a detection lay" if len(inside) == 1 else "detections lay"
    return f", but {lay} inside its box, farther from its centre ({what}{more}): the detector saw part of it"


def _hidden(f: Finding) -> list[str]:
    """The deciding frames where the object had no LiDAR or radar points and no detection: no detector could see
    it."""
    hidden = [s for s in f.sightings if s.frame in f.deciding and s.points == 0 and s.undetected]
    if not hidden:
        return []
    return [
        f"at {frames_text([s.frame for s in hidden])} it had no LiDAR or radar points (no detector could see it) and "
        f"{no_detection(hidden)}"
    ]


def no_detection(sightings: Sequence[Sighting]) -> str:
    """``no detection of a tracked class within 2 m``, or where detections lay that near but each nearer another
    annotated object, or within 2 m of one of the detection's own class (``Near.on_other``): ``no detection of its
    own within 2 m (at frame 3 car m4, 1.8 m away, lay 0.1 m from car GT 26e63e)``: that object's detection, not a
    sight of this one."""
    others = [s for s in sightings if s.nearest_any is not None and s.nearest_any.on_other is not None]
    if not others:
        return f"no detection of a tracked class within {NEAR_M:.0f} m"
    where = []
    for s in others:
        n = s.nearest_any
        gt_id, cls, d = n.on_other
        at = f"at frame {s.frame} " if len(sightings) > 1 else ""
        where.append(
            f"{at}{n.class_name} {meas_name(n.meas)}, {n.distance_m:.1f} m away, lay {d:.1f} m from {cls} GT "
            f"{short_id(gt_id)}"
        )
    return f"no detection of its own within {NEAR_M:.0f} m ({'; '.join(where)})"


def _out_of_reach(lost: LostTrack, s: Sighting) -> bool:
    """Whether the lost track was output on the annotated object at ``s.frame`` while the evaluation scored the
    object at a box it interpolated ``EVALUATED_OFFSET_M`` or more away and ``NEAR_M`` or more from the track's
    box (the devkit's matching distance): there "on it" was no match."""
    g, step = s.evaluated, lost.step(s.frame)
    if (
        g is None
        or g.status is not GtStatus.INTERPOLATED
        or g.offset_m < EVALUATED_OFFSET_M
        or g.evaluated_xy_m is None
    ):
        return False
    if step is None or step.output is None or not any(o.track_id == lost.track_id for o in s.on_it):
        return False
    x, y = step.output.translation_m[:2]
    return math.hypot(x - g.evaluated_xy_m[0], y - g.evaluated_xy_m[1]) >= NEAR_M


def _scored_away(f: Finding, lost: LostTrack) -> str:
    """`` (at frame 16, though, the evaluation scored the object at a box it interpolated 10.9 m from the
    annotation)``: the frames before the failure's at which the lost track was output on the annotated object
    and out of reach of the box the evaluation scored the object at (``_out_of_reach``; "" if none)."""
    away = [s for s in f.sightings if s.frame < f.frame and _out_of_reach(lost, s)]
    if not away:
        return ""
    offsets = ", ".join(f"{s.evaluated.offset_m:.1f}" for s in away)
    return (
        f" (at {frames_text(s.frame for s in away)}, though, the evaluation scored the object at a box it "
        f"interpolated {offsets} m from the annotation, out of the track's reach)"
    )


def _matched_away(f: Finding, lost: LostTrack, name_evaluation: bool) -> str:
    """``, then matched track 160 to pedestrian GT 2e96cc at frames 22–34``: the other objects the evaluation
    matched the lost track to after its last match on this one (``LostTrack.matched_away``; "" if none), so "last
    matched to it" does not read as if the track had followed the object unmatched since; name_evaluation: the
    clause before spoke of the tracker's output (``the evaluation matched ...``)."""
    if not lost.matched_away:
        return ""
    objects = " and ".join(
        f"to {f.class_name} GT {short_id(a.gt_id)} at {frames_text(a.frames)}" for a in lost.matched_away
    )
    who = "the evaluation " if name_evaluation else ""
    return f", then {who}matched track {lost.track_id} {objects}"


def _two_tracks(f: Finding, lost: LostTrack) -> str:
    """The lost track still output within ``NEAR_M`` of the object at the failure's frame beside the track the
    evaluation matched to the object there (the blame ``TWO_TRACKS``). Where the evaluation matched the lost track
    to another object at that frame, it was no spare second track on this one: that is said instead."""
    s = f.sighting(f.frame)
    on = {o.track_id: o for o in (s.on_it if s else ())}
    away = next((a for a in lost.matched_away if f.frame in a.frames), None)
    if away is not None:  # without the lost track's box or the taker, less is said, never the spare-track form
        if lost.track_id not in on or f.taker is None:
            return ""
        return (
            f"at frame {f.frame} track {lost.track_id} was still output {on[lost.track_id].distance_m:.1f} m from "
            f"it, but the evaluation matched track {lost.track_id} to {f.class_name} GT {short_id(away.gt_id)} and "
            f"track {f.taker.track_id} to GT {short_id(f.gt_id or '')}"
        )
    others = [t for t in on if t != lost.track_id]
    return (
        f"at frame {f.frame} track {lost.track_id} was still output on the object, but so was track "
        f"{', '.join(map(str, others))}: two tracks on one object, and the evaluation matched the other"
    )


def _unannotated(f: Finding, held: int | None) -> list[int]:
    """The frames after ``held`` (the lost track's last frame on the annotated object; None: from the object's first
    annotation in the window) before the failure's at which the object had no annotation (it left view and came
    back: the evaluation scores boxes it interpolates only between two annotations, and the failure's frame may lie
    in that gap too; ``f.sightings`` holds the annotated frames of the window, which starts at ``held + 1``)."""
    seen = {s.frame for s in f.sightings}
    if not seen:
        return []
    start = max(held + 1, f.window[0]) if held is not None else min(seen)
    return [x for x in range(start, f.frame) if x not in seen]


def _lost_story(f: Finding, lost: LostTrack) -> str:
    """What the lost track did over the window, in the tracker's terms."""
    mode = UseMode(f.mode)
    t = lost.track_id
    steps = lost.steps
    parts = []
    held, matched = lost.held_until, lost.matched_until
    if matched is not None:
        # "last on it" is not "last output": say where it was output after, away from the object
        after = held if held is not None else -1
        gap = _unannotated(f, held)
        away = [s.frame for s in steps if after < s.frame < f.frame and s.output is not None and s.frame not in gap]
        elsewhere = f" (output farther than {NEAR_M:.0f} m from it at {frames_text(away)})" if away else ""
        if gap:  # no annotation there to be near or far from: the evaluation scored boxes it interpolated
            boxes = "boxes" if len(gap) > 1 else "a box"
            elsewhere += f" (it was not annotated at {frames_text(gap)}: the evaluation scored {boxes} it interpolated)"
        # "on it" reads as the evaluation's match: said only where the devkit's last match was that output, and
        # "last output on it" not of a track still output on the annotated object at the failure's frame
        now = f.sighting(f.frame)
        last_on = held == matched and not (now is not None and t in {o.track_id for o in now.on_it})
        # a match at a frame the track has no box of its own was the devkit's interpolation between two of its boxes
        interpolated = lost.evaluated is not None and matched in lost.evaluated.interpolated
        last = (
            f"track {t} was last output on it at frame {held}"
            if last_on
            else f"the evaluation last matched track {t} to it at frame {matched}"
            + (" (a box it interpolated for the track)" if interpolated else "")
        )
        parts.append(f"{last}{elsewhere}{_scored_away(f, lost)}{_matched_away(f, lost, last_on)}")
    if f.has_existence and steps:
        word = _existence_word(mode)
        alive = [s for s in steps if s.posterior_existence is not None]
        if alive:
            peak = max(alive, key=lambda s: s.posterior_existence)
            last = alive[-1]
            if len({existence_text(s.posterior_existence) for s in alive}) == 1:  # the same over the window
                span = f"frame {last.frame}" if len(alive) == 1 else f"frames {alive[0].frame}–{last.frame}"
                parts.append(f"its {word} was {existence_text(last.posterior_existence)} ({span})")
            elif existence_text(peak.posterior_existence) == existence_text(last.posterior_existence):
                # back up at its highest after a dip: the last frame only, not a span it did not hold over
                parts.append(f"its {word} was {existence_text(last.posterior_existence)} (frame {last.frame})")
            else:
                parts.append(
                    f"its {word} went from {existence_text(peak.posterior_existence)} (frame {peak.frame}) to "
                    f"{existence_text(last.posterior_existence)} (frame {last.frame})"
                )
    deciding = [s for s in steps if s.frame in f.deciding]
    used = [s for s in deciding if s.used]
    if used and mode is not UseMode.ASSIGNED:
        parts.append("; ".join(f"at frame {s.frame} it {use_text(s)}" for s in used))
        said = {(s.frame, m) for s in used for m, _ in s.use.shares[:2]}
        nothing = [p for p in lost.used_of_no_object if p in said]
        if nothing:  # audit truth50 (world5): a soft update from the false bus read as a sight of the bus
            parts.append(_used_of_no_object(nothing))
    not_output = [x for x in f.deciding if lost.step(x) is None or lost.step(x).output is None]
    ended = next((s for s in steps if s.ended is not None), None)
    if not_output:
        parts.append(f"it was not output at {frames_text(not_output)}")
    if ended is not None:
        e = ended.ended
        if e.ending is Ending.DELETED and e.hits >= 0:
            parts.append(f"its track logic deleted it at frame {ended.frame} ({hits_text(e.hits, e.window)})")
        elif e.ending is Ending.DELETED:
            parts.append(f"its track logic deleted it at frame {ended.frame}")
        elif e.ending is Ending.MERGED:
            parts.append(f"it was merged into another component at frame {ended.frame}")
        else:
            parts.append(f"it was pruned at frame {ended.frame} ({e.reason.value})")
    return ", ".join(parts)


def _unused(f: Finding) -> list[tuple[tuple[int, int], str]]:
    """The deciding frames where a detection of the object was there and the lost track's update did not use it:
    ((frame, detection), text)."""
    mode = UseMode(f.mode)
    out = []
    for b in f.blame:
        if b.rule is not Rule.DETECTION_UNUSED:
            continue
        for x in b.frames:
            s = f.sighting(x)
            if s is None:
                continue
            n = s.nearest_own
            if n is None:
                m = s.seen
                text = (
                    f"at frame {x} {meas_name(m.meas)} ({f.class_name}, score {m.score:.2f}, {m.distance_m:.1f} m "
                    "from it) was dropped by preprocessing (score threshold or NMS)"
                )
                out.append(((x, m.meas), text))
                continue
            gate = ""
            if f.lost is not None:
                step = f.lost.step(x)
                nis = next((d2 for m, d2 in (step.gated if step is not None else ()) if m == n.meas), None)
                t = f.lost.track_id
                cost = step.column_cost(n.meas) if step is not None else None
                if nis is not None:
                    gate = f", in track {t}'s gate at NIS {nis:.1f}"
                elif f.output_only and step is None:
                    gate = f"; track {t} was not output"
                elif step is None and x in f.lost.elsewhere:  # held only by hypotheses not chosen
                    gate = f"; track {t} was only in hypotheses the tracker did not choose"
                elif step is None:  # no event of the frame names the track
                    gate = f"; track {t} was gone"
                elif cost is not None and not math.isfinite(cost) and (x, n.meas) in f.lost.finite_elsewhere:
                    gate = (
                        f"; track {t} could not take it in the hypothesis the tracker chose (its column's cost there "
                        f"was infinite, {step_test(step)}; another hypothesis gave it a finite cost)"
                    )
                elif cost is not None and not math.isfinite(cost):  # what stopped it, then its deletion
                    gate = f"; track {t} could not take it: its column's cost for it was infinite ({step_test(step)})"
                    if step.ended is not None:
                        gate += f", and it ended at frame {x}"
            went = went_phrase(s.went, mode) if mode is UseMode.OUTPUT else went_text(s.went, mode)
            text = f"at frame {x} {meas_name(n.meas)} (score {n.score:.2f}, {n.distance_m:.1f} m from it{gate}) {went}"
            out.append(((x, n.meas), text))
    return out


def _still_on_annotated(f: Finding, lost: LostTrack) -> list[str]:
    """The lost track still output on the annotated object at the failure's frame while the evaluation scored the
    object at an interpolated box out of its reach (the blame ``INTERPOLATED`` and ``f.reach``): "last output on
    it" alone would read as if the track had left it."""
    r, s = f.reach, f.sighting(f.frame)
    if r is None or s is None or lost.track_id not in r.near_annotated or lost.track_id in r.near_evaluated:
        return []
    on = next((o for o in s.on_it if o.track_id == lost.track_id), None)
    if on is None:
        return []
    return [
        f"at frame {f.frame} track {lost.track_id} was still output {on.distance_m:.1f} m from the annotated object, "
        f"but the evaluation scored the object at a box it interpolated {r.offset_m:.1f} m from the annotation, "
        f"out of the track's reach{_still_away(s.evaluated, on.xy_m)}"
    ]


def _lost_object(f: Finding) -> list[str]:
    parts = [_presence(f)]
    parts += _detector_gaps(f)
    parts += _hidden(f)
    lost = f.lost
    if lost is not None:
        parts.append(_lost_story(f, lost))
        parts += _counted_unshown(f, lost)
    decided = (f.decision.frame, int(f.decision.choice.meas.ref)) if f.decision is not None else None
    parts += [text for key, text in _unused(f) if key != decided]
    if f.switch is not None:
        parts.append(_switch_text(f))
    if f.decision is not None:
        d = f.decision  # the next best's own detection in the same assignment: the lower total decided, not its cost
        # "then" only at the failure's own frame: the clauses before it run up to that frame (world5 scene-0553 gnn:
        # "it was not output at frames 13–20 ...; at frame 20 m25 → track 48; then, frame 15: ..." read as if
        # frame 15 came after frame 20); "earlier" is earlier than the failure's frame
        lead = "then" if d.frame >= f.frame else "the deciding choice was earlier"
        parts.append(f"{lead}, {choice_text(d.frame, d.choice, d.went, d.born, d.alternative_took)}")
        if d.meas_of_no_object:  # truth49 world5 scene-0553 gnn: m24 was the false bus, nowhere said
            parts.append(f"{meas_name(d.choice.meas.ref)} at frame {d.frame} was {_of_no_object(d.meas_part_of)}")
        parts += _where_from(f)
        o = f.taker  # audit truth50 (world5 scene-0553 gnn id_switch:1): the thief's false start went unsaid here
        started_here = d.born and d.went == (o.track_id if o is not None else None)
        theft = f.kind is FailureKind.IDENTITY_THEFT  # a theft says its thief was a false track
        if o is not None and o.frame >= 0 and o.meas >= 0 and o.of_no_object and not (started_here or theft):
            parts.append(
                f"track {o.track_id} had been started at frame {o.frame} by {meas_name(o.meas)}, "
                f"{_of_no_object(o.part_of)}"
            )
    elif f.taker is not None and f.taker.frame >= 0:
        o = f.taker
        if f.output_only:
            parts.append(f"track {o.track_id} was first output at frame {o.frame}")
        elif o.meas >= 0:
            # audit truth49 (world5 scene-0553, a false bus beside a bus's path): the thief's first detection was
            # of no object; the story needs it said where it started, not only its later false frames
            false = f", {_of_no_object(o.part_of)}" if o.of_no_object else ""
            parts.append(f"track {o.track_id} had been started at frame {o.frame} by {meas_name(o.meas)}{false}")
        elif f.switch is not None:
            parts.append(f"track {o.track_id} had existed since frame {o.frame} in a hypothesis other than the best")
    if lost is not None and lost.off is not None:
        parts.append(_off_text(f, lost))
    if lost is not None:
        parts += _still_on_annotated(f, lost)
    if lost is not None and any(b.rule is Rule.TWO_TRACKS for b in f.blame):
        parts.append(_two_tracks(f, lost))
    if lost is not None and f.kind is FailureKind.FRAGMENTATION:
        s = f.sighting(f.frame)
        for b in f.blame:
            if b.rule is Rule.COVERED_TWO and s is not None:
                parts.append(f"at frame {f.frame} {_covering(f, s)}")
            elif b.rule is Rule.NOT_COUNTED and s is not None:
                parts += [
                    f"track {o.track_id} was output on it, but {averaged_text(o.evaluated)}, is below the "
                    f"{f.class_name} threshold {o.threshold:.3f}: the evaluation did not count it"
                    for o in s.on_it
                    if not o.counted and o.evaluated is not None and o.evaluated.averaged_score is not None
                ]
            elif b.rule is Rule.TRACK_DROPPED and s is not None:
                parts += [f"at frame {f.frame} {clause}" for clause in _dropped_on_it(f, s)]
    if f.taker is not None and f.taker.false_frames:
        victim = f"track {lost.track_id}" if lost is not None else "another track"
        held = f": the evaluation still gave GT {short_id(f.gt_id or '')} to {victim}" if f.taker.victim_held else ""
        parts.append(
            f"track {f.taker.track_id} had been a false track at {frames_text(f.taker.false_frames)} (matched to no "
            f"object{held}), so its taking the object is an identity theft"
        )
    return parts


def _where_from(f: Finding) -> list[str]:
    """When the deciding choice's next best is a track between the two (neither lost nor taker), where it came
    from: the earlier key decision that started it."""
    d = f.decision
    alt = d.choice.alternative
    named = {f.lost.track_id if f.lost else None, f.taker.track_id if f.taker else None}
    if alt is None or alt.kind is not AxisKind.TRACK or alt.ref in named:
        return []
    started = [k for k in f.key_decisions if k.frame < d.frame and k.born and k.went == alt.ref]
    if not started:
        return []
    k = started[-1]
    instead = f" instead of going to {column_name(k.choice.alternative)}" if k.choice.alternative is not None else ""
    return [f"track {alt.ref} had been started at frame {k.frame} by {meas_name(k.choice.meas.ref)}{instead}"]


def _switch_text(f: Finding) -> str:
    s = f.switch
    head = (
        f"at frame {s.frame} the best hypothesis switched: it descends from prior hypothesis {s.parent} "
        f"(probability {s.parent_weight:.2f} after frame {s.frame - 1}, against {s.best_weight:.2f} for the best), "
        "not from a cost choice within the best"
    )
    rows = []
    for t in s.tracks:
        bits = []
        if t.since is not None:
            bits.append(f"held by a kept hypothesis since frame {t.since}")
        if t.decided is not None:
            bits.append(f"predicted existence {existence_text(t.decided)} in hypothesis {s.parent}")
        if t.predicted is not None and (t.decided is None or existence_text(t.decided) != existence_text(t.predicted)):
            bits.append(f"{existence_text(t.predicted)} in the previous best")
        elif t.predicted is None:
            bits.append("absent from the previous best")
        if t.chosen is not None and t.marginal is not None:
            bits.append(
                f"after the update {existence_text(t.chosen)} in the chosen hypothesis, "
                f"{existence_text(t.marginal)} over all kept ones"
            )
        rows.append(f"track {t.track_id}: " + ", ".join(bits))
    return head + " (" + "; ".join(rows) + ")"


def _off_text(f: Finding, lost: LostTrack) -> str:
    off = lost.off
    on = f", on {meas_name(off.meas)}" if off.meas >= 0 else ""
    before = ""
    if off.earlier:
        away = ", ".join(f"{x} ({meas_name(m)}{_share_of(lost, x, m, UseMode(f.mode))})" for x, m in off.earlier)
        verb = "its box had sat on" if f.output_only else "it had used"
        before = (
            f"; {verb} detections {NEAR_M:.0f} m or more from the object at frame"
            f"{'s' if len(off.earlier) > 1 else ''} {away}"
        )
    head = f"at frame {f.frame} track {lost.track_id} was output {off.distance_m:.1f} m from GT "
    head += short_id(f.gt_id or "")
    if off.scored_m is not None and off.scored_m < NEAR_M:  # yet within reach of the box the evaluation scored
        return f"{head}{on}, {off.scored_m:.1f} m from the box the evaluation interpolated for it{before}"
    ev = lost.evaluated
    if ev is not None and f.frame in ev.submitted and f.frame not in ev.kept and f.frame not in ev.interpolated:
        # audit truth53 (world9 scene-1094 pointpillars gnnpmb id_switch:1): the devkit had no box of the track here
        # at all (43.3 m from the ego, beyond the pedestrian range), so no distance decided the match
        dropped = ev.dropped_at(f.frame)
        if dropped is not None:
            return (
                f"{head}{on}, but its box {dropped_lay(dropped)}: the evaluation dropped it and had no box of the "
                f"track to match to the object{before}"
            )
    return f"{head}{on}: beyond the evaluation's {NEAR_M:.0f} m, so it no longer matched the object{before}"


def _share_of(lost: LostTrack, frame: int, meas: int, mode: UseMode) -> str:
    """``, 24 % of its weight`` / ``, p 0.24``: the share of a soft update the lost track took from ``meas`` at
    ``frame`` (a minor share reads as the detection that led it off otherwise); nothing for an assignment."""
    step = lost.step(frame)
    share = next((v for m, v in step.use.shares if m == meas), None) if step and step.use else None
    extra = share_text(share, mode) if share is not None else ""
    return f", {extra}" if extra else ""


def averaged_text(ev: TrackEval) -> str:
    """``its score averaged over the 31 frames the evaluation kept (of 38 submitted), 0.660``."""
    kept, submitted = len(ev.kept), len(ev.submitted)
    over = (
        f"over its {plural(kept, 'frame')}"
        if kept == submitted
        else f"over the {kept} of its {submitted} frames the evaluation kept (within the class range)"
    )
    return f"its score averaged {over}, {ev.averaged_score:.3f}"


def _counted_unshown(f: Finding, lost: LostTrack) -> list[str]:
    """Why a track never shown (existence below ``SHOW_MIN_EXISTENCE``) still counted for the evaluation."""
    ev, threshold = lost.evaluated, lost.threshold
    if not f.has_existence or ev is None or ev.averaged_score is None or threshold is None:
        return []
    output = {s.frame: s.output for s in lost.steps if s.output is not None}
    if not set(ev.submitted) <= set(output):  # output outside the window too: whether it was ever shown is not known
        return []
    if ev.averaged_score < threshold or any(o.existence >= SHOW_MIN_EXISTENCE for o in output.values()):
        return []
    if math.isclose(ev.averaged_score, threshold, rel_tol=1e-9):
        versus = f"is exactly the {f.class_name} threshold (the lowest score counted)"
    else:
        versus = f"is above the {f.class_name} threshold {threshold:.3f}"
    return [
        f"track {lost.track_id}'s {_existence_word(UseMode(f.mode))} stayed below {SHOW_MIN_EXISTENCE:g} (the views "
        f"draw tracks from {SHOW_MIN_EXISTENCE:g} up), yet the evaluation counted it: {averaged_text(ev)}, {versus}"
    ]


def _near_text(n: Near) -> str:
    return f"{meas_name(n.meas)} ({n.class_name}, score {n.score:.2f})"


def _the_one_used(o: FalseOutput) -> str:
    """``the one its update used``; of a soft update (association probabilities, PHD weights) in which that
    detection carried less than half: ``one of the detections its update used (m2 p 0.37, m7 p 0.30, missed p
    0.34)`` (world3 scene-1100 megvii jpda false_track:1: "the one its update used" of a p 0.37 share)."""
    use = o.use
    if use is None or use.mode not in (UseMode.PROBABILITIES, UseMode.WEIGHTS) or o.on is None:
        return "the one its update used"
    share = dict(use.shares).get(o.on.meas)
    if share is not None and share >= 0.5:
        return "the one its update used"
    parts = ", ".join(f"{meas_name(m)} {share_text(x, use.mode)}" for m, x in use.shares[:3])
    more = f" +{len(use.shares) - 3} more" if len(use.shares) > 3 else ""
    missed = f"p {use.missed:.2f}" if use.mode is UseMode.PROBABILITIES else f"{100 * use.missed:.0f} %"
    lead = "one of the detections its update used" if share is not None else "the one its box carries"
    return f"{lead} ({parts}{more}, missed {missed})"


def _false_track(f: Finding) -> list[str]:
    o: FalseOutput = f.false_output
    tests = {b.rule for b in f.blame}
    if Rule.TRACK_INTERPOLATED in tests:
        between = f" between its boxes at frames {o.between[0]} and {o.between[1]}" if o.between else ""
        why = "was not output"
        if Rule.TRACK_DROPPED in tests:
            why = "was output, but " + _dropped_its_box(o.evaluated, f.frame)
        head = (
            f"at frame {f.frame} track {o.track_id} ({f.class_name}) {why}: the evaluation interpolated it{between}, "
            "and that box matched no object"
        )
    else:
        head = f"at frame {f.frame} track {o.track_id} ({f.class_name}) was output on "
        if f.output_only:
            head += _output_on_text(f, f.frame, o.track_id, o.on)
        else:
            head += f"detection {_near_text(o.on)}" if o.on is not None else "no detection this frame (a predicted box)"
            if o.on is not None and o.on.distance_m >= OFF_BOX_M:  # a filtered box between prediction and detection
                head = (
                    f"at frame {f.frame} track {o.track_id} ({f.class_name}) was output {o.on.distance_m:.1f} m from "
                    f"detection {_near_text(o.on)}, {_the_one_used(o)}"
                )
    parts = [head]
    if o.nearest_own is not None:
        gt_id, d, g = o.nearest_own
        on = f"{f.class_name} GT {short_id(gt_id)} lies {d:.1f} m away"
        if Rule.NO_EVAL_BOX in tests:
            parts.append(
                f"{on}, but the evaluation has no box for it here ({_no_box_reason(g, o.kept_around)}): a track on "
                "it is false"
            )
        elif Rule.INTERPOLATED in tests:
            parts.append(
                f"{on}, but the evaluation has it interpolated {g.offset_m:.1f} m from the annotation, out of the "
                f"track's reach{_swap_reach(g, o.output_xy_m)}"
            )
        elif o.object_missed:  # the evaluation matched the object to no track: nothing was matched instead
            parts.append(f"{on}, but the evaluation matched neither to the other (it counted the object missed)")
        else:
            other = f" (track {o.matched_instead})" if o.matched_instead is not None else ""
            parts.append(f"{on} and the evaluation matched it to another track{other}: two tracks on one object")
            if o.beside_untracked is not None:  # audit truth52 (world8): a pedestrian box on a stroller
                parts.append(f"the track's box lay nearer {untracked_text(o.beside_untracked)}")
            if o.twins:  # audit truth50 (world6, a detector without NMS): not the tracker's doing alone
                n = "two" if len(o.twins) == 2 else str(len(o.twins))
                what = ", ".join(meas_name(m) for m in o.twins)
                parts.append(f"the detector gave it {n} {f.class_name} detections within {NEAR_M:.0f} m ({what})")
    elif o.nearest_any is not None:
        gt_id, cls, d = o.nearest_any
        what = "the detector gave it the wrong class" if o.on is not None else "the track coasted onto it"
        if o.on is None and o.coasted_from is not None:  # audit truth51 (world7): not onto it, on with it
            x, m = o.coasted_from
            what = (
                f"the track coasted on with it from {meas_name(m)} at frame {x}, a {f.class_name} detection of it: "
                "the detector gave it the wrong class"
            )
        if f.output_only and o.on is None:
            what = "the tracker output a box there without a detection of its class under it"
        parts.append(
            f"no {f.class_name} GT lies within {NEAR_M:.0f} m, but GT {cls} {short_id(gt_id)} does ({d:.1f} m): {what}"
        )
    elif o.on is not None and o.detection_near is not None:
        gt_id, cls, d, box = o.detection_near
        parts.append(
            f"no object of a tracked class lies within {NEAR_M:.0f} m of the box, but {meas_name(o.on.meas)} lay "
            f"{ego_distance_text(d, NEAR_M, 2)} m from {cls} GT {short_id(gt_id)}: the track's box lay "
            f"{ego_distance_text(box, NEAR_M, 2)} m from that object, beyond the evaluation's {NEAR_M:.0f} m"
        )
    elif o.part_of is not None:  # audit truth50 (world6): a truck's trailer box is no "box where no object was"
        what = "the detection" if o.on is not None else "the box"
        on_what = "" if is_untracked(o.part_of) else "part of "  # audit truth52 (world8): a car box on an ambulance
        parts.append(
            f"no object of a tracked class lies within {NEAR_M:.0f} m, but {what} lies on {on_what}"
            f"{_part_text(o.part_of)}"
        )
    elif o.on is not None:
        parts.append(f"no object of a tracked class lies within {NEAR_M:.0f} m: a detection of no tracked object")
    elif Rule.TRACK_INTERPOLATED in tests:
        parts.append(f"no object of a tracked class lies within {NEAR_M:.0f} m of it{_drifted_text(f, o, 'box')}")
    elif o.drifted_from is not None:  # dev set scene-0916 false_track:14: it ran past an object it had been on
        parts.append(f"no object of a tracked class lies within {NEAR_M:.0f} m{_drifted_text(f, o, 'predicted box')}")
    else:
        parts.append(
            f"no object of a tracked class lies within {NEAR_M:.0f} m: the tracker output a box where no tracked "
            "object was"
        )
    ev = o.evaluated
    if ev is not None and ev.averaged_score is not None and o.threshold is not None:
        parts.append(
            f"the evaluation counted the track: {averaged_text(ev)}, is at least the {f.class_name} threshold "
            f"{o.threshold:.3f}"
        )
    return parts


def _drifted_text(f: Finding, o: FalseOutput, box: str) -> str:
    """``: the track's predicted box lies 2.1 m from bicycle GT 9348e3, which it was last within 2 m of at frame
    27; the evaluation has no box for that one here (it had no LiDAR ...)``: the object a false box on no detection
    ran off (``FalseOutput.drifted_from``; "" without one)."""
    if o.drifted_from is None:
        return ""
    gt_id, d, x, g = o.drifted_from
    unseen = ""
    if g is None or g.status is GtStatus.NO_BOX:
        unseen = f"; the evaluation has no box for that one here ({_no_box_reason(g)})"
    elif g.status is GtStatus.BEYOND_RANGE:
        unseen = f"; that one is beyond the evaluation's {g.range_m:g} m range here, so it has no box for it"
    if x == f.frame:  # the track's own box here, dropped by the evaluation, lay on it (``drifted_off``)
        return (
            f": the box the evaluation interpolated lies {d:.1f} m from {f.class_name} GT {short_id(gt_id)}, though "
            f"the track's own box here, the one the evaluation dropped, lay within {NEAR_M:.0f} m of it{unseen}"
        )
    return (
        f": the track's {box} lies {d:.1f} m from {f.class_name} GT {short_id(gt_id)}, which it was last within "
        f"{NEAR_M:.0f} m of at frame {x}{unseen}"
    )


def box_on_text(on: BoxOn, class_name: str) -> str:
    """How a results file's box was placed on its detection: ``its box carries m3's size, heading and height`` or
    ``m3 is the nearest car detection, 0.31 m from its box (none carries its size, heading and height)``."""
    m = meas_name(on.meas)
    if on.how is OnHow.SAME_BOX:
        return f"its box carries {m}'s size, heading and height"
    return (
        f"{m} is the nearest {class_name} detection, {on.distance_m:.2f} m from its box (none carries its size, "
        "heading and height)"
    )


def _output_on_text(f: Finding, frame: int, track_id: int, on: Near | None) -> str:
    """Where a results file's box was, in words: ``detection m3 (car, score 0.80; its box carries ...)`` or ``no
    detection (...)``."""
    placed = f.box_on(frame, track_id)
    if on is None or placed is None:
        return (
            f"no detection (none of its class carries its box's size, heading and height or lies within "
            f"{NEAREST_M:g} m of it)"
        )
    return (
        f"detection {meas_name(on.meas)} ({on.class_name}, score {on.score:.2f}; {box_on_text(placed, f.class_name)})"
    )


def _no_box_reason(g: GtFrame | None, kept: tuple[int | None, int | None] | None = None) -> str:
    if g is None:
        return "it is not annotated here"
    if g.status is GtStatus.BEYOND_RANGE:
        return (
            f"it lies {ego_distance_text(g.ego_distance_m, g.range_m, 2)} m from the ego vehicle, beyond the "
            f"evaluation's {g.range_m:g} m range, and {_kept_sides_text(kept)}"
        )
    why = f"it had {g.dropped.value}" if g.dropped is Dropped.NO_POINTS else f"it was {g.dropped.value}"
    return f"{why}, so its box was dropped, and no box could be interpolated"


def _kept_sides_text(kept: tuple[int | None, int | None] | None) -> str:
    """Why the evaluation could not interpolate the object's box here: the side on which it kept none of its boxes
    (``FalseOutput.kept_around``)."""
    if kept is None:
        return "no box could be interpolated"
    before, after = kept
    if before is not None and after is None:
        return f"the evaluation keeps none of its boxes after frame {before} to interpolate one from"
    if after is not None and before is None:
        return f"the evaluation keeps none of its boxes before frame {after} to interpolate one from"
    return "the evaluation keeps none of its boxes at any frame" if before is None else "no box could be interpolated"


def _covering(f: Finding, s: Sighting) -> str:
    """``track 50 lay within 2 m of it and was counted, but the evaluation matched it to another object: one track
    for two objects`` (``tracks 50, 49 ... were ... each``): the counted tracks on the object that the evaluation
    matched to another object (``findings.covering``)."""
    ids = [str(o.track_id) for o in covering(s, f.reach)]
    several = len(ids) > 1
    return (
        f"{'tracks' if several else 'track'} {', '.join(ids)} lay within {NEAR_M:.0f} m of it and "
        f"{'were' if several else 'was'} counted, but the evaluation matched {'each' if several else 'it'} to "
        "another object: one track for two objects"
    )


def _not_counted_on_it(f: Finding, s: Sighting) -> list[str]:
    """The tracks output on the object whose averaged score the class threshold did not reach."""
    return [
        f"track {o.track_id} was output on it (score {o.score:.2f}), but {averaged_text(o.evaluated)}, is below the "
        f"{f.class_name} threshold {o.threshold:.3f}: the evaluation did not count it"
        for o in s.on_it
        if not o.counted and o.evaluated is not None and o.evaluated.averaged_score is not None
    ]


def _dropped_on_it(f: Finding, s: Sighting) -> list[str]:
    """The tracks output on the object whose box there the evaluation's range or bike-rack filter dropped, with
    the filter that did (the box's own distance to the ego vehicle: the object's may lie on the other side of the
    range, dev set scene-0757 pointpillars ``pmbm`` miss at frame 37, motorcycle 39.8 m away, the track's box
    40.1 m)."""
    out = []
    for o in s.on_it:
        dropped = None if o.evaluated is None else o.evaluated.dropped_at(f.frame)
        if dropped is not None:
            out.append(
                f"track {o.track_id} was output on it, but its box there {dropped_where(dropped)}: the evaluation "
                "dropped that box"
            )
    return out


def dropped_where(dropped: DroppedBox) -> str:
    """Where a box the devkit's filter dropped lay, by the filter that dropped it: ``lies 40.1 m from the ego
    vehicle, beyond the evaluation's 40 m range`` (its own distance, as the devkit measured it) or ``lies in a bike
    rack``."""
    if dropped.reason is Dropped.BEYOND_RANGE:
        return (
            f"lies {ego_distance_text(dropped.ego_distance_m, dropped.range_m)} m from the ego vehicle, beyond the "
            f"evaluation's {dropped.range_m:g} m range"
        )
    return "lies in a bike rack"


def _dropped_its_box(ev: TrackEval | None, frame: int) -> str:
    """``its box lay 40.2 m from the ego vehicle, beyond the evaluation's 40 m range and was dropped`` where the
    track's evaluation is at hand, else ``the evaluation dropped its box`` (which filter not known here)."""
    dropped = None if ev is None else ev.dropped_at(frame)
    return "the evaluation dropped its box" if dropped is None else f"its box {dropped_lay(dropped)} and was dropped"


def dropped_lay(dropped: DroppedBox) -> str:
    """``dropped_where`` in the past tense: ``lay 43.3 m from the ego vehicle, beyond ...``."""
    return "lay" + dropped_where(dropped).removeprefix("lies")


def _out_of_reach_on_it(f: Finding, s: Sighting) -> list[str]:
    """The counted tracks output on the object that the evaluation's interpolated box put out of the devkit's reach
    (``f.reach``, with the blame ``INTERPOLATED``): a miss beside a track that was on the annotation."""
    r = f.reach
    if r is None:
        return []
    away = [o for o in s.on_it if o.counted and o.track_id in r.near_annotated and o.track_id not in r.near_evaluated]
    return [
        f"at frame {f.frame} track {o.track_id} was output {o.distance_m:.1f} m from the annotated object, but the "
        f"evaluation scored the object at a box it interpolated {r.offset_m:.1f} m from the annotation, out of the "
        f"track's reach{_still_away(s.evaluated, o.xy_m)}"
        for o in away
    ]


def _went_unshown(s: Sighting) -> list[str]:
    """``track 41 was not output on it``: the track the object's detection went to (or started) was not among
    those output on the object, said wherever the detection's destination is (a box tracker's tentative track,
    a PHD label below extraction), lest "started new track 41" read as the object being covered."""
    went = s.went
    if (
        went is not None
        and went.went in (Went.TRACK, Went.NEW_TRACK)
        and went.track_id not in {o.track_id for o in s.on_it}
    ):
        return [f"track {went.track_id} was not output on it"]
    return []


def _miss(f: Finding) -> list[str]:
    s = f.sighting(f.frame)
    if s is None or f.gt_id is None:
        return []
    name = f"{f.class_name} GT {short_id(f.gt_id)}"
    mode = UseMode(f.mode)
    inside = f"{points_text([s])} in its box"
    parts = []
    if s.undetected and s.points == 0:
        carried = "" if s.on_it else ", and no track carried it through"  # said only of an object no track was on
        parts.append(
            f"at frame {f.frame} {name} had no LiDAR or radar points (no detector could see it) and "
            f"{no_detection([s])}{carried}"
        )
    elif s.undetected and s.nearest_any is None and s.in_box is not None:  # audit truth50: a split truck
        n = s.in_box
        parts.append(
            f"at frame {f.frame} the detector gave no detection of a tracked class within {NEAR_M:.0f} m of {name} "
            f"({inside}), but {n.class_name} {meas_name(n.meas)} (score {n.score:.2f}) lay inside its box, "
            f"{n.distance_m:.1f} m from its centre: the detector saw part of it"
        )
    elif s.undetected and s.nearest_any is None and s.untracked_name is not None:  # audit truth52 (world8)
        u_name, u_score, u_m = s.untracked_name
        parts.append(
            f"at frame {f.frame} the detector gave no detection of a tracked class within {NEAR_M:.0f} m of {name} "
            f"({inside}), but a {u_name} box (score {u_score:.2f}) {u_m:.1f} m away: the detector gave it a class "
            "no tracker takes"
        )
    elif s.undetected and s.nearest_any is None and s.off is not None:  # audit truth51 (world7): a box 3-6 m off
        n = s.off
        parts.append(
            f"at frame {f.frame} the detector gave no detection of a tracked class within {NEAR_M:.0f} m of {name} "
            f"({inside}); the nearest {n.class_name} detection, {meas_name(n.meas)} (score {n.score:.2f}), lay "
            f"{n.distance_m:.1f} m away, nearer it than any other annotated object: the detector missed it or placed "
            "its box that far off"
        )
    elif s.undetected and s.nearest_any is None:
        parts.append(
            f"at frame {f.frame} the detector gave no detection of a tracked class within {NEAR_M:.0f} m of {name} "
            f"({inside}): the detector missed it"
        )
    elif s.undetected:
        parts.append(
            f"at frame {f.frame} the detector gave {name} ({inside}) {no_detection([s])}: the detector missed it"
        )
    elif s.nearest_own is None and s.seen.class_name != f.class_name:
        n = s.seen
        parts.append(
            f"at frame {f.frame} the detector gave no {f.class_name} detection{_of_its_own(s)} within "
            f"{NEAR_M:.0f} m of {name} ({inside}), but a {n.class_name} detection, {meas_name(n.meas)} "
            f"(score {n.score:.2f}), {n.distance_m:.1f} m away: the detector gave it the wrong class"
        )
    elif s.nearest_own is None:
        n = s.seen
        parts.append(
            f"at frame {f.frame} detection {meas_name(n.meas)} (score {n.score:.2f}) lay {n.distance_m:.1f} m from "
            f"{name} but was dropped by preprocessing (score threshold or NMS)"
        )
    else:
        n = s.nearest_own
        parts.append(
            f"at frame {f.frame} detection {meas_name(n.meas)} (score {n.score:.2f}) lay {n.distance_m:.1f} m from "
            f"{name} and {went_phrase(s.went, mode)}"
        )
        parts += _went_unshown(s)
    parts += _not_counted_on_it(f, s)
    if s.nearest_own is not None and not s.on_it:
        parts.append(f"no {f.class_name} track was output within {NEAR_M:.0f} m of it")
    if any(b.rule is Rule.COVERED_TWO for b in f.blame):
        parts.append(_covering(f, s))
    g = s.evaluated
    if g is not None and g.status is GtStatus.INTERPOLATED and g.offset_m >= 0.05:
        parts.append(f"the evaluation scored it at a box it interpolated, {g.offset_m:.1f} m from the annotation")
        parts.append(_between(g).removeprefix(" "))
    parts += _out_of_reach_on_it(f, s)
    parts += _dropped_on_it(f, s)
    if g is not None and abs(g.ego_distance_m - g.range_m) <= 5.0:
        side = "inside" if g.ego_distance_m < g.range_m else "beyond"
        parts.append(
            f"the object lies {ego_distance_text(g.ego_distance_m, g.range_m)} m from the ego vehicle, {side} the "
            f"evaluation's {g.range_m:g} m range"
        )
    return parts


def ego_distance_text(distance_m: float, range_m: float, decimals: int = 1) -> str:
    """The distance to one decimal, or to as many as it takes (up to 4) not to print the range itself: ``39.98``
    beside a 40 m range, not ``40.0`` (audit truth53, world9: "it lies 40.0 m from the ego vehicle, inside the
    evaluation's 40 m range" beside a track box there "beyond the evaluation's range")."""
    for nd in range(decimals, max(decimals, 4) + 1):
        text = f"{distance_m:.{nd}f}"
        if float(text) != range_m:
            return text
    return text


def _of_its_own(s: Sighting) -> str:
    """`` of its own`` where a detection of its class lay within reach, nearer another annotated object."""
    return " of its own" if s.neighbours_own is not None else ""


def _also_near(f: Finding, s: Sighting | None, t: int) -> str:
    """``, though counted track 72 lay 0.9 m from it (matched to GT daa05e)``: the other counted tracks output
    within ``NEAR_M`` of a coalescence's object that the evaluation matched to another object at the frame (audit
    truth54, dev set scene-0061 centerpoint jpda: three pedestrians, two tracks; "no counted track covered" it, said
    with a counted track 0.9 m from it)."""
    if s is None:
        return ""
    near = [
        (o, g)
        for o in sorted(s.on_it, key=lambda o: o.distance_m)
        if o.track_id != t and o.counted and o.evaluated is not None
        if (g := o.evaluated.matched_at(f.frame)) is not None and g != f.gt_id
    ]
    said = [f"track {o.track_id} lay {o.distance_m:.1f} m from it (matched to GT {short_id(g)})" for o, g in near]
    return f", though counted {' and '.join(said)}" if said else ""


def _coalescence(f: Finding) -> list[str]:
    s = f.sighting(f.frame)
    t = f.track_ids[0]
    covered = ", ".join(f"GT {short_id(g)}" for g in f.covered)
    tests = {b.rule for b in f.blame}
    if Rule.TRACK_INTERPOLATED in tests:
        ev = next((o.evaluated for o in s.on_it if o.track_id == t), None) if s is not None else None
        why = "was not output"
        if Rule.TRACK_DROPPED in tests:
            why = "was output, but " + _dropped_its_box(ev, f.frame)
        whose = f"track {t} {why}; the box the evaluation interpolated for it in its place"
    else:
        whose = f"track {t}"
    parts = [
        f"at frame {f.frame} {whose} was matched to {covered} and also lay within {NEAR_M:.0f} m of "
        f"GT {short_id(f.gt_id or '')}, which the evaluation matched to no track{_also_near(f, s, t)}"
    ]
    if s is None:
        return parts
    g = s.evaluated
    if any(b.rule is Rule.INTERPOLATED for b in f.blame) and g is not None and g.status is GtStatus.INTERPOLATED:
        parts.append(
            f"the evaluation scored GT {short_id(f.gt_id or '')} at a box it interpolated, {g.offset_m:.1f} m from "
            f"the annotation;{_between(g)}".removesuffix(";")
        )
        parts += _out_of_reach_on_it(f, s)
    mode = UseMode(f.mode)
    if s.undetected:
        parts.append(
            f"the detector gave GT {short_id(f.gt_id or '')} no detection of its own within {NEAR_M:.0f} m "
            f"({points_text([s])}): one object seen, or none, where there were two"
        )
    elif s.nearest_own is not None:
        n = s.nearest_own
        parts.append(
            f"its detection {meas_name(n.meas)} (score {n.score:.2f}, {n.distance_m:.1f} m away) "
            f"{went_phrase(s.went, mode)}"
        )
        parts += _went_unshown(s)
    elif s.seen.class_name != f.class_name:
        n = s.seen
        parts.append(
            f"the detector saw it only as another class ({n.class_name} {meas_name(n.meas)}, score {n.score:.2f})"
        )
    else:
        n = s.seen
        parts.append(
            f"its detection {meas_name(n.meas)} (score {n.score:.2f}, {n.distance_m:.1f} m away) was dropped by "
            "preprocessing (score threshold or NMS)"
        )
    return parts + _not_counted_on_it(f, s) + _dropped_on_it(f, s)  # the evaluation's tests on its own tracks


def _others(f: Finding) -> list[str]:
    out = []
    for o in f.others:
        counted = [x for x in o.on_it if x.counted]
        who = _other_name(f, o)
        if o.unscored:  # its failures of the class are what matching every box finds, not the devkit's counts
            out.append(
                f"{who} reached no score threshold at the evaluation's lowest recall for {f.class_name}s: the "
                f"evaluation counted none of its {f.class_name} tracks"
            )
        elif f.gt_id is None:  # a false track on no object: the same mistake at the same place, or not
            same = (
                f"had a false {f.class_name} track here too"
                if o.failed_same
                else f"had no false {f.class_name} track here"
            )
            out.append(f"{who} {same}")
        elif o.failed_same:
            out.append(f"{who} failed here too")
        elif o.switched:  # a failure of another kind on the object: not "did not fail"
            took = f": the evaluation matched the object to its track {o.matched}" if o.matched is not None else ""
            out.append(f"{who} switched the object's track here instead{took}")
        elif counted and o.matched in {x.track_id for x in counted}:  # only the track it matched: the others near
            # the annotation went to neighbours (a crowd), and naming them would put them on this object
            held = [x for x in counted if x.track_id == o.matched]
            out.append(f"{who} did not fail here: {_its_tracks(held)} output on the object and counted")
        elif counted and o.missed and all(_beside(x, f.frame) for x in counted):  # on a neighbour, matched there
            out.append(f"{who} did not match the object here: {_on_neighbours(f, counted)}")
        elif counted and o.missed:  # on the annotation, but the evaluation matched them elsewhere or to nothing
            counted = [x for x in counted if not _beside(x, f.frame)]  # a neighbour's track is not named on this one
            elsewhere = " and ".join(
                f"track {x.track_id} to "
                + (f"{f.class_name} GT {short_id(g)}" if (g := _matched_at(x, f.frame)) is not None else "no object")
                for x in counted
            )
            out.append(
                f"{who} did not match the object here: {_its_tracks(counted)} output on the object and counted, "
                f"but the evaluation matched {elsewhere}{_scored_out_of_reach(f, counted)}"
            )
        elif o.matched is not None:  # matched to a track of its off the annotation, or to a box the devkit interpolated
            out.append(f"{who} did not fail here: the evaluation matched the object to its track {o.matched}")
        elif o.missed:  # its evaluation counted a miss there: it lost the object too
            out.append(f"{who} had no counted track on the object here either")
        else:
            out.append(f"{who} did not have this failure")
    return out


def _of_no_object(part: tuple[str, str, float] | None = None) -> str:
    """What a detection with no annotated object of a tracked class within ``NEAR_M`` was (audit truth49: a false
    bus's detections), or, inside an object's box (``part``), a sight of part of it (audit truth50: a truck's
    trailer box)."""
    if part is not None:
        return f"a detection of {'' if is_untracked(part) else 'part of '}{_part_text(part)}"
    return f"a detection of no object (none of a tracked class within {NEAR_M:.0f} m)"


def _used_of_no_object(pairs: Sequence[tuple[int, int]]) -> str:
    """``of these, m24 (frames 15, 16) and m29 (frame 17) were detections of no object (none of a tracked class within
    2 m)``: the detections the soft updates told just before used."""
    by: dict[int, list[int]] = {}
    for frame, m in sorted(pairs):
        by.setdefault(m, []).append(frame)
    items = [f"{meas_name(m)} ({frames_text(frames)})" for m, frames in sorted(by.items(), key=lambda kv: kv[1][0])]
    joined = items[0] if len(items) == 1 else ", ".join(items[:-1]) + " and " + items[-1]
    what = "was a detection" if len(items) == 1 else "were detections"
    return f"of these, {joined} {what} of no object (none of a tracked class within {NEAR_M:.0f} m)"


def _part_text(part: tuple[str, str, float]) -> str:
    """``truck GT ecf44b (inside its box, 3.5 m from its centre, beyond the evaluation's 2 m)``."""
    if is_untracked(part):
        return untracked_text(part)
    gt_id, cls, d = part
    where = f"inside its box, {d:.1f} m from its centre, beyond the evaluation's {NEAR_M:.0f} m"
    return f"{cls} GT {short_id(gt_id)} ({where})"


def _beside(o: OnObject, frame: int) -> bool:
    """Whether track ``o`` (within ``NEAR_M`` of the object) lay nearer the annotation of the object the evaluation
    matched it to at ``frame``: it was that neighbour's track, not this object's."""
    return _matched_at(o, frame) is not None and o.matched_m is not None and o.matched_m < o.distance_m


def _on_neighbours(f: Finding, on: Sequence[OnObject]) -> str:
    """``its track 55 was output on the car beside it and counted: the evaluation matched track 55 to car GT 01ffcf,
    0.6 m from the track (1.1 m from this one)``: other runs' tracks within ``NEAR_M`` of the object that lay nearer
    the neighbour the evaluation matched them to (world4's parked pair 1.7 m apart: "output on the object" put the
    neighbour's track on this one)."""
    where = f"the {f.class_name} beside it" if len(on) == 1 else "the objects beside it"
    matched = " and ".join(
        f"track {x.track_id} to {f.class_name} GT {short_id(_matched_at(x, f.frame) or '')}, {x.matched_m:.1f} m "
        f"from the track ({x.distance_m:.1f} m from this one)"
        for x in on
    )
    return f"{_its_tracks(on)} output on {where} and counted: the evaluation matched {matched}"


def _scored_out_of_reach(f: Finding, on: Sequence[OnObject]) -> str:
    """`` (the box it scored for this object, interpolated 1.5 m from the annotation, lay 2.3 m from track 120)``:
    where the evaluation scored the object at a box it interpolated out of the devkit's 2 m of each of ``on`` (other
    runs' tracks output near the annotation), so they could not match it whatever else lay near; "" otherwise
    (world3's pedestrian queue, and the dev set: "on the object" read as a match the devkit gave away)."""
    s = f.sighting(f.frame)
    g = s.evaluated if s is not None else None
    if g is None or g.status is not GtStatus.INTERPOLATED or g.evaluated_xy_m is None:
        return ""
    gone = [(x, math.dist(x.xy_m, g.evaluated_xy_m)) for x in on if x.xy_m is not None]
    if not gone or len(gone) < len(on) or any(d < NEAR_M for _, d in gone):
        return ""
    lay = " and ".join(f"{d:.1f} m from track {x.track_id}" for x, d in gone)
    return f" (the box it scored for this object, interpolated {g.offset_m:.1f} m from the annotation, lay {lay})"


def _its_tracks(on: Sequence[OnObject]) -> str:
    """``its track 12 was`` / ``its tracks 12, 14 were``."""
    ids = ", ".join(str(x.track_id) for x in on)
    return f"its track {ids} was" if len(on) == 1 else f"its tracks {ids} were"


def _matched_at(o: OnObject, frame: int) -> str | None:
    """The object the evaluation matched the track ``o`` to at ``frame`` (None: none, or not evaluated)."""
    return o.evaluated.matched_at(frame) if o.evaluated is not None else None


def _other_name(f: Finding, o: OtherRun) -> str:
    """``pmbm on the same detections``; what a results file was given is not known: ``cv's results``, and beside
    one, ``gnnpmb on the given detections``."""
    if o.output_only:
        return f"{o.tracker}'s results"
    return f"{o.tracker} on the given detections" if f.output_only else f"{o.tracker} on the same detections"


def plain(markdown: str) -> str:
    """A rendered line without its markdown emphasis (``**Why**`` -> ``Why``), for a terminal."""
    return markdown.replace("**", "")


def on_object_text(o: OnObject, frame: int | None = None, gt_id: str | None = None) -> str:
    """A track output on an object, for the object's table: ``62 (0.92; track average 0.69)``; with the frame
    and the object, a track the evaluation matched to another object there says so (``; matched to GT 4f67ad``):
    in a crowd a track within ``NEAR_M`` of one object is often another's."""
    ev = o.evaluated
    other = ev.matched_at(frame) if ev is not None and frame is not None else None
    elsewhere = f"; matched to GT {short_id(other)}" if other is not None and other != gt_id else ""
    if o.threshold is None:
        return f"{o.track_id} ({o.score:.2f}{elsewhere})"
    if ev is None or ev.averaged_score is None:
        return f"{o.track_id} ({o.score:.2f}; not evaluated: beyond the class range)"
    average = beside_threshold(ev.averaged_score, o.threshold)
    return f"{o.track_id} ({o.score:.2f}; track average {average}" + (
        ", not counted)" if not o.counted else f"{elsewhere})"
    )


def beside_threshold(value: float, threshold: float) -> str:
    """A track's average score printed beside its class threshold, which the table's heading gives to 3 decimals:
    3 decimals too, or 4 where 3 would put it on the wrong side of the printed threshold (dev set scene-1100
    centerpoint prob3dmot fragmentation:1: "track average 0.61" of a counted track, threshold 0.613)."""
    shown, limit = round(value, 3), round(threshold, 3)
    if (value >= threshold) == (shown >= limit):
        return f"{value:.3f}"
    return f"{value:.4f}"


def points_text(sightings: Sequence[Sighting]) -> str:
    """``12 LiDAR and radar points`` (a span over several frames: ``2–5``), or where any box had radar returns,
    the two counts apart: ``0 LiDAR and 3 radar points`` (a box with radar returns only is empty to a LiDAR
    detector, which the sum would hide)."""
    if not any(s.radar_points for s in sightings):
        return f"{_span([s.points for s in sightings])} LiDAR and radar points"
    lidar, radar = _span([s.lidar_points for s in sightings]), _span([s.radar_points for s in sightings])
    return f"{lidar} LiDAR and {radar} radar points"


def sighting_points(s: Sighting) -> str:
    """The table's "points in box" cell: the count (``0 LiDAR + 3 radar`` where the box had radar returns) and
    how the evaluation scored the object there."""
    g = s.evaluated
    n = f"{s.lidar_points} LiDAR + {s.radar_points} radar" if s.radar_points else f"{s.points}"
    if g is None:
        return n
    match g.status:
        case GtStatus.SCORED:
            return n
        case GtStatus.INTERPOLATED:
            return f"{n}: interpolated by the evaluation ({g.offset_m:.1f} m off)"
        case GtStatus.BEYOND_RANGE:
            return f"{n}: beyond the {g.range_m:g} m range, not scored"
        case GtStatus.NO_BOX:
            return f"{n}: no box ({g.dropped.value if g.dropped else 'dropped'}), not scored"
    raise AssertionError(g.status)
