"""Every tracker x simulated detector preset on the demo ``mini_val`` scenes with parameters chosen on
``mini_train`` only, scored by the official nuScenes tracking evaluation, as mean ± std over detector seeds
(the layout of the GNN-PMB paper's Table I: AMOTA, AMOTP, recall, MT, ML, FP, FN, IDS, FRAG), plus the median
per-frame tracker time.

The parameters come from ``--params`` (repeatable, each file on top of the ones before; default
``gnnpmb/params/tuned_mini_train.toml``, written by ``benchmarks/tune_mini_train.py`` from mini_train alone, then
``gnnpmb/params/box_noise_mini_train.toml``, written by ``benchmarks/learn_box_noise.py`` from mini_train alone and
read by ``prob3dmot`` only); ``--params default`` uses the built-in defaults. Every tracker reads the same
parameters (the shared sections apply to all of them).

Under each row, each class's AMOTA (mean ± std over the seeds; ``--no-per-class`` leaves them out). The PMB
trackers (gnnpmb, pmbm, topmb) also get a row with the paper's configuration (``gnnpmb/params/paper.toml`` on top
of the same files; ``--no-paper`` leaves it out). ``--external NAME=PATTERN`` adds a row for another tracker's
submissions, one file per preset and seed (``{split}``, ``{preset}`` and ``{seed}`` in PATTERN are filled in),
e.g. Poly-MOT run outside this project on the same simulated detections; its per-frame time is read from
``<file>_time.json`` (``track_cpu_ms``) when there is one.

``--devset DIR`` puts a second world beside the demo: a nuScenes-format dataset nobody here made (e.g.
``../shared/devset``) with its own detection files ``DIR/detections/{preset}_{split}.json``, one run per preset,
printed after the demo's figures on the same row (``| dev`` and its AMOTA, IDS, FP, FN; per class too), so no
lead is read off the demo alone. ``--external`` patterns may use ``{world}`` (demo or dev) for the dev set's files.

Usage: uv run python benchmarks/table1.py [--tracker NAME ...] [--preset NAME ...] [--seeds 0,1,2]
       [--params FILE|default ...] [--split mini_val] [--no-per-class] [--no-paper] [--external NAME=PATTERN ...]
       [--devset DIR] [--out DIR]
"""

from __future__ import annotations

import argparse
import json
import tempfile
import tomllib
from pathlib import Path

import numpy as np
from demo_split import DemoSplit, RunScores, score

from gnnpmb.config import TrackerConfig, config_from_dict
from gnnpmb.data.simdet import PRESETS
from gnnpmb.eval.nuscenes_eval import evaluate_submission
from gnnpmb.registry import TRACKER_NAMES

PARAMS = Path(__file__).resolve().parents[1] / "gnnpmb" / "params"
TUNED = PARAMS / "tuned_mini_train.toml"
PAPER = PARAMS / "paper.toml"
PMB_TRACKERS = ("gnnpmb", "pmbm", "topmb")
BOX_NOISE = PARAMS / "box_noise_mini_train.toml"
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


def layered_config(files: list[str]) -> TrackerConfig:
    """The defaults with each parameter file applied in turn (``default`` alone: the defaults)."""
    config = TrackerConfig()
    for f in files:
        if f != "default":
            config = config_from_dict(tomllib.loads(Path(f).read_text()), config)
    return config


def external_runs(split: DemoSplit, pattern: str, preset: str, seeds: list[int], out: Path) -> list[RunScores]:
    """Score another tracker's submission files (``--external``) like the trackers' own runs."""
    runs = []
    for seed in seeds:
        path = Path(pattern.format(split=split.split, preset=preset, seed=seed))
        scores = evaluate_submission(path, split.location, split.split, out / f"{path.stem}_eval")
        timing = path.with_name(path.stem + "_time.json")
        ms = json.loads(timing.read_text())["track_cpu_ms"] if timing.exists() else [float("nan")]
        runs.append(RunScores(scores, np.asarray(ms, dtype=float)))
    return runs


