"""The simulated detector presets scored as detectors: the devkit's ``DetectionEval`` (``detection_cvpr_2019``)
on the simulated detections of a demo split, per preset: mAP, NDS, mATE, mASE, mAOE, mAVE, mAAE and the
per-class AP and TP errors of the seven tracking classes, next to the published nuScenes-val figure where one
was verified.

Published figures (nuScenes val), only those checked against a source:
- MEGVII / CBGS (Zhu et al., "Class-balanced Grouping and Sampling for Point Cloud 3D Object Detection",
  arXiv:1908.09492, 2019): mAP 50.6, NDS 62.3 (val), as listed by paperswithcode for that paper.
CenterPoint (Yin et al., CVPR 2021) and PointPillars (Lang et al., CVPR 2019; nuScenes baseline in Caesar et
al., CVPR 2020) val figures are not filled in: they were not verified here.

Usage: uv run python benchmarks/detector_calibration.py [--split mini_val] [--seed 0] [--out DIR]
"""

from __future__ import annotations

import argparse
import json
import math
import tempfile
from pathlib import Path

from demo_split import DemoSplit

from gnnpmb.data.simdet import PRESETS, to_submission
from gnnpmb.eval.nuscenes_eval import quiet_devkit
from gnnpmb.types import TRACKING_CLASSES

PUBLISHED_VAL: dict[str, dict[str, float]] = {"megvii": {"mean_ap": 0.506, "nd_score": 0.623}}
"""Verified published nuScenes-val figures (module docstring)."""
SUMMARY = ("mean_ap", "nd_score")
TP_ERRORS = ("trans_err", "scale_err", "orient_err", "vel_err", "attr_err")


def evaluate(split: DemoSplit, preset: str, seed: int, out: Path) -> dict:
    """The devkit's metrics_summary of the simulated detections of ``preset`` on ``split``."""
    from nuscenes.eval.common.config import config_factory
    from nuscenes.eval.detection.evaluate import DetectionEval

    from gnnpmb.data.nuscenes import open_nuscenes

    detections: dict = {}
    for boxes in split.detections(preset, seed):
        detections.update(boxes)
    out.mkdir(parents=True, exist_ok=True)
    path = out / f"{preset}_detections.json"
    path.write_text(json.dumps(to_submission(detections)))
    with quiet_devkit():
        evaluation = DetectionEval(
            open_nuscenes(split.location),
            config=config_factory("detection_cvpr_2019"),
            result_path=str(path),
            eval_set=split.split,
            output_dir=str(out / preset),
            verbose=False,
        )
        return evaluation.main(plot_examples=0, render_curves=False)


def fmt(value: float) -> str:
    return "   n/a" if value is None or (isinstance(value, float) and math.isnan(value)) else f"{value:6.3f}"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--split", default="mini_val")
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--out", type=Path)
    args = parser.parse_args()
    out = args.out or Path(tempfile.mkdtemp(prefix="gnnpmb-detcal-"))
    split = DemoSplit.load(args.split)
    for preset in sorted(PRESETS):
        summary = evaluate(split, preset, args.seed, out)
        published = PUBLISHED_VAL.get(preset, {})
        print(f"\n{preset} (simulated on demo {args.split}, seed {args.seed}) vs published nuScenes val")
        for key in SUMMARY:
            print(f"  {key:10s} simulated {fmt(summary[key])}   published {fmt(published.get(key))}")
        errors = summary["tp_errors"]
        print("  " + "  ".join(f"{k} {fmt(errors[k])}" for k in TP_ERRORS))
        print(f"  {'class':11s} {'AP':>6s} " + " ".join(f"{k[:6]:>6s}" for k in TP_ERRORS))
        for name in TRACKING_CLASSES:
            ap = summary["mean_dist_aps"].get(name)
            tp = summary["label_tp_errors"].get(name, {})
            print(f"  {name:11s} {fmt(ap)} " + " ".join(fmt(tp.get(k)) for k in TP_ERRORS))
    print(f"\ndetection files and metrics: {out}")


if __name__ == "__main__":
    main()
