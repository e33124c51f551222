"""Logging a scene to Rerun: ego poses, LiDAR sweeps, ground truth and detections, one keyframe at a time.

Every keyframe is logged on the timelines of ``viz.timeline.Clock``: ``frame`` (keyframe index) and ``timestamp``
(the keyframe's LiDAR time), plus ``focus`` in focus recordings. Boxes are in the nuScenes global frame (under
``world``); the LiDAR points stay in the sensor frame under ``world/ego_vehicle/LIDAR_TOP`` and Rerun places them
with the logged transforms.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence

import numpy as np
import rerun as rr

from gnnpmb.data.scene import Keyframe, SceneData
from gnnpmb.data.sensor_files import LidarPresence
from gnnpmb.eval.failures import short_id
from gnnpmb.types import Boxes, FrameDetections
from gnnpmb.why.words import frames_text
from viz import paths
from viz.colors import annotation_context, class_colors, class_ids
from viz.geometry import quat_wxyz_to_xyzw, rerun_boxes
from viz.pointcloud import DEFAULT_MAX_POINTS, DEFAULT_VOXEL_M, intensity_colors, prepare_sweep
from viz.timeline import PLAIN_CLOCK, Clock

PointsLoader = Callable[[Keyframe], np.ndarray | None]
"""Returns a keyframe's LiDAR sweep as (N, >=4) [x, y, z, intensity, ...] in the sensor frame, or None when its
file is not on disk (``gnnpmb.data.sensor_files``): that keyframe then shows no points, not the last sweep."""

GT_LINE_RADIUS_M = 0.05
DETECTION_LINE_RADIUS_M = 0.03
SUPPRESSED_ALPHA = 70
EGO_BODY_CENTER_M = (1.4, 0.0, 0.8)
"""Body box of the nuScenes ego car (Renault Zoe) in the ego frame, whose origin is the rear axle centre."""
EGO_BODY_SIZE_XYZ_M = (4.1, 1.73, 1.56)


def log_static_context(stream: rr.RecordingStream) -> None:
    """Z-up world and the class colours; static, logged once per recording."""
    stream.log(paths.WORLD, rr.ViewCoordinates.RIGHT_HAND_Z_UP, static=True)
    stream.log(paths.ROOT, annotation_context(), static=True)


def log_scene(
    stream: rr.RecordingStream,
    scene: SceneData,
    frame_detections: Sequence[FrameDetections],
    frame_range: range | None = None,
    *,
    points_loader: PointsLoader | None = None,
    max_points: int = DEFAULT_MAX_POINTS,
    voxel_m: float = DEFAULT_VOXEL_M,
    on_frame: Callable[[], None] | None = None,
    clock: Clock = PLAIN_CLOCK,
    sensor_note: str | None = None,
) -> None:
    """Log the keyframes ``frame_range`` (default: all) of ``scene`` on the timelines of ``clock``.

    frame_detections: one entry per logged keyframe, in order (``[f.detections for f in run.frames]``).
    points_loader: reads a keyframe's sweep; without one no LiDAR is logged. Sweeps above max_points are
    voxel-downsampled (edge voxel_m). on_frame is called after each keyframe (progress bars). sensor_note: a line
    for the scene's document about sensor files that are not on disk (``lidar_notice``).
    """
    indices = frame_range if frame_range is not None else range(len(scene.keyframes))
    if len(frame_detections) != len(indices):
        raise ValueError(f"got {len(frame_detections)} frames of detections for {len(indices)} keyframes")
    log_static_context(stream)
    stream.log(
        paths.SCENE_INFO, rr.TextDocument(_scene_markdown(scene, sensor_note), media_type="text/markdown"), static=True
    )
    stream.log(
        paths.EGO_BODY,
        rr.Boxes3D(
            centers=[EGO_BODY_CENTER_M],
            sizes=[EGO_BODY_SIZE_XYZ_M],
            labels=["ego"],
            colors=[(200, 200, 200)],
            show_labels=False,  # the grey box the views follow; its name is a click away
        ),
        static=True,
    )
    if len(indices):
        calib = scene.keyframes[indices[0]].lidar_calib
        stream.log(
            paths.LIDAR,
            rr.Transform3D(translation=calib.translation_m, quaternion=quat_wxyz_to_xyzw(calib.quat_wxyz)),
            static=True,
        )
    for i, detections in zip(indices, frame_detections, strict=True):
        keyframe = scene.keyframes[i]
        log_keyframe(
            stream,
            keyframe,
            detections,
            points_loader=points_loader,
            max_points=max_points,
            voxel_m=voxel_m,
            clock=clock,
        )
        if on_frame is not None:
            on_frame()


def log_keyframe(
    stream: rr.RecordingStream,
    keyframe: Keyframe,
    detections: FrameDetections,
    *,
    points_loader: PointsLoader | None = None,
    max_points: int = DEFAULT_MAX_POINTS,
    voxel_m: float = DEFAULT_VOXEL_M,
    clock: Clock = PLAIN_CLOCK,
) -> None:
    """Ego pose, LiDAR sweep, ground truth and detections of one keyframe, at that keyframe's time."""
    clock.set(stream, keyframe.index, keyframe.timestamp_us)
    pose = keyframe.ego_pose
    stream.log(paths.EGO, rr.Transform3D(translation=pose.translation_m, quaternion=quat_wxyz_to_xyzw(pose.quat_wxyz)))
    points = points_loader(keyframe) if points_loader is not None else None
    if points is not None:
        sweep = prepare_sweep(points, max_points=max_points, voxel_m=voxel_m)
        stream.log(paths.LIDAR, rr.Points3D(sweep[:, :3], colors=intensity_colors(sweep[:, 3])))
    elif points_loader is not None:  # this keyframe's file is missing: no points, rather than the last sweep
        stream.log(paths.LIDAR, rr.Points3D(np.empty((0, 3), dtype=np.float32)))
    stream.log(paths.GT, _gt_boxes(keyframe.gt))
    kept = np.flatnonzero(np.asarray(detections.kept, dtype=bool))
    stream.log(paths.DETECTIONS_KEPT, _detection_boxes(detections.boxes.subset(kept), kept))
    dropped = np.flatnonzero(~np.asarray(detections.kept, dtype=bool))
    stream.log(
        paths.DETECTIONS_SUPPRESSED,
        _detection_boxes(
            detections.boxes.subset(dropped),
            dropped,
            reasons=np.where(np.asarray(detections.suppressed_by_nms)[dropped], "nms", "low"),
        ),
    )


