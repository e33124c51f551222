"""What else the sensors recorded besides the LIDAR_TOP keyframes: the camera images of each keyframe and the
LiDAR sweeps between keyframes.

A second persistent index beside ``gnnpmb.data.dataset_index`` (same store, ``gnnpmb.data.index_store``), in
``<cache root>/index/sensors-<key>/``, built once from the ``sensor``, ``calibrated_sensor``, ``scene``,
``sample``, ``sample_data`` and ``ego_pose`` tables. Per scene, one record batch in each of:

* ``cameras.arrow`` — every camera keyframe ``sample_data`` row of the scene's samples (the devkit's
  ``sample['data']['CAM_*']``) with its ego pose, calibration and intrinsic matrix;
* ``sweeps.arrow`` — the scene's non-keyframe LIDAR_TOP ``sample_data`` rows (nuScenes records 20 Hz, keyframes
  are 2 Hz), with ego pose and calibration, in time order.

A dataset without camera rows (or whose image files are absent, like the dev set's) has no cameras: the viewer
says so in one line. The demo's images are rendered on first use (``gnnpmb.data.demo.ensure_scene_images``).
"""

from __future__ import annotations

import hashlib
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import pyarrow as pa

from gnnpmb.data.dataset_index import _Tables
from gnnpmb.data.index_store import (
    code_identity,
    open_or_build,
    source_identity,
    write_batches,
    write_json_file,
    write_manifest,
)
from gnnpmb.data.scene import Pose, SceneData

FORMAT = 1
"""Bumped whenever the layout of this index changes."""
TABLES = ("sensor", "calibrated_sensor", "scene", "sample", "sample_data", "ego_pose")
LIDAR_CHANNEL = "LIDAR_TOP"
CAMERA_MODALITY = "camera"
CAMERA_ORDER = ("CAM_FRONT_LEFT", "CAM_FRONT", "CAM_FRONT_RIGHT", "CAM_BACK_LEFT", "CAM_BACK", "CAM_BACK_RIGHT")
"""nuScenes' six cameras as the devkit's ``render_sample`` lays them out (front row, then back row)."""


@dataclass(frozen=True, slots=True)
class CameraImage:
    """One camera's keyframe image: channel, JPEG path, timestamp_us, width/height in pixels, intrinsic (3, 3),
    ego_pose (the ego at the image's time, global frame) and calib (the camera frame in the ego frame; x right,
    y down, z forward)."""

    channel: str
    path: Path
    timestamp_us: int
    width_px: int
    height_px: int
    intrinsic: np.ndarray
    ego_pose: Pose
    calib: Pose


@dataclass(frozen=True, slots=True)
class LidarSweep:
    """One LIDAR_TOP sweep between keyframes: its sample (the keyframe it belongs to), lidar_path (float32 x 5
    per point, sensor frame), timestamp_us, ego_pose (global) and calib (LiDAR in ego)."""

    sample_token: str
    lidar_path: Path
    timestamp_us: int
    ego_pose: Pose
    calib: Pose


@dataclass(frozen=True, slots=True)
class SceneSensors:
    """cameras: per keyframe of the scene (same order), its camera images in channel order; sweeps: the
    non-keyframe LiDAR sweeps in time order."""

    cameras: tuple[tuple[CameraImage, ...], ...]
    sweeps: tuple[LidarSweep, ...]

    @property
    def channels(self) -> tuple[str, ...]:
        """The camera channels of the scene, in the order nuScenes lists them."""
        seen = {c.channel for images in self.cameras for c in images}
        return tuple(c for c in CAMERA_ORDER if c in seen) + tuple(sorted(seen - set(CAMERA_ORDER)))

    def missing_images(self, frames: range) -> list[Path]:
        """The camera image files of the keyframes ``frames`` that are not on disk."""
        return [c.path for i in frames for c in self.cameras[i] if not c.path.is_file()]


