"""The summary document of a focus recording (``focus/summary``) and its reading guide (``focus/how_to_read``).

The summary puts the cause first: the failure in one line; the evaluation's verdict when it scored the object at
an interpolated box (``viz.evaluated``); a "Why" line (detections of the object, the lost track's existence, the
choice that gave the object away); each tracker's key decisions and, with several trackers, where they part.
Then, per tracker, a diagnosis per involved track, frame tables of the involved objects and tracks, the decisions
at the focus frame and the story lines, so the document alone explains the failure.
"""

from __future__ import annotations

import math
import re
from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np

from gnnpmb.data.scene import SceneData
from gnnpmb.eval.failures import FailureKind, FailureReport, short_id
from gnnpmb.events import AxisKind, PairTerms
from gnnpmb.explain import PairChoice
from gnnpmb.focus import FocusTarget, gt_xy
from gnnpmb.pipeline import FrameResult, TrackingRun
from viz.blueprint import (
    FOCUS_TIMELINE,
)
from viz.decisions import (
    CLOSE_CALL_MARGIN,
    choice_why,
    column_name,
    conflict_markdown,
    cost_brief,
    existence_text,
    meas_name,
    track_why,
)
from viz.evaluated import NEAR_DETECTION_M, devkit_gt, evaluated_notes, evaluated_offsets, range_near_focus
from viz.logger import SHOW_MIN_EXISTENCE, TrackerLogger, TrackStep

MAX_STORY_LINES = 40

MAX_KEY = 3
"""The summary's head names at most this many key decisions per tracker (the newest)."""

MAX_LISTED = 2
"""Per frame, the diagnosis names where the MAX_LISTED detections nearest to a track (lowest NIS) went."""

TABLE_FRAMES = 6
"""The frame tables show the focus frame and the TABLE_FRAMES frames before it."""

READING_GUIDE = f"""# How to read the views

**Bird's-eye and 3D views** (one pair per tracker)

- **Detections**: thin boxes in class colours, labelled `m<idx> <score>` (the same `m<idx>` everywhere: lines,
  tables, logs).
- **Ground truth**: translucent boxes.
- **Tracks**: boxes labelled with their id; the trail behind a track shows its last positions.
- **Gates**: the circles around each track's predicted position.
- **Association lines**: a solid line joins a track's prediction to the detection it was given; a faint line, a
  detection inside its gate that it was not given.
- **Failures**: enlarged boxes: magenta ID switch, orange fragmentation, red false track, green coalescence,
  yellow identity theft, grey miss. This failure's box encloses the others on the same objects; failures of
  other objects at the same frame are pale.
- **Disagreements** (several trackers): boxes around the object in sky blue where only one tracker shows a track
  on it, violet where one changed its id and the other kept it, pink around a track only one shows. Shown means
  an existence of {SHOW_MIN_EXISTENCE:g} or more (output, for GNN, JPDA and greedy, which have no existences):
  an involved track below that is drawn here all the same, but counts as not shown in the comparison (and is
  not drawn in the full recording).
- **Involved objects**: drawn enlarged; their labels stand in a column beside them, with a line to each object.
  A detection's label says where it went (`m2 0.75 → track 26`, `→ new track 212`); a track's predicted
  position, its predicted existence and the detection it was given (`26 predicted r=0.40 → m2`) or `missed`.
  An involved track kept but not output this frame is a pale box at its predicted position, in the shape of its
  last output box: where the tracker expected the object.
  The involved tracks take distinct colours (blue, green, black, light blue, lime, … in order of their ids,
  skipping a colour close to their class's own), the same in every view and plot; the others are pale.
- **GT … as evaluated**: where the evaluation put an object that had no LiDAR or radar points at this frame (it
  interpolates a box between the frames where the object had points); the failure is scored against that box.
  It is drawn thin in the class colour, with a line to the annotated box and a circle of 2 m around it: a track
  outside that circle is not matched to the object.
- **evaluation range**: when the failure lies near it, the circle around the ego vehicle beyond which the
  evaluation drops boxes of the class (50 m for vehicles, 40 m for pedestrians and two-wheelers), ground truth
  and tracks alike: an object just beyond it with a track just inside makes a false track.

**Panels**

- **focus**: the failure in words: **Why** (the cause: for a lost object, its detections and the lost track's
  existence up to the choice that gave it away; for a false track, what it was output on and why no object
  matched it; for a miss, whether the detector or the tracker missed it), **Because** (that choice's costs taken
  apart), the key decisions, and per tracker what happened to each involved track.
- **story**: each frame's events of the involved class (confirmed, missed, ended, close calls).
- **decisions** and **cost grid**: per conflict the chosen pair, its cost, the next best and the margin (lower
  cost = more likely). When the next best was a track, the line under the table takes both costs apart (GNN-PMB,
  PMBM, TO-PMB): a track's cost is what its predicted existence adds (low existence, high cost), plus the
  uncertainty of its predicted position (a track not seen for a while is spread wide), plus the distance to the
  detection, plus the detection's score; and it gives the existence at which that track would have won the
  detection. GNN has no existence or score in its cost, but a constant (a detection against clutter); it gives
  the distance at which the track would have won.
- **existence**, **NIS**, **chosen cost**: the involved tracks' series up to the failure; the grey line is the
  existence from which a Bernoulli is shown as a track. GNN, JPDA and greedy have no existence plot: their
  tracks have no existence probability (track logic keeps a track or deletes it).

**Terms**

- **r, existence**: the filter's probability that a track's object exists (a Bernoulli's existence); it falls
  each frame the track gets no detection. **Predicted** values are before this frame's detections are used.
- **candidate**: a track (Bernoulli) never shown, because its existence never reached the line above.
- **d², NIS**: the squared Mahalanobis distance between a detection and a track's predicted position (normalised
  innovation squared); the gate keeps detections with d² ≤ 40.
- **uncertainty of the predicted position (± m)**: the spread of the track's predicted position plus the
  detection noise (the fourth root of det S); it grows while a track gets no detection.
- **cost**: −log of how much more likely a pairing is than the track being missed; the solver picks the set of
  pairings of least total cost. **new**: the cost of a detection starting a track (or being clutter), about the
  same for every detection (the birth weight against the clutter rate, −log(clutter + birth weight × score ×
  birth density)).
- **margin**: how much the best total cost rises without a chosen pair; shown up to 5.00 (larger is no contest).
- **identity theft** (the paper's cascading identity theft): a track whose first frames were false (matched to
  no object) takes over a real object another track held, an ID switch; the victim, left without its object,
  may steal the next one in turn.
- **counted**: the evaluation keeps a track only if its score averaged over the whole track reaches the class's
  threshold (chosen for the best MOTA), at all its frames or at none.
"""


