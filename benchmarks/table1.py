"""Every tracker x simulated detector preset on the demo mini_val scenes, scored by the official nuScenes
tracking evaluation, in the layout of the GNN-PMB paper's Table I (AMOTA, AMOTP, MT, ML, TP, FP, FN, IDS, FRAG),
plus the median and max per-frame tracker time.

Usage: uv run python benchmarks/table1.py [--tracker NAME ...] [--preset NAME ...] [--out DIR]
"""

from __future__ import annotations

import argparse
import tempfile
from pathlib import Path

import numpy as np

from gnnpmb.config import TrackerConfig
from gnnpmb.data.nuscenes import load_scene, open_nuscenes, resolve_dataroot, split_scenes
from gnnpmb.data.simdet import PRESETS
from gnnpmb.eval.nuscenes_eval import evaluate_submission, split_sample_tokens
from gnnpmb.eval.submission import build_submission, run_results, write_submission
from gnnpmb.pipeline import get_detections, preprocess_frames, run_tracker
from gnnpmb.registry import TRACKER_NAMES
from gnnpmb.types import TRACKING_CLASSES

COLUMNS = ("amota", "amotp", "mt", "ml", "tp", "fp", "fn", "ids", "frag")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--tracker", action="append", choices=TRACKER_NAMES)
    parser.add_argument("--preset", action="append", choices=sorted(PRESETS))
    parser.add_argument("--out", type=Path, help="keep submissions and metric files here")
    args = parser.parse_args()
    out = args.out or Path(tempfile.mkdtemp(prefix="gnnpmb-table1-"))
    out.mkdir(parents=True, exist_ok=True)
    config = TrackerConfig()
    location = resolve_dataroot(None, None)
    nusc = open_nuscenes(location)
    names = split_scenes("mini_val", location)
    scenes = [load_scene(nusc, location, n) for n in names]
    tokens = split_sample_tokens(nusc, names)
    header = f"{'preset':13s} {'tracker':8s} " + " ".join(f"{c.upper():>6s}" for c in COLUMNS)
    print(header + f" {'med ms':>7s} {'max ms':>7s}")
    for preset in args.preset or ("centerpoint", "megvii", "pointpillars"):
        inputs = []
        for scene in scenes:
            dets = get_detections(scene, None, preset, seed=0)
            inputs.append((scene, dets, preprocess_frames(scene, dets, config, TRACKING_CLASSES)))
        for tracker in args.tracker or TRACKER_NAMES:
            runs = [run_tracker(s, d, tracker, config, frame_detections=f) for s, d, f in inputs]
            path = out / f"{preset}_{tracker}.json"
            write_submission(path, build_submission([run_results(r) for r in runs], tokens))
            scores = evaluate_submission(path, location, "mini_val", out / f"{preset}_{tracker}_eval")
            times = np.array([f.step_time_s for r in runs for f in r.frames]) * 1e3
            cells = []
            for c in COLUMNS:
                v = scores.overall[c]
                cells.append(f"{v:6.3f}" if c in ("amota", "amotp") else f"{int(round(v)):6d}")
            print(f"{preset:13s} {tracker:8s} " + " ".join(cells) + f" {np.median(times):7.2f} {times.max():7.2f}")
    print(f"submissions and metric files: {out}")


if __name__ == "__main__":
    main()
