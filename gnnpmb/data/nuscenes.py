"""Find a nuScenes dataroot, open it with the devkit and turn its scenes into ``SceneData``.

Where the data comes from: an explicit ``--dataroot`` wins, then the environment variable ``NUSCENES_DATAROOT``,
then the built-in synthetic demo (``gnnpmb.data.demo.ensure_demo_dataset``); a damaged demo cache is generated
again. Any dataroot is checked before the devkit loads it (loading the full trainval tables takes a while), so a
wrong path fails fast with one line.
The devkit is imported lazily: importing this module stays cheap.
"""

from __future__ import annotations

import json
import os
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from gnnpmb.data.demo import (
    CLUTTER_HOTSPOTS,
    DEMO_VERSION,
    SYNTHETIC_MARKER,
    TABLE_NAMES,
    ClutterHotspot,
    ensure_demo_dataset,
)
from gnnpmb.data.scene import Keyframe, Pose, SceneData
from gnnpmb.errors import DataError, UnknownNameError
from gnnpmb.types import Boxes

if TYPE_CHECKING:
    from nuscenes.nuscenes import NuScenes

DATAROOT_ENV = "NUSCENES_DATAROOT"
LIDAR_CHANNEL = "LIDAR_TOP"
_POINT_BYTES = 5 * 4
_FIX_HINT = "pass --dataroot pointing at the folder that contains v1.0-mini/ (or another v1.0-* folder)"


@dataclass(frozen=True, slots=True)
class DatasetLocation:
    """A checked dataroot: the folder, the version (table folder name) and whether it is the synthetic demo."""

    dataroot: Path
    version: str
    synthetic: bool


def _not_a_dataroot(dataroot: Path, why: str) -> DataError:
    return DataError(f"{dataroot} is not a nuScenes dataroot: {why}; {_FIX_HINT}")


def _version_folders(dataroot: Path) -> list[str]:
    return sorted(p.name for p in dataroot.iterdir() if p.is_dir() and p.name.startswith("v1.0-"))


def _read_scene_table(dataroot: Path, version: str) -> list[dict]:
    path = dataroot / version / "scene.json"
    try:
        table = json.loads(path.read_text(encoding="utf-8"))
    except (OSError, UnicodeDecodeError, ValueError) as exc:
        raise _not_a_dataroot(dataroot, f"{version}/scene.json cannot be read ({type(exc).__name__})") from exc
    if not isinstance(table, list) or not all(isinstance(r, dict) and "name" in r for r in table):
        raise _not_a_dataroot(dataroot, f"{version}/scene.json is not a list of scene records")
    return table


def is_synthetic_description(description: str) -> bool:
    """Whether a scene description marks the scene as the synthetic demo's."""
    return description.startswith(SYNTHETIC_MARKER)


def check_dataroot(dataroot: Path, version: str | None, source: str = "--dataroot") -> DatasetLocation:
    """Check that ``dataroot`` holds the tables of ``version`` (or of its only ``v1.0-*`` folder if None).

    ``source`` names where the path came from, for the error message.
    """
    dataroot = Path(dataroot).expanduser()
    if not dataroot.exists():
        raise DataError(f"dataroot {dataroot} (from {source}) does not exist; {_FIX_HINT}")
    if not dataroot.is_dir():
        raise _not_a_dataroot(dataroot, "it is a file, not a folder")
    dataroot = dataroot.resolve()
    found = _version_folders(dataroot)
    if version is None:
        if not found:
            why = "it has no v1.0-* folder"
            if dataroot.name.startswith("v1.0-"):
                why = f"it is itself a version folder (use its parent {dataroot.parent})"
            raise _not_a_dataroot(dataroot, why)
        if len(found) > 1:
            raise DataError(
                f"{dataroot} holds several nuScenes versions ({', '.join(found)}); "
                "pass --nuscenes-version with one of them"
            )
        version = found[0]
    elif not (dataroot / version).is_dir():
        have = f"found: {', '.join(found)}" if found else "it has no v1.0-* folder"
        raise _not_a_dataroot(dataroot, f"no {version}/ folder ({have})")
    missing = [t for t in TABLE_NAMES if not (dataroot / version / f"{t}.json").is_file()]
    if missing:
        raise _not_a_dataroot(dataroot, f"{version}/ lacks the table(s) {', '.join(f'{t}.json' for t in missing)}")
    scenes = _read_scene_table(dataroot, version)
    synthetic = bool(scenes) and all(is_synthetic_description(str(r.get("description", ""))) for r in scenes)
    return DatasetLocation(dataroot=dataroot, version=version, synthetic=synthetic)


