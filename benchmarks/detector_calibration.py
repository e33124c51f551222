"""The simulated detector presets scored as detectors, next to the published figures of the real detectors.

The devkit's ``DetectionEval`` (``detection_cvpr_2019``) runs on the simulated detections of a demo split (default
``mini_val``), per preset. The devkit averages over its 10 detection classes; the demo has only the 7 tracking
classes, so the 3 absent classes count AP 0 and TP errors 1 in its mAP / NDS / mTP. This script therefore also
prints the figures over the 7 tracking classes (mAP7, mTP7, NDS7 = (5 mAP7 + sum(1 - min(1, mTP7))) / 10), which
are what is compared with (and fitted to) the published figures.

Published nuScenes **val** figures, each row with its source (fractions, not percent). No per-class val figures
(per-class AP or TP errors) of these three detectors were found in the sources searched (the CenterPoint and
mmdetection3d model-zoo READMEs, OpenPCDet's README, the CBGS paper's listing on paperswithcode); the per-class
columns print "n/a" for them and only the summary figures are fitted.

The ``--fit N`` mode (use it on ``--split mini_train`` only) runs N rounds of multiplicative updates of each
preset's knobs towards the first published row of that preset: recall (and, at the recall cap, the point count
needed for detection and the false-positive rates) for mAP7, position noise for mATE7, size noise for mASE7, yaw
noise and flip probability for mAOE7, velocity noise for mAVE7; it prints the fitted values to copy into
``gnnpmb/data/simdet_presets.py``.

Usage: uv run python benchmarks/detector_calibration.py [--split mini_val] [--seed 0] [--out DIR]
       uv run python benchmarks/detector_calibration.py --split mini_train --fit 4
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import math
import tempfile
from dataclasses import dataclass
from pathlib import Path

from demo_split import DemoSplit

from gnnpmb.data.simdet import PRESETS, DetectorPreset, to_submission
from gnnpmb.eval.nuscenes_eval import quiet_devkit
from gnnpmb.types import TRACKING_CLASSES

TP_ERRORS = ("trans_err", "scale_err", "orient_err", "vel_err", "attr_err")
SUMMARY = ("mean_ap", "nd_score", *TP_ERRORS)


@dataclass(frozen=True, slots=True)
class Published:
    """One published nuScenes detection result: summary figures (``SUMMARY`` keys) and where they come from."""

    preset: str
    model: str
    split: str
    figures: dict[str, float]
    source: str


PUBLISHED: tuple[Published, ...] = (
    Published(
        "centerpoint",
        "CenterPoint (voxel 0.075)",
        "val",
        {
            "mean_ap": 0.5922,
            "nd_score": 0.6648,
            "trans_err": 0.2880,
            "scale_err": 0.2543,
            "orient_err": 0.3727,
            "vel_err": 0.2155,
            "attr_err": 0.1824,
        },
        "open-mmlab/OpenPCDet README.md, 'NuScenes 3D Object Detection Baselines' table",
    ),
    Published(
        "centerpoint",
        "CenterPoint centerpoint_voxel_1440",
        "val",
        {"mean_ap": 0.585, "nd_score": 0.663},
        "tianweiy/CenterPoint configs/nusc/README.md, 'nuScenes 3D Detection / VoxelNet' table",
    ),
    Published(
        "megvii",
        "SECOND-MultiHead (CBGS)",
        "val",
        {
            "mean_ap": 0.5059,
            "nd_score": 0.6229,
            "trans_err": 0.3115,
            "scale_err": 0.2551,
            "orient_err": 0.2664,
            "vel_err": 0.2626,
            "attr_err": 0.2046,
        },
        "open-mmlab/OpenPCDet README.md, 'NuScenes 3D Object Detection Baselines' table",
    ),
    Published(
        "megvii",
        "MEGVII / CBGS (Zhu et al., arXiv:1908.09492)",
        "val",
        {"mean_ap": 0.506, "nd_score": 0.623},
        "paperswithcode listing of arXiv:1908.09492 ('mAP (val)', 'NDS (val)')",
    ),
    Published(
        "pointpillars",
        "PointPillar-MultiHead",
        "val",
        {
            "mean_ap": 0.4463,
            "nd_score": 0.5823,
            "trans_err": 0.3387,
            "scale_err": 0.2600,
            "orient_err": 0.3207,
            "vel_err": 0.2874,
            "attr_err": 0.2015,
        },
        "open-mmlab/OpenPCDet README.md, 'NuScenes 3D Object Detection Baselines' table",
    ),
    Published(
        "pointpillars",
        "PointPillars hv_pointpillars_fpn_sbn-all_4x8_2x_nus-3d",
        "val",
        {"mean_ap": 0.400, "nd_score": 0.533},
        "open-mmlab/mmdetection3d configs/pointpillars/README.md, nuScenes table",
    ),
    Published(
        "pointpillars",
        "PointPillars hv_pointpillars_secfpn_sbn-all_4x8_2x_nus-3d",
        "val",
        {"mean_ap": 0.3517, "nd_score": 0.497},
        "open-mmlab/mmdetection3d configs/pointpillars/README.md, nuScenes table",
    ),
)
"""Published nuScenes-val figures; the first row of each preset is the fitting target."""

RECALL_CAP = 0.995
FIT_KNOBS: dict[str, tuple[str, ...]] = {
    "trans_err": ("pos_noise_std_m", "pos_bias_std_m"),
    "scale_err": ("size_noise_rel",),
    "orient_err": ("yaw_noise_std_rad", "yaw_flip_prob"),
    "vel_err": ("vel_noise_std_mps",),
}
"""The preset knobs scaled to move each TP error."""
FP_KNOBS = ("fp_rate", "ghost_rate", "fp_high_score_frac")


def evaluate(split: DemoSplit, preset: DetectorPreset, seed: int, out: Path) -> dict:
    """The devkit's metrics_summary of the simulated detections of ``preset`` on ``split``."""
    from nuscenes.eval.common.config import config_factory
    from nuscenes.eval.detection.evaluate import DetectionEval

    from gnnpmb.data.nuscenes import open_nuscenes
    from gnnpmb.pipeline import get_detections

    detections: dict = {}
    for scene in split.scenes:
        detections.update(get_detections(scene, None, preset, seed))
    out.mkdir(parents=True, exist_ok=True)
    path = out / f"{preset.name}_detections.json"
    path.write_text(json.dumps(to_submission(detections)))
    with quiet_devkit():
        evaluation = DetectionEval(
            open_nuscenes(split.location),
            config=config_factory("detection_cvpr_2019"),
            result_path=str(path),
            eval_set=split.split,
            output_dir=str(out / preset.name),
            verbose=False,
        )
        return evaluation.main(plot_examples=0, render_curves=False)


