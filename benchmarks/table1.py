"""Every tracker x simulated detector preset on the demo ``mini_val`` scenes with parameters chosen on
``mini_train`` only, scored by the official nuScenes tracking evaluation, as mean ± std over detector seeds
(the layout of the GNN-PMB paper's Table I: AMOTA, AMOTP, recall, MT, ML, FP, FN, IDS, FRAG), plus the median
per-frame tracker time.

The parameters come from ``--params`` (default ``gnnpmb/params/tuned_mini_train.toml``, written by
``benchmarks/tune_mini_train.py`` from mini_train alone); ``--params default`` uses the built-in defaults.
Every tracker reads the same file (the shared sections apply to all of them).

Usage: uv run python benchmarks/table1.py [--tracker NAME ...] [--preset NAME ...] [--seeds 0,1,2]
       [--params FILE|default] [--split mini_val] [--out DIR]
"""

from __future__ import annotations

import argparse
import tempfile
from pathlib import Path

import numpy as np
from demo_split import DemoSplit, score

from gnnpmb.config import TrackerConfig, load_config
from gnnpmb.data.simdet import PRESETS
from gnnpmb.registry import TRACKER_NAMES

TUNED = Path(__file__).resolve().parents[1] / "gnnpmb" / "params" / "tuned_mini_train.toml"
WITH_STD = ("amota", "amotp", "ids")
COLUMNS = ("amota", "amotp", "recall", "mt", "ml", "fp", "fn", "ids", "frag")


def cell(metric: str, values: list[float]) -> str:
    mean, std = float(np.mean(values)), float(np.std(values))
    if metric in ("amota", "amotp"):
        return f"{mean:.3f}±{std:.3f}"
    if metric == "recall":
        return f"{mean:.3f}"
    if metric in WITH_STD:
        return f"{mean:.1f}±{std:.1f}"
    return f"{mean:.1f}"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--tracker", action="append", choices=TRACKER_NAMES)
    parser.add_argument("--preset", action="append", choices=sorted(PRESETS))
    parser.add_argument("--seeds", default="0,1,2", help="comma-separated detector seeds")
    parser.add_argument("--params", default=str(TUNED), help="parameter TOML, or 'default'")
    parser.add_argument("--split", default="mini_val")
    parser.add_argument("--out", type=Path, help="keep submissions and metric files here")
    args = parser.parse_args()
    out = args.out or Path(tempfile.mkdtemp(prefix="gnnpmb-table1-"))
    config = TrackerConfig() if args.params == "default" else load_config(Path(args.params))
    seeds = [int(s) for s in args.seeds.split(",")]
    split = DemoSplit.load(args.split)
    print(f"split {args.split}, params {args.params}, detector seeds {seeds}")
    widths = {c: 12 if c in ("amota", "amotp") else 10 if c in WITH_STD else 6 for c in COLUMNS}
    header = f"{'preset':13s} {'tracker':8s} " + " ".join(f"{c.upper():>{widths[c]}s}" for c in COLUMNS)
    print(header + f" {'med ms':>7s}", flush=True)
    for preset in args.preset or ("centerpoint", "megvii", "pointpillars"):
        detections = {seed: split.detections(preset, seed) for seed in seeds}
        for tracker in args.tracker or TRACKER_NAMES:
            runs = [
                score(split, detections[seed], tracker, config, out / f"{preset}_{tracker}_s{seed}") for seed in seeds
            ]
            cells = [f"{cell(c, [r.scores.overall[c] for r in runs]):>{widths[c]}s}" for c in COLUMNS]
            ms = float(np.median(np.concatenate([r.step_ms for r in runs])))
            print(f"{preset:13s} {tracker:8s} " + " ".join(cells) + f" {ms:7.2f}", flush=True)
    print(f"submissions and metric files: {out}")


if __name__ == "__main__":
    main()