def print_row(
    preset: str,
    label: str,
    runs: list[RunScores],
    widths: dict[str, int],
    per_class: bool,
    dev: RunScores | None = None,
) -> None:
    cells = [f"{cell(c, [r.scores.overall[c] for r in runs]):>{widths[c]}s}" for c in COLUMNS]
    ms = float(np.median(np.concatenate([r.step_ms for r in runs])))
    tail = ""
    if dev is not None:
        o = dev.scores.overall
        tail = f" | dev {o['amota']:.3f} IDS {o['ids']:3.0f} FP {o['fp']:4.0f} FN {o['fn']:4.0f}"
    print(f"{preset:13s} {label:16s} " + " ".join(cells) + f" {ms:7.2f}" + tail, flush=True)
    if per_class:
        classes = sorted(runs[0].scores.per_class)
        values = [[r.scores.per_class[c]["amota"] for r in runs] for c in classes]
        print(f"{'':13s} {'':16s} " + " ".join(f"{c} {cell('amota', v)}" for c, v in zip(classes, values, strict=True)))
        if dev is not None:
            print(f"{'':13s} {'(dev)':16s} " + " ".join(f"{c} {dev.scores.per_class[c]['amota']:.3f}" for c in classes))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--tracker", action="append", choices=TRACKER_NAMES)
    parser.add_argument("--preset", action="append", choices=sorted(PRESETS))
    parser.add_argument("--seeds", default="0,1,2", help="comma-separated detector seeds")
    parser.add_argument("--params", action="append", help="parameter TOML (repeatable, later on top), or 'default'")
    parser.add_argument("--split", default="mini_val")
    parser.add_argument("--no-per-class", dest="per_class", action="store_false", help="overall rows only")
    parser.add_argument("--no-paper", dest="paper", action="store_false", help="no paper-configuration rows")
    parser.add_argument("--external", action="append", default=[], help="NAME=PATTERN of submission files")
    parser.add_argument("--devset", type=Path, help="a second nuScenes-format world, scored beside the demo")
    parser.add_argument("--out", type=Path, help="keep submissions and metric files here")
    args = parser.parse_args()
    out = args.out or Path(tempfile.mkdtemp(prefix="gnnpmb-table1-"))
    params = args.params or [str(TUNED), str(BOX_NOISE)]
    config = layered_config(params)
    paper = layered_config([*params, str(PAPER)])
    seeds = [int(s) for s in args.seeds.split(",")]
    split = DemoSplit.load(args.split)
    dev = DemoSplit.load(args.split, args.devset, "v1.0-mini") if args.devset else None
    print(f"split {args.split}, params {' + '.join(params)}, detector seeds {seeds}")
    widths = {c: 12 if c in ("amota", "amotp") else 10 if c in WITH_STD else 6 for c in COLUMNS}
    header = f"{'preset':13s} {'tracker':16s} " + " ".join(f"{c.upper():>{widths[c]}s}" for c in COLUMNS)
    print(header + f" {'med ms':>7s}" + (f" | dev ({args.devset}, one run per preset)" if dev else ""), flush=True)
    for preset in args.preset or ("centerpoint", "megvii", "pointpillars"):
        detections = {seed: split.detections(preset, seed) for seed in seeds}
        dev_file = args.devset / "detections" / f"{preset}_{args.split}.json" if dev is not None else None
        dev_detections = dev.detections(preset, 0, dev_file) if dev is not None else None
        for tracker in args.tracker or TRACKER_NAMES:
            configs = [(tracker, config)]
            if args.paper and tracker in PMB_TRACKERS:
                configs.append((f"{tracker} (paper)", paper))
            for label, cfg in configs:
                name = label.replace(" (paper)", "_paper")
                runs = [
                    score(split, detections[seed], tracker, cfg, out / f"{preset}_{name}_s{seed}") for seed in seeds
                ]
                dev_run = None
                if dev is not None and dev_detections is not None:
                    dev_run = score(dev, dev_detections, tracker, cfg, out / f"dev_{preset}_{name}")
                print_row(preset, label, runs, widths, args.per_class, dev_run)
        for item in args.external:
            label, _, pattern = item.partition("=")
            runs = external_runs(split, pattern.replace("{world}", "demo"), preset, seeds, out)
            dev_run = None
            if dev is not None and "{world}" in pattern:
                dev_run = external_runs(dev, pattern.replace("{world}", "dev"), preset, [0], out / "dev")[0]
            print_row(preset, label, runs, widths, args.per_class, dev_run)
    print(f"submissions and metric files: {out}")


if __name__ == "__main__":
    main()