def absent_reason(sensors: SceneSensors, frames: range) -> str | None:
    """Why the scene's cameras cannot be shown at the keyframes ``frames`` (None: they can): no camera rows, or
    image files missing."""
    count = sum(len(sensors.cameras[i]) for i in frames)
    if count == 0:
        return "cameras absent: the dataset has no camera images for this scene"
    missing = sensors.missing_images(frames)
    if missing:
        return (
            f"cameras absent: {len(missing)} of {count} camera images of this scene are missing (first: "
            f"{missing[0]}); download the nuScenes samples/CAM_* folders into the dataroot"
        )
    return None


_POSE = ["ego_t_0", "ego_t_1", "ego_t_2", "ego_q_0", "ego_q_1", "ego_q_2", "ego_q_3"]
_CALIB = ["calib_t_0", "calib_t_1", "calib_t_2", "calib_q_0", "calib_q_1", "calib_q_2", "calib_q_3"]
_CAMERA_SCHEMA = pa.schema(
    [("sample_token", pa.string()), ("channel", pa.string()), ("filename", pa.string())]
    + [("timestamp", pa.int64()), ("width", pa.int64()), ("height", pa.int64())]
    + [(n, pa.float64()) for n in _POSE + _CALIB + [f"k_{i}" for i in range(9)]]
)
_SWEEP_SCHEMA = pa.schema(
    [("sample_token", pa.string()), ("filename", pa.string()), ("timestamp", pa.int64())]
    + [(n, pa.float64()) for n in _POSE + _CALIB]
)


def _index_folder(cache: Path, dataroot: Path, version: str) -> Path:
    key = hashlib.sha256(f"{dataroot}\0{version}".encode()).hexdigest()[:16]
    return cache / "index" / f"sensors-{key}"


def _build(tmp: Path, dataroot: Path, version: str, sources: list[list[Any]]) -> None:
    tables = _Tables(dataroot, version, None)
    sensors = {r["token"]: r for r in tables.rows("sensor")}
    calibrated = {r["token"]: r for r in tables.rows("calibrated_sensor")}
    scenes = [r["name"] for r in tables.rows("scene")]
    scene_pos = {tok: i for i, tok in enumerate(r["token"] for r in tables.rows("scene"))}
    sample_scene = {r["token"]: scene_pos.get(r["scene_token"], -1) for r in tables.rows("sample")}
    channel_of = {tok: sensors.get(r["sensor_token"], {}) for tok, r in calibrated.items()}
    cams: list[dict[str, Any]] = []
    sweeps: list[dict[str, Any]] = []
    for row in tables.rows("sample_data"):
        sensor = channel_of.get(row["calibrated_sensor_token"], {})
        if sensor.get("modality") == CAMERA_MODALITY and row["is_key_frame"]:
            cams.append(row | {"channel": sensor["channel"]})
        elif sensor.get("channel") == LIDAR_CHANNEL and not row["is_key_frame"]:
            sweeps.append(row)
    wanted = {r["ego_pose_token"] for r in cams} | {r["ego_pose_token"] for r in sweeps}
    poses = {r["token"]: r for r in tables.rows("ego_pose") if r["token"] in wanted}

    def columns(rows: list[dict[str, Any]], schema: pa.Schema, camera: bool) -> pa.RecordBatch:
        cols: dict[str, list[Any]] = {f.name: [] for f in schema}
        for r in sorted(rows, key=lambda r: (r["timestamp"], r.get("channel", ""))):
            pose, calib = poses[r["ego_pose_token"]], calibrated[r["calibrated_sensor_token"]]
            cols["sample_token"].append(r["sample_token"])
            cols["filename"].append(r["filename"])
            cols["timestamp"].append(int(r["timestamp"]))
            values = [*pose["translation"], *pose["rotation"], *calib["translation"], *calib["rotation"]]
            if camera:
                cols["channel"].append(r["channel"])
                cols["width"].append(int(r["width"]))
                cols["height"].append(int(r["height"]))
                values += list(np.asarray(calib["camera_intrinsic"], dtype=float).reshape(9))
            for name, v in zip(_POSE + _CALIB + ([f"k_{i}" for i in range(9)] if camera else []), values, strict=True):
                cols[name].append(float(v))
        return pa.RecordBatch.from_pydict(cols, schema=schema)

    def per_scene(rows: list[dict[str, Any]]) -> list[list[dict[str, Any]]]:
        out: list[list[dict[str, Any]]] = [[] for _ in scenes]
        for r in rows:
            pos = sample_scene.get(r["sample_token"], -1)
            if pos >= 0:
                out[pos].append(r)
        return out

    cam_batches = [columns(rows, _CAMERA_SCHEMA, True) for rows in per_scene(cams)]
    sweep_batches = [columns(rows, _SWEEP_SCHEMA, False) for rows in per_scene(sweeps)]
    files = {
        "scenes.json": write_json_file(tmp / "scenes.json", scenes),
        "cameras.arrow": write_batches(tmp / "cameras.arrow", _CAMERA_SCHEMA, cam_batches),
        "sweeps.arrow": write_batches(tmp / "sweeps.arrow", _SWEEP_SCHEMA, sweep_batches),
    }
    key = hashlib.sha256(repr((FORMAT, sources)).encode()).hexdigest()[:16]
    write_manifest(tmp, {"format": FORMAT, "sources": sources, "key": key, "version": version, "files": files})


