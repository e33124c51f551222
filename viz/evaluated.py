"""Where the evaluation put an involved object, when that is not where it was annotated.

The devkit drops every ground-truth box without LiDAR or radar points and interpolates each object's track over
the gap (``nuscenes.eval.tracking.loaders.interpolate_tracks``), with the two ends' weights swapped
(nuscenes-devkit issue #1141): the box a failure is scored against can lie metres from the annotation. This
module finds such objects at the focus frame (``evaluated_offsets``), says so in the focus summary
(``evaluated_notes``) and draws the evaluated box with its match circle (``log_evaluated``); ``devkit_gt`` says
where the evaluation has any object at any frame.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from functools import cache

import numpy as np
import rerun as rr

from gnnpmb.data.scene import SceneData
from gnnpmb.eval.failures import short_id
from gnnpmb.focus import FocusTarget
from gnnpmb.pipeline import TrackingRun
from viz.blueprint import focus_world
from viz.colors import CLASS_COLORS, GREY
from viz.geometry import quat_wxyz_to_xyzw, size_wlh_to_xyz

NEAR_DETECTION_M = 2.0
"""A detection or track within this BEV distance of a ground-truth object is "on" it (the devkit's match
distance)."""
EVALUATED_OFFSET_M = 0.5
"""An object whose box as evaluated lies farther than this from its annotated box gets a note and a label."""
MIRROR_MATCH_M = 0.05
"""The evaluated box is taken for the devkit's swapped-weight interpolation when it lies this close to it."""
BOX_LINE_RADIUS_M = 0.06
CIRCLE_LINE_RADIUS_M = 0.04
"""Line radii of the evaluated box and of its match circle and offset line: thinner than the focus highlights."""


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
        center, points, _kept = annotated[i]
        offset = float(np.hypot(center[0] - xy[0], center[1] - xy[1]))
        if offset > EVALUATED_OFFSET_M:
            out[gt_id] = EvaluatedGt(center, offset, points, _mirror_frame(scene, annotated, i, np.array(xy)))
    return out


def _annotated_track(scene: SceneData, gt_id: str) -> dict[int, tuple[np.ndarray, int, bool]]:
    """Frame -> (3,) annotated centre, points in the box and whether the devkit keeps the box (some points and
    within its class's range of the ego vehicle: ``filter_eval_boxes``) for one object."""
    ranges = _class_ranges()
    out = {}
    for keyframe in scene.keyframes:
        hit = np.flatnonzero(keyframe.gt.instance_id.astype(str) == gt_id)
        if hit.size:
            center = keyframe.gt.translation_m[hit[0]]
            points = int(keyframe.gt_num_pts[hit[0]])
            ego_m = float(np.hypot(*(center[:2] - keyframe.ego_pose.translation_m[:2])))
            reach = ranges.get(str(keyframe.gt.class_name[hit[0]]), np.inf)
            out[keyframe.index] = (center, points, points > 0 and ego_m <= reach)
    return out


@cache
def _class_ranges() -> dict[str, float]:
    """The evaluation's range per class (m from the ego vehicle; ``tracking_nips_2019``)."""
    from gnnpmb.eval.nuscenes_eval import tracking_config

    return {k: float(v) for k, v in tracking_config().class_range.items()}


def _devkit_interpolation(
    scene: SceneData, annotated: Mapping[int, tuple[np.ndarray, int, bool]], i: int
) -> tuple[int, int, np.ndarray] | None:
    """The nearest frames before and after frame ``i`` where the devkit keeps the object's box, and the (2,) BEV
    centre it interpolates between them for frame ``i``, with its weights swapped (``right_ratio`` = (t_right - t) /
    (t_right - t_left) applied to the right box; nuscenes-devkit issue #1141); None without such frames on both
    sides (the devkit then has no box for the object at frame ``i``)."""
    kept = sorted(f for f, (_c, _p, keep) in annotated.items() if keep)
    left = max((f for f in kept if f < i), default=None)
    right = min((f for f in kept if f > i), default=None)
    if left is None or right is None:
        return None
    t = [scene.keyframes[f].timestamp_us for f in (left, i, right)]
    swapped = (t[2] - t[1]) / (t[2] - t[0])
    return left, right, (1.0 - swapped) * annotated[left][0][:2] + swapped * annotated[right][0][:2]


@dataclass(frozen=True, slots=True)
class DevkitBox:
    """Where the evaluation has an object at one frame: the (2,) BEV centre (None: it has no box for it) and why
    (``annotated``, ``interpolated`` or the reason it has none)."""

    xy_m: np.ndarray | None
    why: str


NO_INTERPOLATION = "and the evaluation cannot interpolate it (it keeps no box of it both before and after this frame)"


