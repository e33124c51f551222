"""Per-frame time of every tracker on a dense crowd: 1000 pedestrians on a grid at 0.9 m spacing.

Usage: uv run python benchmarks/crowd.py [--tracker NAME ...] [--n 1000] [--spacing-m 0.9] [--frames 4]

The crowd walks at 1.2 m/s in one direction; each keyframe (0.5 s apart) detects every pedestrian with 0.1 m
position noise and a score in [0.5, 1.0], plus 5 % uniform clutter. Every gate then holds several detections,
the worst case for hypothesis management. Prints, per tracker, the step time of each frame, the worst frame,
the number of estimates and the process's peak memory; the budget is 1 s per frame (issue 10). Run it on an
otherwise idle machine.
"""

from __future__ import annotations

import argparse
import resource
import time

import numpy as np

from gnnpmb.config import TrackerConfig
from gnnpmb.data.preprocess import preprocess
from gnnpmb.events import NullSink
from gnnpmb.registry import TRACKER_NAMES
from gnnpmb.tracker import MultiClassTracker
from gnnpmb.types import Boxes

FRAME_DT_S = 0.5
BUDGET_S = 1.0


def crowd_frames(n: int, spacing_m: float, n_frames: int, seed: int = 0) -> list[Boxes]:
    """``n_frames`` frames of ``n`` pedestrian detections on a square grid ``spacing_m`` apart (walking at
    1.2 m/s along x, 0.1 m noise) plus 5 % clutter."""
    rng = np.random.default_rng(seed)
    side = int(np.ceil(np.sqrt(n)))
    grid = np.stack(np.meshgrid(np.arange(side), np.arange(side)), axis=-1).reshape(-1, 2)[:n] * spacing_m
    grid = grid - grid.mean(axis=0)
    velocity = np.array([1.2, 0.0])
    frames = []
    for f in range(n_frames):
        xy = grid + velocity * FRAME_DT_S * f + rng.normal(0.0, 0.1, size=(n, 2))
        half = side * spacing_m / 2 + 5.0
        clutter = rng.uniform(-half, half, size=(n // 20, 2))
        xy = np.concatenate([xy, clutter])
        m = len(xy)
        frames.append(
            Boxes(
                translation_m=np.column_stack([xy, np.full(m, 1.0)]),
                size_wlh_m=np.tile([0.6, 0.6, 1.7], (m, 1)),
                quat_wxyz=np.tile([1.0, 0.0, 0.0, 0.0], (m, 1)),
                velocity_mps=np.concatenate([np.tile(velocity, (n, 1)), np.zeros((m - n, 2))]),
                score=rng.uniform(0.5, 1.0, size=m),
                class_name=np.full(m, "pedestrian", dtype=object),
                instance_id=np.full(m, "", dtype=object),
            )
        )
    return frames


def time_crowd(tracker: str, config: TrackerConfig, frames: list[Boxes]) -> tuple[list[float], int]:
    """Step time (s) of every frame and the number of estimates of the last."""
    mot = MultiClassTracker(tracker, config)
    prepared = [preprocess(b, config.preprocess, ("pedestrian",)) for b in frames]
    times, estimates = [], []
    for i, frame in enumerate(prepared):
        start = time.perf_counter()
        estimates = mot.step(frame, FRAME_DT_S if i else 0.0, NullSink())
        times.append(time.perf_counter() - start)
    return times, len(estimates)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--tracker", action="append", choices=TRACKER_NAMES)
    parser.add_argument("--n", type=int, default=1000)
    parser.add_argument("--spacing-m", type=float, default=0.9)
    parser.add_argument("--frames", type=int, default=4)
    args = parser.parse_args()
    config = TrackerConfig()
    frames = crowd_frames(args.n, args.spacing_m, args.frames)
    n_clutter = len(frames[0]) - args.n
    print(f"crowd: {args.n} pedestrians {args.spacing_m} m apart + {n_clutter} clutter, {args.frames} frames")
    print(f"{'tracker':8s} {'ms per frame':>40s} {'max ms':>8s} {'tracks':>7s} {'<= 1 s':>7s} {'peak MB':>8s}")
    for tracker in args.tracker or TRACKER_NAMES:
        times, n_tracks = time_crowd(tracker, config, frames)
        ms = " ".join(f"{t * 1e3:.0f}" for t in times)
        peak_mb = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
        ok = "yes" if max(times) <= BUDGET_S else "NO"
        print(f"{tracker:8s} {ms:>40s} {max(times) * 1e3:8.0f} {n_tracks:7d} {ok:>7s} {peak_mb:8.0f}", flush=True)


if __name__ == "__main__":
    main()
