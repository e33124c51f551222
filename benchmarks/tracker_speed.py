"""Per-frame tracker time on the demo mini_val scenes and on a dense stress frame.

Usage: uv run python benchmarks/tracker_speed.py [--tracker NAME ...] [--preset centerpoint] [--stress-n 320]
       [--params FILE.toml]

Prints, per tracker: median / max per-frame step time (all 7 classes, preprocessing excluded) over the demo
mini_val scenes with the simulated detector preset, and the step time of a stress frame with >= 300 detections,
many of them a metre or two apart (the 2 Hz keyframe budget is 500 ms). Run it on an otherwise idle machine.
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

import numpy as np

from gnnpmb.config import TrackerConfig, load_config
from gnnpmb.data.nuscenes import load_scene, resolve_dataroot, split_scenes
from gnnpmb.data.preprocess import preprocess
from gnnpmb.events import NullSink
from gnnpmb.pipeline import get_detections, preprocess_frames, run_tracker
from gnnpmb.registry import TRACKER_NAMES
from gnnpmb.tracker import MultiClassTracker
from gnnpmb.types import TRACKING_CLASSES, Boxes


def stress_frames(n: int, n_frames: int, seed: int = 0) -> list[Boxes]:
    """``n_frames`` frames of ``n`` detections: clusters of 6-10 objects spaced 1-2 m apart, moving at up to
    10 m/s, all classes, plus 10 % clutter; positions jittered by 0.2 m per frame."""
    rng = np.random.default_rng(seed)
    n_clusters = n // 8
    centres = rng.uniform(-50, 50, size=(n_clusters, 2))
    offsets = rng.uniform(-3.0, 3.0, size=(n, 2))
    cluster = rng.integers(0, n_clusters, size=n)
    velocity = rng.uniform(-10, 10, size=(n_clusters, 2))[cluster]
    classes = rng.choice(np.array(TRACKING_CLASSES, dtype=object), size=n, p=[0.05, 0.05, 0.5, 0.05, 0.25, 0.05, 0.05])
    frames = []
    for f in range(n_frames):
        xy = centres[cluster] + offsets + velocity * 0.5 * f + rng.normal(0, 0.2, size=(n, 2))
        n_clutter = n // 10
        xy = np.concatenate([xy, rng.uniform(-50, 50, size=(n_clutter, 2))])
        m = len(xy)
        cls = np.concatenate([classes, rng.choice(classes, size=n_clutter)])
        frames.append(
            Boxes(
                translation_m=np.column_stack([xy, np.ones(m)]),
                size_wlh_m=np.tile([0.6, 0.8, 1.7], (m, 1)),  # small boxes: close objects survive NMS
                quat_wxyz=np.tile([1.0, 0.0, 0.0, 0.0], (m, 1)),
                velocity_mps=np.concatenate([velocity, np.zeros((n_clutter, 2))]),
                score=rng.uniform(0.3, 1.0, size=m),
                class_name=cls,
                instance_id=np.array([""] * m, dtype=object),
            )
        )
    return frames


def time_stress(tracker: str, config: TrackerConfig, n: int, repeat: int = 1) -> tuple[float, int]:
    """Step time of the last of 4 stress frames (tracks exist by then), the fastest of ``repeat`` runs, and its
    number of kept detections."""
    frames = [preprocess(b, config.preprocess, TRACKING_CLASSES) for b in stress_frames(n, 4)]
    fastest = float("inf")
    for _ in range(repeat):
        mot = MultiClassTracker(tracker, config)
        for i, frame in enumerate(frames):
            start = time.perf_counter()
            mot.step(frame, 0.5 if i else 0.0, NullSink())
            elapsed = time.perf_counter() - start
        fastest = min(fastest, elapsed)
    return fastest, int(frames[-1].kept.sum())


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--tracker", action="append", choices=TRACKER_NAMES)
    parser.add_argument("--preset", default="centerpoint")
    parser.add_argument("--stress-n", type=int, default=320)
    parser.add_argument(
        "--repeat", type=int, default=3, help="runs per scene and of the stress frames; the fastest per frame counts"
    )
    parser.add_argument("--params", type=Path, help="parameter file, as gnnpmb track --params")
    args = parser.parse_args()
    config = load_config(args.params)
    location = resolve_dataroot(None, None)
    scenes = [load_scene(location, name) for name in split_scenes("mini_val", location)]
    inputs = []
    for scene in scenes:
        dets = get_detections(scene, None, args.preset, seed=0)
        inputs.append((scene, preprocess_frames(scene, dets, config, TRACKING_CLASSES)))
    n_dets = [int(f.kept.sum()) for _, frames in inputs for f in frames]
    print(
        f"demo mini_val: {len(scenes)} scenes, {len(n_dets)} frames, {np.mean(n_dets):.1f} kept detections/frame "
        f"(max {max(n_dets)}), preset {args.preset}"
    )
    print(f"{'tracker':8s} {'median ms':>10s} {'p90 ms':>8s} {'max ms':>8s} {'stress ms':>10s} {'stress dets':>12s}")
    for tracker in args.tracker or TRACKER_NAMES:
        per_frame: list[float] = []
        for scene, frames in inputs:
            best = None
            for _ in range(args.repeat):
                run = run_tracker(scene, frames, tracker, config)
                times = np.array([f.step_time_s for f in run.frames])
                best = times if best is None else np.minimum(best, times)
            per_frame.extend(best.tolist())
        t = np.array(per_frame) * 1e3
        stress_s, stress_n = time_stress(tracker, config, args.stress_n, args.repeat)
        print(
            f"{tracker:8s} {np.median(t):10.2f} {np.percentile(t, 90):8.2f} {t.max():8.2f} "
            f"{stress_s * 1e3:10.1f} {stress_n:12d}"
        )


if __name__ == "__main__":
    main()
