"""The persistent index of one nuScenes dataset version: what the tool reads of each scene, stored per scene.

Built once from the version's table files (streamed row by row, ``gnnpmb.data.json_stream``) into
``<cache root>/index/dataset-<key>/`` and rebuilt whenever a table file changes (path, size or modification
time), the code that derives it changes (this module and the category table, ``index_store.code_identity``)
or the index is damaged (``gnnpmb.data.index_store``). Per scene, one record batch in each of:

* ``samples.arrow`` — the keyframes in time order (the ``next`` chain), each with its LIDAR_TOP keyframe
  ``sample_data`` row, that row's ego pose and calibrated sensor (the devkit's ``sample['data']['LIDAR_TOP']``);
* ``annotations.arrow`` — every annotation of those samples (all categories: the evaluation's bike-rack filter
  needs the racks), by sample, in table order (the devkit's ``sample['anns']``), with its category, tracking
  class and the devkit's ``box_velocity`` (centred difference over prev/next, NaN beyond 1.5 s / 3 s);
* ``instances.arrow`` — the instances annotated in the scene.

``scenes.json`` lists the scenes in table order and ``small.json`` holds the small tables (category, attribute,
visibility, sensor, log, map). A command for one scene reads one batch of each file; ``eval_subset`` gives the
rows of the tables the devkit's evaluation reads for a set of scenes, in the original tables' order.
"""

from __future__ import annotations

import hashlib
from array import array
from collections.abc import Callable, Iterable, Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import pyarrow as pa
import pyarrow.compute as pc

from gnnpmb.classes import TRACKING_NAME_OF_CATEGORY
from gnnpmb.data.index_store import (
    Store,
    build_progress,
    code_identity,
    open_or_build,
    source_identity,
    write_batches,
    write_json_file,
    write_manifest,
)
from gnnpmb.data.json_stream import JsonStreamError, NotUtf8Error, iter_array
from gnnpmb.errors import DataError

FORMAT = 1
"""Bumped whenever the index layout or what is derived into it changes."""
TABLES: tuple[str, ...] = (
    "category",
    "attribute",
    "visibility",
    "sensor",
    "calibrated_sensor",
    "log",
    "map",
    "scene",
    "sample",
    "sample_data",
    "ego_pose",
    "instance",
    "sample_annotation",
)
"""The devkit's tables, in the order the build reads them (sample_data before ego_pose: only the poses of
LIDAR_TOP keyframes are kept)."""
LIDAR_CHANNEL = "LIDAR_TOP"
SMALL_TABLES = ("category", "attribute", "visibility", "sensor", "log", "map")
_CHUNK_ROWS = 65_536
_MAX_TIME_DIFF_S = 1.5
"""The devkit's ``box_velocity`` default; doubled for a centred difference."""

ProgressFn = Callable[[int], None]
"""Called with the number of bytes just read."""

_ANN_STRINGS = ("token", "instance_token", "visibility_token", "prev", "next", "category_name", "tracking_name")
_VEC = {"translation": 3, "size": 3, "rotation": 4}


def _vec_names(name: str, n: int) -> list[str]:
    return [f"{name}_{i}" for i in range(n)]


@dataclass(frozen=True, slots=True)
class SceneRecord:
    """One scene's row and where its batches are: index ``batch`` in every per-scene file."""

    batch: int
    row: dict[str, Any]

    @property
    def name(self) -> str:
        return str(self.row["name"])


@dataclass(frozen=True, slots=True)
class SceneSlice:
    """One scene read from the index: its row, keyframes (K rows, time order) and annotations (by keyframe)."""

    scene: SceneRecord
    samples: pa.RecordBatch
    annotations: pa.RecordBatch
    instances: pa.RecordBatch

    def ann_sample_index(self) -> np.ndarray:
        """(A,) index into ``samples`` of each annotation's keyframe."""
        return self.annotations.column("sample_index").to_numpy()


