"""The focus overlay of a bug-report recording (``gnnpmb-viz --focus``): what went wrong, where, and the story.

* ``focus/summary`` (static TextDocument): the failure in words, the involved ids, what each tracker decided
  about them at the focus frame (the conflict tables of the decision view) and the story lines of the involved
  tracks, so the document alone explains the failure;
* ``world/focus``: the involved ground-truth objects and the detections the involved tracks were given, drawn
  slightly enlarged in their class colours;
* ``world/trackers/<tracker>/focus``: that tracker's involved tracks, enlarged, in their colours (their own
  boxes carry the id labels);
* ``world/trackers/<tracker>/focus/callouts``: the labels of the involved objects (``GT 8bccf2``, ``m10 0.83``,
  ``26 predicted r=0.04``) in a column beside them with leader lines (``viz.callouts``), so labels of objects
  on one spot do not cover each other.
"""

from __future__ import annotations

import re
from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import numpy as np
import rerun as rr

from gnnpmb.compare import Comparison, DisagreementKind
from gnnpmb.data.scene import SceneData
from gnnpmb.eval.failures import FailureKind, FailureReport, short_id
from gnnpmb.events import AxisKind
from gnnpmb.explain import PairChoice
from gnnpmb.focus import FocusTarget
from gnnpmb.pipeline import FrameResult, TrackingRun
from gnnpmb.types import Boxes
from viz import compare, paths
from viz.blueprint import (
    DEFAULT_FOCUS_HEIGHT_M,
    FOCUS_HEIGHT_M,
    FOCUS_TIMELINE,
    focus_doc,
    focus_world,
    reading_guide_doc,
)
from viz.callouts import Callout, log_callouts
from viz.colors import CLASS_COLORS, class_ids, track_colors
from viz.decisions import CLOSE_CALL_MARGIN, column_name, conflict_markdown, meas_name
from viz.geometry import estimate_boxes, quat_wxyz_to_xyzw, size_wlh_to_xyz
from viz.legend import COMPARISON_PLOT_HEIGHT_PX, PROBABILITY_RANGE, LegendPlacement, place_legend
from viz.logger import TrackerLogger, TrackStep
from viz.scene import detection_label
from viz.timeline import Clock

SCALE = 1.15
MARGIN_M = 0.25
LINE_RADIUS_M = 0.12
MAX_STORY_LINES = 40
MAX_KEY = 3
"""The summary's head names at most this many key decisions per tracker (the newest)."""
MAX_LISTED = 2
"""Per frame, the diagnosis names where the MAX_LISTED detections nearest to a track (lowest NIS) went."""
TABLE_FRAMES = 6
"""The frame tables show the focus frame and the TABLE_FRAMES frames before it."""
READING_GUIDE = """# How to read the views

**Bird's-eye and 3D views** (one pair per tracker)

- **Detections**: thin boxes in class colours, labelled `m<idx> <score>` (the same `m<idx>` everywhere: lines,
  tables, logs).
- **Ground truth**: translucent boxes.
- **Tracks**: boxes labelled with their id; the trail behind a track shows its last positions.
- **Gates**: the circles around each track's predicted position.
- **Association lines**: a solid line joins a track's prediction to the detection it was given; a faint line, a
  detection inside its gate that it was not given.
- **Failures**: enlarged boxes: magenta ID switch, orange fragmentation, red false track, green coalescence,
  yellow identity theft, grey miss.
- **Involved objects**: drawn enlarged; their labels stand in a column beside them, with a line to each object.
  Tracks that are not involved are drawn pale.
- **GT … as evaluated**: where the evaluation put an object that had no LiDAR or radar points at this frame (it
  interpolates a box between the frames where the object had points); the failure is scored against that box.
  It is drawn thin in the class colour, with a line to the annotated box and a circle of 2 m around it: a track
  outside that circle is not matched to the object.

**Panels**

- **focus**: the failure in words, the key decisions, and per tracker what happened to each involved track.
- **story**: each frame's events of the involved class (confirmed, missed, ended, close calls).
- **decisions** and **cost grid**: per conflict the chosen pair, its cost, the next best and the margin (lower
  cost = more likely).
- **existence**, **NIS**, **chosen cost**: the involved tracks' series up to the failure; the grey line is the
  existence from which a Bernoulli is shown as a track.
"""
GREY = (160, 160, 160)
NEAR_DETECTION_M = 2.0
"""A detection or track within this BEV distance of a ground-truth object is "on" it (the devkit's match
distance)."""
EVALUATED_OFFSET_M = 0.5
"""An object whose box as evaluated lies farther than this from its annotated box gets a note and a label."""
MIRROR_MATCH_M = 0.05
"""The evaluated box is taken for the devkit's swapped-weight interpolation when it lies this close to it."""


