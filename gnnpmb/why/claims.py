"""What a finding asserts, as atomic typed claims, so each can be checked against facts gathered apart from the
explanation code (the tracker's submission, its raw events, the devkit's evaluation): ``tools.truth.fields`` does.

Every sentence of ``words`` is rendered from the fields these claims are drawn from; a claim that fails is a
sentence a user would catch being wrong.
"""

from __future__ import annotations

from dataclasses import dataclass

from gnnpmb.why.findings import Finding


@dataclass(frozen=True, slots=True)
class Claim:
    """One assertion: ``what`` it is about (a ``CLAIM_KINDS`` name), the frame (-1: none), and its values."""

    what: str
    frame: int
    values: tuple


CLAIM_KINDS = (
    "detection near",  # (gt, meas, class, score, distance_m, other gt): that detection lies that far from the object,
    # and nearer that other annotated object (None: the object's own detection)
    "no detection near",  # (gt,): no detection of a tracked class (any score) within NEAR_M of the object
    "nearest own",  # (gt, meas): the nearest kept detection of the failure's class within NEAR_M
    "no own near",  # (gt,): no kept detection of the class within NEAR_M
    "points",  # (gt, n): LiDAR + radar points in its box
    "went",  # (class, meas, went, track, share): where the detection went
    "output",  # (track, meas): the track was output, on detection meas (-1: without one)
    "not output",  # (track,)
    "output near",  # (track, gt, distance_m): its output box lies that far from the object
    "used",  # (class, track, ((meas, share), ...), missed): what its update used
    "existence",  # (class, track, value): after the update (None: it ended)
    "ended",  # (class, track, ending, hits, window)
    "gated",  # (class, track, ((meas, d2), ...)): detections in its gate with the d2 the tracker computed
    "born",  # (class, track, meas): the detection started the track
    "held since",  # (class, track): some kept PMBM hypothesis held the track after this frame's update, and
    # none before
    "chosen",  # (class, meas, chosen kind, chosen ref, cost, alternative kind, alternative ref, alt cost)
    "parent",  # (class, parent): the best hypothesis descends from this prior hypothesis
    "averaged score",  # (track, value, kept frames): the devkit's averaged score over the frames it kept
    "evaluated",  # (gt, status, evaluated xy or None)
    "kept around",  # (gt, before, after): the last frame before this one and the first after it at which the
    # evaluation kept the object's annotated box (None: none on that side)
    "false at",  # (track, frames): the evaluation counted it a false track at these frames
    "other failed",  # (tracker, kind, gt, place xy, failed): at the object (or, without one, the place)
    "other matched",  # (tracker, gt, track): that run's evaluation matched the object to this track (None: none)
    "other switched",  # (tracker, gt, switched): that run's evaluation switched the object's track at this frame
    "blame",  # (rule, frames): the stated test held at each frame
    "deciding",  # (track, gt, frames): the frames after the track was last output on the object, up to the failure
    "matched away",  # (track, gt, since, ((other gt, frames), ...)): the evaluation last matched the object before
    # this frame at frame since, to the track, and after it up to this frame matched the track to exactly these
    # other objects at these frames
    "output on",  # (track, meas, how, distance_m): a results file's box sits on that detection by ``foreign.box_on``
    "first output",  # (track,): a results file's track has its first box at this frame
)