class DatasetIndex:
    """An opened dataset index (``dataset_index``)."""

    def __init__(self, store: Store, dataroot: Path, version: str) -> None:
        self.store = store
        self.dataroot = dataroot
        self.version = version
        self.scenes = [SceneRecord(i, row) for i, row in enumerate(store.json("scenes.json"))]
        self._by_name = {s.name: s for s in self.scenes}

    @property
    def key(self) -> str:
        """What this index was built from (sources and format), as a short hash."""
        return self.store.manifest["key"]

    def scene(self, name: str) -> SceneRecord | None:
        return self._by_name.get(name)

    def read(self, name: str) -> SceneSlice:
        """The batches of scene ``name`` (``KeyError`` if it is not in the dataset)."""
        record = self._by_name[name]
        return SceneSlice(
            record,
            self.store.batch("samples.arrow", record.batch),
            self.store.batch("annotations.arrow", record.batch),
            self.store.batch("instances.arrow", record.batch),
        )

    def tracked_annotations(self, name: str) -> int:
        """How many annotations of scene ``name`` are of a tracking class (what the evaluation scores against)."""
        batch = self.store.batch("annotations.arrow", self._by_name[name].batch)
        return batch.num_rows - batch.column("tracking_name").null_count

    def sample_tokens(self, name: str) -> list[str]:
        """The sample tokens of scene ``name`` in time order."""
        return self.store.batch("samples.arrow", self._by_name[name].batch).column("token").to_pylist()

    def small(self) -> dict[str, list[dict[str, Any]]]:
        """The small tables (category, attribute, visibility, sensor, log, map) as the table files hold them."""
        return self.store.json("small.json")


def index_folder(cache: Path, dataroot: Path, version: str) -> Path:
    """Where the index of ``dataroot``/``version`` lives in the cache."""
    key = hashlib.sha256(f"{dataroot}\0{version}".encode()).hexdigest()[:16]
    return cache / "index" / f"dataset-{key}"


def table_paths(dataroot: Path, version: str) -> list[Path]:
    return [dataroot / version / f"{t}.json" for t in TABLES]


def open_dataset_index(cache: Path, dataroot: Path, version: str) -> DatasetIndex:
    """The index of ``dataroot``/``version``, built now if missing, stale or damaged (``DataError`` when a table
    cannot be read)."""
    files = source_identity(table_paths(dataroot, version))
    sources = [*files, code_identity(__name__, "gnnpmb.classes")]
    folder = index_folder(cache, dataroot, version)

    def build(tmp: Path) -> None:
        total = sum(max(source[1], 0) for source in files)
        note = f"indexing {dataroot / version} ({total / 1e6:.0f} MB of tables) into {cache}, once per version"
        with build_progress(note, total) as advance:
            _build(tmp, dataroot, version, sources, advance)

    store = open_or_build(folder, FORMAT, sources, build)
    return DatasetIndex(store, dataroot, version)


# --- build -----------------------------------------------------------------------------------------------------


def _bad_table(dataroot: Path, version: str, table: str, why: str) -> DataError:
    return DataError(
        f"{dataroot} is not a nuScenes dataroot: {version}/{table}.json cannot be read ({why}); pass --dataroot "
        "pointing at the folder that contains v1.0-mini/ (or another v1.0-* folder)"
    )


class _Tables:
    """Streams the table files in order, reporting bytes read."""

    def __init__(self, dataroot: Path, version: str, progress: ProgressFn | None) -> None:
        self.dataroot, self.version = dataroot, version
        self.progress = progress or (lambda _n: None)

    def rows(self, table: str) -> Iterator[dict[str, Any]]:
        path = self.dataroot / self.version / f"{table}.json"
        try:
            with open(path, "rb") as f:
                for pos, row in enumerate(iter_array(f, lambda block: self.progress(len(block)))):
                    if not isinstance(row, dict) or "token" not in row:
                        raise _bad_table(self.dataroot, self.version, table, f"row {pos} is not a record with a token")
                    yield row
        except (OSError, JsonStreamError, NotUtf8Error) as exc:
            raise _bad_table(self.dataroot, self.version, table, f"{type(exc).__name__}: {exc}") from None
        except TypeError as exc:
            raise _bad_table(self.dataroot, self.version, table, f"a JSON {exc.args[0]}, not a list of rows") from None

    def field_error(self, table: str, exc: Exception) -> DataError:
        return _bad_table(self.dataroot, self.version, table, f"a row lacks or mistypes field {exc}")