def mentions(text: str, track_ids: set[int]) -> bool:
    """Whether a story line names one of ``track_ids`` ("track 26", "→ 26")."""
    numbers = {int(n) for n in re.findall(r"(?:track |→ )(\d+)", text)}
    return bool(numbers & track_ids)


def focus_markdown(
    focus: FocusTarget,
    loggers: Mapping[str, TrackerLogger],
    shown: range,
    scene: SceneData,
    runs: Mapping[str, TrackingRun],
    reports: Mapping[str, FailureReport] | None = None,
) -> str:
    """The summary document: the failure, the ids; per tracker a diagnosis line per involved track, the involved
    objects' and tracks' frames, its decisions about them and their story. reports: per tracker, its failure
    report (the evaluation's score threshold of the focused class and each track's averaged score)."""
    lines = [f"# {focus.title}", ""]
    evaluated = evaluated_offsets(focus, scene)
    lines += evaluated_notes(focus, scene, runs, evaluated)
    owner = focus.failure_tracker
    if owner in loggers and owner in runs and not evaluated:
        lines += _why(focus, scene, runs[owner], loggers[owner], shown, (reports or {}).get(owner))
        lines += _why_false_track(focus, scene, runs[owner], (reports or {}).get(owner))
        lines += _why_miss(focus, scene, runs[owner], loggers[owner], (reports or {}).get(owner))
    for tracker, logger in loggers.items():
        key = _key_decisions(logger, set(focus.track_ids.get(tracker, ())), focus.class_name, shown, focus.frame_index)
        if key:
            lines += [f"**Key decisions of {tracker}** (a detection an involved track could have taken):", ""]
            lines += [f"- {k.text}" for k in key] + [""]
    parting = _parting(focus, loggers)
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
        f"Opened at frame **{focus.frame_index}** on the `{FOCUS_TIMELINE}` timeline, which ends there; choose the "
        f"`frame` timeline in the time panel to step past it. Recorded frames: {shown.start}–{shown.stop - 1}. "
        "The tab *how to read the views* explains the boxes, lines and colours.",
        "",
    ]
    for tracker, logger in loggers.items():
        ids = set(focus.track_ids.get(tracker, ()))
        lines.append(f"## {tracker}")
        lines += [f"- {line}" for line in _diagnosis(logger, sorted(ids), shown, focus.frame_index)]
        lines.append("")
        run = runs.get(tracker)
        if run is not None:
            lines += _gt_markdown(focus, scene, run, logger, shown, (reports or {}).get(tracker))
        lines += _steps_markdown(logger, sorted(ids), shown, focus.frame_index, focus.class_name)
        decided = [
            c
            for d in logger.decisions.get(focus.frame_index, [])
            if d.class_name == focus.class_name
            for c in d.conflicts
            if c.involves(ids)
        ]
        if decided:
            lines.append(f"Decisions at frame {focus.frame_index} about the involved tracks:")
            lines.append("")
            lines += [conflict_markdown(c, logger.reported_ever) for c in decided]
        else:
            reach = "nothing in their gates" if logger.has_gates else "no detection within their matching distance"
            lines.append(f"No conflict involved these tracks at frame {focus.frame_index} ({reach}).")
            lines.append("")
        story = [
            (f, text)
            for f, class_name, text, _level in logger.story
            if class_name == focus.class_name and f <= focus.frame_index and mentions(text, ids)
        ]
        if story:
            lines.append("Story of the involved tracks:")
            lines.append("")
            lines += [f"- frame {f}: {text}" for f, text in story[-MAX_STORY_LINES:]]
            lines.append("")
    return "\n".join(lines) + "\n"


