"""Where and how the persistent indexes are stored: a folder of Arrow IPC files in the user cache, built whole in a
temporary folder and renamed into place, with a manifest that says what it was built from.

Integrity: the manifest (``manifest.json``) is written last; it holds the format version, the source files'
identity (``gnnpmb.data.file_identity``: path, size, modification and change times, inode, a digest of the first
and last blocks) and, per Arrow file, its size and the CRC-32 of every record batch.
``open_store`` trusts a folder only when the manifest parses, matches the sources, every file has its recorded
size and every small JSON side file its CRC (a damaged one makes the index be built again); each batch read is
checked against its CRC (``Store.batch``), so damage found later raises ``IndexDamaged`` and the caller rebuilds.
Files are memory-mapped: a command reads only the batches it needs.
A lock file serialises builds of the same index between processes.
"""

from __future__ import annotations

import contextlib
import fcntl
import hashlib
import importlib
import json
import os
import re
import shutil
import tempfile
import zlib
from collections.abc import Callable, Iterable, Iterator, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import pyarrow as pa

from gnnpmb.atomic import sweep_leftovers, temp_prefix
from gnnpmb.data.file_identity import file_identity
from gnnpmb.errors import GnnpmbError
from gnnpmb.os_errors import os_error_line

MANIFEST = "manifest.json"
NOTE_MIN_BYTES = 50_000_000
"""Sources from this size on take seconds to index: say so even when stderr is not a terminal."""


class CacheWriteError(GnnpmbError):
    """An index could not be written into the cache (a full disk, a read-only cache folder)."""


def _with_errno(exc: OSError) -> OSError:
    """``exc`` with its errno and the system's text for it; pyarrow puts the errno only in a long text ("Error
    writing bytes to file. Detail: [errno 28] No space left on device")."""
    number = exc.errno
    if number is None:
        match = re.search(r"\[errno (\d+)\]", str(exc))
        number = int(match[1]) if match else None
    return exc if number is None else OSError(number, os.strerror(number))


class IndexDamaged(Exception):
    """An index file does not match its manifest (truncated, edited, corrupted): rebuild the index."""


def source_identity(paths: Sequence[Path]) -> list[list[Any]]:
    """The identity of each source file (``file_identity.file_identity``: path, size, modification and change
    times, inode and a digest of its first and last blocks), checked at every open."""
    return [file_identity(path) for path in paths]


def code_identity(*modules: str) -> list[Any]:
    """``["code", digest]`` of the source files of ``modules`` (dotted names), for an index's sources: an index
    derived by other code (a fixed conversion, a reworded problem stored in it) is rebuilt on its next open, so
    a cached index never serves what the running code would not derive. Costs one read of each file."""
    digest = hashlib.sha256()
    for name in modules:
        digest.update(Path(str(importlib.import_module(name).__file__)).read_bytes())
    return ["code", digest.hexdigest()[:16]]


def batch_crc(batch: pa.RecordBatch) -> int:
    """CRC-32 of a record batch's IPC serialisation."""
    return zlib.crc32(batch.serialize())


def write_batches(path: Path, schema: pa.Schema, batches: Iterable[pa.RecordBatch]) -> dict[str, Any]:
    """Write ``batches`` (one per scene or sample) to an Arrow IPC file; its manifest entry (size, and the CRC
    of each batch as it reads back, whatever slicing or padding the writer applied)."""
    with pa.OSFile(str(path), "wb") as sink, pa.ipc.new_file(sink, schema) as writer:
        for batch in batches:
            writer.write_batch(batch)
    return {"size": path.stat().st_size, "crc": file_crcs(path)}


def file_crcs(path: Path) -> list[int]:
    """The CRC of every record batch of an Arrow IPC file, read back from disk."""
    reader = pa.ipc.open_file(pa.memory_map(str(path)))
    return [batch_crc(reader.get_batch(i)) for i in range(reader.num_record_batches)]


def write_json_file(path: Path, data: Any) -> dict[str, Any]:
    """Write a small JSON file; its manifest entry (size, CRC of the bytes)."""
    raw = json.dumps(data, separators=(",", ":")).encode()
    path.write_bytes(raw)
    return {"size": len(raw), "crc": [zlib.crc32(raw)]}


@dataclass(frozen=True, slots=True)
class Store:
    """An opened index folder: its manifest and memory-mapped Arrow files."""

    folder: Path
    manifest: dict[str, Any]
    readers: dict[str, pa.ipc.RecordBatchFileReader]

    def batch(self, name: str, i: int) -> pa.RecordBatch:
        """Record batch ``i`` of file ``name``, checked against its CRC (``IndexDamaged`` otherwise)."""
        try:
            batch = self.readers[name].get_batch(i)
        except (pa.ArrowException, OSError, IndexError) as exc:
            raise IndexDamaged(f"{name} batch {i}: {exc}") from None
        if batch_crc(batch) != self.manifest["files"][name]["crc"][i]:
            raise IndexDamaged(f"{name} batch {i} fails its checksum")
        return batch

    def json(self, name: str) -> Any:
        """A small JSON file of the index, checked against its CRC."""
        raw = (self.folder / name).read_bytes()
        if zlib.crc32(raw) != self.manifest["files"][name]["crc"][0]:
            raise IndexDamaged(f"{name} fails its checksum")
        return json.loads(raw)


