"""Which files belong to a nuScenes dataset: the files no output may replace.

A dataset's files are inputs of every command that reads it: every file of a version folder (the tables and the
custom ``splits.json``) and the sensor files under ``samples/``, ``sweeps/`` and ``maps/``. ``dataset_file_of``
tells from a path's place alone (symlinks and relative spellings resolved) whether it is one of them, in any
dataset; ``linked_dataset_file`` finds a hard link to one of the files of a known dataset (same device and inode),
which no path comparison can see.
"""

from __future__ import annotations

import os
from collections.abc import Iterator
from pathlib import Path

SENSOR_FOLDERS = ("samples", "sweeps", "maps")
"""The dataroot's folders of sensor files and map images."""
_TABLE_MARKERS = ("scene.json", "sample.json")
"""Files whose presence makes a folder a nuScenes version folder."""


def is_version_folder(folder: Path) -> bool:
    """Whether ``folder`` holds nuScenes tables (its ``scene.json`` and ``sample.json`` exist)."""
    return all((folder / name).is_file() for name in _TABLE_MARKERS)


def is_dataroot(folder: Path) -> bool:
    """Whether ``folder`` holds a nuScenes version folder (``v1.0-*`` with tables)."""
    try:
        return any(p.name.startswith("v1.0-") and is_version_folder(p) for p in folder.iterdir() if p.is_dir())
    except OSError:
        return False


def dataset_file_of(path: Path) -> str | None:
    """What of a nuScenes dataset ``path`` is or lies in, by its resolved place, or None: "the table
    <file>" for a file of a version folder, the version folder itself, or a sensor folder (``samples/``,
    ``sweeps/``, ``maps/`` of a dataroot) or anything inside it."""
    try:
        resolved = Path(path).expanduser().resolve()
    except (OSError, RuntimeError):
        return None
    if resolved.is_dir() and is_version_folder(resolved):
        return f"the nuScenes table folder {resolved}"
    if is_version_folder(resolved.parent):
        return f"the nuScenes table {resolved}"
    for folder in (resolved, *resolved.parents):
        if folder.name in SENSOR_FOLDERS and is_dataroot(folder.parent):
            return f"in the nuScenes sensor folder {folder}"
    return None


def linked_dataset_file(path: Path, dataroot: Path, version: str) -> Path | None:
    """The file of the dataset at ``dataroot``/``version`` that ``path`` is a hard link of, or None.

    Only an existing file with more than one link can be one; the version folder is compared first, then the
    sensor folders are walked (inode numbers from the directory entries, no stat per file) on the same device.
    """
    try:
        st = os.stat(path)
    except OSError:
        return None
    if st.st_nlink < 2:
        return None
    folders = [Path(dataroot) / version, *(Path(dataroot) / name for name in SENSOR_FOLDERS)]
    for folder in folders:
        try:
            if os.stat(folder).st_dev != st.st_dev:
                continue
        except OSError:
            continue
        for entry in _files_under(folder):
            if entry.inode() == st.st_ino and entry.stat().st_dev == st.st_dev:
                return Path(entry.path)
    return None


def _files_under(folder: Path) -> Iterator[os.DirEntry[str]]:
    """The regular files under ``folder`` (symlinks not followed); unreadable folders are skipped."""
    stack = [str(folder)]
    while stack:
        try:
            with os.scandir(stack.pop()) as entries:
                for entry in entries:
                    if entry.is_dir(follow_symlinks=False):
                        stack.append(entry.path)
                    elif entry.is_file(follow_symlinks=False):
                        yield entry
        except OSError:
            continue