def _parting(focus: FocusTarget, loggers: Mapping[str, TrackerLogger]) -> list[str]:
    """With several trackers: per detection of the focus frame that went to different places in different
    trackers, with an involved track chosen or next best in one of them, each tracker's choice, its cost and
    the next best column with its cost."""
    if len(loggers) < 2:
        return []
    f = focus.frame_index
    choices: dict[str, dict[int, PairChoice]] = {}
    for tracker, logger in loggers.items():
        choices[tracker] = {
            int(c.meas.ref): c
            for d in logger.decisions.get(f, [])
            if d.class_name == focus.class_name
            for conflict in d.conflicts
            for c in conflict.choices
        }
    out = []
    for m in sorted({m for mine in choices.values() for m in mine}):
        went = {t: logger.given.get(f, {}).get(m) for t, logger in loggers.items()}
        if len(set(went.values())) < 2:
            continue
        touches, parts = False, []
        for tracker in loggers:
            ids = set(focus.track_ids.get(tracker, ()))
            c = choices[tracker].get(m)
            if c is None:
                parts.append(f"{tracker}: {meas_name(m)} → {went[tracker] or 'in no gate'}")
                continue
            labels = [c.chosen] if c.alternative is None else [c.chosen, c.alternative]
            touches |= any(label.kind is AxisKind.TRACK and label.ref in ids for label in labels)
            touches |= any(str(t) in str(went[tracker]).split() for t in ids)
            other = ""
            if c.alternative is not None:
                other = f"; next {column_name(c.alternative)} {c.alternative_cost:.2f}" + _brief(c.alternative_terms)
            chosen = f"{c.chosen_cost:.2f}{_brief(c.chosen_terms)}"
            parts.append(f"{tracker}: {meas_name(m)} → **{went[tracker]}** ({chosen}{other})")
        if touches:
            out.append(" · ".join(parts))
    return out


def _score_of(choice: PairChoice) -> str:
    """`` (score 0.75)``: the detection's score where its costs hold one (it is part of every track's cost), else
    ""."""
    terms = choice.chosen_terms or choice.alternative_terms
    return f" (score {terms.score:.2f})" if terms is not None and terms.score is not None else ""


def _brief(terms: PairTerms | None) -> str:
    """`` at existence 0.62, ±1.2 m, d² 0.3`` (``decisions.cost_brief``), or "" for a column without terms."""
    return f" at {cost_brief(terms)}" if terms is not None else ""


@dataclass(frozen=True, slots=True)
class KeyDecision:
    """A choice of the solver at ``frame`` that decided an involved track's fate, and how the summary words it
    (where the detection went: ``went``)."""

    frame: int
    choice: PairChoice
    went: str
    text: str


def _key_decisions(
    logger: TrackerLogger, ids: set[int], class_name: str, shown: range, last: int, limit: int | None = MAX_KEY
) -> list[KeyDecision]:
    """The solver's choices up to frame ``last`` that decided the involved tracks' fate, newest ``MAX_KEY``: a
    detection given elsewhere while an involved track was its next best column, or given to an involved track by
    a close call (``decisions.CLOSE_CALL_MARGIN``)."""
    out = []
    for f in range(shown.start, last + 1):
        for d in logger.decisions.get(f, []):
            if d.class_name != class_name:
                continue
            for c in (c for conflict in d.conflicts for c in conflict.choices):
                alt = c.alternative
                alt_involved = alt is not None and alt.kind is AxisKind.TRACK and alt.ref in ids
                chosen_involved = c.chosen.kind is AxisKind.TRACK and c.chosen.ref in ids
                if (alt_involved and not chosen_involved) or (chosen_involved and c.margin < CLOSE_CALL_MARGIN):
                    went = logger.given.get(f, {}).get(int(c.meas.ref), column_name(c.chosen))
                    other = "(no other)"
                    if alt is not None:
                        other = f"over {column_name(alt)} ({c.alternative_cost:.2f}{_brief(c.alternative_terms)})"
                    text = (
                        f"frame {f}: {meas_name(c.meas.ref)}{_score_of(c)} → **{went}** (cost {c.chosen_cost:.2f}) "
                        f"{other}, margin {c.margin:.2f}"
                    )
                    out.append(KeyDecision(f, c, went, text))
    return out if limit is None else out[-limit:]


def _diagnosis(logger: TrackerLogger, track_ids: list[int], shown: range, last: int) -> list[str]:
    """One sentence per involved track summarising its table: when it last got a detection, the frames since
    with nothing in its gate or with detections it was not given, and its existence then and at ``last``."""
    out = []
    for t in track_ids:
        steps = {f: s for f, s in logger.track_steps.get(t, {}).items() if shown.start <= f <= last}
        if not steps:
            continue
        frames = sorted(steps)
        given = [f for f in frames if steps[f].given >= 0]
        since = [f for f in frames if not given or f > given[-1]]
        empty = [f for f in since if not steps[f].gated]
        passed = [f for f in since if steps[f].gated]
        parts = []
        if given:
            parts.append(f"last given a detection at frame {given[-1]} (m{steps[given[-1]].given})")
        else:
            span = f"frames {frames[0]}-{frames[-1]}" if len(frames) > 1 else f"frame {frames[0]}"
            parts.append(f"given no detection in {span}")
        if empty and logger.has_gates:
            parts.append(f"nothing in its gate at frame{'s' if len(empty) > 1 else ''} {_frames(empty)}")
        if passed:
            went = []
            for f in passed:
                nearest = sorted(steps[f].gated, key=lambda g: g[1])  # by NIS: the detections closest to it
                sent = ", ".join(f"m{m} -> {logger.given.get(f, {}).get(m, '?')}" for m, _ in nearest[:MAX_LISTED])
                more = f", +{len(nearest) - MAX_LISTED} more" if len(nearest) > MAX_LISTED else ""
                went.append(f"{f} ({sent}{more})")
            plural = "s" if len(passed) > 1 else ""
            parts.append(f"detections in its gate went elsewhere at frame{plural} {'; '.join(went)}")
        if not logger.has_existence:
            parts.append("shown as a track" if steps[frames[-1]].reported else "not output")
            out.append(f"**track {t}**: " + "; ".join(parts) + ".")
            continue
        peak = max(frames, key=lambda f: _after(steps[f]))
        final_r = steps[frames[-1]].posterior_existence
        then = (
            f"{existence_text(final_r)} at frame {frames[-1]}"
            if final_r == final_r
            else f"pruned at frame {frames[-1]}"
        )
        if peak == frames[-1]:
            parts.append(f"existence after update {then}")
        else:
            parts.append(f"existence after update {existence_text(_after(steps[peak]))} at frame {peak} -> {then}")
        parts.append("shown as a track" if steps[frames[-1]].reported else "not shown as a track")
        out.append(f"**track {t}**: " + "; ".join(parts) + ".")
    return out


