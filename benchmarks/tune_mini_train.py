"""Choose GNN-PMB parameters on the demo ``mini_train`` split only (never on ``mini_val``) by coordinate search,
and write them to ``gnnpmb/params/tuned_mini_train.toml``.

Objective: mean AMOTA over the three detector presets (detector seed 0) of the eight mini_train scenes, scored by
the official evaluation. Starting from the defaults, each parameter in ``GRID`` is set in turn to the value of its
list that scores best with the others fixed (one pass; ties keep the earlier value).

Usage: uv run python benchmarks/tune_mini_train.py [--tracker gnnpmb] [--out DIR] [--write FILE]
"""

from __future__ import annotations

import argparse
import tempfile
from pathlib import Path

import numpy as np
from demo_split import DemoSplit, score

from gnnpmb.config import TrackerConfig, get_param, with_params

PRESETS = ("centerpoint", "megvii", "pointpillars")
GRID: dict[str, tuple[float, ...]] = {
    "pmb.extraction_threshold": (0.01, 0.05, 0.2),
    "pmb.p_survive": (0.8, 0.9, 0.95),
    "pmb.birth_weight": (0.03, 0.1, 0.3),
    "pmb.gate_chi2": (20.0, 40.0),
    "preprocess.score_threshold": (0.0, 0.1),
}
DEFAULT_OUT = Path(__file__).resolve().parents[1] / "gnnpmb" / "params" / "tuned_mini_train.toml"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--tracker", default="gnnpmb")
    parser.add_argument("--out", type=Path, help="keep submissions and metric files here")
    parser.add_argument("--write", type=Path, default=DEFAULT_OUT, help="where to write the chosen parameters")
    args = parser.parse_args()
    out = args.out or Path(tempfile.mkdtemp(prefix="gnnpmb-tune-"))
    split = DemoSplit.load("mini_train")
    detections = {p: split.detections(p, seed=0) for p in PRESETS}
    cache: dict[tuple, float] = {}

    def objective(cfg: TrackerConfig) -> float:
        key = tuple(get_param(cfg, name) for name in GRID)
        if key not in cache:
            amota = [
                score(split, detections[p], args.tracker, cfg, out / f"{len(cache)}_{p}").scores.overall["amota"]
                for p in PRESETS
            ]
            cache[key] = float(np.mean(amota))
            print(f"{dict(zip(GRID, key, strict=True))}: mean AMOTA {cache[key]:.4f}", flush=True)
        return cache[key]

    best = TrackerConfig()
    best_score = objective(best)
    for name, values in GRID.items():
        for value in values:
            candidate = with_params(best, {name: value})
            if objective(candidate) > best_score:
                best, best_score = candidate, objective(candidate)
    chosen = {name: get_param(best, name) for name in GRID}
    print(f"chosen on mini_train: {chosen}, mean AMOTA {best_score:.4f}")
    header = (
        f"# Chosen on the demo mini_train split only by benchmarks/tune_mini_train.py ({args.tracker}, mean AMOTA "
        f"{best_score:.4f} over {', '.join(PRESETS)}, detector seed 0). Never tuned on mini_val.\n"
    )
    changed = {k: v for k, v in chosen.items() if get_param(TrackerConfig(), k) != v}
    sections: dict[str, list[str]] = {}
    for k, v in changed.items():
        section, key = k.split(".")
        sections.setdefault(section, []).append(f"{key} = {v!r}")
    body = "".join(f"\n[{section}]\n" + "\n".join(lines) + "\n" for section, lines in sections.items())
    args.write.parent.mkdir(parents=True, exist_ok=True)
    args.write.write_text(header + body)
    print(f"-> {args.write}")


if __name__ == "__main__":
    main()