def tracker_focus(tracker: str) -> str:
    """Boxes3D of one tracker's involved tracks (only in that tracker's views)."""
    return f"{paths.tracker_world(tracker)}/focus"


def _mentions(text: str, track_ids: set[int]) -> bool:
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
    lines += _evaluated_gt_notes(focus, scene, runs)
    owner = focus.failure_tracker
    if owner in loggers and owner in runs and not evaluated_offsets(focus, scene):
        lines += _why(focus, scene, runs[owner], loggers[owner], shown)
    for tracker, logger in loggers.items():
        key = _key_decisions(logger, set(focus.track_ids.get(tracker, ())), focus.class_name, shown, focus.frame_index)
        if key:
            lines += [f"**Key decisions of {tracker}** (a detection an involved track could have taken):", ""]
            lines += [f"- {line}" for line in key] + [""]
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
        lines += _steps_markdown(logger, sorted(ids), shown, focus.frame_index)
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
            lines.append(f"No conflict involved these tracks at frame {focus.frame_index} (nothing in their gates).")
            lines.append("")
        story = [
            (f, text)
            for f, class_name, text, _level in logger.story
            if class_name == focus.class_name and f <= focus.frame_index and _mentions(text, ids)
        ]
        if story:
            lines.append("Story of the involved tracks:")
            lines.append("")
            lines += [f"- frame {f}: {text}" for f, text in story[-MAX_STORY_LINES:]]
            lines.append("")
    return "\n".join(lines) + "\n"


@dataclass(frozen=True, slots=True)
class EvaluatedGt:
    """An involved object the evaluation saw elsewhere than its annotation at the focus frame.

    center_m: (3,) annotated centre; offset_m: BEV distance of the evaluated box from it; points: LiDAR + radar
    points in the annotated box; swapped: when the evaluated box is the devkit's interpolation with its weights
    swapped (nuscenes-devkit issue #1141), the frames it interpolated between (the nearest with points) and the
    frame whose annotated place it took (else None).
    """

    center_m: np.ndarray
    offset_m: float
    points: int
    swapped: tuple[int, int, int] | None


def evaluated_offsets(focus: FocusTarget, scene: SceneData) -> dict[str, EvaluatedGt]:
    """The involved objects whose box as evaluated at the focus frame lies more than ``EVALUATED_OFFSET_M`` from
    their annotated box."""
    i = focus.frame_index
    out = {}
    for gt_id, xy in focus.evaluated_gt_xy_m.items():
        annotated = _annotated_track(scene, gt_id)
        if i not in annotated:
            continue
        center, points = annotated[i]
        offset = float(np.hypot(center[0] - xy[0], center[1] - xy[1]))
        if offset > EVALUATED_OFFSET_M:
            out[gt_id] = EvaluatedGt(center, offset, points, _mirror_frame(scene, annotated, i, np.array(xy)))
    return out


def _annotated_track(scene: SceneData, gt_id: str) -> dict[int, tuple[np.ndarray, int]]:
    """Frame -> (3,) annotated centre and points in the box of one object."""
    out = {}
    for keyframe in scene.keyframes:
        hit = np.flatnonzero(keyframe.gt.instance_id.astype(str) == gt_id)
        if hit.size:
            out[keyframe.index] = (keyframe.gt.translation_m[hit[0]], int(keyframe.gt_num_pts[hit[0]]))
    return out


