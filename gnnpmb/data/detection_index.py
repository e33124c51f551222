"""The persistent index of one detection results file: each sample's tracking-class boxes as one Arrow record batch.

A full val results file (6,019 samples, 300-700 MB of JSON) took ~45 s and 3.3 GB to parse whole in every
command. It is read once instead, member by member (``gnnpmb.data.json_stream``: bounded memory, a progress
bar), each sample converted and checked exactly as before (``gnnpmb.data.detections.convert_sample``), and
stored under ``<cache root>/index/detections-<key>/``: ``boxes.arrow`` (one batch per sample, in file order),
``untracked.arrow`` (one batch per sample that has any: its boxes of the detection names no tracker takes,
barrier, traffic_cone and construction_vehicle, as name, score and BEV centre, which the explanations name),
``samples.json`` (token -> batch, or the sample's first problem) and the file's SHA-256 (the provenance's
detections hash, computed while reading). The index is rebuilt when the file changes (path, size, modification
time), when the code that converts a sample changes (``index_store.code_identity``: the boxes and the problems'
texts are derived by it), or when the index is damaged (``gnnpmb.data.index_store``).
"""

from __future__ import annotations

import hashlib
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
import pyarrow as pa

from gnnpmb.data.index_store import (
    Store,
    build_progress,
    code_identity,
    file_crcs,
    open_or_build,
    source_identity,
    write_json_file,
    write_manifest,
)
from gnnpmb.data.json_stream import JsonStreamError, NotUtf8Error, iter_object
from gnnpmb.errors import DataError
from gnnpmb.types import Boxes

FORMAT = 2
_VECTORS = {"translation_m": 3, "size_wlh_m": 3, "quat_wxyz": 4, "velocity_mps": 2}
SCHEMA = pa.schema(
    [(f"{name}_{i}", pa.float64()) for name, n in _VECTORS.items() for i in range(n)]
    + [("score", pa.float64()), ("class_name", pa.string())]
)


UNTRACKED_SCHEMA = pa.schema(
    [("name", pa.string()), ("score", pa.float64()), ("x_m", pa.float64()), ("y_m", pa.float64())]
)
UntrackedBox = tuple[str, float, float, float]
"""A box of a detection name no tracker takes: (name, score, x m, y m)."""


class DetectionIndex:
    """An opened detection index: ``boxes(token)`` and what was wrong with a sample (``problem``)."""

    def __init__(self, store: Store) -> None:
        self.store = store
        samples = store.json("samples.json")
        self.batch_of: dict[str, int] = samples["batch"]
        self.problems: dict[str, str] = samples["problems"]
        self.untracked_of: dict[str, int] = samples["untracked"]

    @property
    def sha256(self) -> str:
        """SHA-256 (hex) of the file's bytes."""
        return self.store.manifest["sha256"]

    def __contains__(self, token: str) -> bool:
        return token in self.batch_of or token in self.problems

    def boxes(self, token: str) -> Boxes:
        """The tracking-class boxes of sample ``token`` (which must have no problem)."""
        batch = self.store.batch("boxes.arrow", self.batch_of[token])
        if batch.num_rows == 0:
            return Boxes.empty()
        arrays = {
            name: np.column_stack([batch.column(f"{name}_{i}").to_numpy() for i in range(n)])
            for name, n in _VECTORS.items()
        }
        return Boxes(
            score=batch.column("score").to_numpy().copy(),
            class_name=np.array(batch.column("class_name").to_pylist(), dtype=object),
            instance_id=np.full(batch.num_rows, "", dtype=object),
            **arrays,
        )

    def untracked(self, token: str) -> tuple[UntrackedBox, ...]:
        """Sample ``token``'s boxes of the detection names no tracker takes (none: an empty tuple)."""
        if token not in self.untracked_of:
            return ()
        batch = self.store.batch("untracked.arrow", self.untracked_of[token])
        return tuple(zip(*(batch.column(n).to_pylist() for n in UNTRACKED_SCHEMA.names), strict=True))


