"""Trackers and parameter sets on one split of both worlds: the demo (simulated detector presets, several
seeds) and a second nuScenes-format dataset nobody here made (``--devset DIR``, its detection files
``detections/{preset}_{split}.json``), scored by the official evaluation.

A tracker is ``NAME`` or ``LABEL=NAME:FILE.toml[:FILE.toml...]`` (parameter files applied in turn on top of
the defaults). One line per world, preset and seed (AMOTA, IDS, FP, FN and each class's AMOTA), then per world
and tracker the mean over presets and seeds. Choose on ``mini_train``; ``mini_val`` is for reporting.
``--jsonl FILE`` appends every run's figures as JSON lines.

Usage: uv run python benchmarks/two_worlds.py --devset ../shared/devset [--split mini_train]
       [--tracker SPEC ...] [--preset NAME ...] [--seeds 0,1] [--worlds demo,dev] [--jsonl FILE] [--out DIR]
"""

from __future__ import annotations

import argparse
import json
import tempfile
from collections import defaultdict
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from demo_split import DemoSplit, score
from table1 import layered_config

from gnnpmb.config import TrackerConfig

PRESETS = ("centerpoint", "megvii", "pointpillars")
CLASS_SHORT = {
    "bicycle": "bic",
    "bus": "bus",
    "car": "car",
    "motorcycle": "mot",
    "pedestrian": "ped",
    "trailer": "tra",
    "truck": "tru",
}


@dataclass(frozen=True)
class TrackerSpec:
    """A label, a registered tracker name and its parameters."""

    label: str
    tracker: str
    config: TrackerConfig


def parse_tracker(text: str) -> TrackerSpec:
    label, sep, rest = text.partition("=")
    if not sep:
        label, rest = text, text
    name, *files = rest.split(":")
    return TrackerSpec(label, name, layered_config(files or ["default"]))


@dataclass(frozen=True)
class WorldRun:
    """Where one run's detections come from: a world, a preset and a seed (the dev set has one seed)."""

    world: str
    preset: str
    seed: int
    split: DemoSplit
    detections_file: Path | None


def world_runs(worlds: list[str], split: str, devset: Path | None, presets: list[str], seeds: list[int]):
    if "demo" in worlds:
        demo = DemoSplit.load(split)
        yield from (WorldRun("demo", p, s, demo, None) for p in presets for s in seeds)
    if "dev" in worlds:
        if devset is None:
            raise SystemExit("error: --worlds dev needs --devset DIR")
        dev = DemoSplit.load(split, devset, "v1.0-mini")
        for p in presets:
            yield WorldRun("dev", p, 0, dev, devset / "detections" / f"{p}_{split}.json")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--devset", type=Path)
    parser.add_argument("--split", default="mini_train")
    parser.add_argument("--tracker", action="append", help="NAME or LABEL=NAME:FILE.toml[:FILE.toml...]")
    parser.add_argument("--preset", action="append", choices=PRESETS)
    parser.add_argument("--seeds", default="0,1", help="demo detector seeds, comma-separated")
    parser.add_argument("--worlds", default="demo,dev")
    parser.add_argument("--jsonl", type=Path)
    parser.add_argument("--out", type=Path)
    args = parser.parse_args()
    if args.split == "mini_val":
        print("note: mini_val is for reporting; never choose parameters on it")
    out = args.out or Path(tempfile.mkdtemp(prefix="gnnpmb-two-worlds-"))
    specs = [parse_tracker(t) for t in args.tracker or ["gnnpmb"]]
    seeds = [int(s) for s in args.seeds.split(",")]
    runs = world_runs(args.worlds.split(","), args.split, args.devset, args.preset or list(PRESETS), seeds)
    means: dict[tuple[str, str], list[dict[str, float]]] = defaultdict(list)
    for run in runs:
        detections = run.split.detections(run.preset, run.seed, run.detections_file)
        for spec in specs:
            name = f"{run.world}_{run.preset}_s{run.seed}_{spec.label}".replace("/", "_")
            result = score(run.split, detections, spec.tracker, spec.config, out / name)
            overall = result.scores.overall
            row = {k: float(overall[k]) for k in ("amota", "ids", "fp", "fn")}
            row |= {c: float(v["amota"]) for c, v in result.scores.per_class.items()}
            row["ms"] = float(np.median(result.step_ms))
            means[(run.world, spec.label)].append(row)
            classes = " ".join(f"{CLASS_SHORT[c]} {result.scores.per_class[c]['amota']:.3f}" for c in CLASS_SHORT)
            print(
                f"{run.world:4s} {args.split} {run.preset:12s} s{run.seed} {spec.label:14s} AMOTA {row['amota']:.4f}"
                f" IDS {row['ids']:3.0f} FP {row['fp']:4.0f} FN {row['fn']:4.0f} | {classes}",
                flush=True,
            )
            if args.jsonl:
                record = {"world": run.world, "split": args.split, "preset": run.preset, "seed": run.seed}
                with args.jsonl.open("a") as f:
                    f.write(json.dumps(record | {"tracker": spec.label} | row) + "\n")
    print(f"mean over presets and seeds, {args.split}")
    for (world, label), rows in means.items():
        mean = {k: float(np.mean([r[k] for r in rows])) for k in rows[0]}
        print(
            f"{world:4s} {label:14s} AMOTA {mean['amota']:.4f} IDS {mean['ids']:5.1f} FP {mean['fp']:6.1f}"
            f" FN {mean['fn']:6.1f} ms {mean['ms']:.2f} | "
            + " ".join(f"{CLASS_SHORT[c]} {mean[c]:.3f}" for c in CLASS_SHORT)
        )
    print(f"files: {out}")


if __name__ == "__main__":
    main()
