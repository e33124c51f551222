"""Find a nuScenes dataroot, open it with the devkit and turn its scenes into ``SceneData``.

Where the data comes from: an explicit ``--dataroot`` wins, then the environment variable ``NUSCENES_DATAROOT``,
then the built-in synthetic demo (``gnnpmb.data.demo.ensure_demo_dataset``); a damaged demo cache is generated
again. Any dataroot is checked before the devkit loads it (loading the full trainval tables takes a while), so a
wrong path fails fast with one line.
The devkit is imported lazily: importing this module stays cheap.
"""

from __future__ import annotations

import functools
import json
import os
import shutil
from collections.abc import Sequence
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
from gnnpmb.outputs import check_dataset_inputs
from gnnpmb.symlinks import refuse_symlink_loop
from gnnpmb.types import Boxes

if TYPE_CHECKING:
    import pyarrow as pa
    from nuscenes.nuscenes import NuScenes

    from gnnpmb.data.dataset_index import DatasetIndex, SceneSlice
    from gnnpmb.data.sensors import LidarSweep

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

    ``source`` names where the path came from, for the error message. The dataset's files become inputs: an
    output of this process that is one of them (a hard link included) is refused (``outputs.check_dataset_inputs``).
    """
    dataroot = Path(dataroot).expanduser()
    refuse_symlink_loop(dataroot, f"dataroot (from {source})")
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
    check_dataset_inputs(dataroot, version)
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


_INDEXES: dict[tuple[Path, str], DatasetIndex] = {}


def dataset_index(location: DatasetLocation, *, fresh: bool = False) -> DatasetIndex:
    """The persistent index of ``location`` (``gnnpmb.data.dataset_index``), opened once per process; built on
    first use (a damaged cached demo is generated again first). ``fresh`` drops the index and builds it again
    (it was found damaged)."""
    from gnnpmb.cache_folder import cache_root
    from gnnpmb.data.dataset_index import index_folder, open_dataset_index

    key = (location.dataroot, location.version)
    if fresh:
        _INDEXES.pop(key, None)
        shutil.rmtree(index_folder(cache_root(), *key), ignore_errors=True)
    if key not in _INDEXES:
        try:
            _INDEXES[key] = open_dataset_index(cache_root(), location.dataroot, location.version)
        except DataError:
            needs = _demo_needs(location)
            if needs is None or key in _REBUILT:
                raise
            _REBUILT.add(key)
            _rebuild_demo(needs)
            return dataset_index(location)
    return _INDEXES[key]


def _check_scene(index: DatasetIndex, scene_name: str) -> None:
    if index.scene(scene_name) is None:
        names = sorted(s.name for s in index.scenes)
        raise UnknownNameError(f"unknown scene '{scene_name}'; available: {', '.join(names)}")


def sample_tokens(location: DatasetLocation, scene_names: Sequence[str]) -> list[str]:
    """Every sample token of the given scenes, scene by scene in time order (from the index)."""
    from gnnpmb.data.index_store import IndexDamaged

    index = dataset_index(location)
    for name in scene_names:
        _check_scene(index, name)
    try:
        return [t for name in scene_names for t in index.sample_tokens(name)]
    except IndexDamaged:
        index = dataset_index(location, fresh=True)
        return [t for name in scene_names for t in index.sample_tokens(name)]


def all_sample_tokens(location: DatasetLocation) -> set[str]:
    """Every sample token of the dataset (every scene's samples, from the index)."""
    index = dataset_index(location)
    return {t for scene in index.scenes for t in index.sample_tokens(scene.name)}


def _pose(translation: np.ndarray, quat: np.ndarray) -> Pose:
    return Pose(translation_m=np.array(translation, dtype=float), quat_wxyz=np.array(quat, dtype=float))


def _columns(batch: pa.RecordBatch, prefix: str, n: int) -> np.ndarray:
    """(rows, n) float64 of the columns ``prefix_0`` ... ``prefix_{n-1}``."""
    return np.column_stack([batch.column(f"{prefix}_{i}").to_numpy() for i in range(n)]).reshape(-1, n)


def _gt_boxes(
    anns: pa.RecordBatch, rows: np.ndarray, fields: dict[str, np.ndarray]
) -> tuple[Boxes, np.ndarray, np.ndarray]:
    """Ground truth of the 7 tracking classes among annotation ``rows`` (global frame), each box's LiDAR + radar
    points and its radar points."""
    if rows.size == 0:
        return Boxes.empty(), np.zeros(0, dtype=np.int64), np.zeros(0, dtype=np.int64)
    boxes = Boxes(
        translation_m=fields["translation"][rows],
        size_wlh_m=fields["size"][rows],
        quat_wxyz=fields["rotation"][rows],
        velocity_mps=np.nan_to_num(fields["velocity"][rows], nan=0.0),
        score=np.ones(rows.size),
        class_name=np.array(fields["tracking_name"][rows], dtype=object),
        instance_id=np.array(fields["instance_token"][rows], dtype=object),
    )
    return boxes, fields["num_pts"][rows], fields["num_radar_pts"][rows]


def load_scene(location: DatasetLocation, scene_name: str) -> SceneData:
    """One scene's keyframes in time order with LIDAR_TOP pose, calibration, sweep path and tracking-class GT,
    read from the dataset's index (only this scene's rows)."""
    from gnnpmb.data.index_store import IndexDamaged

    index = dataset_index(location)
    _check_scene(index, scene_name)
    try:
        part = index.read(scene_name)
    except IndexDamaged:
        part = dataset_index(location, fresh=True).read(scene_name)
    return _scene_data(location, part)


def _scene_data(location: DatasetLocation, part: SceneSlice) -> SceneData:
    samples, anns = part.samples, part.annotations
    name, tokens = part.scene.name, samples.column("token").to_pylist()
    has_lidar = samples.column("has_lidar").to_numpy(zero_copy_only=False)
    if not has_lidar.all():
        missing = tokens[int(np.flatnonzero(~has_lidar)[0])]
        raise DataError(f"sample {missing} of {name} has no {LIDAR_CHANNEL} data; the dataset is incomplete")
    tracking = anns.column("tracking_name")
    fields = {
        "translation": _columns(anns, "translation", 3),
        "size": _columns(anns, "size", 3),
        "rotation": _columns(anns, "rotation", 4),
        "velocity": _columns(anns, "velocity", 2),
        "tracking_name": np.array(tracking.to_pylist(), dtype=object),
        "instance_token": np.array(anns.column("instance_token").to_pylist(), dtype=object),
        "num_pts": anns.column("num_lidar_pts").to_numpy() + anns.column("num_radar_pts").to_numpy(),
        "num_radar_pts": anns.column("num_radar_pts").to_numpy(),
    }
    kept = tracking.is_valid().to_numpy(zero_copy_only=False)
    sample_index = part.ann_sample_index()
    ego_t, ego_q = _columns(samples, "ego_t", 3), _columns(samples, "ego_q", 4)
    calib_t, calib_q = _columns(samples, "calib_t", 3), _columns(samples, "calib_q", 4)
    filenames = samples.column("sd_filename").to_pylist()
    timestamps = samples.column("timestamp").to_pylist()
    keyframes = []
    for k, token in enumerate(tokens):
        gt, gt_num_pts, gt_num_radar_pts = _gt_boxes(anns, np.flatnonzero((sample_index == k) & kept), fields)
        keyframes.append(
            Keyframe(
                index=k,
                sample_token=token,
                timestamp_us=int(timestamps[k]),
                ego_pose=_pose(ego_t[k], ego_q[k]),
                lidar_calib=_pose(calib_t[k], calib_q[k]),
                lidar_path=location.dataroot / filenames[k],
                gt=gt,
                gt_num_pts=gt_num_pts,
                gt_num_radar_pts=gt_num_radar_pts,
            )
        )
    description = str(part.scene.row["description"])
    synthetic = is_synthetic_description(description)
    return SceneData(
        name=name,
        token=str(part.scene.row["token"]),
        description=description,
        dataroot=location.dataroot,
        version=location.version,
        synthetic=synthetic,
        keyframes=tuple(keyframes),
        clutter_hotspots=_demo_hotspots(name) if synthetic else (),
    )


def _demo_hotspots(scene_name: str) -> tuple[ClutterHotspot, ...]:
    """The clutter hotspots the demo generator placed in its scene ``scene_name``."""
    return tuple(h for h in CLUTTER_HOTSPOTS if h.scene_name == scene_name)


def load_lidar_points(keyframe: Keyframe | LidarSweep) -> np.ndarray:
    """(N, 4) float32 x, y, z, intensity of the keyframe's LIDAR_TOP sweep (or of a sweep between keyframes), in
    the sensor frame.

    Read as the devkit's ``LidarPointCloud.from_file`` reads it (float32 x 5 per point, the ring index dropped),
    without importing the devkit: ``nuscenes.utils`` pulls in scikit-learn and matplotlib, over a second of a warm
    ``gnnpmb-viz`` start for a two-line read (``tests/gnnpmb/data/test_nuscenes_loader.py`` holds the two equal)."""
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
    points = np.ascontiguousarray(np.fromfile(path, dtype=np.float32).reshape(-1, 5)[:, :4])
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


SPLIT_VERSION_SUFFIX = {
    "train": "trainval",
    "val": "trainval",
    "train_detect": "trainval",
    "train_track": "trainval",
    "mini_train": "mini",
    "mini_val": "mini",
    "test": "test",
}
"""The devkit's predefined splits and the end of the dataset version each is evaluated on (its ``TrackingEval``
checks it); a custom split (``splits.json``) goes with any version."""


def split_fits_version(split: str, version: str) -> bool:
    """Whether the devkit evaluates ``split`` on dataset ``version`` (``SPLIT_VERSION_SUFFIX``)."""
    suffix = SPLIT_VERSION_SUFFIX.get(split)
    return suffix is None or version.endswith(suffix)


_DEVKIT_SPLIT_LISTS = ("train_detect", "train_track", "val", "test", "mini_train", "mini_val")
"""The scene lists the devkit's ``nuscenes/utils/splits.py`` writes out (its ``train`` is their union)."""


@functools.cache
def _devkit_split_lists() -> dict[str, tuple[str, ...]] | None:
    """The devkit's predefined splits read from the source of ``nuscenes/utils/splits.py`` (its lists of scene
    names are literals), in ``create_splits_scenes``' order; None when that file is not as expected."""
    import ast
    import importlib.util

    spec = importlib.util.find_spec("nuscenes")  # finds the package without importing it
    if spec is None or not spec.submodule_search_locations:
        return None
    path = Path(next(iter(spec.submodule_search_locations))) / "utils" / "splits.py"
    try:
        tree = ast.parse(path.read_text(encoding="utf-8"))
    except (OSError, UnicodeDecodeError, SyntaxError, ValueError):
        return None
    lists: dict[str, list] = {}
    for node in tree.body:
        if isinstance(node, ast.Assign) and len(node.targets) == 1 and isinstance(node.targets[0], ast.Name):
            try:
                lists[node.targets[0].id] = ast.literal_eval(node.value)
            except ValueError:
                continue  # not a literal: ``train`` is computed
    if not all(isinstance(lists.get(n), list) for n in _DEVKIT_SPLIT_LISTS):
        return None
    train = sorted(set(lists["train_detect"] + lists["train_track"]))
    splits = {"train": train, "val": lists["val"], "test": lists["test"]}
    splits |= {name: lists[name] for name in ("mini_train", "mini_val", "train_detect", "train_track")}
    return {name: tuple(scenes) for name, scenes in splits.items()}


def devkit_splits() -> dict[str, list[str]]:
    """The devkit's predefined splits, what ``nuscenes.utils.splits.create_splits_scenes()`` gives (a new dict of
    new lists), without importing the devkit when it is not loaded yet: that module imports the devkit's package,
    which loads scikit-learn and matplotlib, 2 s of CPU of a ``gnnpmb track`` that never evaluates."""
    import sys

    lists = None if "nuscenes.utils.splits" in sys.modules else _devkit_split_lists()
    if lists is None:
        from nuscenes.utils.splits import create_splits_scenes

        return create_splits_scenes()
    return {name: list(scenes) for name, scenes in lists.items()}


def split_names(location: DatasetLocation) -> list[str]:
    """The split names usable on ``location``, sorted: the devkit's splits of its version and the custom ones."""
    names = {**_custom_splits(location), **devkit_splits()}
    return sorted(n for n in names if split_fits_version(n, location.version))


def split_scenes(split: str, location: DatasetLocation) -> list[str]:
    """Scene names of a devkit split (``mini_val``, ``val``, ...) or of a custom split in ``splits.json`` that
    exist in the dataset, in the split's order. Like the devkit, a predefined split wins over a custom one
    of the same name."""
    splits = {**_custom_splits(location), **devkit_splits()}
    if split not in splits:
        import difflib

        usable = split_names(location)
        close = difflib.get_close_matches(split, usable, n=1)
        guess = f" (did you mean {close[0]}?)" if close else ""
        raise UnknownNameError(f"unknown split '{split}'{guess}; the splits of {location.version}: {', '.join(usable)}")
    present = {r["name"] for r in _read_scene_table(location.dataroot, location.version)}
    return [name for name in splits[split] if name in present]