def _after(step) -> float:
    """Existence after the update (0 when the track was pruned that frame)."""
    r = step.posterior_existence
    return 0.0 if r != r else r


def _frames(frames: list[int]) -> str:
    return ", ".join(str(f) for f in frames)


def _frames_named(frames: list[int]) -> str:
    """``frame 7`` or ``frames 7, 13``."""
    return f"frame{'s' if len(frames) > 1 else ''} {_frames(frames)}"


def _counted(average: float | None, threshold: float | None) -> str:
    """How the evaluation saw a track: its averaged score and, below ``threshold``, that it was not counted."""
    if threshold is None:
        return ""
    if average is None:
        return "; not evaluated (out of the class's range)"
    return f"; track average {average:.2f}" + (", not counted" if average < threshold else "")


def _nearest_detection(frame: FrameResult, class_name: str, xy_m: np.ndarray) -> tuple[int, float] | None:
    """The index and BEV distance of the kept detection of ``class_name`` nearest to ``xy_m`` if it is within
    ``NEAR_DETECTION_M``, else None."""
    boxes = frame.detections.boxes
    mine = np.flatnonzero(np.asarray(frame.detections.kept) & (boxes.class_name == class_name))
    if not mine.size:
        return None
    d = np.hypot(*(boxes.translation_m[mine, :2] - xy_m).T)
    k = int(np.argmin(d))
    return (int(mine[k]), float(d[k])) if d[k] < NEAR_DETECTION_M else None


DETECTOR = "the detector's doing"
TRACKER = "the tracker's doing"
EVALUATION = "the evaluation's doing"
"""Whose doing a failure was, as the Why line opens: the detector gave no (or a wrong) detection, the tracker
had one and did not use it well, or the evaluation scored a box where there was none."""

WHY_KINDS = {
    FailureKind.ID_SWITCH: (0, 1),
    FailureKind.IDENTITY_THEFT: (1, 0),
    FailureKind.FRAGMENTATION: (0, None),
}
"""Per failure kind with a track that lost the object: the positions in ``Failure.track_ids`` of that track and
of the track that took the object over (None: none did)."""


def _why(
    focus: FocusTarget,
    scene: SceneData,
    run: TrackingRun,
    logger: TrackerLogger,
    shown: range,
    report: FailureReport | None = None,
) -> list[str]:
    """One line for a failure where a track lost its object: how often the object was detected, what the lost
    track's existence did meanwhile (and, when it was too low for the track to be shown, why the evaluation still
    counted the track: ``report``'s averaged score) and the choice that gave the object's detection to the other
    track."""
    if focus.failure_kind not in WHY_KINDS or not focus.gt_ids or not focus.failure_tracks:
        return []
    lost_at, took_at = WHY_KINDS[focus.failure_kind]
    lost = focus.failure_tracks[lost_at]
    took = focus.failure_tracks[took_at] if took_at is not None else None
    by_frame = {f.keyframe.index: f for f in run.frames}
    gt_id, detected, seen, empty = focus.gt_ids[0], [], [], []
    for i in range(shown.start, focus.frame_index + 1):
        gt = scene.keyframes[i].gt
        hit = np.flatnonzero(gt.instance_id.astype(str) == gt_id)
        if hit.size == 0 or i not in by_frame:
            continue
        seen.append(i)
        if scene.keyframes[i].gt_num_pts[hit[0]] == 0:
            empty.append(i)
        if _nearest_detection(by_frame[i], focus.class_name, gt.translation_m[hit[0], :2]) is not None:
            detected.append(i)
    parts = []
    if seen:
        only = " only" if len(detected) < len(seen) else ""
        at = f"{_frames_named(detected)}{only}" if detected else "no frame"
        no_points = f" and no LiDAR or radar points at {_frames_named(empty)}" if empty else ""
        parts.append(
            f"in the {len(seen)} recorded frames up to {focus.frame_index} ({seen[0]}–{seen[-1]}), GT "
            f"{short_id(gt_id)} had a detection within {NEAR_DETECTION_M:.0f} m at {at}{no_points}"
        )
    steps = {f: st for f, st in logger.track_steps.get(lost, {}).items() if shown.start <= f <= focus.frame_index}
    at_failure = steps.get(focus.frame_index)
    if steps and not logger.has_existence and (at_failure is None or at_failure.given < 0):
        # track logic: when it last had a detection and whether it ended (a track given one at the failure frame
        # followed something else: ``_lost_elsewhere`` says where)
        given = [f for f in sorted(steps) if steps[f].given >= 0]
        span = f"frames {min(steps)}–{max(steps)}" if len(steps) > 1 else f"frame {min(steps)}"
        had = f"was last given a detection at frame {given[-1]}" if given else f"was given no detection in {span}"
        ended = f" and ended after frame {max(steps)}" if max(steps) < focus.frame_index else ""
        parts.append(f"track {lost} {had}{ended}")
    if steps and logger.has_existence:
        peak = max(steps, key=lambda f: _after(steps[f]))
        parts.append(
            f"track {lost}'s existence went from {existence_text(_after(steps[peak]))} (frame {peak}) to "
            f"{existence_text(_after(steps[max(steps)]))} (frame {max(steps)})"
        )
        if report is not None and not any(step.reported for step in steps.values()):
            parts += _counted_unshown(lost, report, focus.class_name, logger.show_min_existence)
    because = []
    doing = TRACKER if focus.frame_index in detected else DETECTOR
    if took is not None:
        keys = _key_decisions(
            logger, set(focus.track_ids.get(run.tracker, ())), focus.class_name, shown, focus.frame_index, None
        )
        chosen = [k for k in keys if k.went in (f"new track {took}", f"track {took}")]
        if chosen:
            parts.append(f"then, {chosen[-1].text}")
            parts += _where_from(chosen[-1], keys, (lost, took))
            step = logger.track_steps.get(lost, {}).get(chosen[-1].frame)
            because = _because(chosen[-1], lost, step, focus.frame_index)
        else:  # no close call: say where the track that took the object came from
            started = [
                (f, m)
                for f in sorted(logger.given)
                for m, went in logger.given[f].items()
                if went == f"new track {took}"
            ]
            if started:
                f, m = started[0]
                parts.append(f"then, at frame {f}, {meas_name(m)} started track {took} (not a close call)")
    parts += _lost_elsewhere(focus, scene, by_frame, logger, lost)
    if focus.failure_kind is FailureKind.IDENTITY_THEFT and report is not None and took is not None:
        parts += _first_false(report, took, lost, gt_id, focus.frame_index)
    return [f"**Why** ({run.tracker}, {doing}): " + "; ".join(parts) + ".", "", *because]


