"""Learn the per-class box Kalman noise of Probabilistic 3D MOT (``prob3dmot``) on the demo ``mini_train`` split
only (never on ``mini_val``) and write it to ``gnnpmb/params/box_noise_mini_train.toml`` (``gnnpmb.box.noise``).

The annotations of the split give the process noise; the detections of every simulated detector preset
(detector seed 0), pooled, give the measurement noise and the initial velocity variance, since one parameter
file serves all presets (``benchmarks/table1.py``). Classes without enough samples keep Probabilistic 3D MOT's
published nuScenes statistics.

Usage: uv run python benchmarks/learn_box_noise.py [--split mini_train] [--write FILE]
"""

from __future__ import annotations

import argparse
from pathlib import Path

from demo_split import DemoSplit

from gnnpmb.box.noise import collect_samples, noise_from_samples
from gnnpmb.config import NUSCENES_BOX_NOISE, TrackerConfig, dump_config
from gnnpmb.data.simdet import PRESETS
from gnnpmb.types import TRACKING_CLASSES

DEFAULT_OUT = Path(__file__).resolve().parents[1] / "gnnpmb" / "params" / "box_noise_mini_train.toml"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--split", default="mini_train")
    parser.add_argument("--write", type=Path, default=DEFAULT_OUT, help="where to write the [box_noise] tables")
    args = parser.parse_args()
    split = DemoSplit.load(args.split)
    presets = sorted(PRESETS)
    scenes = [scene for _ in presets for scene in split.scenes]
    detections = [d for preset in presets for d in split.detections(preset, seed=0)]
    samples = collect_samples(scenes, detections, TRACKING_CLASSES)
    noise = {c: noise_from_samples(samples[c], NUSCENES_BOX_NOISE[c]) for c in TRACKING_CLASSES}
    text = dump_config(TrackerConfig(box_noise=noise))
    tables = text[text.index("[box_noise.") :]
    counts = ", ".join(
        f"{c} {len(samples[c].residual)}/{len(samples[c].d2p)}/{len(samples[c].error_velocity)}"
        for c in TRACKING_CLASSES
    )
    header = (
        f"# Per-class box Kalman noise (prob3dmot) learned on the demo {args.split} split only by\n"
        f"# benchmarks/learn_box_noise.py: annotations for Q, the detections of the {', '.join(presets)}\n"
        f"# presets (seed 0) pooled for R and the initial velocity variance. Samples per class (detection\n"
        f"# residuals / annotation second differences / error velocities): {counts}.\n# Never tuned on mini_val.\n\n"
    )
    args.write.parent.mkdir(parents=True, exist_ok=True)
    args.write.write_text(header + tables)
    for c in TRACKING_CLASSES:
        n = noise[c]
        print(f"{c:11s} r_xy {n.r_x:.3f} {n.r_y:.3f} r_yaw {n.r_yaw:.3f} q_xy {n.q_x:.4f} {n.q_y:.4f} p_v {n.p_vx:.3f}")
    print(f"-> {args.write}")


if __name__ == "__main__":
    main()