def _strings(values: Iterable[Any]) -> pa.Array:
    return pa.array([None if v is None else str(v) for v in values], type=pa.string())


def _build(tmp: Path, dataroot: Path, version: str, sources: list[list[Any]], progress: ProgressFn | None) -> None:
    tables = _Tables(dataroot, version, progress)
    small = {t: list(tables.rows(t)) for t in SMALL_TABLES}
    calibrated = {r["token"]: (pos, r) for pos, r in enumerate(tables.rows("calibrated_sensor"))}
    sensors = {r["token"]: r for r in small["sensor"]}
    scenes = [dict(r) for r in tables.rows("scene")]
    samples = {r["token"]: (pos, r) for pos, r in enumerate(tables.rows("sample"))}
    lidar = _lidar_keyframes(tables, calibrated, sensors)
    poses = _poses(tables, {sd["ego_pose_token"] for _, sd in lidar.values()})
    instances = [r for r in tables.rows("instance")]
    try:
        chains = [_chain(scene, samples, tables) for scene in scenes]
    except KeyError as exc:
        raise tables.field_error("sample", exc) from None
    sample_rows = _sample_batches(chains, samples, lidar, poses, calibrated, tables)
    sample_of = {tok: (i, k) for i, chain in enumerate(chains) for k, tok in enumerate(chain)}
    annotations, instance_scene = _annotations(tables, samples, sample_of, len(scenes), instances, small["category"])
    files = {
        "scenes.json": write_json_file(tmp / "scenes.json", [_scene_row(s, pos) for pos, s in enumerate(scenes)]),
        "small.json": write_json_file(tmp / "small.json", small),
        "samples.arrow": write_batches(tmp / "samples.arrow", sample_rows[0].schema, sample_rows),
        "annotations.arrow": write_batches(tmp / "annotations.arrow", annotations[0].schema, annotations),
    }
    inst = _instance_batches(instances, instance_scene, len(scenes))
    files["instances.arrow"] = write_batches(tmp / "instances.arrow", inst[0].schema, inst)
    key = hashlib.sha256(repr((FORMAT, sources)).encode()).hexdigest()[:16]
    write_manifest(tmp, {"format": FORMAT, "sources": sources, "key": key, "version": version, "files": files})


def _scene_row(scene: dict[str, Any], pos: int) -> dict[str, Any]:
    keep = ("token", "log_token", "nbr_samples", "first_sample_token", "last_sample_token", "name", "description")
    return {k: scene.get(k) for k in keep} | {"table_pos": pos}


def _lidar_keyframes(
    tables: _Tables, calibrated: dict[str, tuple[int, dict]], sensors: dict[str, dict]
) -> dict[str, tuple[int, dict]]:
    """sample token -> (table position, row) of its LIDAR_TOP keyframe sample_data (the last one in table order,
    as the devkit's reverse index keeps)."""
    lidar_calibs = {
        tok
        for tok, (_pos, r) in calibrated.items()
        if sensors.get(r.get("sensor_token"), {}).get("channel") == LIDAR_CHANNEL
    }
    out: dict[str, tuple[int, dict]] = {}
    try:
        for pos, row in enumerate(tables.rows("sample_data")):
            if row["is_key_frame"] and row["calibrated_sensor_token"] in lidar_calibs:
                out[row["sample_token"]] = (pos, row)
    except KeyError as exc:
        raise tables.field_error("sample_data", exc) from None
    return out


def _poses(tables: _Tables, wanted: set[str]) -> dict[str, tuple[int, dict]]:
    return {r["token"]: (pos, r) for pos, r in enumerate(tables.rows("ego_pose")) if r["token"] in wanted}


def _chain(scene: dict[str, Any], samples: dict[str, tuple[int, dict]], tables: _Tables) -> list[str]:
    """The scene's sample tokens in time order (following ``next`` from ``first_sample_token``); a token that
    points at no sample, or a chain that loops, is a DataError naming the table, row and field that hold it."""
    chain: list[str] = []
    name = scene.get("name")
    token, table, field = scene["first_sample_token"], "scene", f"scene {name!r} has first_sample_token"
    while token:
        if token not in samples:
            raise _broken_link(tables, table, f"{field} {token!r}, the token of no row of sample.json")
        chain.append(token)
        table, field = "sample", f"sample {token} of scene {name!r} has next"
        token = samples[token][1]["next"]
        if len(chain) > len(samples):
            raise _broken_link(tables, "sample", f"the next chain of scene {name!r} loops")
    return chain