def resolve_dataroot(dataroot: Path | None, version: str | None, needs: tuple[str, ...] = ()) -> DatasetLocation:
    """The dataset to use: ``dataroot`` if given, else ``$NUSCENES_DATAROOT``, else the synthetic demo (with the
    generated train scenes when ``needs``, split or scene names, asks for them)."""
    if dataroot is not None:
        return check_dataroot(Path(dataroot), version, "--dataroot")
    from_env = os.environ.get(DATAROOT_ENV)
    if from_env:
        return check_dataroot(Path(from_env), version, DATAROOT_ENV)
    if version is not None and version != DEMO_VERSION:
        raise DataError(
            f"the built-in demo dataset only has version {DEMO_VERSION}, not {version}; pass --dataroot (or set "
            f"{DATAROOT_ENV}) for real nuScenes data"
        )
    try:
        return check_dataroot(ensure_demo_dataset(needs), DEMO_VERSION, "the built-in demo")
    except DataError:
        return check_dataroot(_rebuild_demo(needs), DEMO_VERSION, "the built-in demo")


def _rebuild_demo(needs: tuple[str, ...]) -> Path:
    """Generate the cached demo for ``needs`` again (it was damaged, e.g. a table edited or truncated)."""
    from gnnpmb.data.demo import demo_layout

    _OPENED.pop((demo_layout(needs)[0].expanduser().resolve(), DEMO_VERSION), None)
    return ensure_demo_dataset(needs, rebuild=True)


def _demo_needs(location: DatasetLocation) -> tuple[str, ...] | None:
    """The ``needs`` whose cached demo is at ``location`` (None: not a cached demo)."""
    from gnnpmb.data.demo import demo_layout

    if location.version != DEMO_VERSION:
        return None
    for needs in ((), ("mini_train",)):
        if location.dataroot == demo_layout(needs)[0].expanduser().resolve():
            return needs
    return None


_OPENED: dict[tuple[Path, str], NuScenes] = {}
_REBUILT: set[tuple[Path, str]] = set()
"""Demo caches rebuilt in this process (at most once each)."""


def open_nuscenes(location: DatasetLocation) -> NuScenes:
    """The devkit's ``NuScenes`` for ``location`` (quiet), loaded once per process per (dataroot, version)."""
    key = (location.dataroot, location.version)
    if key not in _OPENED:
        from nuscenes.nuscenes import NuScenes

        try:
            _OPENED[key] = NuScenes(version=location.version, dataroot=str(location.dataroot), verbose=False)
        except Exception as exc:  # the devkit raises AssertionError, KeyError, JSONDecodeError, ... on bad tables
            needs = _demo_needs(location)
            if needs is not None and key not in _REBUILT:
                _REBUILT.add(key)
                _rebuild_demo(needs)
                return open_nuscenes(location)
            detail = str(exc).splitlines()[0] if str(exc) else type(exc).__name__
            raise _not_a_dataroot(
                location.dataroot, f"the devkit cannot load {location.version}/ ({type(exc).__name__}: {detail})"
            ) from exc
    return _OPENED[key]


def list_scenes(nusc: NuScenes) -> list[str]:
    """Scene names in table order."""
    return [s["name"] for s in nusc.scene]


def _scene_record(nusc: NuScenes, scene_name: str) -> dict:
    for record in nusc.scene:
        if record["name"] == scene_name:
            return record
    raise UnknownNameError(f"unknown scene '{scene_name}'; available: {', '.join(sorted(list_scenes(nusc)))}")


def _pose(record: dict) -> Pose:
    return Pose(
        translation_m=np.asarray(record["translation"], dtype=float),
        quat_wxyz=np.asarray(record["rotation"], dtype=float),
    )


def _gt_boxes(nusc: NuScenes, sample: dict) -> tuple[Boxes, np.ndarray]:
    """Ground truth of the 7 tracking classes in one sample (global frame) and each box's LiDAR + radar points."""
    from nuscenes.eval.tracking.utils import category_to_tracking_name

    rows = []
    for ann_token in sample["anns"]:
        ann = nusc.get("sample_annotation", ann_token)
        name = category_to_tracking_name(ann["category_name"])
        if name is not None:
            rows.append((ann, name))
    if not rows:
        return Boxes.empty(), np.zeros(0, dtype=np.int64)
    velocity = np.array([nusc.box_velocity(ann["token"])[:2] for ann, _ in rows], dtype=float)
    boxes = Boxes(
        translation_m=np.array([ann["translation"] for ann, _ in rows], dtype=float),
        size_wlh_m=np.array([ann["size"] for ann, _ in rows], dtype=float),
        quat_wxyz=np.array([ann["rotation"] for ann, _ in rows], dtype=float),
        velocity_mps=np.nan_to_num(velocity, nan=0.0),
        score=np.ones(len(rows)),
        class_name=np.array([name for _, name in rows], dtype=object),
        instance_id=np.array([ann["instance_token"] for ann, _ in rows], dtype=object),
    )
    num_pts = np.array([ann["num_lidar_pts"] + ann["num_radar_pts"] for ann, _ in rows], dtype=np.int64)
    return boxes, num_pts