def _batch(boxes: Boxes) -> pa.RecordBatch:
    columns: dict[str, Any] = {}
    for name, n in _VECTORS.items():
        values = np.asarray(getattr(boxes, name), dtype=np.float64).reshape(-1, n)
        columns |= {f"{name}_{i}": values[:, i] for i in range(n)}
    columns["score"] = np.asarray(boxes.score, dtype=np.float64)
    columns["class_name"] = [str(c) for c in boxes.class_name]
    return pa.RecordBatch.from_pydict(columns, schema=SCHEMA)


def index_folder(cache: Path, path: Path) -> Path:
    return cache / "index" / f"detections-{hashlib.sha256(str(path).encode()).hexdigest()[:16]}"


def open_detection_index(
    cache: Path,
    path: Path,
    convert: Callable[[str, Any], Boxes | str],
    untracked: Callable[[list[Any]], list[UntrackedBox]],
    describe: Callable[[Exception], DataError],
) -> DetectionIndex:
    """The index of the detection file ``path`` (absolute), built now if missing, stale or damaged. ``convert``
    turns one sample's entries into boxes or a problem; ``untracked`` gives the boxes of untracked names of a
    sample ``convert`` found no problem in; ``describe`` turns a read error into the user's one line."""
    files = source_identity([path])
    sources = [*files, code_identity(convert.__module__, __name__)]

    def build(tmp: Path) -> None:
        size = max(files[0][1], 0)
        note = f"indexing {path.name} ({size / 1e6:.0f} MB) into {cache}, once per detection file"
        with build_progress(note, size) as advance:
            _build(tmp, path, sources, convert, untracked, describe, advance)

    return DetectionIndex(open_or_build(index_folder(cache, path), FORMAT, sources, build))


def _build(
    tmp: Path,
    path: Path,
    sources: list[list[Any]],
    convert: Callable[[str, Any], Boxes | str],
    untracked: Callable[[list[Any]], list[UntrackedBox]],
    describe: Callable[[Exception], DataError],
    advance: Callable[[int], None],
) -> None:
    digest = hashlib.sha256()

    def on_bytes(block: bytes) -> None:
        digest.update(block)
        advance(len(block))

    batch_of: dict[str, int] = {}
    untracked_of: dict[str, int] = {}
    problems: dict[str, str] = {}
    written = written_untracked = 0
    try:
        with (
            open(path, "rb") as f,
            pa.OSFile(str(tmp / "boxes.arrow"), "wb") as sink,
            pa.ipc.new_file(sink, SCHEMA) as writer,
            pa.OSFile(str(tmp / "untracked.arrow"), "wb") as side_sink,
            pa.ipc.new_file(side_sink, UNTRACKED_SCHEMA) as side,
        ):
            for token, entries in iter_object(f, on_bytes, member="results"):
                converted = convert(token, entries)
                problems.pop(token, None)
                batch_of.pop(token, None)
                untracked_of.pop(token, None)
                if isinstance(converted, str):
                    problems[token] = converted
                    continue
                writer.write_batch(_batch(converted))
                batch_of[token] = written
                written += 1
                if rows := untracked(entries):
                    columns = [list(c) for c in zip(*rows, strict=True)]
                    side.write_batch(pa.RecordBatch.from_arrays(columns, schema=UNTRACKED_SCHEMA))
                    untracked_of[token] = written_untracked
                    written_untracked += 1
    except (JsonStreamError, NotUtf8Error, KeyError, TypeError, OSError) as exc:
        raise describe(exc) from None
    files = {
        "boxes.arrow": {"size": (tmp / "boxes.arrow").stat().st_size, "crc": file_crcs(tmp / "boxes.arrow")},
        "untracked.arrow": {
            "size": (tmp / "untracked.arrow").stat().st_size,
            "crc": file_crcs(tmp / "untracked.arrow"),
        },
        "samples.json": write_json_file(
            tmp / "samples.json", {"batch": batch_of, "problems": problems, "untracked": untracked_of}
        ),
    }
    manifest = {"format": FORMAT, "sources": sources, "sha256": digest.hexdigest(), "files": files}
    write_manifest(tmp, manifest)
