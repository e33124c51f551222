"""A version folder holding only what the devkit's tracking evaluation reads of some scenes, built from the index.

``TrackingEval`` and the failure finder load a whole ``NuScenes`` (every table of the version: 40 s and 2.7 GB
for trainval) to evaluate one scene or one split. The evaluation reads of the evaluated scenes only their
samples, annotations (all categories: the bike-rack filter), instances and categories, the LIDAR_TOP keyframe
``sample_data`` with its ego pose and calibrated sensor (ego distances) and, to build the devkit's reverse
index, sensors, logs and maps. ``eval_location`` writes exactly those rows, in the original tables' order and
with the original values (floats written with ``repr`` read back bit for bit), into
``<cache root>/evalroot/<key>/<version>/`` beside the version's ``splits.json``; the metrics are those of a full
load (``tests/gnnpmb/eval/test_subset.py``). Map masks are empty placeholder files: the devkit checks that they
exist and the evaluation never opens them. The folder is built in a temporary folder and renamed into place,
with ``sizes.json`` written last; one whose files do not have their recorded sizes and CRCs is built again. The
newest ``KEEP_FOLDERS`` are kept.
"""

from __future__ import annotations

import hashlib
import json
import os
import shutil
import tempfile
import zlib
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import pyarrow as pa

from gnnpmb.atomic import sweep_leftovers, temp_prefix
from gnnpmb.data.dataset_index import SMALL_TABLES, DatasetIndex, SceneSlice
from gnnpmb.data.nuscenes import DatasetLocation, dataset_index

EVALROOT_FOLDER = "evalroot"
SIZES = "sizes.json"
"""Written last in an eval folder: each file's size, so a damaged or partial folder is built again."""
KEEP_FOLDERS = 50
"""Eval folders kept in the cache (a one-scene folder is tens of kB, a val split one tens of MB)."""


def eval_location(location: DatasetLocation, scene_names: Sequence[str]) -> DatasetLocation:
    """A dataroot whose ``location.version`` folder holds only what evaluating ``scene_names`` reads."""
    from gnnpmb.cache_folder import cache_root

    index = dataset_index(location)
    splits = location.dataroot / location.version / "splits.json"
    custom = splits.read_bytes() if splits.is_file() else b""
    key = hashlib.sha256(json.dumps([index.key, list(scene_names), custom.decode(errors="replace")]).encode())
    folder = cache_root() / EVALROOT_FOLDER / key.hexdigest()[:24]
    if not _complete(folder):
        tables = subset_tables(index, scene_names)
        shutil.rmtree(folder, ignore_errors=True)
        _write(folder, location.version, tables, custom)
        _drop_oldest(folder.parent, KEEP_FOLDERS)
    return DatasetLocation(dataroot=folder, version=location.version, synthetic=location.synthetic)


def _complete(folder: Path) -> bool:
    """Whether every file listed in the folder's ``sizes.json`` (written last) has its recorded size and CRC-32
    (a table damaged in place at the same size is written again, not scored)."""
    try:
        sizes = json.loads((folder / SIZES).read_text(encoding="utf-8"))
        return all(_size_crc(folder / name) == list(entry) for name, entry in sizes.items())
    except (OSError, ValueError, AttributeError, TypeError):
        return False


def _size_crc(path: Path) -> list[int]:
    data = path.read_bytes()
    return [len(data), zlib.crc32(data)]


def _write(folder: Path, version: str, tables: dict[str, list[dict[str, Any]]], custom: bytes) -> None:
    folder.parent.mkdir(parents=True, exist_ok=True)
    sweep_leftovers(folder.parent)  # folders of killed runs (gnnpmb.atomic)
    tmp = Path(tempfile.mkdtemp(prefix=temp_prefix(folder, "build"), dir=folder.parent))
    try:
        (tmp / version).mkdir()
        for name, rows in tables.items():
            (tmp / version / f"{name}.json").write_text(json.dumps(rows), encoding="utf-8")
        if custom:
            (tmp / version / "splits.json").write_bytes(custom)
        for row in tables["map"]:
            path = tmp / row["filename"]
            path.parent.mkdir(parents=True, exist_ok=True)
            path.touch()
        sizes = {p.relative_to(tmp).as_posix(): _size_crc(p) for p in tmp.rglob("*") if p.is_file()}
        (tmp / SIZES).write_text(json.dumps(sizes), encoding="utf-8")
        try:
            os.replace(tmp, folder)
        except OSError:  # another process wrote the same folder first
            if not _complete(folder):
                raise
    finally:
        shutil.rmtree(tmp, ignore_errors=True)


def _drop_oldest(root: Path, keep: int) -> None:
    folders = sorted((p for p in root.iterdir() if not p.name.startswith(".")), key=lambda p: p.stat().st_mtime_ns)
    for path in folders[:-keep]:
        shutil.rmtree(path, ignore_errors=True)