def load_scene(nusc: NuScenes, location: DatasetLocation, scene_name: str) -> SceneData:
    """One scene's keyframes in time order with LIDAR_TOP pose, calibration, sweep path and tracking-class GT."""
    scene = _scene_record(nusc, scene_name)
    keyframes: list[Keyframe] = []
    sample_token = scene["first_sample_token"]
    while sample_token:
        sample = nusc.get("sample", sample_token)
        if LIDAR_CHANNEL not in sample["data"]:
            raise DataError(
                f"sample {sample_token} of {scene_name} has no {LIDAR_CHANNEL} data; the dataset is incomplete"
            )
        sweep = nusc.get("sample_data", sample["data"][LIDAR_CHANNEL])
        gt, gt_num_pts = _gt_boxes(nusc, sample)
        keyframes.append(
            Keyframe(
                index=len(keyframes),
                sample_token=sample_token,
                timestamp_us=int(sample["timestamp"]),
                ego_pose=_pose(nusc.get("ego_pose", sweep["ego_pose_token"])),
                lidar_calib=_pose(nusc.get("calibrated_sensor", sweep["calibrated_sensor_token"])),
                lidar_path=location.dataroot / sweep["filename"],
                gt=gt,
                gt_num_pts=gt_num_pts,
            )
        )
        sample_token = sample["next"]
    synthetic = is_synthetic_description(scene["description"])
    return SceneData(
        name=scene_name,
        token=scene["token"],
        description=scene["description"],
        dataroot=location.dataroot,
        version=location.version,
        synthetic=synthetic,
        keyframes=tuple(keyframes),
        clutter_hotspots=_demo_hotspots(scene_name) if synthetic else (),
    )


def _demo_hotspots(scene_name: str) -> tuple[ClutterHotspot, ...]:
    """The clutter hotspots the demo generator placed in its scene ``scene_name``."""
    return tuple(h for h in CLUTTER_HOTSPOTS if h.scene_name == scene_name)


def load_lidar_points(keyframe: Keyframe) -> np.ndarray:
    """(N, 4) float32 x, y, z, intensity of the keyframe's LIDAR_TOP sweep, in the sensor frame."""
    from nuscenes.utils.data_classes import LidarPointCloud

    path = keyframe.lidar_path
    try:
        size = path.stat().st_size
    except OSError as exc:
        raise DataError(
            f"LiDAR file {path} is missing; download the nuScenes LiDAR sweeps (samples/LIDAR_TOP) into the dataroot"
        ) from exc
    if size % _POINT_BYTES:
        raise DataError(
            f"LiDAR file {path} is truncated ({size} bytes is not a whole number of 20-byte points); download it again"
        )
    if size == 0:
        raise DataError(f"LiDAR file {path} of sample {keyframe.sample_token} is empty (0 points); download it again")
    points = np.ascontiguousarray(LidarPointCloud.from_file(str(path)).points.T, dtype=np.float32)
    bad = int(np.count_nonzero(~np.isfinite(points).all(axis=1)))
    if bad:
        raise DataError(
            f"LiDAR file {path} of sample {keyframe.sample_token} has {bad} points with NaN or infinite x, y, z "
            "or intensity; the file is corrupt, download it again"
        )
    return points


def _custom_splits(location: DatasetLocation) -> dict[str, list[str]]:
    path = location.dataroot / location.version / "splits.json"
    if not path.is_file():
        return {}
    try:
        data = json.loads(path.read_text(encoding="utf-8"))
    except (OSError, UnicodeDecodeError, ValueError) as exc:
        raise DataError(f"custom split file {path} cannot be read ({type(exc).__name__}); fix or remove it") from exc
    if not isinstance(data, dict) or not all(
        isinstance(v, list) and all(isinstance(n, str) for n in v) for v in data.values()
    ):
        raise DataError(f"custom split file {path} must map split names to lists of scene names; fix or remove it")
    return data


def split_scenes(split: str, location: DatasetLocation) -> list[str]:
    """Scene names of a devkit split (``mini_val``, ``val``, ...) or of a custom split in ``splits.json`` that
    exist in the dataset, in the split's order. Like the devkit, a predefined split wins over a custom one
    of the same name."""
    from nuscenes.utils.splits import create_splits_scenes

    splits = {**_custom_splits(location), **create_splits_scenes()}
    if split not in splits:
        raise UnknownNameError(f"unknown split '{split}'; known: {', '.join(sorted(splits))}")
    present = {r["name"] for r in _read_scene_table(location.dataroot, location.version)}
    return [name for name in splits[split] if name in present]