def _gt_boxes(gt: Boxes) -> rr.Boxes3D:
    b = rerun_boxes(gt)
    return rr.Boxes3D(
        centers=b.centers_m,
        sizes=b.sizes_xyz_m,
        quaternions=b.quat_xyzw,
        class_ids=class_ids(gt.class_name),
        labels=[short_id(str(t)) for t in gt.instance_id],
        radii=GT_LINE_RADIUS_M,
        fill_mode=rr.components.FillMode.TransparentFillMajorWireframe,
        show_labels=False,
    )


def detection_label(source_index: int, score: float) -> str:
    """``m<idx> <score>``: the detection's name in every view, event and log line, and its score."""
    return f"m{int(source_index)} {float(score):.2f}"


def _detection_boxes(boxes: Boxes, source_index: np.ndarray, reasons: np.ndarray | None = None) -> rr.Boxes3D:
    """Kept detections in class colours labelled ``m<idx> <score>``; dropped ones (reasons "nms"/"low" score)
    dimmed."""
    b = rerun_boxes(boxes)
    scores = np.asarray(boxes.score, dtype=np.float64)
    labels = [detection_label(i, s) for i, s in zip(np.asarray(source_index).tolist(), scores, strict=True)]
    if reasons is None:
        colors = None
    else:
        labels = [f"{label} {r}" for label, r in zip(labels, reasons, strict=True)]
        colors = class_colors(boxes.class_name, alpha=SUPPRESSED_ALPHA)
    return rr.Boxes3D(
        centers=b.centers_m,
        sizes=b.sizes_xyz_m,
        quaternions=b.quat_xyzw,
        class_ids=class_ids(boxes.class_name),
        labels=labels,
        colors=colors,
        radii=DETECTION_LINE_RADIUS_M,
        show_labels=False,
    )


def lidar_notice(presence: LidarPresence) -> str | None:
    """The one line that says which LiDAR files the recording is drawn without (None when none is missing)."""
    if presence.complete:
        return None
    if presence.absent:
        return (
            f"{presence.scene_name}: no LiDAR files in this dataroot (looked for {presence.example}; a metadata-only "
            "download?): boxes, tracks, failures and explanations are drawn without the point cloud"
        )
    return (
        f"{presence.scene_name}: the LiDAR files of {len(presence.missing)} of {len(presence.checked)} keyframes are "
        f"missing ({frames_text(presence.missing)}; e.g. {presence.example}): those keyframes are drawn without "
        "points, the others with their sweep"
    )


def _scene_markdown(scene: SceneData, sensor_note: str | None = None) -> str:
    kind = "synthetic demo data" if scene.synthetic else "nuScenes"
    note = f"- sensor files: {sensor_note.split(': ', 1)[-1]}\n" if sensor_note else ""
    return (
        f"# {scene.name}\n\n{scene.description}\n\n"
        f"- dataset: {kind}, version `{scene.version}`\n- keyframes: {len(scene.keyframes)}\n- token: `{scene.token}`\n"
        + note
    )