def devkit_gt(scene: SceneData, gt_id: str, i: int) -> DevkitBox:
    """The box the evaluation has for object ``gt_id`` at frame ``i``: its annotation when the devkit keeps it,
    else the devkit's interpolation (``_devkit_interpolation``), else none."""
    annotated = _annotated_track(scene, gt_id)
    if i not in annotated:
        return DevkitBox(None, "not annotated at this frame")
    center, points, keep = annotated[i]
    if keep:
        return DevkitBox(center[:2], "annotated")
    interpolated = _devkit_interpolation(scene, annotated, i)
    if interpolated is not None:
        return DevkitBox(interpolated[2], "interpolated")
    if points == 0:
        return DevkitBox(None, f"it has no LiDAR or radar points here, {NO_INTERPOLATION}")
    keyframe = scene.keyframes[i]
    hit = np.flatnonzero(keyframe.gt.instance_id.astype(str) == gt_id)[0]
    class_name = str(keyframe.gt.class_name[hit])
    ego_m = float(np.hypot(*(center[:2] - keyframe.ego_pose.translation_m[:2])))
    reach = _class_ranges().get(class_name, np.inf)
    return DevkitBox(
        None,
        f"it lies {ego_m:.2f} m from the ego vehicle, beyond the evaluation's {reach:g} m range for {class_name}, "
        f"{NO_INTERPOLATION}",
    )


def _mirror_frame(
    scene: SceneData, annotated: Mapping[int, tuple[np.ndarray, int, bool]], i: int, evaluated_xy: np.ndarray
) -> tuple[int, int, int] | None:
    """The frames the devkit interpolated between and the frame mirrored about ``i`` between them, if the
    evaluated box is the devkit's swapped-weight interpolation (``_devkit_interpolation``) and that frame is
    annotated; else None."""
    interpolated = _devkit_interpolation(scene, annotated, i)
    if interpolated is None:
        return None
    left, right, xy = interpolated
    mirror = left + right - i
    if np.hypot(*(xy - evaluated_xy)) > MIRROR_MATCH_M or mirror not in annotated:
        return None
    return left, right, mirror


def evaluated_notes(
    focus: FocusTarget, scene: SceneData, runs: Mapping[str, TrackingRun], evaluated: Mapping[str, EvaluatedGt]
) -> list[str]:
    """A paragraph per involved object the evaluation saw elsewhere than its annotation (``evaluated``, from
    ``evaluated_offsets``):
    why, how far, and which tracks were within match distance of each box."""
    out = []
    for gt_id, seen in evaluated.items():
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


def evaluated_world() -> str:
    """Where the evaluation put the involved objects it interpolated (``EvaluatedGt``), at the focus frame."""
    return f"{focus_world()}/as_evaluated"


def log_evaluated(
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
            radii=BOX_LINE_RADIUS_M,
            labels=[f"GT {short_id(g)} as evaluated" for g in evaluated],
            show_labels=False,
        ),
        rr.LineStrips3D(strips, colors=[color], radii=CIRCLE_LINE_RADIUS_M, labels=labels, show_labels=False),
    )


RANGE_SHOWN_M = 5.0
"""The evaluation's range circle is drawn when the focused place lies within this of it (a failure made by an
object or track crossing the range)."""
RANGE_CIRCLE_POINTS = 721


def evaluation_range_world() -> str:
    """The evaluation's range around the ego vehicle for the focused class, when the failure lies near it."""
    return f"{focus_world()}/evaluation_range"


def range_near_focus(focus: FocusTarget, scene: SceneData) -> float | None:
    """The evaluation's range (m) for the focused class if the focused place lies within ``RANGE_SHOWN_M`` of it
    at the focus frame (the devkit drops boxes, ground truth and tracks alike, beyond it), else None."""
    reach = _class_ranges().get(focus.class_name)
    if reach is None:
        return None
    ego_xy = scene.keyframes[focus.frame_index].ego_pose.translation_m[:2]
    ego_m = float(np.hypot(focus.center_xy_m[0] - ego_xy[0], focus.center_xy_m[1] - ego_xy[1]))
    return reach if abs(ego_m - reach) <= RANGE_SHOWN_M else None


def log_evaluation_range(
    stream: rr.RecordingStream, focus: FocusTarget, scene: SceneData, frame_index: int, reach_m: float, z_m: float
) -> tuple[float, float, float]:
    """The circle of radius ``reach_m`` around the ego vehicle at ``frame_index`` (at height ``z_m``) in the
    focused class's colour; returns its point nearest the focused place, where its label goes."""
    ego_xy = scene.keyframes[frame_index].ego_pose.translation_m[:2]
    angles = np.linspace(0.0, 2.0 * np.pi, RANGE_CIRCLE_POINTS)
    circle = np.column_stack(
        [ego_xy[0] + reach_m * np.cos(angles), ego_xy[1] + reach_m * np.sin(angles), np.full(len(angles), z_m)]
    )
    color = CLASS_COLORS.get(focus.class_name, GREY)
    stream.log(evaluation_range_world(), rr.LineStrips3D([circle], colors=[color], radii=CIRCLE_LINE_RADIUS_M))
    toward = np.asarray(focus.center_xy_m) - ego_xy
    nearest = ego_xy + reach_m * toward / max(float(np.hypot(*toward)), 1e-9)
    return float(nearest[0]), float(nearest[1]), z_m