def _lost_elsewhere(
    focus: FocusTarget, scene: SceneData, by_frame: Mapping[int, FrameResult], logger: TrackerLogger, lost: int
) -> list[str]:
    """When the track that lost the object is still output at the failure frame, but too far from the object for
    the evaluation to match it: where it was, the detection it followed there, and the earlier frames it was
    given a detection that far from the object (it drifted onto something else)."""
    frame = by_frame.get(focus.frame_index)
    if frame is None or not focus.gt_ids:
        return []
    estimate = next((e for e in frame.estimates if e.track_id == lost), None)
    at = gt_xy(scene, focus.frame_index, focus.gt_ids[:1])
    if estimate is None or not len(at):
        return []
    gap_m = float(np.hypot(*(np.asarray(estimate.translation_m[:2]) - at[0])))
    if gap_m < NEAR_DETECTION_M:
        return []
    steps = logger.track_steps.get(lost, {})
    step = steps.get(focus.frame_index)
    on = f", on {meas_name(step.given)}" if step is not None and step.given >= 0 else ""
    away = []
    for f in sorted(f for f in steps if f < focus.frame_index and steps[f].given >= 0 and f in by_frame):
        xy = gt_xy(scene, f, focus.gt_ids[:1])
        m = steps[f].given
        if len(xy) and np.hypot(*(by_frame[f].detections.boxes.translation_m[m, :2] - xy[0])) >= NEAR_DETECTION_M:
            away.append(f"{f} ({meas_name(m)})")
    before = (
        f"; it had been given detections {NEAR_DETECTION_M:.0f} m or more from the object at frame"
        f"{'s' if len(away) > 1 else ''} {', '.join(away)}"
        if away
        else ""
    )
    return [
        f"at frame {focus.frame_index} track {lost} was output {gap_m:.1f} m from GT {short_id(focus.gt_ids[0])}"
        f"{on}: beyond the evaluation's {NEAR_DETECTION_M:.0f} m, so it no longer matched the object{before}"
    ]


def _first_false(report: FailureReport, thief: int, victim: int, gt_id: str, frame: int) -> list[str]:
    """What makes a takeover an identity theft rather than a plain ID switch: the thief's earlier frames the
    evaluation counted as a false track (matched to no object)."""
    false_at = sorted(
        {f.frame_index for f in report.of_kind(FailureKind.FALSE_TRACK) if str(thief) in f.track_ids}
        & set(range(frame))
    )
    if not false_at:
        return []
    return [
        f"track {thief} had been a false track at {_frames_named(false_at)} (matched to no object: the evaluation "
        f"still gave GT {short_id(gt_id)} to track {victim}), so its taking the object is an identity theft"
    ]


def _counted_unshown(track_id: int, report: FailureReport, class_name: str, show_min: float) -> list[str]:
    """Why a track the viewer did not show (existence below ``show_min``) still counts for the evaluation: it
    scores a track by its score averaged over all its frames, against the class's threshold."""
    average, threshold = report.track_scores.get(str(track_id)), report.threshold_of(class_name)
    if average is None or threshold is None or average < threshold:
        return []
    # The threshold is one of the averaged scores (the devkit's best-MOTA threshold), possibly this track's own.
    if math.isclose(average, threshold, rel_tol=1e-9):
        versus = f"is exactly the {class_name} threshold (the lowest score counted)"
    else:
        versus = f"is above the {class_name} threshold {threshold:.3f}"
    return [
        f"too low for track {track_id} to be shown here (existence below {show_min:g}), yet the evaluation counted "
        f"it: its score averaged over all its frames, {average:.3f}, {versus}"
    ]