def _broken_link(tables: _Tables, table: str, what: str) -> DataError:
    """A table whose rows parse but point at a row that does not exist."""
    return DataError(
        f"{tables.dataroot / tables.version / table}.json: {what}; repair the table or use an unedited copy of the "
        "dataset"
    )


_Rows = dict[str, tuple[int, dict[str, Any]]]
"""token -> (table position, row)."""


def _sample_batches(
    chains: list[list[str]], samples: _Rows, lidar: _Rows, poses: _Rows, calibrated: _Rows, tables: _Tables
) -> list[pa.RecordBatch]:
    """Per scene, its keyframes in time order with their LIDAR_TOP sample_data, ego pose and calibration (NaN
    poses where a sample has no LIDAR_TOP keyframe: ``has_lidar`` False)."""
    out = []
    missing_pose = {"translation": [np.nan] * 3, "rotation": [np.nan] * 4, "timestamp": -1}
    for chain in chains:
        cols: dict[str, list[Any]] = {}

        def put(name: str, value: Any, cols: dict[str, list[Any]] = cols) -> None:
            cols.setdefault(name, []).append(value)

        try:
            for token in chain:
                pos, sample = samples[token]
                sd_pos, sd = lidar.get(token, (-1, None))
                pose_pos, pose = poses.get(sd["ego_pose_token"], (-1, missing_pose)) if sd else (-1, missing_pose)
                calib_pos, calib = calibrated.get(sd["calibrated_sensor_token"], (-1, {})) if sd else (-1, {})
                for name in ("token", "prev", "next"):
                    put(name, sample[name])
                put("timestamp", int(sample["timestamp"]))
                put("table_pos", pos)
                put("has_lidar", sd is not None)
                sd = sd or {}
                for name in ("token", "filename", "fileformat", "prev", "next"):
                    put(f"sd_{name}", sd.get(name))
                for name in ("timestamp", "height", "width"):
                    put(f"sd_{name}", int(sd.get(name, 0)))
                put("sd_is_key_frame", bool(sd.get("is_key_frame", False)))
                put("sd_table_pos", sd_pos)
                put("ego_pose_token", sd.get("ego_pose_token"))
                put("ego_timestamp", int(pose["timestamp"]))
                put("ego_table_pos", pose_pos)
                put("calib_token", sd.get("calibrated_sensor_token"))
                put("calib_sensor_token", calib.get("sensor_token"))
                put("calib_table_pos", calib_pos)
                for i, v in enumerate(pose["translation"]):
                    put(f"ego_t_{i}", float(v))
                for i, v in enumerate(pose["rotation"]):
                    put(f"ego_q_{i}", float(v))
                for i, v in enumerate(calib.get("translation", [np.nan] * 3)):
                    put(f"calib_t_{i}", float(v))
                for i, v in enumerate(calib.get("rotation", [np.nan] * 4)):
                    put(f"calib_q_{i}", float(v))
        except (KeyError, TypeError, ValueError) as exc:
            raise tables.field_error("sample", exc) from None
        out.append(_batch(cols, _SAMPLE_SCHEMA))
    return out


_SAMPLE_SCHEMA = pa.schema(
    [(n, pa.string()) for n in ("token", "prev", "next")]
    + [("timestamp", pa.int64()), ("table_pos", pa.int64()), ("has_lidar", pa.bool_())]
    + [(f"sd_{n}", pa.string()) for n in ("token", "filename", "fileformat", "prev", "next")]
    + [(f"sd_{n}", pa.int64()) for n in ("timestamp", "height", "width")]
    + [("sd_is_key_frame", pa.bool_()), ("sd_table_pos", pa.int64())]
    + [("ego_pose_token", pa.string()), ("ego_timestamp", pa.int64()), ("ego_table_pos", pa.int64())]
    + [("calib_token", pa.string()), ("calib_sensor_token", pa.string()), ("calib_table_pos", pa.int64())]
    + [(n, pa.float64()) for n in _vec_names("ego_t", 3) + _vec_names("ego_q", 4)]
    + [(n, pa.float64()) for n in _vec_names("calib_t", 3) + _vec_names("calib_q", 4)]
)