def _mirror_frame(
    scene: SceneData, annotated: Mapping[int, tuple[np.ndarray, int]], i: int, evaluated_xy: np.ndarray
) -> tuple[int, int, int] | None:
    """The nearest annotated frames with points before and after frame ``i`` and the frame mirrored about ``i``
    between them, if the evaluated box is the devkit's interpolation with swapped weights (``right_ratio`` =
    (t_right - t) / (t_right - t_left) applied to the right box; nuscenes-devkit issue #1141) and that frame is
    annotated; else None."""
    seen = sorted(f for f, (_c, points) in annotated.items() if points > 0)
    left = max((f for f in seen if f < i), default=None)
    right = min((f for f in seen if f > i), default=None)
    if left is None or right is None:
        return None
    t = [scene.keyframes[f].timestamp_us for f in (left, i, right)]
    swapped = (t[2] - t[1]) / (t[2] - t[0])
    xy = (1.0 - swapped) * annotated[left][0][:2] + swapped * annotated[right][0][:2]
    mirror = left + right - i
    if np.hypot(*(xy - evaluated_xy)) > MIRROR_MATCH_M or mirror not in annotated:
        return None
    return left, right, mirror


def _evaluated_gt_notes(focus: FocusTarget, scene: SceneData, runs: Mapping[str, TrackingRun]) -> list[str]:
    """A paragraph per involved object the evaluation saw elsewhere than its annotation (``evaluated_offsets``):
    why, how far, and which tracks were within match distance of each box."""
    out = []
    for gt_id, seen in evaluated_offsets(focus, scene).items():
        xy = np.array(focus.evaluated_gt_xy_m[gt_id])
        near_evaluated, near_annotated, on_it = [], [], []
        for tracker, run in runs.items():
            frame = next((f for f in run.frames if f.keyframe.index == focus.frame_index), None)
            mine = [e for e in (frame.estimates if frame is not None else ()) if e.class_name == focus.class_name]
            for box_xy, found in ((xy, near_evaluated), (seen.center_m[:2], near_annotated)):
                ids = [
                    str(e.track_id)
                    for e in mine
                    if np.hypot(*(np.array(e.translation_m[:2]) - box_xy)) < NEAR_DETECTION_M
                ]
                found.append(f"{tracker} {'track ' + ', '.join(ids) if ids else 'no track'}")
            if near_evaluated[-1].endswith("no track") and not near_annotated[-1].endswith("no track"):
                on_it.append(near_annotated[-1])
        verdict = (
            f"**Verdict: the evaluation's doing.** {' and '.join(on_it)} followed the annotated object, but the "
            f"evaluation scored it against a box {seen.offset_m:.1f} m away."
            if on_it
            else ""
        )
        if seen.points == 0:
            why = (
                "it had no LiDAR or radar points, so the evaluation dropped its annotated box and interpolated one "
                "from the frames around it where it had points"
            )
            if seen.swapped is not None:
                left, right, mirror = seen.swapped
                t = [scene.keyframes[f].timestamp_us for f in (left, focus.frame_index, right)]
                share = (t[1] - t[0]) / (t[2] - t[0])
                why += (
                    f" (frames {left} and {right}). Frame {focus.frame_index} is {share:.2f} of the way from "
                    f"{left} to {right}, but the devkit weights the two ends the wrong way round (nuscenes-devkit "
                    f"issue #1141) and puts the box {1.0 - share:.2f} of the way, where the object is annotated at "
                    f"frame {mirror}"
                )
        else:
            why = "the evaluation's box differs from the annotated one"
        out += [
            f"**GT {short_id(gt_id)} as evaluated**: at frame {focus.frame_index} {why}; that box lies "
            f"**{seen.offset_m:.1f} m** from the annotated one (the column beside the views labels both). Within "
            f"{NEAR_DETECTION_M:.0f} m of the evaluated box: {'; '.join(near_evaluated)}. Within "
            f"{NEAR_DETECTION_M:.0f} m of the annotated box: {'; '.join(near_annotated)}.",
            "",
        ]
        if verdict:
            out[-2:-2] = [verdict, ""]
    return out


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
            other = f"; next {column_name(c.alternative)} {c.alternative_cost:.2f}" if c.alternative is not None else ""
            parts.append(f"{tracker}: {meas_name(m)} → **{went[tracker]}** ({c.chosen_cost:.2f}{other})")
        if touches:
            out.append(" · ".join(parts))
    return out