def open_store(folder: Path, fmt: int, sources: list[list[Any]]) -> Store | None:
    """The index in ``folder`` if it is complete, of format ``fmt`` and built from ``sources``; else None."""
    try:
        manifest = json.loads((folder / MANIFEST).read_text(encoding="utf-8"))
        if manifest.get("format") != fmt or manifest.get("sources") != sources:
            return None
        files: Mapping[str, Any] = manifest["files"]
        for name, entry in files.items():
            if (folder / name).stat().st_size != entry["size"]:
                return None
            if not name.endswith(".arrow") and zlib.crc32((folder / name).read_bytes()) != entry["crc"][0]:
                return None  # a small JSON side file (scenes.json, samples.json, ...) is checked whole at open
        readers = {
            name: pa.ipc.open_file(pa.memory_map(str(folder / name))) for name in files if name.endswith(".arrow")
        }
        for name, reader in readers.items():
            if reader.num_record_batches != len(files[name]["crc"]):
                return None
    except (OSError, ValueError, KeyError, TypeError, AttributeError, pa.ArrowException):
        return None
    return Store(folder, manifest, readers)


def open_or_build(folder: Path, fmt: int, sources: list[list[Any]], build: Callable[[Path], None]) -> Store:
    """The index in ``folder``, built first by ``build(tmp)`` if it is missing, stale or damaged.

    ``build`` writes every file into the empty folder ``tmp`` and the manifest last (``write_manifest``); ``tmp``
    then replaces ``folder``, so a reader never sees a half-built index. Processes building the same index wait
    for each other (a lock file beside it) and the later ones use the first one's result.
    """
    store = open_store(folder, fmt, sources)
    if store is not None:
        return store
    folder.parent.mkdir(parents=True, exist_ok=True)
    with open(folder.parent / f".{folder.name}.lock", "w") as lock:
        fcntl.flock(lock, fcntl.LOCK_EX)
        store = open_store(folder, fmt, sources)
        if store is not None:
            return store
        sweep_leftovers(folder.parent)  # builds of killed runs (gnnpmb.atomic)
        tmp = Path(tempfile.mkdtemp(prefix=temp_prefix(folder, "build"), dir=folder.parent))
        try:
            try:
                build(tmp)
            except OSError as exc:  # pyarrow's write errors are OSErrors without a file name
                raise CacheWriteError(os_error_line(_with_errno(exc), folder)) from None
            if folder.exists():
                old = Path(tempfile.mkdtemp(prefix=temp_prefix(folder, "old"), dir=folder.parent))
                os.replace(folder, old / "index")
                shutil.rmtree(old, ignore_errors=True)
            os.replace(tmp, folder)
        finally:
            shutil.rmtree(tmp, ignore_errors=True)
        drop_orphans(folder.parent)
    store = open_store(folder, fmt, sources)
    if store is None:
        raise IndexDamaged(f"the index just built in {folder} cannot be opened")
    return store


def drop_orphans(root: Path) -> None:
    """Delete the indexes in ``root`` whose source files are all gone (e.g. a deleted dataroot or detection
    file), so the cache does not grow with every temporary dataset."""
    for folder in root.iterdir():
        try:
            sources = json.loads((folder / MANIFEST).read_text(encoding="utf-8"))["sources"]
        except (OSError, ValueError, KeyError, TypeError):
            continue
        if sources and not any(Path(source[0]).exists() for source in sources):
            shutil.rmtree(folder, ignore_errors=True)


def write_manifest(folder: Path, manifest: Mapping[str, Any]) -> None:
    """Write the manifest last, atomically, after every file it lists is on disk."""
    for entry in os.scandir(folder):
        with open(entry.path, "rb") as f:
            os.fsync(f.fileno())
    tmp = folder / f".{MANIFEST}.tmp"
    tmp.write_text(json.dumps(manifest, separators=(",", ":")), encoding="utf-8")
    os.replace(tmp, folder / MANIFEST)


@contextlib.contextmanager
def build_progress(note: str, total_bytes: int) -> Iterator[Callable[[int], None]]:
    """Print ``note`` on stderr (on a terminal, or for a build of at least ``NOTE_MIN_BYTES`` in a log) and show a
    rich progress bar of the bytes read (on a terminal); yields the callback that advances it."""
    from rich.console import Console
    from rich.progress import BarColumn, DownloadColumn, Progress, TextColumn, TimeRemainingColumn

    console = Console(stderr=True)
    if console.is_terminal or total_bytes >= NOTE_MIN_BYTES:
        console.print(note, highlight=False, soft_wrap=True)
    bar = Progress(
        TextColumn("indexing"),
        BarColumn(),
        DownloadColumn(),
        TimeRemainingColumn(),
        console=console,
        transient=True,
        disable=not console.is_terminal,
    )
    with bar:
        task = bar.add_task("indexing", total=total_bytes)
        yield lambda n: bar.advance(task, n)
