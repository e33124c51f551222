"""Frames per second of ``gnnpmb track`` for every tracker on the 10-scene demo split (the 8 mini_train and 2
mini_val scenes), in one process and with ``--workers 2`` (scenes in parallel on a local Ray).

The split is a custom one (``splits.json``) in a temporary dataroot that links to the cached demo's files, so
the cache is not changed. Each command runs as the user would type it; printed per tracker and mode:

* tracker fps: 1000 / the ms per frame the command prints (the trackers' own step time, all 7 classes);
* command fps: frames / wall time of the whole command (start-up, loading, preprocessing, Ray, writing);
* whether the submission of ``--workers 2`` is byte-identical to the one-process one.

    uv run python benchmarks/split_speed.py [--tracker NAME ...] [--detector centerpoint] [--workers 2]

Run it with ``nice -n 5`` on a machine others share; say what its load was.
"""

from __future__ import annotations

import argparse
import hashlib
import json
import os
import re
import subprocess
import tempfile
import time
from dataclasses import dataclass
from pathlib import Path

from gnnpmb.data.demo import DEMO_VERSION, ensure_demo_dataset
from gnnpmb.data.demo_train import TRAIN_SCENES
from gnnpmb.registry import TRACKER_NAMES

SPLIT = "demo_all"
VAL_SCENES = ("scene-0103", "scene-0916")
_PRINTED = re.compile(r": (\d+) scenes of \S+, (\d+) frames, \d+ boxes, ([0-9.]+) ms/frame")


@dataclass(frozen=True, slots=True)
class TrackRun:
    """One ``gnnpmb track`` command: scenes and frames tracked, the ms/frame it printed, its wall seconds and
    the sha256 of its submission."""

    scenes: int
    frames: int
    step_ms: float
    wall_s: float
    sha256: str


def split_dataroot(root: Path) -> Path:
    """A dataroot under ``root`` whose files link to the cached 10-scene demo, plus a ``splits.json`` naming
    all ten scenes ``SPLIT``."""
    demo = ensure_demo_dataset(("mini_train",))
    for entry in demo.iterdir():
        if entry.name != DEMO_VERSION:
            (root / entry.name).symlink_to(entry)
    tables = root / DEMO_VERSION
    tables.mkdir()
    for entry in (demo / DEMO_VERSION).iterdir():
        if entry.name != "splits.json":
            (tables / entry.name).symlink_to(entry)
    (tables / "splits.json").write_text(json.dumps({SPLIT: [*TRAIN_SCENES, *VAL_SCENES]}), encoding="utf-8")
    return root


def track(dataroot: Path, tracker: str, detector: str, workers: int, out: Path) -> TrackRun:
    """Run ``gnnpmb track`` on the split; raise with its output if it fails or prints no ms/frame."""
    command = ["gnnpmb", "track", "--out", str(out), "--dataroot", str(dataroot), "--split", SPLIT]
    command += ["--tracker", tracker, "--detector", detector, "--workers", str(workers), "--no-progress"]
    start = time.perf_counter()
    done = subprocess.run(command, capture_output=True, text=True, check=False, env=os.environ.copy())
    wall_s = time.perf_counter() - start
    printed = _PRINTED.search(done.stdout)
    if done.returncode != 0 or printed is None:
        raise RuntimeError(f"{' '.join(command)} failed ({done.returncode}):\n{done.stdout}\n{done.stderr}")
    sha = hashlib.sha256(out.read_bytes()).hexdigest()
    return TrackRun(int(printed[1]), int(printed[2]), float(printed[3]), wall_s, sha)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--tracker", action="append", default=None, choices=TRACKER_NAMES)
    parser.add_argument("--detector", default="centerpoint")
    parser.add_argument("--workers", type=int, default=2, help="workers of the parallel run")
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        dataroot = split_dataroot(Path(tmp))
        print(f"{SPLIT}: {len(TRAIN_SCENES) + len(VAL_SCENES)} demo scenes, {args.detector}, {os.cpu_count()} CPUs")
        print(
            f"{'tracker':8} {'frames':>6} | {'1 process: tracker fps':>22} {'command fps':>11} {'wall s':>7} | "
            f"{f'--workers {args.workers}: tracker fps':>28} {'command fps':>11} {'wall s':>7} | same submission"
        )
        for tracker in args.tracker or TRACKER_NAMES:
            one = track(dataroot, tracker, args.detector, 1, Path(tmp) / f"{tracker}-1.json")
            many = track(dataroot, tracker, args.detector, args.workers, Path(tmp) / f"{tracker}-n.json")
            print(
                f"{tracker:8} {one.frames:6d} | {1000 / one.step_ms:22.1f} {one.frames / one.wall_s:11.1f} "
                f"{one.wall_s:7.1f} | {1000 / many.step_ms:28.1f} {many.frames / many.wall_s:11.1f} "
                f"{many.wall_s:7.1f} | {'yes' if one.sha256 == many.sha256 else 'NO'}"
            )


if __name__ == "__main__":
    main()
