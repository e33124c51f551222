"""How fast parameter studies run: configurations per minute with 1 worker (in process) and with N Ray workers
on this machine, the official evaluation's share of the time, and a planned figure for a 150-scene val split
on a cluster, extrapolated from the measured per-scene costs.

Each configuration tracks the whole demo split and runs one evaluation (``gnnpmb sweep``); the cache is fresh
for every measurement. Planned figure: a configuration of S scenes costs S x (tracking + evaluation per scene)
on one core; N nodes with C cores each run N x C configurations at once. The per-scene evaluation cost is the
measured evaluation time divided by the scene count, so it also spreads the devkit's fixed start-up (it
reloads the dataset tables for every evaluation) over the scenes; on trainval that table load is much larger
and is not measured here.

Ray starts its workers at nice 15; on a machine shared with other jobs, ``RAY_worker_niceness=0`` in the
environment measures them at normal priority.

Usage: uv run python benchmarks/study_scaling.py [--configs 4] [--workers 2] [--nodes 1,2,4,8] [--cores-per-node 2]
"""

from __future__ import annotations

import argparse
import os
import statistics
import tempfile
import time
from pathlib import Path

from gnnpmb.data.nuscenes import resolve_dataroot
from gnnpmb.eval.result_cache import ResultCache
from gnnpmb.study.data import resolve_study_data
from gnnpmb.study.grid import parse_param
from gnnpmb.study.runner import Execution, session
from gnnpmb.study.sweep import SweepPlan, plan_sweep, run_sweep

VAL_SCENES = 150


def measure(plan: SweepPlan, run: Execution) -> tuple[float, float, list[dict]]:
    """(seconds including Ray start-up, seconds of the sweep alone, rows) with a fresh cache."""
    with tempfile.TemporaryDirectory(prefix="gnnpmb-scaling-") as tmp:
        start = time.perf_counter()
        with session(run):
            ready = time.perf_counter()
            outcome = run_sweep(plan, ResultCache(Path(tmp)), run)
        end = time.perf_counter()
    return end - start, end - ready, outcome.rows


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--configs", type=int, default=4, help="configurations per measurement")
    parser.add_argument("--workers", type=int, default=2, help="Ray workers of the parallel measurement")
    parser.add_argument("--nodes", default="1,2,4,8")
    parser.add_argument("--cores-per-node", type=int, default=2)
    parser.add_argument("--detector", default="centerpoint")
    args = parser.parse_args()

    load = os.getloadavg()[0]
    location = resolve_dataroot(None, None)
    data = resolve_study_data(location, "mini_val", None, args.detector, 0)
    values = ",".join(f"{0.05 * (i + 1):.2f}" for i in range(args.configs))
    plan = plan_sweep("gnnpmb", data, {}, [parse_param(f"pmb.birth_weight={values}")], one_at_a_time_mode=False)
    n_scenes = len(data.scene_names)
    n_frames = len(data.sample_tokens)
    print(f"{args.configs} configurations of gnnpmb on demo mini_val ({n_scenes} scenes, {n_frames} keyframes)")

    serial_s, _, rows = measure(plan, Execution(workers=1))
    parallel_s, parallel_sweep_s, parallel_rows = measure(plan, Execution(workers=args.workers))
    eval_share = sum(r["eval_time_s"] for r in rows) / sum(r["wall_time_s"] for r in rows)
    track_scene_s = statistics.median(r["track_time_s"] for r in rows) / n_scenes
    eval_scene_s = statistics.median(r["eval_time_s"] for r in rows) / n_scenes
    print(f"1 worker (in process): {serial_s:.1f} s, {60 * args.configs / serial_s:.1f} configurations/min")
    print(
        f"{args.workers} Ray workers: {parallel_s:.1f} s with Ray start-up ({60 * args.configs / parallel_s:.1f} "
        f"configurations/min), {parallel_sweep_s:.1f} s after start-up ({60 * args.configs / parallel_sweep_s:.1f}"
        " configurations/min)"
    )
    print(
        "median wall time of one configuration: "
        f"{statistics.median(r['wall_time_s'] for r in rows):.1f} s in process, "
        f"{statistics.median(r['wall_time_s'] for r in parallel_rows):.1f} s in a Ray worker "
        f"(load average before the runs: {load:.1f} on {os.cpu_count()} CPUs)"
    )
    print(f"evaluation share of a configuration's time: {100 * eval_share:.0f} %")
    print(
        f"per scene (median over configurations): tracking {track_scene_s:.2f} s, evaluation {eval_scene_s:.2f} s "
        f"({n_frames // n_scenes} keyframes per scene)"
    )
    config_s = VAL_SCENES * (track_scene_s + eval_scene_s)
    print(
        f"\nplanned: one configuration of a {VAL_SCENES}-scene val split = {config_s / 60:.1f} min on one core "
        f"(tables load of trainval not included); {args.cores_per_node} cores per node"
    )
    print("| nodes | cores | configurations/hour | 100-configuration sweep |")
    print("|---|---|---|---|")
    for nodes in (int(n) for n in args.nodes.split(",")):
        cores = nodes * args.cores_per_node
        per_hour = 3600 * cores / config_s
        print(f"| {nodes} | {cores} | {per_hour:.1f} | {100 / per_hour:.1f} h |")


if __name__ == "__main__":
    main()
