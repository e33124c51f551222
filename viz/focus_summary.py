"""The summary document of a focus recording (``focus/summary``), laid out from the failure's ``Finding`` and the
trackers' facts.

The cause comes first: the failure in one line, the evaluation's note when it scored an interpolated box, the
**Why** and **Because** lines (``gnnpmb.why.words``), each tracker's key decisions and, with several trackers,
where they part. Then, per tracker: what each involved track did, the involved object's frames, each involved
track's frames, the update at the focus frame and the story lines about the involved tracks. Nothing here works
out a fact: it lays out what ``gnnpmb.why`` found.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass

from gnnpmb.eval.failures import short_id
from gnnpmb.events import AxisKind
from gnnpmb.focus import FocusTarget
from gnnpmb.focus_cameras import FocusSight
from gnnpmb.why.facts import Destination, Ending, TrackerFacts, TrackStep, UseMode, Went
from gnnpmb.why.findings import NEAR_M, Finding, Sighting
from gnnpmb.why.reason import Evidence, key_decisions, object_frames
from gnnpmb.why.story import StoryLine
from gnnpmb.why.words import (
    column_name,
    cost_brief,
    cost_value,
    destination_name,
    evaluation_lines,
    existence_text,
    frames_text,
    hits_text,
    key_text,
    meas_name,
    on_object_text,
    share_text,
    sighting_points,
    threshold_held,
    use_text,
    went_text,
    why_lines,
)
from viz.blueprint import FOCUS_TIMELINE
from viz.decisions import conflict_markdown

MAX_STORY_LINES = 40
MAX_KEY = 3
"""The summary's head names at most this many key decisions per tracker (the newest)."""
TABLE_FRAMES = 6
"""The frame tables show the focus frame and the TABLE_FRAMES frames before it."""


@dataclass(frozen=True, slots=True)
class TrackerView:
    """What the document shows of one tracker: its evidence (report, facts, run), whether its tracks have gates
    and existences, the story lines its logger logged, and the tracks it showed at least once."""

    evidence: Evidence
    has_gates: bool
    story: tuple[StoryLine, ...]
    shown_ever: frozenset[int]

    @property
    def facts(self) -> TrackerFacts:
        return self.evidence.facts


def focus_markdown(
    focus: FocusTarget,
    finding: Finding | None,
    views: Mapping[str, TrackerView],
    shown: range,
    scene,
    sight: FocusSight | None = None,
) -> str:
    """The summary document: the failure and its finding, the key decisions, where the trackers part, the ids
    (and which camera held the object in view, ``sight``; None: no cameras); per tracker a line per involved
    track, frame tables of the involved object and tracks, the update at the focus frame and the story."""
    lines = [f"# {focus.title}", ""]
    if finding is not None:
        lines += evaluation_lines(finding)
        lines += why_lines(finding)
    upto = range(shown.start, focus.frame_index + 1)
    for tracker, view in views.items():
        ids = set(focus.track_ids.get(tracker, ()))
        keys = key_decisions(view.evidence, scene, focus.class_name, ids, upto)[-MAX_KEY:]
        if keys:
            lines += [f"**Key decisions of {tracker}** (a detection an involved track could have taken):", ""]
            lines += [f"- {key_text(k)}" for k in keys] + [""]
    parting = _parting(focus, views)
    if parting:
        lines += [
            f"**Where the trackers part** at frame {focus.frame_index} (each detection an involved track took "
            "or could have taken, in every tracker):",
            "",
        ]
        lines += [f"- {line}" for line in parting] + [""]
    involved = [f"GT {short_id(g)}" for g in focus.gt_ids]
    involved += [f"{t}: tracks {', '.join(map(str, ids))}" for t, ids in focus.track_ids.items() if ids]
    lines += [
        f"**Involved** ({focus.class_name}): " + (" · ".join(involved) or "nothing else"),
        "",
        *camera_lines(sight),
        f"Opened at frame **{focus.frame_index}** on the `{FOCUS_TIMELINE}` timeline, which ends there; choose the "
        f"`frame` timeline in the time panel to step past it. Recorded frames: {shown.start}–{shown.stop - 1}. "
        "The tab *how to read the views* explains the boxes, lines and colours.",
        "",
    ]
    for tracker, view in views.items():
        ids = sorted(focus.track_ids.get(tracker, ()))
        lines.append(f"## {tracker}")
        lines += [f"- {line}" for line in _diagnosis(view, focus.class_name, ids, upto)]
        lines.append("")
        table = range(max(shown.start, focus.frame_index - TABLE_FRAMES), focus.frame_index + 1)
        for gt_id in focus.gt_ids:
            lines += _gt_markdown(
                focus, view, gt_id, object_frames(view.evidence, scene, focus.class_name, gt_id, table)
            )
        lines += _steps_markdown(view, focus.class_name, ids, table)
        lines += _update_markdown(view, focus.class_name, set(ids), focus.frame_index)
        story = [
            line
            for line in view.story
            if line.class_name == focus.class_name
            and line.frame <= focus.frame_index
            and line.level != "DEBUG"
            and set(line.track_ids) & set(ids)
        ]
        if story:
            lines.append("Story of the involved tracks:")
            lines.append("")
            lines += [f"- frame {line.frame}: {line.text}" for line in story[-MAX_STORY_LINES:]]
            lines.append("")
    return "\n".join(lines) + "\n"


