"""Where the evaluation put an involved object, when that is not where it was annotated, drawn.

The devkit drops every ground-truth box without LiDAR or radar points and interpolates each object's track over
the gap with the two ends' weights swapped (nuscenes-devkit issue #1141): the box a failure is scored against can
lie metres from the annotation. The evaluation's own record of it (``gnnpmb.eval.evaluated.GtFrame``, kept in the
failure report) is what this module draws: the evaluated box with its match circle and a line to the annotation
(``log_evaluated``), and the evaluation's range around the ego vehicle when the failure lies near it.
"""

from __future__ import annotations

from collections.abc import Mapping
from functools import cache

import numpy as np
import rerun as rr

from gnnpmb.data.scene import SceneData
from gnnpmb.eval.evaluated import GtFrame, GtStatus
from gnnpmb.eval.failures import FailureReport, short_id
from gnnpmb.focus import FocusTarget
from gnnpmb.why.findings import EVALUATED_OFFSET_M, NEAR_M
from viz.blueprint import focus_world
from viz.colors import CLASS_COLORS, GREY
from viz.geometry import quat_wxyz_to_xyzw, size_wlh_to_xyz

BOX_LINE_RADIUS_M = 0.06
CIRCLE_LINE_RADIUS_M = 0.04
"""Line radii of the evaluated box and of its match circle and offset line: thinner than the focus highlights."""


def evaluated_offsets(focus: FocusTarget, report: FailureReport | None) -> dict[str, GtFrame]:
    """The involved objects the evaluation scored at the focus frame against an interpolated box
    ``EVALUATED_OFFSET_M`` or more from their annotation (from the report's record of the evaluation)."""
    if report is None:
        return {}
    out = {}
    for gt_id in focus.gt_ids:
        g = report.gt_frame(gt_id, focus.frame_index)
        if g is not None and g.status is GtStatus.INTERPOLATED and g.offset_m >= EVALUATED_OFFSET_M:
            out[gt_id] = g
    return out


def unannotated_evaluated(focus: FocusTarget, report: FailureReport | None) -> dict[str, tuple[float, float, float]]:
    """The involved objects with no annotation at the focus frame (they left view and came back) that the focused
    failure scored at a box the evaluation interpolated between their annotations: that box's centre (m, global),
    from the failure's own boxes. Nothing of the object is drawn there otherwise."""
    failure = report.by_id(focus.failure_id) if report is not None and focus.failure_id is not None else None
    if failure is None or failure.frame_index != focus.frame_index:
        return {}
    return {
        str(b.object_id): b.translation_m
        for b in failure.boxes
        if b.is_gt and b.interpolated and not b.annotated and str(b.object_id) in focus.gt_ids
    }


def evaluated_world() -> str:
    """Where the evaluation put the involved objects it interpolated, at the focus frame."""
    return f"{focus_world()}/as_evaluated"


def log_evaluated(
    stream: rr.RecordingStream, focus: FocusTarget, scene: SceneData, evaluated: Mapping[str, GtFrame]
) -> None:
    """Each ``evaluated`` object's box as evaluated (its annotated size and heading at the evaluated centre), the
    circle of the evaluation's match distance around it and a line from the annotated centre labelled with the
    offset; an empty batch clears them (frames other than the focus frame)."""
    gt = scene.keyframes[focus.frame_index].gt
    centers, sizes, quats, strips, labels = [], [], [], [], []
    for gt_id, g in evaluated.items():
        row = int(np.flatnonzero(gt.instance_id.astype(str) == gt_id)[0])
        annotated = np.asarray(gt.translation_m[row], dtype=np.float64)
        at = np.array([*g.evaluated_xy_m, annotated[2]])
        centers.append(at)
        sizes.append(size_wlh_to_xyz(gt.size_wlh_m[row : row + 1])[0])
        quats.append(quat_wxyz_to_xyzw(gt.quat_wxyz[row : row + 1])[0])
        angles = np.linspace(0.0, 2.0 * np.pi, 65)
        circle = np.stack([at[0] + NEAR_M * np.cos(angles), at[1] + NEAR_M * np.sin(angles)], 1)
        strips += [np.column_stack([circle, np.full(len(angles), at[2])]), np.stack([annotated, at])]
        labels += [f"{NEAR_M:.0f} m: match distance", f"{g.offset_m:.1f} m from the annotation"]
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


@cache
def _class_ranges() -> dict[str, float]:
    """The evaluation's range per class (m from the ego vehicle; the devkit's ``tracking_nips_2019``)."""
    from gnnpmb.eval.nuscenes_eval import tracking_config_file

    return {k: float(v) for k, v in tracking_config_file()["class_range"].items()}


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