def _key_decisions(logger: TrackerLogger, ids: set[int], class_name: str, shown: range, last: int) -> list[str]:
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
                    other = f"over {column_name(alt)} ({c.alternative_cost:.2f})" if alt is not None else "(no other)"
                    out.append(
                        f"frame {f}: {meas_name(c.meas.ref)} → **{went}** (cost {c.chosen_cost:.2f}) {other}, "
                        f"margin {c.margin:.2f}"
                    )
    return out[-MAX_KEY:]


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
        if empty:
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
        peak = max(frames, key=lambda f: _after(steps[f]))
        parts.append(
            f"existence after update {_after(steps[peak]):.2f} at frame {peak} -> "
            f"{_after(steps[frames[-1]]):.2f} at frame {frames[-1]}"
        )
        parts.append("shown as a track" if steps[frames[-1]].reported else "not shown as a track")
        out.append(f"**track {t}**: " + "; ".join(parts) + ".")
    return out


def _after(step) -> float:
    """Existence after the update (0 when the track was pruned that frame)."""
    r = step.posterior_existence
    return 0.0 if r != r else r


def _frames(frames: list[int]) -> str:
    return ", ".join(str(f) for f in frames)


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


WHY_KINDS = {
    FailureKind.ID_SWITCH: (0, 1),
    FailureKind.IDENTITY_THEFT: (1, 0),
    FailureKind.FRAGMENTATION: (0, None),
}
"""Per failure kind with a track that lost the object: the positions in ``Failure.track_ids`` of that track and
of the track that took the object over (None: none did)."""


def _why(focus: FocusTarget, scene: SceneData, run: TrackingRun, logger: TrackerLogger, shown: range) -> list[str]:
    """One line for a failure where a track lost its object: how often the object was detected, what the lost
    track's existence did meanwhile and the choice that gave the object's detection to the other track."""
    if focus.failure_kind not in WHY_KINDS or not focus.gt_ids or not focus.failure_tracks:
        return []
    lost_at, took_at = WHY_KINDS[focus.failure_kind]
    lost = focus.failure_tracks[lost_at]
    took = focus.failure_tracks[took_at] if took_at is not None else None
    by_frame = {f.keyframe.index: f for f in run.frames}
    gt_id, detected, seen, empty = focus.gt_ids[0], [], 0, 0
    for i in range(shown.start, focus.frame_index + 1):
        gt = scene.keyframes[i].gt
        hit = np.flatnonzero(gt.instance_id.astype(str) == gt_id)
        if hit.size == 0 or i not in by_frame:
            continue
        seen += 1
        empty += int(scene.keyframes[i].gt_num_pts[hit[0]] == 0)
        if _nearest_detection(by_frame[i], focus.class_name, gt.translation_m[hit[0], :2]) is not None:
            detected.append(i)
    parts = [
        f"GT {short_id(gt_id)} had a detection within {NEAR_DETECTION_M:.0f} m in {len(detected)} of its {seen} "
        f"recorded frames up to {focus.frame_index}"
        + (f" ({empty} of them with no LiDAR or radar points)" if empty else "")
    ]
    steps = {f: st for f, st in logger.track_steps.get(lost, {}).items() if shown.start <= f <= focus.frame_index}
    if steps:
        peak = max(steps, key=lambda f: _after(steps[f]))
        parts.append(
            f"track {lost}'s existence went from {_after(steps[peak]):.2f} (frame {peak}) to "
            f"{_after(steps[max(steps)]):.2f} (frame {max(steps)})"
        )
    if took is not None:
        chosen = [
            line
            for line in _key_decisions(
                logger, set(focus.track_ids.get(run.tracker, ())), focus.class_name, shown, focus.frame_index
            )
            if f"**new track {took}**" in line or f"**track {took}**" in line
        ]
        if chosen:
            parts.append(f"then, {chosen[-1]}")
    return [f"**Why** ({run.tracker}): " + "; ".join(parts) + ".", ""]


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
        seen, detected, sent = 0, 0, []
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
            out += [
                f"**GT {short_id(gt_id)}**: a detection within {NEAR_DETECTION_M:.0f} m in {detected} of its {seen} "
                f"frames up to {focus.frame_index}; {news} of them started a new track, the others went to "
                f"{', '.join(sorted({w for w in sent if w != '—' and not w.startswith('new')})) or 'no track'}.",
                "",
                f"GT {short_id(gt_id)}, frame by frame (the evaluation counted {counted}):",
                "",
                "| frame | points in box | nearest detection | sent to | tracks output on it (score) |",
                "|---|---|---|---|---|",
                *rows,
                "",
            ]
    return out


