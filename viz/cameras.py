"""The camera images of each keyframe and the LiDAR sweeps between keyframes, and the views that show them.

Layout as in Rerun's nuScenes example: each camera is ``world/ego_vehicle/CAM_*`` with its calibration (a
``Transform3D`` per keyframe: the camera in the keyframe's ego frame, and a static ``Pinhole``, camera frame x right,
y down, z forward) and its JPEG as an ``EncodedImage`` (the file's bytes, never decoded). A 2D view whose origin is
a camera entity projects the 3D boxes under ``world`` (ground truth, detections, each tracker's tracks and the focus
highlights) into the image through that transform tree, so the boxes are drawn where the camera saw them.

Images and transforms go in together with ``send_columns``: per camera one static chunk (the pinhole) and one
temporal chunk (two where the recording opens at a failure, ``viz.timeline.Clock``), whatever the number of
keyframes.

Sweeps (``--sweeps``): the LIDAR_TOP sweeps between keyframes on the ``timestamp`` timeline only (their own time),
under ``world/sweeps/ego_vehicle/LIDAR_TOP`` with each sweep's own ego pose; tracks stay at the keyframes.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence

import numpy as np
import rerun as rr
import rerun.blueprint as rrb

from gnnpmb.data.scene import SceneData
from gnnpmb.data.sensors import SceneSensors, camera_in_ego
from viz import paths
from viz.geometry import quat_wxyz_to_xyzw
from viz.pointcloud import DEFAULT_MAX_POINTS, DEFAULT_VOXEL_M, intensity_colors, prepare_sweep
from viz.timeline import TIMESTAMP, Clock

SCENE_ROW_SHARES = (3.0, 2.0)
"""Row shares of the scene views and the camera views below them."""
IMAGE_PLANE_DISTANCE_M = 1.5
"""How far in front of a camera its image is drawn in a 3D view (Rerun's frustum)."""


def log_cameras(
    stream: rr.RecordingStream, scene: SceneData, sensors: SceneSensors, frames: range, clock: Clock
) -> int:
    """Each camera's pinhole (static), its pose in the keyframe's ego frame and its JPEG at every keyframe of
    ``frames``; the number of JPEG bytes logged."""
    logged = 0
    for channel in sensors.channels:
        rows = [(i, image) for i in frames for image in sensors.cameras[i] if image.channel == channel]
        if not rows:
            continue
        path, first = paths.camera(channel), rows[0][1]
        stream.log(
            path,
            rr.Pinhole(
                image_from_camera=first.intrinsic,
                resolution=[first.width_px, first.height_px],
                camera_xyz=rr.ViewCoordinates.RDF,
                image_plane_distance=IMAGE_PLANE_DISTANCE_M,
            ),
            static=True,
        )
        index = np.array([i for i, _ in rows], dtype=np.int64)
        stamps = np.array([scene.keyframes[i].timestamp_us for i in index], dtype=np.int64)
        poses = [camera_in_ego(image, scene.keyframes[i].ego_pose) for i, image in rows]
        rotation = np.array([r for r, _ in poses])
        translation = np.array([t for _, t in poses])
        blobs = [image.path.read_bytes() for _, image in rows]
        logged += sum(len(b) for b in blobs)
        clock.send(stream, path, index, stamps, _camera_columns(rotation, translation, blobs))
    return logged


def _camera_columns(
    rotation: np.ndarray, translation: np.ndarray, blobs: list[bytes]
) -> Callable[[np.ndarray], rr.ComponentColumnList]:
    """The pose and JPEG columns of the selected rows, sent together: one chunk per camera (and timeline group)."""

    def columns(rows: np.ndarray) -> rr.ComponentColumnList:
        pose = rr.Transform3D.columns(translation=translation[rows], mat3x3=rotation[rows])
        image = rr.EncodedImage.columns(blob=[blobs[j] for j in rows], media_type=["image/jpeg"] * len(rows))
        return rr.ComponentColumnList([*pose, *image])

    return columns


def log_sweeps(
    stream: rr.RecordingStream,
    scene: SceneData,
    sensors: SceneSensors,
    frames: range,
    *,
    max_points: int = DEFAULT_MAX_POINTS,
    voxel_m: float = DEFAULT_VOXEL_M,
) -> int:
    """The LiDAR sweeps between the first and last keyframe of ``frames``, each at its own time on the
    ``timestamp`` timeline (not on ``frame``), with its own ego pose; the number of sweeps logged. On that
    timeline a keyframe's cloud shows until the first sweep after it, and each sweep until the next sweep or
    keyframe (``Clear`` rows on ``timestamp`` only, so the ``frame`` timeline is unchanged)."""
    from gnnpmb.data.nuscenes import load_lidar_points

    if not len(frames):
        return 0
    start_us = scene.keyframes[frames[0]].timestamp_us
    stop_us = scene.keyframes[frames[-1]].timestamp_us
    inside = [s for s in sensors.sweeps if start_us < s.timestamp_us < stop_us]
    if not inside:
        return 0
    calib = inside[0].calib
    stream.log(
        paths.SWEEP_LIDAR,
        rr.Transform3D(translation=calib.translation_m, quaternion=quat_wxyz_to_xyzw(calib.quat_wxyz)),
        static=True,
    )
    keyframe_us = [scene.keyframes[i].timestamp_us for i in frames]
    for t_us in keyframe_us:  # at a keyframe its own cloud shows, not the last sweep's
        stream.reset_time()
        stream.set_time(TIMESTAMP, timestamp=np.datetime64(int(t_us), "us"))
        stream.log(paths.SWEEP_LIDAR, rr.Clear(recursive=False))
    last_us = None
    for sweep in inside:
        stream.reset_time()
        stream.set_time(TIMESTAMP, timestamp=np.datetime64(int(sweep.timestamp_us), "us"))
        previous_keyframe = max(t for t in keyframe_us if t < sweep.timestamp_us)
        if last_us is None or last_us < previous_keyframe:  # the first sweep after a keyframe hides its cloud
            stream.log(paths.LIDAR, rr.Clear(recursive=False))
        last_us = sweep.timestamp_us
        pose = sweep.ego_pose
        transform = rr.Transform3D(translation=pose.translation_m, quaternion=quat_wxyz_to_xyzw(pose.quat_wxyz))
        stream.log(paths.SWEEP_EGO, transform)
        points = prepare_sweep(load_lidar_points(sweep), max_points=max_points, voxel_m=voxel_m)
        stream.log(paths.SWEEP_LIDAR, rr.Points3D(points[:, :3], colors=intensity_colors(points[:, 3])))
    stream.reset_time()
    return len(inside)


def camera_view(channel: str) -> rrb.Spatial2DView:
    """One camera's image with the boxes drawn into it (``viz.camera_boxes``: ground truth, kept detections, each
    tracker's tracks and the frame's failures, clipped to the image), nothing from the 3D scene: Rerun would
    draw 3D boxes past the image's edge and every 3D label with them."""
    return rrb.Spatial2DView(origin=paths.camera(channel), contents=["+ $origin/**"], name=channel)


def with_cameras(
    scene: rrb.Container, channels: Sequence[str], focus: bool, focus_channel: str | None
) -> rrb.Container:
    """The scene views above the cameras: in a focus recording the camera that sees the focus object (all six when
    none does), else the six in nuScenes' layout."""
    if focus and focus_channel is not None:
        return rrb.Vertical(scene, camera_view(focus_channel), row_shares=list(SCENE_ROW_SHARES))
    views = [camera_view(c) for c in channels]
    return rrb.Vertical(scene, rrb.Grid(*views, grid_columns=3, name="cameras"), row_shares=list(SCENE_ROW_SHARES))