def _rows(batch: pa.RecordBatch, fields: dict[str, str | tuple[str, ...]], order: str) -> list[tuple[int, dict]]:
    """(table position, row) of each record: ``fields`` maps a table field to a column, or to the columns of a
    vector."""
    data = {
        c: batch.column(c).to_pylist() for spec in fields.values() for c in ((spec,) if isinstance(spec, str) else spec)
    }
    positions = batch.column(order).to_pylist()
    out = []
    for i, pos in enumerate(positions):
        row = {
            name: data[spec][i] if isinstance(spec, str) else [data[c][i] for c in spec]
            for name, spec in fields.items()
        }
        out.append((pos, row))
    return out


def _vec(prefix: str, n: int) -> tuple[str, ...]:
    return tuple(f"{prefix}_{i}" for i in range(n))


_SAMPLE = {"token": "token", "timestamp": "timestamp", "prev": "prev", "next": "next"}
_SAMPLE_DATA = {
    "token": "sd_token",
    "sample_token": "token",
    "ego_pose_token": "ego_pose_token",
    "calibrated_sensor_token": "calib_token",
    "timestamp": "sd_timestamp",
    "fileformat": "sd_fileformat",
    "is_key_frame": "sd_is_key_frame",
    "height": "sd_height",
    "width": "sd_width",
    "filename": "sd_filename",
    "prev": "sd_prev",
    "next": "sd_next",
}
_EGO_POSE = {
    "token": "ego_pose_token",
    "timestamp": "ego_timestamp",
    "rotation": _vec("ego_q", 4),
    "translation": _vec("ego_t", 3),
}
_CALIBRATED = {
    "token": "calib_token",
    "sensor_token": "calib_sensor_token",
    "translation": _vec("calib_t", 3),
    "rotation": _vec("calib_q", 4),
}
_ANNOTATION = {
    "token": "token",
    "instance_token": "instance_token",
    "visibility_token": "visibility_token",
    "attribute_tokens": "attribute_tokens",
    "translation": _vec("translation", 3),
    "size": _vec("size", 3),
    "rotation": _vec("rotation", 4),
    "num_lidar_pts": "num_lidar_pts",
    "num_radar_pts": "num_radar_pts",
    "prev": "prev",
    "next": "next",
}
_INSTANCE = {
    "token": "token",
    "category_token": "category_token",
    "nbr_annotations": "nbr_annotations",
    "first_annotation_token": "first_annotation_token",
    "last_annotation_token": "last_annotation_token",
}


def subset_tables(index: DatasetIndex, scene_names: Sequence[str]) -> dict[str, list[dict[str, Any]]]:
    """The devkit's tables restricted to ``scene_names`` (see the module docstring), each in table order."""
    parts: list[SceneSlice] = [index.read(name) for name in scene_names]
    small = index.small()
    tables: dict[str, list[tuple[int, dict]]] = {
        t: [] for t in ("sample", "sample_data", "ego_pose", "calibrated_sensor", "sample_annotation", "instance")
    }
    scenes = []
    for part in parts:
        scene = dict(part.scene.row)
        scenes.append((scene.pop("table_pos"), scene))
        samples = part.samples
        tables["sample"] += [(p, r | {"scene_token": scene["token"]}) for p, r in _rows(samples, _SAMPLE, "table_pos")]
        tables["sample_data"] += _rows(samples, _SAMPLE_DATA, "sd_table_pos")
        tables["ego_pose"] += _rows(samples, _EGO_POSE, "ego_table_pos")
        tables["calibrated_sensor"] += [
            (p, r | {"camera_intrinsic": []}) for p, r in _rows(samples, _CALIBRATED, "calib_table_pos")
        ]
        tokens = samples.column("token").to_pylist()
        sample_index = part.ann_sample_index()
        anns = _rows(part.annotations, _ANNOTATION, "table_pos")
        tables["sample_annotation"] += [
            (p, r | {"sample_token": tokens[k]}) for (p, r), k in zip(anns, sample_index.tolist(), strict=True)
        ]
        tables["instance"] += _rows(part.instances, _INSTANCE, "table_pos")
    out = {name: _ordered(rows) for name, rows in tables.items()}
    out["scene"] = _ordered(scenes)
    logs = {s["log_token"] for _, s in scenes}
    out |= {t: small[t] for t in SMALL_TABLES if t not in ("log", "map")}
    out["log"] = [r for r in small["log"] if r["token"] in logs]
    maps = [r | {"log_tokens": [t for t in r["log_tokens"] if t in logs]} for r in small["map"]]
    out["map"] = [r for r in maps if r["log_tokens"]]
    return out


def _ordered(rows: list[tuple[int, dict]]) -> list[dict]:
    """Rows in table order, each once (a pose or calibration shared by several samples)."""
    seen: dict[int, dict] = {}
    for pos, row in rows:
        seen.setdefault(pos, row)
    return [seen[p] for p in sorted(seen)]