def _steps_markdown(logger: TrackerLogger, track_ids: list[int], shown: range, last: int) -> list[str]:
    """Per involved track, a table of its frames up to ``last``: existence before and after the update, the
    detections in its gate (with NIS) and the one it was given, and whether it was reported."""
    out: list[str] = []
    for t in track_ids:
        steps = {
            f: s for f, s in logger.track_steps.get(t, {}).items() if max(shown.start, last - TABLE_FRAMES) <= f <= last
        }
        if not steps:
            continue
        out += [
            f"Track {t}, frame by frame:",
            "",
            "| frame | r before update | in gate (NIS) | given | r after | shown |",
            "|---|---|---|---|---|---|",
        ]
        for f in sorted(steps):
            s = steps[f]
            gated = ", ".join(f"m{m} ({nis:.1f})" for m, nis in s.gated) or "nothing"
            given = f"m{s.given}" if s.given >= 0 else "—"
            after = "pruned" if s.posterior_existence != s.posterior_existence else f"{s.posterior_existence:.2f}"
            out.append(
                f"| {f} | {s.prior_existence:.2f} | {gated} | {given} | {after} | {'yes' if s.reported else 'no'} |"
            )
        out.append("")
    return out


def log_focus(
    stream: rr.RecordingStream,
    focus: FocusTarget,
    scene: SceneData,
    runs: Sequence[TrackingRun],
    loggers: Mapping[str, TrackerLogger],
    clock: Clock,
    shown: range,
    reports: Mapping[str, FailureReport] | None = None,
) -> None:
    """The summary document and, at every keyframe of ``shown``, the highlighted objects (reports: see
    ``focus_markdown``)."""
    stream.log(
        focus_doc(),
        rr.TextDocument(
            focus_markdown(focus, loggers, shown, scene, {run.tracker: run for run in runs}, reports),
            media_type="text/markdown",
        ),
        static=True,
    )
    stream.log(reading_guide_doc(), rr.TextDocument(READING_GUIDE, media_type="text/markdown"), static=True)
    frames = {run.tracker: {f.keyframe.index: f for f in run.frames} for run in runs}
    gt_ids = set(focus.gt_ids)
    evaluated = evaluated_offsets(focus, scene)
    height_m = FOCUS_HEIGHT_M.get(focus.class_name, DEFAULT_FOCUS_HEIGHT_M)
    for i in shown:
        keyframe = scene.keyframes[i]
        clock.set(stream, i, keyframe.timestamp_us)
        gt = keyframe.gt
        rows = np.flatnonzero(np.isin(gt.instance_id.astype(str), list(gt_ids))) if len(gt) else np.zeros(0, int)
        centers = [gt.translation_m[rows]]
        sizes = [size_wlh_to_xyz(gt.size_wlh_m[rows])]
        quats = [quat_wxyz_to_xyzw(gt.quat_wxyz[rows])]
        names = [gt.class_name[rows]]
        labels = [f"GT {short_id(str(t))}" for t in gt.instance_id[rows]]
        gt_callouts = [
            Callout(tuple(gt.translation_m[r]), label, CLASS_COLORS.get(str(gt.class_name[r]), GREY))
            for r, label in zip(rows.tolist(), labels, strict=True)
        ]
        z_m = float(gt.translation_m[rows[0], 2]) if rows.size else scene.ground_z_m
        if i == focus.frame_index:
            gt_callouts += [
                Callout(
                    (*focus.evaluated_gt_xy_m[gt_id], float(seen.center_m[2])),
                    f"GT {short_id(gt_id)} as evaluated ({seen.offset_m:.1f} m off)",
                    CLASS_COLORS.get(focus.class_name, GREY),
                )
                for gt_id, seen in evaluated_offsets(focus, scene).items()
            ]
        meas: set[int] = set()
        detections = None
        for tracker, ids in focus.track_ids.items():
            frame = frames[tracker].get(i)
            if frame is None:
                log_callouts(stream, paths.focus_callouts(tracker), [], height_m)
                continue
            chosen = [e for e in frame.estimates if e.track_id in ids]
            boxes = estimate_boxes(chosen)
            stream.log(
                tracker_focus(tracker),
                rr.Boxes3D(
                    centers=boxes.centers_m,
                    half_sizes=0.5 * (boxes.sizes_xyz_m * SCALE + MARGIN_M),
                    quaternions=boxes.quat_xyzw,
                    colors=track_colors(np.array([e.track_id for e in chosen], dtype=np.int64)),
                    radii=LINE_RADIUS_M,
                ),
            )
            steps = {t: loggers[tracker].track_steps.get(t, {}).get(i) for t in sorted(ids)}
            given = {e.meas_index for e in chosen if e.meas_index >= 0}
            given |= {s.given for s in steps.values() if s is not None and s.given >= 0}
            meas |= given
            detections = frame.detections.boxes
            log_callouts(
                stream,
                paths.focus_callouts(tracker),
                gt_callouts + _detection_callouts(detections, sorted(given)) + _prediction_callouts(steps, z_m),
                height_m,
            )
        if meas and detections is not None:
            given = sorted(meas)
            det = detections.subset(np.array(given, dtype=np.int64))
            centers.append(det.translation_m)
            sizes.append(size_wlh_to_xyz(det.size_wlh_m))
            quats.append(quat_wxyz_to_xyzw(det.quat_wxyz))
            names.append(det.class_name)
            labels += [detection_label(m, s) for m, s in zip(given, det.score, strict=True)]
        size = np.concatenate(sizes).reshape(-1, 3)
        stream.log(
            focus_world(),
            rr.Boxes3D(
                centers=np.concatenate(centers).reshape(-1, 3),
                half_sizes=0.5 * (size * SCALE + MARGIN_M),
                quaternions=np.concatenate(quats).reshape(-1, 4),
                class_ids=class_ids(np.concatenate(names)),
                labels=labels,
                radii=LINE_RADIUS_M,
                show_labels=False,
            ),
        )
        if evaluated:
            _log_evaluated(stream, focus, scene, evaluated if i == focus.frame_index else {})