def _where_from(key: KeyDecision, keys: list[KeyDecision], named: tuple[int | None, ...]) -> list[str]:
    """When the decisive choice's next best is a track the failure does not name (a track in between), where that
    track came from: the earlier key decision that started it."""
    alt = key.choice.alternative
    if alt is None or alt.kind is not AxisKind.TRACK or alt.ref in named:
        return []
    started = [k for k in keys if k.frame < key.frame and k.went == f"new track {alt.ref}"]
    if not started:
        return []
    k = started[-1]
    instead = f" instead of going to {column_name(k.choice.alternative)}" if k.choice.alternative is not None else ""
    return [f"track {alt.ref} had been started at frame {k.frame} by {meas_name(k.choice.meas.ref)}{instead}"]


def _because(key: KeyDecision, lost: int, step: TrackStep | None, opened_at: int) -> list[str]:
    """The decisive choice's costs taken apart (``decisions.choice_why``), as a paragraph, and, when the track
    that lost the object (``lost``, its ``TrackStep`` at that frame) was neither of the two columns compared,
    what it would have cost or that the detection was outside its gate; none when the tracker's cost matrix does
    not say what its costs are made of. A choice before the frame the views open at (``opened_at``) says how
    far to step back to see it."""
    why = choice_why(key.choice, key.went)
    if why is None:
        return []
    c = key.choice
    compared = {label.ref for label in (c.chosen, c.alternative) if label is not None and label.kind is AxisKind.TRACK}
    if lost not in compared:
        if step is not None and all(m != c.meas.ref for m, _ in step.gated):
            why += f". {meas_name(c.meas.ref)} was outside the gate of track {lost}, which had the object"
        elif (lost_why := track_why(c, lost, ", which had the object,")) is not None:
            why += f". {lost_why}"
    back = opened_at - key.frame
    where = ""
    if back > 0:
        where = f"; the views open at frame {opened_at}: step back {back} frame{'s' if back > 1 else ''} to see it"
    return [f"**Because** (frame {key.frame}{where}): {why}.", ""]


def _why_false_track(focus: FocusTarget, scene: SceneData, run: TrackingRun, report: FailureReport | None) -> list[str]:
    """One line for a false track: the detection it was output on, the nearest ground truth of its class and of
    any class (a near object of another class: the detector gave it the wrong class; none: a detection of
    nothing), and the averaged score by which the evaluation counted it."""
    if focus.failure_kind is not FailureKind.FALSE_TRACK or not focus.failure_tracks:
        return []
    t, f = focus.failure_tracks[0], focus.frame_index
    frame = next((fr for fr in run.frames if fr.keyframe.index == f), None)
    estimate = next((e for e in frame.estimates if e.track_id == t), None) if frame is not None else None
    if estimate is None:
        return []
    boxes = frame.detections.boxes
    m = estimate.meas_index
    if m >= 0:
        xy = boxes.translation_m[m, :2]
        source = f"detection {meas_name(m)} ({boxes.class_name[m]}, score {boxes.score[m]:.2f})"
    else:
        xy = np.array(estimate.translation_m[:2])
        source = "no detection this frame (predicted)"
    gt = scene.keyframes[f].gt
    d = np.hypot(*(gt.translation_m[:, :2] - xy).T) if len(gt) else np.zeros(0)
    same = np.flatnonzero(gt.class_name == focus.class_name) if len(gt) else np.zeros(0, int)
    parts = [f"at frame {f} track {t} ({focus.class_name}) was output on {source}"]
    doing = DETECTOR
    if same.size and d[same].min() < NEAR_DETECTION_M:
        k = int(same[np.argmin(d[same])])
        gt_id = str(gt.instance_id[k])
        evaluated = devkit_gt(scene, gt_id, f)
        on = f"{focus.class_name} GT {short_id(gt_id)} lies {d[k]:.1f} m away"
        doing = EVALUATION
        if evaluated.xy_m is None:
            parts.append(f"{on}, but the evaluation has no box for it here ({evaluated.why}): a track on it is false")
        elif np.hypot(*(evaluated.xy_m - estimate.translation_m[:2])) >= NEAR_DETECTION_M:
            parts.append(
                f"{on}, but the evaluation has it {evaluated.why} "
                f"{np.hypot(*(evaluated.xy_m - gt.translation_m[k, :2])):.1f} m from the annotation, out of the "
                "track's reach (see nuscenes-devkit issue #1141)"
            )
        else:
            doing = TRACKER
            parts.append(f"{on} and the evaluation matched it to another track: two tracks on one object")
    elif d.size and d.min() < NEAR_DETECTION_M:
        k = int(np.argmin(d))
        parts.append(
            f"no {focus.class_name} GT lies within {NEAR_DETECTION_M:.0f} m, but GT {gt.class_name[k]} "
            f"{short_id(str(gt.instance_id[k]))} does ({d[k]:.1f} m): the detector gave it the wrong class"
        )
    else:
        nearest = f" (the nearest is {d.min():.1f} m away)" if d.size else ""
        parts.append(f"no object of any class lies within {NEAR_DETECTION_M:.0f} m{nearest}: a detection of nothing")
    threshold = report.threshold_of(focus.class_name) if report is not None else None
    average = report.track_scores.get(str(t)) if report is not None else None
    if threshold is not None and average is not None:
        parts.append(
            f"the evaluation counted the track: its score averaged over all its frames, {average:.3f}, is at least the "
            f"{focus.class_name} threshold {threshold:.3f}"
        )
    return [f"**Why** ({run.tracker}, {doing}): " + "; ".join(parts) + ".", ""]


