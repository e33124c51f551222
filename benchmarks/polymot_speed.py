"""CPU time per frame of the PMB trackers beside Poly-MOT's own, unmodified code, on the same detections, in one
run, both single-threaded.

Usage: uv run python benchmarks/polymot_speed.py --polymot DIR --polymot-python PYTHON [--preset centerpoint]
       [--seed 0] [--split mini_val] [--tracker gnnpmb ...]

DIR is a checkout of Poly-MOT (Li et al., "Poly-MOT", IROS 2023, its authors' public repository
lixiaoyu2000/Poly-MOT) and PYTHON an interpreter of an environment holding its requirements from PyPI (numpy <
1.24, numba, lap, pyyaml, nuscenes-devkit, ...: its code stacks a generator, which numpy 1.24 refused). This
script writes the demo split's simulated detections as a nuScenes detection file in time order, with Poly-MOT's
first-token table, and runs ``polymot_driver.py`` with PYTHON (its tracker in its own process, default
configuration). Every thread pool is limited to one thread (OMP, MKL, OpenBLAS, numba) in both processes.
Each tracker's step is timed as CPU time of the process (``time.process_time``), preprocessing (score filter,
NMS) excluded on both sides, each frame the fastest of ``--repeat`` runs for this project's trackers; the ratio
is of medians (Poly-MOT's numba compilation on first use lands in one frame, its max). The target of issue 32:
every PMB tracker <= 1/10 of Poly-MOT's CPU per frame.
"""

from __future__ import annotations

import os

for _var in ("OMP_NUM_THREADS", "MKL_NUM_THREADS", "OPENBLAS_NUM_THREADS", "NUMBA_NUM_THREADS"):
    os.environ[_var] = "1"

import argparse  # noqa: E402
import json  # noqa: E402
import subprocess  # noqa: E402
import tempfile  # noqa: E402
import time  # noqa: E402
from pathlib import Path  # noqa: E402

import numpy as np  # noqa: E402

from gnnpmb.config import TrackerConfig  # noqa: E402
from gnnpmb.data.nuscenes import load_scene, resolve_dataroot, split_scenes  # noqa: E402
from gnnpmb.data.scene import SceneData  # noqa: E402
from gnnpmb.events import NullSink  # noqa: E402
from gnnpmb.pipeline import get_detections, preprocess_frames  # noqa: E402
from gnnpmb.tracker import MultiClassTracker  # noqa: E402
from gnnpmb.types import TRACKING_CLASSES, Boxes  # noqa: E402

PMB_TRACKERS = ("gnnpmb", "pmbm", "topmb")
DRIVER = Path(__file__).with_name("polymot_driver.py")


def detection_records(sample_token: str, boxes: Boxes) -> list[dict]:
    """The nuScenes detection-submission records of one sample's boxes."""
    return [
        {
            "sample_token": sample_token,
            "translation": boxes.translation_m[i].tolist(),
            "size": boxes.size_wlh_m[i].tolist(),
            "rotation": boxes.quat_wxyz[i].tolist(),
            "velocity": boxes.velocity_mps[i].tolist(),
            "detection_name": str(boxes.class_name[i]),
            "detection_score": float(boxes.score[i]),
            "attribute_name": "",
        }
        for i in range(len(boxes))
    ]


def run_polymot(
    python: str,
    polymot_dir: Path,
    scenes: list[SceneData],
    detections: list[dict[str, Boxes]],
    work: Path,
    results_path: Path | None = None,
) -> dict:
    """Run Poly-MOT's own tracker (``polymot_driver.py`` with ``python``) on ``detections``, written in time order
    with its first-token table under ``work``; returns the driver's figures (``cpu_ms`` per frame in time order,
    scene after scene). ``results_path``: also write its tracks there as a tracking submission."""
    results = {
        k.sample_token: detection_records(k.sample_token, dets[k.sample_token])
        for scene, dets in zip(scenes, detections, strict=True)
        for k in scene.keyframes
    }
    det_path, first_path, out_path = work / "detections.json", work / "first_tokens.json", work / "polymot.json"
    det_path.write_text(json.dumps({"results": results, "meta": {"use_lidar": True}}))
    first_path.write_text(json.dumps([s.keyframes[0].sample_token for s in scenes]))
    command = [python, str(DRIVER), str(polymot_dir), str(det_path), str(first_path), str(out_path)]
    command += [str(results_path)] if results_path is not None else []
    subprocess.run(command, check=True, env=os.environ.copy())
    return json.loads(out_path.read_text())