def claims(f: Finding) -> list[Claim]:
    """Every claim ``f`` makes (``CLAIM_KINDS``)."""
    out: list[Claim] = []

    def add(what: str, frame: int, *values) -> None:
        out.append(Claim(what, frame, values))

    c = f.class_name
    for s in f.sightings:
        add("points", s.frame, f.gt_id, s.points)
        if s.nearest_any is None:
            add("no detection near", s.frame, f.gt_id)
        else:
            n = s.nearest_any
            other = n.on_other[0] if n.on_other is not None else None
            add("detection near", s.frame, f.gt_id, n.meas, n.class_name, n.score, n.distance_m, other)
        if s.nearest_own is None:
            add("no own near", s.frame, f.gt_id)
        else:
            add("nearest own", s.frame, f.gt_id, s.nearest_own.meas)
        if s.went is not None:
            add("went", s.frame, c, s.went.meas, s.went.went.value, s.went.track_id, s.went.share)
        if s.evaluated is not None:
            add("evaluated", s.frame, f.gt_id, s.evaluated.status, s.evaluated.evaluated_xy_m)
        for o in s.on_it:
            add("output", s.frame, o.track_id, o.meas)
            add("output near", s.frame, o.track_id, f.gt_id, o.distance_m)
            if o.evaluated is not None and o.evaluated.averaged_score is not None:
                add("averaged score", -1, o.track_id, o.evaluated.averaged_score, o.evaluated.kept)
    if f.lost is not None:
        lost = f.lost
        t = lost.track_id
        for s in lost.steps:
            if s.output is not None:
                add("output", s.frame, t, s.output.meas_index)
            else:
                add("not output", s.frame, t)
            if s.use is not None:
                add("used", s.frame, c, t, s.use.shares, s.use.missed)
            if s.ended is not None:
                add("ended", s.frame, c, t, s.ended.ending.value, s.ended.hits, s.ended.window)
            elif f.has_existence and s.posterior_existence is not None:
                add("existence", s.frame, c, t, s.posterior_existence)
            add("gated", s.frame, c, t, s.gated)
        if lost.held_until is not None:
            add("output near", lost.held_until, t, f.gt_id, None)
        add("deciding", f.frame, t, f.gt_id, f.deciding)
        if lost.matched_until is not None:
            away = tuple((a.gt_id, a.frames) for a in lost.matched_away)
            add("matched away", f.frame, t, f.gt_id, lost.matched_until, away)
        for x in f.deciding:
            step = lost.step(x)
            if step is None or step.output is None:
                add("not output", x, t)
        if lost.off is not None:
            add("output", f.frame, t, lost.off.meas)
            add("output near", f.frame, t, f.gt_id, lost.off.distance_m)
        if lost.evaluated is not None and lost.evaluated.averaged_score is not None:
            add("averaged score", -1, t, lost.evaluated.averaged_score, lost.evaluated.kept)
    if f.taker is not None:
        o = f.taker
        if f.output_only:
            add("first output", o.frame, o.track_id)
        elif o.meas >= 0:
            add("born", o.frame, c, o.track_id, o.meas)
        elif f.switch is not None:
            add("held since", o.frame, c, o.track_id)
        if o.false_frames:
            add("false at", -1, o.track_id, o.false_frames)
    for d in ([f.decision] if f.decision is not None else []) + list(f.key_decisions):
        ch = d.choice
        alt = ch.alternative
        add(
            "chosen",
            d.frame,
            c,
            int(ch.meas.ref),
            ch.chosen.kind.value,
            int(ch.chosen.ref),
            ch.chosen_cost,
            None if alt is None else alt.kind.value,
            None if alt is None else int(alt.ref),
            ch.alternative_cost,
        )
        if d.went >= 0 and d.born:
            add("born", d.frame, c, d.went, int(ch.meas.ref))
        elif d.went >= 0:
            add("went", d.frame, c, int(ch.meas.ref), "track", d.went, 1.0)
    for k in f.key_decisions:
        if k.alternative_took is not None and k.choice.alternative is not None:
            add("went", k.frame, c, k.alternative_took, "track", int(k.choice.alternative.ref), 1.0)
    if f.switch is not None:
        add("parent", f.switch.frame, c, f.switch.parent)
    if f.false_output is not None:
        o = f.false_output
        rules = {b.rule.name for b in f.blame}
        if "TRACK_INTERPOLATED" in rules:
            if "TRACK_DROPPED" not in rules:
                add("not output", f.frame, o.track_id)
            if o.between is not None:
                add("output", o.between[0], o.track_id, None)
                add("output", o.between[1], o.track_id, None)
        else:
            add("output", f.frame, o.track_id, o.on.meas if o.on is not None else -1)
        if o.evaluated is not None and o.evaluated.averaged_score is not None:
            add("averaged score", -1, o.track_id, o.evaluated.averaged_score, o.evaluated.kept)
        if o.nearest_own is not None:
            gt_id, d, g = o.nearest_own
            if "TRACK_INTERPOLATED" not in rules:
                add("output near", f.frame, o.track_id, gt_id, d)
            if g is not None:
                add("evaluated", f.frame, gt_id, g.status, g.evaluated_xy_m)
            if o.kept_around is not None:
                add("kept around", f.frame, gt_id, *o.kept_around)
    for other in f.others:
        add("other failed", f.frame, other.tracker, f.kind.value, f.gt_id, other.place_xy_m, other.failed_same)
        if f.gt_id is not None:
            add("other matched", f.frame, other.tracker, f.gt_id, other.matched)
            add("other switched", f.frame, other.tracker, f.gt_id, other.switched)
    for frame, track, on in f.boxes_on:
        add("output on", frame, track, on.meas, on.how.value, on.distance_m)
    for b in f.blame:
        add("blame", -1, b.rule, b.frames)
    return out
