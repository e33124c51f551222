"""Runs Poly-MOT's own, unmodified tracker (Li et al. 2023, its authors' public repository
lixiaoyu2000/Poly-MOT) frame by frame and prints its CPU time per frame as JSON; started by ``polymot_speed.py``
with Poly-MOT's own Python environment (numba, lap, ...), never imported by this project.

Usage: PYTHON polymot_driver.py POLYMOT_DIR DETECTIONS.json FIRST_TOKENS.json OUT.json

Times ``Tracker.tracking(frame)`` only: its loader's score filter and NMS (preprocessing, which this project's
tracker times leave out as well) run outside the timed part. numba compiles on first use, inside one frame's
time; the caller compares medians.
"""

import contextlib
import io
import json
import os
import sys
import time


def main() -> None:
    polymot_dir, detections, first_tokens, out = sys.argv[1:5]
    sys.path.insert(0, polymot_dir)
    os.chdir(polymot_dir)
    import yaml
    from dataloader.nusc_loader import NuScenesloader
    from tracking.nusc_tracker import Tracker

    with open(os.path.join(polymot_dir, "config", "nusc_config.yaml")) as f:
        config = yaml.load(f, Loader=yaml.Loader)
    loader = NuScenesloader(detections, first_tokens, config)
    tracker = Tracker(config=loader.config)
    cpu_ms, wall_ms, boxes = [], [], 0
    for i in range(len(loader)):
        with contextlib.redirect_stdout(io.StringIO()):
            frame = loader[i]
            cpu0, wall0 = time.process_time(), time.perf_counter()
            tracker.tracking(frame)
            cpu_ms.append((time.process_time() - cpu0) * 1e3)
            wall_ms.append((time.perf_counter() - wall0) * 1e3)
        boxes += 0 if "no_val_track_result" in frame else len(frame["box_track_res"])
    with open(out, "w") as f:
        json.dump({"cpu_ms": cpu_ms, "wall_ms": wall_ms, "output_boxes": boxes}, f)


if __name__ == "__main__":
    main()