def tracker_cpu_ms(
    tracker: str, scenes: list[SceneData], detections: list[dict[str, Boxes]], repeat: int
) -> np.ndarray:
    """This project's tracker: CPU ms of each frame's step (all classes), the fastest of ``repeat`` runs."""
    config = TrackerConfig()
    per_frame = []
    for scene, dets in zip(scenes, detections, strict=True):
        frames = preprocess_frames(scene, dets, config, TRACKING_CLASSES)
        best = np.full(len(frames), np.inf)
        for _ in range(repeat):
            mot = MultiClassTracker(tracker, config)
            previous_us = None
            for i, keyframe in enumerate(scene.keyframes):
                dt_s = 0.0 if previous_us is None else (keyframe.timestamp_us - previous_us) * 1e-6
                previous_us = keyframe.timestamp_us
                start = time.process_time()
                mot.step(frames[i], dt_s, NullSink())
                best[i] = min(best[i], (time.process_time() - start) * 1e3)
        per_frame.extend(best.tolist())
    return np.array(per_frame)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--polymot", type=Path, required=True, help="a checkout of Poly-MOT's code")
    parser.add_argument("--polymot-python", required=True, help="python of an environment with its requirements")
    parser.add_argument("--preset", default="centerpoint")
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--split", default="mini_val")
    parser.add_argument("--tracker", action="append", choices=PMB_TRACKERS)
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--work", type=Path, help="keep Poly-MOT's input and output files here (default: a temp dir)")
    args = parser.parse_args()
    if not (args.polymot / "tracking" / "nusc_tracker.py").is_file():
        raise SystemExit(f"error: {args.polymot} is not a Poly-MOT checkout (no tracking/nusc_tracker.py)")
    location = resolve_dataroot(None, None)
    scenes = [load_scene(location, name) for name in split_scenes(args.split, location)]
    detections = [get_detections(s, None, args.preset, args.seed) for s in scenes]
    n_frames = sum(len(s.keyframes) for s in scenes)
    print(f"demo {args.split}: {len(scenes)} scenes, {n_frames} frames, preset {args.preset}, seed {args.seed}")
    if args.work:
        args.work.mkdir(parents=True, exist_ok=True)
        poly = np.array(run_polymot(args.polymot_python, args.polymot, scenes, detections, args.work)["cpu_ms"])
    else:
        with tempfile.TemporaryDirectory(prefix="gnnpmb-polymot-") as work:
            poly = np.array(run_polymot(args.polymot_python, args.polymot, scenes, detections, Path(work))["cpu_ms"])
    print(
        f"{'polymot':8s} CPU ms/frame median {np.median(poly):7.2f} mean {poly.mean():7.2f} "
        f"(max {poly.max():.0f} ms: numba compiles on first use)"
    )
    for tracker in args.tracker or PMB_TRACKERS:
        t = tracker_cpu_ms(tracker, scenes, detections, args.repeat)
        ratio = np.median(t) / np.median(poly)
        verdict = "met" if ratio <= 0.1 else "not met"
        print(
            f"{tracker:8s} CPU ms/frame median {np.median(t):7.2f} mean {t.mean():7.2f}  median ratio to Poly-MOT "
            f"{ratio:.3f} (target <= 0.1: {verdict})"
        )


if __name__ == "__main__":
    main()