def evaluated_world() -> str:
    """Where the evaluation put the involved objects it interpolated (``EvaluatedGt``), at the focus frame."""
    return f"{focus_world()}/as_evaluated"


def _log_evaluated(
    stream: rr.RecordingStream, focus: FocusTarget, scene: SceneData, evaluated: Mapping[str, EvaluatedGt]
) -> None:
    """Each ``evaluated`` object's box as evaluated (its annotated size and heading at the evaluated centre), the
    circle of the evaluation's match distance around it and a line from the annotated centre labelled with the
    offset; an empty batch clears them (frames other than the focus frame)."""
    gt = scene.keyframes[focus.frame_index].gt
    centers, sizes, quats, strips, labels = [], [], [], [], []
    for gt_id, seen in evaluated.items():
        row = int(np.flatnonzero(gt.instance_id.astype(str) == gt_id)[0])
        at = np.array([*focus.evaluated_gt_xy_m[gt_id], seen.center_m[2]])
        centers.append(at)
        sizes.append(size_wlh_to_xyz(gt.size_wlh_m[row : row + 1])[0])
        quats.append(quat_wxyz_to_xyzw(gt.quat_wxyz[row : row + 1])[0])
        angles = np.linspace(0.0, 2.0 * np.pi, 65)
        circle = np.stack([at[0] + NEAR_DETECTION_M * np.cos(angles), at[1] + NEAR_DETECTION_M * np.sin(angles)], 1)
        strips += [np.column_stack([circle, np.full(len(angles), at[2])]), np.stack([seen.center_m, at])]
        labels += [f"{NEAR_DETECTION_M:.0f} m: match distance", f"{seen.offset_m:.1f} m from the annotation"]
    color = CLASS_COLORS.get(focus.class_name, GREY)
    stream.log(
        evaluated_world(),
        rr.Boxes3D(
            centers=np.array(centers).reshape(-1, 3),
            half_sizes=0.5 * np.array(sizes).reshape(-1, 3),
            quaternions=np.array(quats).reshape(-1, 4),
            colors=[color],
            radii=LINE_RADIUS_M / 2,
            labels=[f"GT {short_id(g)} as evaluated" for g in evaluated],
            show_labels=False,
        ),
        rr.LineStrips3D(strips, colors=[color], radii=LINE_RADIUS_M / 3, labels=labels, show_labels=False),
    )