def _poses(batch: pa.RecordBatch, names: list[str]) -> list[Pose]:
    values = np.column_stack([batch.column(n).to_numpy() for n in names]).reshape(-1, 7)
    return [Pose(translation_m=v[:3].copy(), quat_wxyz=v[3:].copy()) for v in values]


def load_scene_sensors(scene: SceneData, frames: range | None = None) -> SceneSensors:
    """The camera images of ``scene``'s keyframes and its LiDAR sweeps between keyframes (from the sensor index,
    built on first use). A demo scene's missing images of the keyframes ``frames`` (default: all) are rendered
    first (``gnnpmb.data.demo.ensure_scene_images``)."""
    from gnnpmb.cache_folder import cache_root

    dataroot, version = Path(scene.dataroot), scene.version
    sources = [*source_identity([dataroot / version / f"{t}.json" for t in TABLES]), code_identity(__name__)]
    store = open_or_build(
        _index_folder(cache_root(), dataroot, version),
        FORMAT,
        sources,
        lambda tmp: _build(tmp, dataroot, version, sources),
    )
    names = store.json("scenes.json")
    if scene.name not in names:
        return SceneSensors(cameras=tuple(() for _ in scene.keyframes), sweeps=())
    pos = names.index(scene.name)
    cams, sweeps = store.batch("cameras.arrow", pos), store.batch("sweeps.arrow", pos)
    if scene.synthetic and cams.num_rows:
        from gnnpmb.data.demo import ensure_scene_images

        ensure_scene_images(dataroot, scene.name, frames)
    keyframe_of = {k.sample_token: i for i, k in enumerate(scene.keyframes)}
    per_keyframe: list[list[CameraImage]] = [[] for _ in scene.keyframes]
    intrinsic = np.column_stack([cams.column(f"k_{i}").to_numpy() for i in range(9)]).reshape(-1, 3, 3)
    rows = zip(
        cams.column("sample_token").to_pylist(),
        cams.column("channel").to_pylist(),
        cams.column("filename").to_pylist(),
        cams.column("timestamp").to_pylist(),
        cams.column("width").to_pylist(),
        cams.column("height").to_pylist(),
        intrinsic,
        _poses(cams, _POSE),
        _poses(cams, _CALIB),
        strict=True,
    )
    for sample, channel, filename, stamp, width, height, k, pose, calib in rows:
        if sample in keyframe_of:
            per_keyframe[keyframe_of[sample]].append(
                CameraImage(channel, dataroot / filename, int(stamp), int(width), int(height), k, pose, calib)
            )
    order = {c: i for i, c in enumerate(CAMERA_ORDER)}
    cameras = tuple(
        tuple(sorted(images, key=lambda c: (order.get(c.channel, 99), c.channel))) for images in per_keyframe
    )
    lidar = tuple(
        LidarSweep(s, dataroot / f, int(t), pose, calib)
        for s, f, t, pose, calib in zip(
            sweeps.column("sample_token").to_pylist(),
            sweeps.column("filename").to_pylist(),
            sweeps.column("timestamp").to_pylist(),
            _poses(sweeps, _POSE),
            _poses(sweeps, _CALIB),
            strict=True,
        )
    )
    return SceneSensors(cameras=cameras, sweeps=lidar)