def _why_miss(
    focus: FocusTarget, scene: SceneData, run: TrackingRun, logger: TrackerLogger, report: FailureReport | None
) -> list[str]:
    """One line for a missed object: whether the detector gave a detection of its class within match distance
    (none: the detector missed it, or gave it another class); if it did, where the solver sent it; and the tracks
    output on the object with why the evaluation did not count them (their averaged score below the threshold)."""
    if focus.failure_kind is not FailureKind.MISS or not focus.gt_ids:
        return []
    f, gt_id = focus.frame_index, focus.gt_ids[0]
    frame = next((fr for fr in run.frames if fr.keyframe.index == f), None)
    gt = scene.keyframes[f].gt
    hit = np.flatnonzero(gt.instance_id.astype(str) == gt_id)
    if frame is None or hit.size == 0:
        return []
    xy, points = gt.translation_m[hit[0], :2], int(scene.keyframes[f].gt_num_pts[hit[0]])
    name = f"{focus.class_name} GT {short_id(gt_id)}"
    parts = []
    found = _nearest_detection(frame, focus.class_name, xy)
    doing = DETECTOR if found is None else TRACKER
    if found is None:
        boxes = frame.detections.boxes
        kept = np.flatnonzero(np.asarray(frame.detections.kept))
        d = np.hypot(*(boxes.translation_m[kept, :2] - xy).T) if kept.size else np.zeros(0)
        inside = f"{points} LiDAR and radar points in its box"
        if d.size and d.min() < NEAR_DETECTION_M:
            m = int(kept[np.argmin(d)])
            parts.append(
                f"at frame {f} the detector gave no {focus.class_name} detection within {NEAR_DETECTION_M:.0f} m of "
                f"{name} ({inside}), but a {boxes.class_name[m]} detection, {meas_name(m)} (score "
                f"{boxes.score[m]:.2f}), {d.min():.1f} m away: the detector gave it the wrong class"
            )
        else:
            parts.append(
                f"at frame {f} the detector gave no detection within {NEAR_DETECTION_M:.0f} m of {name} ({inside}): "
                "the detector missed it"
            )
    else:
        m, distance_m = found
        went = logger.given.get(f, {}).get(m)
        where = f" and went to {went}" if went else ""
        parts.append(
            f"at frame {f} detection {meas_name(m)} (score {frame.detections.boxes.score[m]:.2f}) lay "
            f"{distance_m:.1f} m from {name}{where}"
        )
    threshold = report.threshold_of(focus.class_name) if report is not None else None
    on = [
        e
        for e in frame.estimates
        if e.class_name == focus.class_name and np.hypot(*(np.asarray(e.translation_m[:2]) - xy)) < NEAR_DETECTION_M
    ]
    for e in on:
        average = report.track_scores.get(str(e.track_id)) if report is not None else None
        if threshold is not None and average is not None and average < threshold:
            parts.append(
                f"track {e.track_id} was output on it (score {e.score:.2f}), but its score averaged over all its "
                f"frames, {average:.3f}, is below the {focus.class_name} threshold {threshold:.3f}: the evaluation "
                "did not count it"
            )
    if found is not None and not on:
        parts.append(f"no {focus.class_name} track was output within {NEAR_DETECTION_M:.0f} m of it")
    reach_m = range_near_focus(focus, scene)
    if reach_m is not None:  # the circle is drawn: say which side of it the object is
        ego_m = float(np.hypot(*(xy - scene.keyframes[f].ego_pose.translation_m[:2])))
        side = "inside" if ego_m <= reach_m else "beyond"
        parts.append(f"it lies {ego_m:.1f} m from the ego vehicle, {side} the evaluation's {reach_m:g} m range")
    return [f"**Why** ({run.tracker}, {doing}): " + "; ".join(parts) + ".", ""]