def focus_legends(
    focus: FocusTarget, loggers: Mapping[str, TrackerLogger], comparison: Comparison | None = None
) -> dict[str, LegendPlacement]:
    """Legend placements (``viz.legend``) of the series views a focus recording opens with, keyed by the view's
    origin: per tracker the existence (the involved tracks and the class's threshold) and NIS views, and the
    disagreement counts; from the values the views show, which end at the focus frame."""
    out: dict[str, LegendPlacement] = {}
    last = focus.frame_index
    for tracker, logger in loggers.items():
        ids = focus.track_ids.get(tracker, ())
        views = {
            paths.existence_root(tracker): [
                *(paths.existence(tracker, focus.class_name, t) for t in ids),
                paths.extraction_threshold(tracker, focus.class_name),
            ],
            paths.nis_root(tracker): [paths.nis(tracker, focus.class_name, t) for t in ids],
        }
        for root, series in views.items():
            sent = [logger.sent_series[p] for p in series if p in logger.sent_series]
            # The legend names every series of the view, also those without a value up to the focus frame.
            lines = [(f[f <= last], v[f <= last]) for f, v in sent]
            fixed = PROBABILITY_RANGE if root == paths.existence_root(tracker) else None
            out[root] = place_legend(lines, len(sent), y_range=fixed)
    if comparison is not None:
        frames = np.asarray(comparison.frame_indices)
        upto = frames <= last
        counts = [(frames[upto], comparison.counts(kind)[upto]) for kind in DisagreementKind]
        out[compare.counts_root()] = place_legend(counts, plot_height_px=COMPARISON_PLOT_HEIGHT_PX)
    return out


def _detection_callouts(detections: Boxes, given: list[int]) -> list[Callout]:
    """``m<idx> <score>`` at each detection ``given`` (indices into the frame's detections)."""
    return [
        Callout(
            tuple(detections.translation_m[m]),
            detection_label(m, detections.score[m]),
            CLASS_COLORS.get(str(detections.class_name[m]), GREY),
        )
        for m in given
    ]


def _prediction_callouts(steps: Mapping[int, TrackStep | None], z_m: float) -> list[Callout]:
    """``<id> predicted r=<prior existence>`` at each focused track's predicted position this frame."""
    return [
        Callout(
            (*step.predicted_xy_m, z_m),
            f"{t} predicted r={step.prior_existence:.2f}",
            tuple(int(v) for v in track_colors(np.array([t], dtype=np.int64))[0]),
        )
        for t, step in steps.items()
        if step is not None
    ]
