"""The paper's point in numbers: GNN-PMB, PMBM and TO-PMB share one PMB core and differ only in hypothesis
management. Runs the three on a demo scene and prints tracks per frame, id count and step time.

Usage: uv run python examples/compare_hypothesis_management.py [SCENE] [PRESET]
"""

from __future__ import annotations

import sys

import numpy as np

from gnnpmb.config import TrackerConfig
from gnnpmb.data.nuscenes import load_scene, resolve_dataroot
from gnnpmb.pipeline import get_detections, preprocess_frames, run_tracker
from gnnpmb.types import TRACKING_CLASSES


def main() -> None:
    scene_name = sys.argv[1] if len(sys.argv) > 1 else "scene-0916"
    preset = sys.argv[2] if len(sys.argv) > 2 else "pointpillars"
    config = TrackerConfig()
    location = resolve_dataroot(None, None)
    scene = load_scene(location, scene_name)
    detections = get_detections(scene, None, preset, seed=0)
    frames = preprocess_frames(scene, detections, config, TRACKING_CLASSES)
    print(f"{scene_name}, simulated {preset} detections, {len(frames)} keyframes")
    print(f"{'tracker':8s} {'tracks/frame':>12s} {'distinct ids':>12s} {'median ms':>10s}")
    for tracker in ("gnnpmb", "pmbm", "topmb"):
        run = run_tracker(scene, frames, tracker, config)
        per_frame = [len(f.estimates) for f in run.frames]
        ids = {e.track_id for f in run.frames for e in f.estimates}
        ms = np.median([f.step_time_s for f in run.frames]) * 1e3
        print(f"{tracker:8s} {np.mean(per_frame):12.1f} {len(ids):12d} {ms:10.2f}")


if __name__ == "__main__":
    main()