def camera_lines(sight: FocusSight | None) -> list[str]:
    """Whether the focus object was inside a camera's view at the focus frame, and which (none: no cameras)."""
    if sight is None:
        return []
    what = "The focus place" if sight.track_id is None else f"Track {sight.track_id}"
    if sight.gt_id is not None:
        what = f"GT {short_id(sight.gt_id)}"
    if not sight.seen:
        return [f"**Cameras**: {what} was outside every camera's view at frame {sight.frame_index}.", ""]
    seen = ", ".join(f"{s.channel} ({s.distance_m:.0f} m away)" for s in sight.seen)
    return [
        f"**Cameras**: {what} was inside the view of {seen} at frame {sight.frame_index} (field of view only: "
        f"something may hide it); the camera view shows {sight.seen[0].channel}.",
        "",
    ]


def _parting(focus: FocusTarget, views: Mapping[str, TrackerView]) -> list[str]:
    """With several trackers: each detection of the focus frame that went to different places in different
    trackers (another kind of destination, or a track started by another detection: ``_same_place``), with an
    involved track chosen, next best or sharing it in one of them: each tracker's destination and, where it chose
    from a cost matrix, the cost and the next best."""
    if len(views) < 2:
        return []
    f, c = focus.frame_index, focus.class_name
    uses = {t: v.facts.use(f, c) for t, v in views.items()}
    choices = {}
    for t, v in views.items():
        d = v.facts.decisions(f, c)
        choices[t] = {int(ch.meas.ref): ch for conflict in (d.conflicts if d else ()) for ch in conflict.choices}
    metas = sorted({m for u in uses.values() if u is not None for m in u.destinations})
    out = []
    for m in metas:
        went = {t: (u.destinations.get(m) if u is not None else None) for t, u in uses.items()}
        if len({_same_place(t, d, views[t], c) for t, d in went.items()}) < 2:
            continue
        touches, parts = False, []
        for t in views:
            ids = set(focus.track_ids.get(t, ()))
            d, ch = went[t], choices[t].get(m)
            touches |= d is not None and d.track_id in ids
            mode = uses[t].mode if uses[t] is not None else UseMode.ASSIGNED
            text = destination_name(d, mode)
            if ch is None:
                arrow = "" if mode is UseMode.OUTPUT else " →"  # a results run: where its boxes are, not where it went
                parts.append(f"{t}: {meas_name(m)}{arrow} **{text}**")
                continue
            labels = [ch.chosen] if ch.alternative is None else [ch.chosen, ch.alternative]
            touches |= any(label.kind is AxisKind.TRACK and label.ref in ids for label in labels)
            other = ""
            held = threshold_held(ch.alternative, ch.alternative_cost, ch)
            if held is not None:  # a new-track column holding the tracker's cost threshold: no cost of a track
                other = f"; next a new track, {held}"
            elif ch.alternative is not None:
                brief = cost_brief(ch.alternative_terms)
                other = f"; next {column_name(ch.alternative)} {cost_value(ch.alternative_cost, ch)}"
                other += f" at {brief}" if brief else ""
            brief = cost_brief(ch.chosen_terms)
            chosen = threshold_held(ch.chosen, ch.chosen_cost, ch) or cost_value(ch.chosen_cost, ch) + (
                f" at {brief}" if brief else ""
            )
            parts.append(f"{t}: {meas_name(m)} → **{text}** ({chosen}{other})")
        if touches:
            out.append(" · ".join(parts))
    return out


