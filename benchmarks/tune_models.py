"""Compare candidate parameter sets of one tracker on a demo split (``mini_train``: never ``mini_val`` for a
choice) over detector presets, their realism variants and seeds, scored by the official evaluation.

Each candidate is a name and dotted parameters on top of the defaults (``--params`` files first), e.g.
``--candidate decay=pmb.miss_score_decay=0.3`` or ``--candidate both=pmb.miss_score_decay=0.3,pmb.heading_std_rad=0.1``;
``base`` (no change) is always scored. Prints, per candidate, the mean AMOTA per detector model and over all of
them, with mean FP, IDS and AMOTP, and the number of detector models on which it beats ``base``. Runs two
evaluations at a time (``--workers``) as Ray tasks (``gnnpmb.study.runner``; ``--workers 1``: in this process).

Usage: uv run python benchmarks/tune_models.py [--tracker gnnpmb] [--split mini_train] [--preset NAME ...]
       [--seeds 0,1,2] [--candidate NAME=KEY=VALUE,... ...] [--params FILE ...] [--workers 2] [--out DIR]
"""

from __future__ import annotations

import argparse
import json
import os
import tempfile
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from demo_split import DemoSplit, score
from table1 import layered_config

from gnnpmb.config import TrackerConfig, with_params
from gnnpmb.study.runner import execution, run_tasks, session
from gnnpmb.types import Boxes


def parse_candidate(text: str) -> tuple[str, dict[str, float]]:
    name, _, rest = text.partition("=")
    values: dict[str, float] = {}
    for item in filter(None, rest.split(",")):
        key, _, value = item.partition("=")
        values[key] = float(value)
    return name, values


@dataclass(frozen=True)
class Job:
    """One candidate on one detector model and seed, with everything a Ray worker needs to score it."""

    name: str
    preset: str
    seed: int
    split: DemoSplit
    detections: list[dict[str, Boxes]]
    tracker: str
    config: TrackerConfig
    out: Path


def _run(job: Job) -> tuple[str, str, int, dict[str, float]]:
    run = score(job.split, job.detections, job.tracker, job.config, job.out / f"{job.name}_{job.preset}_s{job.seed}")
    overall = run.scores.overall
    metrics = {k: float(overall[k]) for k in ("amota", "amotp", "recall", "fp", "fn", "ids")}
    metrics["ms"] = float(np.median(run.step_ms))
    return job.name, job.preset, job.seed, metrics


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--tracker", default="gnnpmb")
    parser.add_argument("--split", default="mini_train")
    parser.add_argument("--preset", action="append", help="detector model, e.g. centerpoint or pointpillars+runs")
    parser.add_argument("--seeds", default="0,1,2")
    parser.add_argument("--candidate", action="append", default=[])
    parser.add_argument("--params", action="append", default=[])
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--out", type=Path)
    args = parser.parse_args()
    if args.split == "mini_val":
        print("note: mini_val is for reporting; never choose parameters on it")
    out = args.out or Path(tempfile.mkdtemp(prefix="gnnpmb-tune-models-"))
    base = layered_config(args.params or ["default"])
    candidates = dict([("base", {})] + [parse_candidate(c) for c in args.candidate])
    presets = args.preset or ["centerpoint", "megvii", "pointpillars"]
    seeds = [int(s) for s in args.seeds.split(",")]
    split = DemoSplit.load(args.split)
    configs = {name: with_params(base, values) for name, values in candidates.items()}
    detections = {(p, s): split.detections(p, s) for p in presets for s in seeds}
    jobs = [
        Job(name, p, s, split, detections[(p, s)], args.tracker, configs[name], out)
        for name in candidates
        for p in presets
        for s in seeds
    ]
    # Ray workers import this folder's modules (demo_split, table1) as the driver does.
    here = str(Path(__file__).resolve().parent)
    os.environ["PYTHONPATH"] = os.pathsep.join(filter(None, [here, os.environ.get("PYTHONPATH")]))
    results: dict[tuple[str, str, int], dict[str, float]] = {}
    run = execution(args.workers, None)
    with session(run):
        for _, (name, preset, seed, metrics) in run_tasks(_run, jobs, run):
            results[(name, preset, seed)] = metrics
            print(f"  {name} {preset} s{seed}: AMOTA {metrics['amota']:.4f} IDS {metrics['ids']:.0f}", flush=True)
    print(f"split {args.split}, tracker {args.tracker}, seeds {seeds}; mean over seeds")
    print(f"{'candidate':22s} " + " ".join(f"{p[:16]:>16s}" for p in presets) + "     mean     FP   IDS  AMOTP  wins")
    table = {}
    for name in candidates:
        per = [float(np.mean([results[(name, p, s)]["amota"] for s in seeds])) for p in presets]
        base_per = [float(np.mean([results[("base", p, s)]["amota"] for s in seeds])) for p in presets]
        every = [results[(name, p, s)] for p in presets for s in seeds]
        fp, ids, amotp = (float(np.mean([m[k] for m in every])) for k in ("fp", "ids", "amotp"))
        wins = sum(a > b + 1e-9 for a, b in zip(per, base_per, strict=True))
        table[name] = {"values": candidates[name], "per_preset": dict(zip(presets, per, strict=True))}
        print(
            f"{name:22s} "
            + " ".join(f"{v:16.4f}" for v in per)
            + f" {np.mean(per):8.4f} {fp:6.1f} {ids:5.1f} {amotp:6.3f} {wins:3d}/{len(presets)}"
        )
    (out / "summary.json").write_text(json.dumps(table, indent=1))
    print(f"files: {out}")


if __name__ == "__main__":
    main()