def tracking_class_summary(summary: dict) -> dict[str, float]:
    """mAP, NDS and mean TP errors over the 7 tracking classes (module docstring)."""
    aps = [summary["mean_dist_aps"][c] for c in TRACKING_CLASSES]
    out = {"mean_ap": sum(aps) / len(aps)}
    for key in TP_ERRORS:
        values = [summary["label_tp_errors"][c][key] for c in TRACKING_CLASSES]
        values = [v for v in values if not math.isnan(v)]
        out[key] = sum(values) / len(values)
    out["nd_score"] = (5.0 * out["mean_ap"] + sum(1.0 - min(1.0, out[k]) for k in TP_ERRORS)) / 10.0
    return out


def fmt(value: float | None) -> str:
    return "   n/a" if value is None or (isinstance(value, float) and math.isnan(value)) else f"{value:6.3f}"


def report(preset: str, split: str, seed: int, summary: dict) -> None:
    """Simulated figures (devkit 10-class, 7-class) beside every published row of ``preset``, then per class."""
    print(f"\n{preset}: simulated on demo {split} (seed {seed}) vs published nuScenes figures")
    print(f"  {'':58s} " + " ".join(f"{k[:6]:>6s}" for k in SUMMARY))
    rows = [
        ("simulated, devkit (10 classes, 3 absent)", {k: summary[k] for k in ("mean_ap", "nd_score")}),
        ("simulated, 7 tracking classes", tracking_class_summary(summary)),
    ]
    rows[0][1].update(summary["tp_errors"])
    rows += [(f"published {p.split}: {p.model}", p.figures) for p in PUBLISHED if p.preset == preset]
    for label, figures in rows:
        print(f"  {label[:58]:58s} " + " ".join(fmt(figures.get(k)) for k in SUMMARY))
    print(
        f"  per class (published per-class val figures: n/a, not found)  {'AP':>6s} "
        + " ".join(f"{k[:6]:>6s}" for k in TP_ERRORS)
    )
    for name in TRACKING_CLASSES:
        tp = summary["label_tp_errors"].get(name, {})
        ap = summary["mean_dist_aps"].get(name)
        print(f"  {'simulated ' + name:58s} {fmt(ap)} " + " ".join(fmt(tp.get(k)) for k in TP_ERRORS))


def fit_step(preset: DetectorPreset, current: dict[str, float], target: dict[str, float]) -> DetectorPreset:
    """One multiplicative update of the knobs of ``preset`` towards ``target`` (module docstring)."""
    changes: dict[str, float] = {}
    for error, knobs in FIT_KNOBS.items():
        ratio = target[error] / max(current[error], 1e-6)
        for knob in knobs:
            changes[knob] = getattr(preset, knob) * ratio
    ap_ratio = target["mean_ap"] / max(current["mean_ap"], 1e-6)
    recall = preset.recall_near * ap_ratio
    changes["recall_near"] = min(recall, RECALL_CAP)
    if recall > RECALL_CAP:
        changes["pts_scale"] = preset.pts_scale / ap_ratio**2
        for knob in FP_KNOBS:
            changes[knob] = getattr(preset, knob) / ap_ratio
    return dataclasses.replace(preset, **changes)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--split", default="mini_val")
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--preset", action="append", choices=sorted(PRESETS))
    parser.add_argument("--fit", type=int, default=0, help="rounds of knob updates (fit on mini_train only)")
    parser.add_argument("--out", type=Path)
    args = parser.parse_args()
    out = args.out or Path(tempfile.mkdtemp(prefix="gnnpmb-detcal-"))
    split = DemoSplit.load(args.split)
    for name in args.preset or list(PRESETS):
        preset = PRESETS[name]
        target = next(p.figures for p in PUBLISHED if p.preset == name)
        for round_ in range(args.fit):
            current = tracking_class_summary(evaluate(split, preset, args.seed, out / f"fit{round_}"))
            print(f"{name} round {round_}: " + " ".join(f"{k} {current[k]:.3f}" for k in SUMMARY), flush=True)
            preset = fit_step(preset, current, target)
        if args.fit:
            knobs = ("recall_near", "pts_scale", *FP_KNOBS, *(k for ks in FIT_KNOBS.values() for k in ks))
            print(f"{name} fitted: " + ", ".join(f"{k}={getattr(preset, k):.4g}" for k in knobs), flush=True)
        report(name, args.split, args.seed, evaluate(split, preset, args.seed, out))
    print(f"\ndetection files and metrics: {out}")


if __name__ == "__main__":
    main()