def _same_place(tracker: str, d: Destination | None, view: TrackerView, class_name: str) -> object:
    """What a destination is across runs, whose track ids differ: its kind, and for an existing track the birth
    that started it (a track id of this run alone when no birth names it)."""
    if d is None or d.went is not Went.TRACK:
        return None if d is None else d.went
    return d.went, view.facts.origin(d.track_id, class_name) or (tracker, d.track_id)


def _diagnosis(view: TrackerView, class_name: str, track_ids: list[int], frames: range) -> list[str]:
    """One sentence per involved track, in the tracker's terms: when its update last used a detection, the frames
    since with nothing in its gate or with detections it did not use (and where they went), its existence (or
    PHD weight) then and at the end, how it ended, and whether it was output at the last frame."""
    out = []
    facts = view.facts
    for t in track_ids:
        steps = [s for f, s in sorted(facts.steps(t, class_name).items()) if f in frames]
        if not steps:
            continue
        parts = []
        born = next((s for s in steps if s.born_from is not None), None)
        if born is not None:
            parts.append(f"started by {meas_name(born.born_from)} at frame {born.frame}")
        used = [s for s in steps if s.used]
        if used:
            parts.append(f"last {use_text(used[-1])} at frame {used[-1].frame}")
        elif facts.output_only:
            parts.append(f"output on no detection at {frames_text([s.frame for s in steps])}")
        elif born is None or len(steps) > 1:
            parts.append(f"used no detection in {frames_text([s.frame for s in steps if s is not born])}")
        since = [s for s in steps if (not used or s.frame > used[-1].frame) and s is not born]
        empty = [s.frame for s in since if not s.gated and s.ended is None]
        if empty and view.has_gates:
            parts.append(f"nothing in its gate at {frames_text(empty)}")
        passed = [s for s in since if s.gated and not s.used]
        if passed:
            mode = facts.mode(class_name, frames)
            went = []
            for s in passed:
                nearest = s.gated[:2]
                sent = ", ".join(
                    f"{meas_name(m)} {went_text(facts.destination(s.frame, class_name, m), mode)}" for m, _ in nearest
                )
                more = f", +{len(s.gated) - 2} more" if len(s.gated) > 2 else ""
                went.append(f"{s.frame} ({sent}{more})")
            parts.append(
                f"detections in its gate went elsewhere at frame{'s' if len(passed) > 1 else ''} {'; '.join(went)}"
            )
        ended = next((s for s in steps if s.ended is not None), None)
        if ended is not None:
            e = ended.ended
            if e.hits >= 0:
                parts.append(f"{e.ending.value} at frame {ended.frame} ({hits_text(e.hits, e.window)})")
            elif e.ending is Ending.DELETED:
                parts.append(f"{e.ending.value} at frame {ended.frame}")
            else:
                parts.append(f"{e.ending.value} at frame {ended.frame} ({e.reason.value})")
        alive = [s for s in steps if s.posterior_existence is not None]
        if facts.has_existence and alive:
            word = "weight" if facts.mode(class_name, frames) is UseMode.WEIGHTS else "existence"
            peak = max(alive, key=lambda s: s.posterior_existence)
            last = alive[-1]
            if existence_text(peak.posterior_existence) == existence_text(last.posterior_existence):
                parts.append(f"{word} after update {existence_text(last.posterior_existence)} at frame {last.frame}")
            else:
                parts.append(
                    f"{word} after update {existence_text(peak.posterior_existence)} at frame {peak.frame} -> "
                    f"{existence_text(last.posterior_existence)} at frame {last.frame}"
                )
        at_last = steps[-1].frame == frames.stop - 1 and steps[-1].output is not None
        parts.append("output at the last frame" if at_last else "not output at the last frame")
        out.append(f"**track {t}**: " + "; ".join(parts) + ".")
    return out