def _batch(cols: dict[str, list[Any]], schema: pa.Schema) -> pa.RecordBatch:
    return pa.RecordBatch.from_pydict({f.name: cols.get(f.name, []) for f in schema}, schema=schema)


_ANN_SCHEMA = pa.schema(
    [(n, pa.string()) for n in _ANN_STRINGS]
    + [("attribute_tokens", pa.list_(pa.string()))]
    + [(n, pa.float64()) for name, k in _VEC.items() for n in _vec_names(name, k)]
    + [("num_lidar_pts", pa.int64()), ("num_radar_pts", pa.int64()), ("table_pos", pa.int64())]
    + [("sample_index", pa.int32()), ("velocity_0", pa.float64()), ("velocity_1", pa.float64())]
)


def _annotations(
    tables: _Tables,
    samples: dict[str, tuple[int, dict]],
    sample_of: dict[str, tuple[int, int]],
    n_scenes: int,
    instances: list[dict],
    categories: list[dict],
) -> tuple[list[pa.RecordBatch], dict[str, int]]:
    """Per scene, its annotations (by keyframe, then table order) with category, tracking class and velocity;
    and the scene of every annotated instance."""
    category_name = {c["token"]: c["name"] for c in categories}
    try:
        instance_category = {i["token"]: category_name[i["category_token"]] for i in instances}
    except KeyError as exc:
        raise tables.field_error("instance", exc) from None
    tracking = {name: TRACKING_NAME_OF_CATEGORY.get(name) for name in set(category_name.values())}
    chunks: list[pa.Table] = []
    rows: list[dict] = []
    meta = [array("q") for _ in range(4)]  # scene, keyframe, table position, sample timestamp
    try:
        for pos, row in enumerate(tables.rows("sample_annotation")):
            scene_i, k = sample_of[row["sample_token"]]
            for column, value in zip(
                meta, (scene_i, k, pos, samples[row["sample_token"]][1]["timestamp"]), strict=True
            ):
                column.append(int(value))
            rows.append(row)
            if len(rows) == _CHUNK_ROWS:
                chunks.append(_ann_chunk(rows, instance_category, tracking))
                rows = []
        if rows or not chunks:
            chunks.append(_ann_chunk(rows, instance_category, tracking))
    except (KeyError, TypeError, ValueError) as exc:
        raise tables.field_error("sample_annotation", exc) from None
    table = pa.concat_tables(chunks)
    del chunks, rows
    info = np.column_stack([np.frombuffer(column, dtype=np.int64) for column in meta]).reshape(-1, 4)
    table = _with_velocity(table, info[:, 3])
    order = np.lexsort((info[:, 2], info[:, 1], info[:, 0]))
    table = table.append_column("sample_index", pa.array(info[:, 1].astype(np.int32)))
    table = table.append_column("table_pos", pa.array(info[:, 2])).take(pa.array(order))
    table = table.select([f.name for f in _ANN_SCHEMA]).cast(_ANN_SCHEMA).combine_chunks()
    scene_of = info[order, 0]
    bounds = np.searchsorted(scene_of, np.arange(n_scenes + 1))
    batches = [_slice_batch(table, int(a), int(b)) for a, b in zip(bounds[:-1], bounds[1:], strict=True)]
    instance_scene: dict[str, int] = {}
    for scene_i, batch in enumerate(batches):
        for token in pc.unique(batch.column("instance_token")).to_pylist():
            instance_scene.setdefault(token, scene_i)
    return batches, instance_scene


def _slice_batch(table: pa.Table, start: int, stop: int) -> pa.RecordBatch:
    """Rows ``start:stop`` of a single-chunk table as one record batch (no copy)."""
    part = table.slice(start, stop - start)
    return part.to_batches()[0] if part.num_rows else pa.RecordBatch.from_pylist([], table.schema)


