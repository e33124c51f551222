"""Poly-MOT's own, unmodified tracker on a split of both worlds: its tracking submissions, one per world, preset
and seed, scored by the official evaluation beside this project's trackers with ``table1.py --external``.

Poly-MOT (Li et al., "Poly-MOT", IROS 2023; its authors' public repository lixiaoyu2000/Poly-MOT, default
configuration ``config/nusc_config.yaml``) runs in its own process with its own Python environment
(``polymot_driver.py``; see ``polymot_speed.py`` for what that environment holds), on the same detections this
project's trackers read: the demo's simulated detector presets and seeds, and ``--devset DIR``'s detection files
``DIR/detections/{preset}_{split}.json``. Every thread pool is limited to one thread. Each submission is written to
``OUT/{world}_{split}_{preset}_s{seed}.json`` with its CPU ms per frame in ``..._time.json``
(``track_cpu_ms``), and scored: one line per run (AMOTA, IDS, FP, FN, each class's AMOTA).

Usage: uv run python benchmarks/polymot_results.py --polymot DIR --polymot-python PYTHON --out OUT
       [--devset ../shared/devset] [--worlds demo,dev] [--split mini_train] [--preset NAME ...] [--seeds 0,1]
Then:  uv run python benchmarks/table1.py --devset ../shared/devset --split mini_train
       --external "polymot=OUT/{world}_{split}_{preset}_s{seed}.json"
"""

from __future__ import annotations

import os

for _var in ("OMP_NUM_THREADS", "MKL_NUM_THREADS", "OPENBLAS_NUM_THREADS", "NUMBA_NUM_THREADS"):
    os.environ[_var] = "1"

import argparse  # noqa: E402
import json  # noqa: E402
import tempfile  # noqa: E402
from pathlib import Path  # noqa: E402

from polymot_speed import run_polymot  # noqa: E402
from two_worlds import CLASS_SHORT, PRESETS, world_runs  # noqa: E402

from gnnpmb.atomic import write_text  # noqa: E402
from gnnpmb.eval.nuscenes_eval import evaluate_submission  # noqa: E402


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--polymot", type=Path, required=True, help="a checkout of Poly-MOT's code")
    parser.add_argument("--polymot-python", required=True, help="python of an environment with its requirements")
    parser.add_argument("--out", type=Path, required=True, help="folder for the submissions and their scores")
    parser.add_argument("--devset", type=Path, help="a nuScenes-format dataset with detections/{preset}_{split}.json")
    parser.add_argument("--worlds", default="demo,dev")
    parser.add_argument("--split", default="mini_train")
    parser.add_argument("--preset", action="append", choices=PRESETS)
    parser.add_argument("--seeds", default="0,1", help="demo detector seeds, comma-separated")
    args = parser.parse_args()
    if not (args.polymot / "tracking" / "nusc_tracker.py").is_file():
        raise SystemExit(f"error: {args.polymot} is not a Poly-MOT checkout (no tracking/nusc_tracker.py)")
    args.out.mkdir(parents=True, exist_ok=True)
    seeds = [int(s) for s in args.seeds.split(",")]
    for run in world_runs(args.worlds.split(","), args.split, args.devset, args.preset or list(PRESETS), seeds):
        detections = run.split.detections(run.preset, run.seed, run.detections_file)
        path = args.out / f"{run.world}_{args.split}_{run.preset}_s{run.seed}.json"
        with tempfile.TemporaryDirectory(prefix="gnnpmb-polymot-") as work:
            figures = run_polymot(
                args.polymot_python, args.polymot, list(run.split.scenes), detections, Path(work), path
            )
        write_text(path.with_name(path.stem + "_time.json"), json.dumps({"track_cpu_ms": figures["cpu_ms"]}))
        scores = evaluate_submission(path, run.split.location, args.split, path.with_name(path.stem + "_eval"))
        overall = scores.overall
        classes = " ".join(f"{CLASS_SHORT[c]} {scores.per_class[c]['amota']:.3f}" for c in CLASS_SHORT)
        print(
            f"{run.world:4s} {args.split} {run.preset:12s} s{run.seed} polymot        AMOTA {overall['amota']:.4f}"
            f" IDS {overall['ids']:3.0f} FP {overall['fp']:4.0f} FN {overall['fn']:4.0f} | {classes}",
            flush=True,
        )


if __name__ == "__main__":
    main()