def _gt_markdown(focus: FocusTarget, view: TrackerView, gt_id: str, seen: tuple[Sighting, ...]) -> list[str]:
    """The involved object frame by frame: points in its box and how the evaluation scored it, the nearest
    detection of its class preprocessing kept (a nearer duplicate NMS removed is not it: dev set scene-1077 megvii
    cphd, m26 0.1 m beside m20), or of another class, where the tracker sent it, and the tracks output on it with
    their scores and whether the evaluation counted them."""
    if not seen:
        return []
    mode = view.facts.mode(focus.class_name, range(seen[0].frame, seen[-1].frame + 1))
    rows = []
    for s in seen:
        if s.nearest_own is not None:
            n = s.nearest_own
            nearest = f"m{n.meas} at {n.distance_m:.1f} m (score {n.score:.2f})"
            sent = destination_name(s.went, mode)
        elif s.nearest_any is not None:
            n = s.nearest_any
            notes = []
            if n.class_name != focus.class_name:
                notes.append("another class")
            elif not n.kept:
                notes.append("dropped by preprocessing")
            if n.on_other is not None:  # nearer another object: that one's detection, not a sight of this one
                notes.append(f"{n.on_other[2]:.1f} m from {n.on_other[1]} GT {short_id(n.on_other[0])}")
            why = "".join(f", {note}" for note in notes[:1]) + "".join(f"; {note}" for note in notes[1:])
            nearest = f"none; m{n.meas} {n.class_name} at {n.distance_m:.1f} m (score {n.score:.2f}{why})"
            sent = "—"
        else:
            nearest, sent = "none", "—"
        on = ", ".join(on_object_text(o, s.frame, gt_id) for o in s.on_it) or "none"
        rows.append(f"| {s.frame} | {sighting_points(s)} | {nearest} | {sent} | {on} |")
    report = view.evidence.report
    threshold = report.threshold_of(focus.class_name)
    counted = (
        "every output box"
        if threshold is None
        else f"{focus.class_name} tracks whose score averaged over their frames within its range is >= {threshold:.3f}"
        " (its best-MOTA threshold)"
    )
    detected = [s.frame for s in seen if s.nearest_own is not None]
    sent_to = "output box on its detection" if mode is UseMode.OUTPUT else "sent to"
    rows_at = {s.frame for s in seen}
    gap = [x for x in range(seen[0].frame, seen[-1].frame) if x not in rows_at]  # it left view and came back
    unannotated = f"; not annotated at {frames_text(gap)}" if gap else ""
    return [
        f"**GT {short_id(gt_id)}**, in the {len(seen)} frames of the table ({seen[0].frame}–{seen[-1].frame}"
        f"{unannotated}): a kept "
        f"{focus.class_name} detection within {NEAR_M:.0f} m at "
        f"{frames_text(detected) if detected else 'no frame'}.",
        "",
        f"GT {short_id(gt_id)}, frame by frame (the evaluation counted {counted}):",
        "",
        f"| frame | points in box | nearest kept detection | {sent_to} | tracks output on it (score) |",
        "|---|---|---|---|---|",
        *rows,
        "",
    ]


def _used_cell(s: TrackStep) -> str:
    if s.born_from is not None and (s.use is None or not s.use.shares):
        return f"started by {meas_name(s.born_from)}"
    if s.use is None or not s.use.shares:
        return "—"
    return ", ".join(
        meas_name(m) + (f" ({text})" if (text := share_text(share, s.use.mode)) else "")
        for m, share in s.use.shares[:3]
    )


