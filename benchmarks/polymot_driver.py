"""Runs Poly-MOT's own, unmodified tracker (Li et al. 2023, its authors' public repository
lixiaoyu2000/Poly-MOT) frame by frame and prints its CPU time per frame as JSON; started by ``polymot_speed.py``
with Poly-MOT's own Python environment (numba, lap, ...), never imported by this project.

Usage: PYTHON polymot_driver.py POLYMOT_DIR DETECTIONS.json FIRST_TOKENS.json OUT.json [RESULTS.json]

RESULTS.json, when given, receives Poly-MOT's tracks as a nuScenes tracking submission, written as its own
``test.py`` writes it (each sample's boxes by descending score, at most 500).

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
import warnings


def main() -> None:
    polymot_dir, detections, first_tokens, out = (os.path.abspath(a) for a in sys.argv[1:5])
    results_path = os.path.abspath(sys.argv[5]) if len(sys.argv) > 5 else None
    warnings.simplefilter("ignore", FutureWarning)  # its code stacks a generator each frame (numpy < 1.24 warns)
    sys.path.insert(0, polymot_dir)
    os.chdir(polymot_dir)
    import yaml
    from dataloader.nusc_loader import NuScenesloader
    from tracking.nusc_tracker import Tracker

    with open(os.path.join(polymot_dir, "config", "nusc_config.yaml")) as f:
        config = yaml.load(f, Loader=yaml.Loader)
    with contextlib.redirect_stdout(io.StringIO()):  # its loader prints each file it parses
        loader = NuScenesloader(detections, first_tokens, config)
    tracker = Tracker(config=loader.config)
    cpu_ms, wall_ms, boxes = [], [], 0
    results: dict[str, list[dict]] = {}
    for i in range(len(loader)):
        with contextlib.redirect_stdout(io.StringIO()):
            frame = loader[i]
            cpu0, wall0 = time.process_time(), time.perf_counter()
            tracker.tracking(frame)
            cpu_ms.append((time.process_time() - cpu0) * 1e3)
            wall_ms.append((time.perf_counter() - wall0) * 1e3)
        tracked = [] if "no_val_track_result" in frame else list(frame["box_track_res"])
        boxes += len(tracked)
        records = results.setdefault(frame["sample_token"], [])
        records.extend(submission_record(frame["sample_token"], box) for box in tracked)
    write_json(out, {"cpu_ms": cpu_ms, "wall_ms": wall_ms, "output_boxes": boxes})
    if results_path is not None:
        for token, records in results.items():
            results[token] = sorted(records, key=lambda r: -r["tracking_score"])[:500]
        meta = {"use_camera": False, "use_lidar": True, "use_radar": False, "use_map": False, "use_external": False}
        write_json(results_path, {"results": results, "meta": meta})


def write_json(path: str, data: dict) -> None:
    """Write ``data`` to a temporary file beside ``path``, then rename it: never a half-written file."""
    tmp = f"{path}.{os.getpid()}.tmp"
    with open(tmp, "w") as f:
        json.dump(data, f)
    os.replace(tmp, path)


def submission_record(sample_token: str, box) -> dict:
    """One of Poly-MOT's output boxes (its ``NuscBox``) as a tracking-submission record, field by field as its
    ``test.py`` writes them."""
    return {
        "sample_token": sample_token,
        "translation": [float(x) for x in box.center],
        "size": [float(x) for x in box.wlh],
        "rotation": [float(x) for x in box.orientation],
        "velocity": [float(box.velocity[0]), float(box.velocity[1])],
        "tracking_id": str(box.tracking_id),
        "tracking_name": box.name,
        "tracking_score": float(box.score),
    }


if __name__ == "__main__":
    main()