MIN_DEPTH_M = 1.0
"""A point nearer than this in front of a camera is not in its view (the devkit's ``map_pointcloud_to_image``)."""


def _rotation(quat_wxyz: np.ndarray) -> np.ndarray:
    from pyquaternion import Quaternion

    return Quaternion(np.asarray(quat_wxyz, dtype=float)).rotation_matrix


def camera_in_ego(image: CameraImage, ego: Pose) -> tuple[np.ndarray, np.ndarray]:
    """The camera frame of ``image`` in the ego frame ``ego`` (the keyframe's LiDAR-time ego pose, global):
    rotation (3, 3) and translation_m (3,), through the global frame (the ego moves between the two times)."""
    ego_r, img_r, cal_r = (
        _rotation(ego.quat_wxyz),
        _rotation(image.ego_pose.quat_wxyz),
        _rotation(image.calib.quat_wxyz),
    )
    rotation = ego_r.T @ img_r @ cal_r
    position = img_r @ image.calib.translation_m + image.ego_pose.translation_m
    return rotation, ego_r.T @ (position - ego.translation_m)


@dataclass(frozen=True, slots=True)
class CameraSighting:
    """A point inside one camera's field of view: channel, distance_m from the camera, pixel (u, v) and how far
    from the image centre it falls (0 at the centre, 1 at a corner)."""

    channel: str
    distance_m: float
    pixel: tuple[float, float]
    off_centre: float


def _pixel(point_m: np.ndarray, intrinsic: np.ndarray) -> tuple[float, float]:
    """(u, v) pixels of a (3,) camera point: ``K p / p_z`` in homogeneous coordinates, with the products of the
    devkit's ``view_points`` (the same bits) but without importing the devkit: its package loads scikit-learn,
    matplotlib and OpenCV (1.4 s)."""
    view = np.eye(4)
    view[:3, :3] = intrinsic
    uvw = np.dot(view, np.concatenate((point_m.reshape(3, 1), np.ones((1, 1)))))[:3]
    u, v = (uvw / uvw[2:3, :].repeat(3, 0).reshape(3, 1))[:2, 0]
    return u, v


def sightings(images: tuple[CameraImage, ...], point_global_m: np.ndarray) -> tuple[CameraSighting, ...]:
    """The cameras among ``images`` whose field of view holds the global point (3,) (in front by at least
    ``MIN_DEPTH_M`` and projecting inside the image; occlusion is not considered), most central first."""
    out = []
    for image in images:
        in_ego = _rotation(image.ego_pose.quat_wxyz).T @ (
            np.asarray(point_global_m, float) - image.ego_pose.translation_m
        )
        in_cam = _rotation(image.calib.quat_wxyz).T @ (in_ego - image.calib.translation_m)
        if in_cam[2] < MIN_DEPTH_M:
            continue
        u, v = _pixel(in_cam, image.intrinsic)
        if 0 <= u < image.width_px and 0 <= v < image.height_px:
            off = float(np.hypot(2 * u / image.width_px - 1, 2 * v / image.height_px - 1) / np.sqrt(2))
            out.append(CameraSighting(image.channel, float(np.linalg.norm(in_cam)), (float(u), float(v)), off))
    return tuple(sorted(out, key=lambda s: s.off_centre))