def _steps_markdown(view: TrackerView, class_name: str, track_ids: list[int], frames: range) -> list[str]:
    """Per involved track, a table of its frames: existence (a PHD label's weight) before the update (and, when it
    differs, in the PMBM hypothesis its detection was decided in) and after it (trackers with existences), the
    detections in its gate with their NIS (trackers with gates), the ones its update used, and whether it was
    output."""
    out: list[str] = []
    facts = view.facts
    for t in track_ids:
        steps = [s for f, s in sorted(facts.steps(t, class_name).items()) if f in frames]
        if not steps:
            continue
        out += [f"Track {t}, frame by frame:", ""]
        if facts.output_only:
            out += ["| frame | detection under its box | output |", "|---|---|---|"]
        elif not view.has_gates:
            out += ["| frame | used | output |", "|---|---|---|"]
        elif not facts.has_existence:
            out += ["| frame | in gate (NIS) | used | output |", "|---|---|---|---|"]
        else:  # a GM-PHD / CPHD label's heaviest component's weight (may exceed 1), else an existence
            r = "weight" if _weighs(facts, class_name, frames, steps) else "r"
            out += [
                f"| frame | {r} before update | in gate (NIS) | used | {r} after | output |",
                "|---|---|---|---|---|---|",
            ]
        for s in steps:
            gated = ", ".join(f"m{m} ({d2:.1f})" for m, d2 in s.gated) or "nothing"
            used = _used_cell(s)
            output = "yes" if s.output is not None else "no"
            if not view.has_gates:
                out.append(f"| {s.frame} | {used} | {output} |")
                continue
            if not facts.has_existence:
                out.append(f"| {s.frame} | {gated} | {used} | {output} |")
                continue
            before = "—" if s.prior_existence is None else existence_text(s.prior_existence)
            if s.decided_existence is not None and existence_text(s.decided_existence) != before:
                before += f" ({existence_text(s.decided_existence)} in the hypothesis its detection was decided in)"
            after = (
                "ended"
                if s.ended is not None
                else "—"
                if s.posterior_existence is None  # e.g. a copy a GM-PHD extraction made: no component of its own
                else existence_text(s.posterior_existence)
            )
            out.append(f"| {s.frame} | {before} | {gated} | {used} | {after} | {output} |")
        out.append("")
    return out


def _weighs(facts: TrackerFacts, class_name: str, frames: range, steps: list) -> bool:
    """Whether the tracker's updates in ``frames`` split weights (a GM-PHD / CPHD): by the window's mode, or by
    any update event at a frame of the track's ``steps`` (a window whose updates gave no track a share read as
    an assignment, and a CPHD label's weight was headed "r", an existence: audit truth52, world8 scene-0655
    centerpoint cphd miss:5)."""
    if facts.mode(class_name, frames) is UseMode.WEIGHTS:
        return True
    return any((u := facts.use(s.frame, class_name)) is not None and u.mode is UseMode.WEIGHTS for s in steps)


def _update_markdown(view: TrackerView, class_name: str, ids: set[int], frame: int) -> list[str]:
    """The update at the focus frame about the involved tracks: the solver's conflicts (a tracker that chooses an
    assignment), or each track's association probabilities or weights (a soft update)."""
    facts = view.facts
    if facts.output_only:
        return []  # nothing is known of its update
    d = facts.decisions(frame, class_name)
    if d is not None:
        decided = [c for c in d.conflicts if c.involves(ids)]
        if decided:
            return [
                f"Decisions at frame {frame} about the involved tracks:",
                "",
                *[conflict_markdown(c, set(view.shown_ever)) for c in decided],
            ]
        gated = [(t, s) for t in sorted(ids) if (s := facts.steps(t, class_name).get(frame)) is not None and s.gated]
        if not gated:
            reach = "nothing in their gates" if view.has_gates else "no detection within their matching distance"
        else:
            names = ", ".join(f"{meas_name(m)} (track {t})" for t, s in gated for m, _ in s.gated[:2])
            reach = f"the detections in their gates, {names}, were far cheaper as new tracks or elsewhere"
        return [f"No conflict involved these tracks at frame {frame} ({reach}).", ""]
    use = facts.use(frame, class_name)
    if use is None:
        return []
    rows = []
    for t in sorted(ids):
        u = use.tracks.get(t)
        if u is None:
            continue
        shares = ", ".join(f"{meas_name(m)} {share_text(s, u.mode)}" for m, s in u.shares) or "none"
        missed = f"missed {share_text(u.missed, u.mode)}" if u.mode is not UseMode.ASSIGNED else ""
        rows.append(f"| {t} | {shares} | {missed} |")
    if not rows:
        return [f"None of the involved tracks was updated at frame {frame}.", ""]
    what = "association probabilities" if use.mode is UseMode.PROBABILITIES else "share of each track's weight"
    new = [m for m, dest in use.destinations.items() if dest.went is not Went.TRACK]
    return [
        f"The update at frame {frame} about the involved tracks ({what}):",
        "",
        "| track | detections used | missed |",
        "|---|---|---|",
        *rows,
        "",
        *([f"Detections no track took most of: {', '.join(meas_name(m) for m in new)}.", ""] if new else []),
    ]