def _ann_chunk(rows: list[dict], instance_category: dict[str, str], tracking: dict[str, str | None]) -> pa.Table:
    cats = [instance_category[r["instance_token"]] for r in rows]
    cols: dict[str, pa.Array] = {
        "token": _strings(r["token"] for r in rows),
        "instance_token": _strings(r["instance_token"] for r in rows),
        "visibility_token": _strings(r.get("visibility_token") for r in rows),
        "prev": _strings(r["prev"] for r in rows),
        "next": _strings(r["next"] for r in rows),
        "category_name": _strings(cats),
        "tracking_name": _strings(tracking[c] for c in cats),
        "attribute_tokens": pa.array([list(r.get("attribute_tokens", [])) for r in rows], pa.list_(pa.string())),
        "num_lidar_pts": pa.array([int(r["num_lidar_pts"]) for r in rows], pa.int64()),
        "num_radar_pts": pa.array([int(r["num_radar_pts"]) for r in rows], pa.int64()),
    }
    for name, k in _VEC.items():
        values = np.array([r[name] for r in rows], dtype=np.float64).reshape(len(rows), k)
        for i, col in enumerate(_vec_names(name, k)):
            cols[col] = pa.array(values[:, i])
    return pa.table(cols)


def _with_velocity(table: pa.Table, timestamp_us: np.ndarray) -> pa.Table:
    """Add the devkit's ``box_velocity`` (x, y) of every annotation, computed the same way (float64, the same
    operations), from its prev/next annotations' positions and their samples' timestamps."""
    n = table.num_rows
    tokens = table.column("token")
    prev = pc.index_in(table.column("prev"), value_set=tokens).to_numpy(zero_copy_only=False)
    nxt = pc.index_in(table.column("next"), value_set=tokens).to_numpy(zero_copy_only=False)
    prev = np.where(np.isnan(prev.astype(float)), -1, prev).astype(np.int64) if n else np.zeros(0, np.int64)
    nxt = np.where(np.isnan(nxt.astype(float)), -1, nxt).astype(np.int64) if n else np.zeros(0, np.int64)
    here = np.arange(n)
    has_prev, has_next = prev >= 0, nxt >= 0
    first = np.where(has_prev, prev, here)
    last = np.where(has_next, nxt, here)
    xyz = np.column_stack([table.column(c).to_numpy() for c in _vec_names("translation", 3)]) if n else np.zeros((0, 3))
    pos_diff = xyz[last] - xyz[first]
    time_diff = 1e-6 * timestamp_us[last] - 1e-6 * timestamp_us[first]
    max_diff = np.where(has_prev & has_next, _MAX_TIME_DIFF_S * 2, _MAX_TIME_DIFF_S)
    with np.errstate(divide="ignore", invalid="ignore"):
        velocity = pos_diff / time_diff[:, None]
    velocity[(~has_prev & ~has_next) | (time_diff > max_diff)] = np.nan
    table = table.append_column("velocity_0", pa.array(velocity[:, 0]))
    return table.append_column("velocity_1", pa.array(velocity[:, 1]))


def _instance_batches(instances: list[dict], instance_scene: dict[str, int], n_scenes: int) -> list[pa.RecordBatch]:
    schema = pa.schema(
        [(n, pa.string()) for n in ("token", "category_token", "first_annotation_token", "last_annotation_token")]
        + [("nbr_annotations", pa.int64()), ("table_pos", pa.int64())]
    )
    per_scene: list[list[dict]] = [[] for _ in range(n_scenes)]
    for pos, inst in enumerate(instances):
        scene = instance_scene.get(inst["token"])
        if scene is not None:
            per_scene[scene].append(
                {
                    "token": inst["token"],
                    "category_token": inst["category_token"],
                    "first_annotation_token": inst.get("first_annotation_token"),
                    "last_annotation_token": inst.get("last_annotation_token"),
                    "nbr_annotations": int(inst.get("nbr_annotations", 0)),
                    "table_pos": pos,
                }
            )
    return [pa.RecordBatch.from_pylist(rows, schema) for rows in per_scene]