def _gt_markdown(
    focus: FocusTarget,
    scene: SceneData,
    run: TrackingRun,
    logger: TrackerLogger,
    shown: range,
    report: FailureReport | None = None,
) -> list[str]:
    """Per involved ground-truth object, frame by frame up to the focus frame: the nearest detection of its class
    (distance, score), where the tracker sent it, and the tracks output on the object with their tracking scores
    and whether the evaluation counted them: it compares each track's score averaged over the whole track
    (``FailureReport.track_scores``) with the class's threshold, so a track is counted at every frame or at none.
    """
    threshold = report.threshold_of(focus.class_name) if report is not None else None
    averaged = report.track_scores if report is not None else {}
    out: list[str] = []
    by_frame = {f.keyframe.index: f for f in run.frames}
    for gt_id in focus.gt_ids:
        rows = []
        seen, detected, sent, first = 0, 0, [], focus.frame_index
        for i in range(max(shown.start, focus.frame_index - TABLE_FRAMES), focus.frame_index + 1):
            gt = scene.keyframes[i].gt
            hit = np.flatnonzero(gt.instance_id.astype(str) == gt_id)
            frame = by_frame.get(i)
            if hit.size == 0 or frame is None:
                continue
            xy = gt.translation_m[hit[0], :2]
            nearest = "none"
            went = "—"
            found = _nearest_detection(frame, focus.class_name, xy)
            if found is not None:
                m, distance_m = found
                nearest = f"m{m} at {distance_m:.1f} m (score {frame.detections.boxes.score[m]:.2f})"
                went = logger.given.get(i, {}).get(m, "—")
            covering = [
                f"{e.track_id} ({e.score:.2f}{_counted(averaged.get(str(e.track_id)), threshold)})"
                for e in frame.estimates
                if e.class_name == focus.class_name
                and np.hypot(e.translation_m[0] - xy[0], e.translation_m[1] - xy[1]) < NEAR_DETECTION_M
            ]
            points = int(scene.keyframes[i].gt_num_pts[hit[0]])
            evaluated = f"{points}" if points else "0: not scored as annotated (interpolated)"
            rows.append(f"| {i} | {evaluated} | {nearest} | {went} | {', '.join(covering) or 'none'} |")
            first = i if not seen else first
            seen += 1
            detected += nearest != "none"
            sent += [went] if nearest != "none" else []
        if rows:
            news = sum(w.startswith("new") for w in sent)
            counted = (
                "every output box"
                if threshold is None
                else f"{focus.class_name} tracks whose score averaged over the track is >= {threshold:.3f} (its "
                "best-MOTA threshold)"
            )
            tracks = sorted({w for w in sent if w != "—" and not w.startswith("new")})
            others = "the other" if len(sent) - news == 1 else "the others"
            rest = f", {others} went to {', '.join(tracks) or 'no track'}" if news < len(sent) else ""
            out += [
                f"**GT {short_id(gt_id)}**, in the {seen} frames of the table ({first}–{focus.frame_index}): a "
                f"detection within {NEAR_DETECTION_M:.0f} m in {detected}; {news} of them started a new track{rest}.",
                "",
                f"GT {short_id(gt_id)}, frame by frame (the evaluation counted {counted}):",
                "",
                "| frame | points in box | nearest detection | sent to | tracks output on it (score) |",
                "|---|---|---|---|---|",
                *rows,
                "",
            ]
    return out


def existence_as_decided(logger: TrackerLogger, frame: int, class_name: str) -> dict[int, float]:
    """Track id -> its predicted existence in the cost matrix the frame's assignment was explained on, for the
    tracks given a detection. For PMBM that is the chosen posterior's parent hypothesis, whose Bernoullis can
    differ from those of the most likely prior hypothesis, which ``Predicted`` (and ``TrackStep``) show: a track
    nearly dead in one hypothesis can be alive in another."""
    out = {}
    for d in logger.decisions.get(frame, []):
        if d.class_name != class_name:
            continue
        for c in (c for conflict in d.conflicts for c in conflict.choices):
            terms = c.chosen_terms
            if terms is not None and terms.existence is not None:
                out[int(c.chosen.ref)] = terms.existence
    return out


def _steps_markdown(logger: TrackerLogger, track_ids: list[int], shown: range, last: int, class_name: str) -> list[str]:
    """Per involved track, a table of its frames up to ``last``: existence before (and, if it differs, in the
    hypothesis its detection was decided in: ``existence_as_decided``) and after the update (for a tracker that
    has existences), the detections in its gate (with NIS) and the one it was given, and whether it was
    reported."""
    out: list[str] = []
    decided: dict[int, dict[int, float]] = {}  # frame -> existence_as_decided, worked out once per frame
    for t in track_ids:
        steps = {
            f: s for f, s in logger.track_steps.get(t, {}).items() if max(shown.start, last - TABLE_FRAMES) <= f <= last
        }
        if not steps:
            continue
        out += [f"Track {t}, frame by frame:", ""]
        if not logger.has_gates:  # greedy: neither gates nor existences
            out += ["| frame | given | shown |", "|---|---|---|"]
        elif not logger.has_existence:  # a track-logic tracker: no existence to tabulate
            out += ["| frame | in gate (NIS) | given | shown |", "|---|---|---|---|"]
        else:
            out += [
                "| frame | r before update | in gate (NIS) | given | r after | shown |",
                "|---|---|---|---|---|---|",
            ]
        for f in sorted(steps):
            s = steps[f]
            gated = ", ".join(f"m{m} ({nis:.1f})" for m, nis in s.gated) or "nothing"
            given = f"m{s.given}" if s.given >= 0 else "—"
            if not logger.has_gates:
                out.append(f"| {f} | {given} | {'yes' if s.reported else 'no'} |")
                continue
            if not logger.has_existence:
                out.append(f"| {f} | {gated} | {given} | {'yes' if s.reported else 'no'} |")
                continue
            after = (
                "pruned" if s.posterior_existence != s.posterior_existence else existence_text(s.posterior_existence)
            )
            before = existence_text(s.prior_existence)
            if f not in decided:
                decided[f] = existence_as_decided(logger, f, class_name)
            r = decided[f].get(t)
            if r is not None and existence_text(r) != before:
                before += f" ({existence_text(r)} in the hypothesis its detection was decided in)"
            out.append(f"| {f} | {before} | {gated} | {given} | {after} | {'yes' if s.reported else 'no'} |")
        out.append("")
    return out
