"""``gnnpmb calibrate``: learn the trackers' per-class model parameters from an annotated split and a detector's
boxes on it, into one parameter file (``gnnpmb.calibration``)."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from cli.options import DatarootOption, DetectionsOption, DetectorOption, SeedOption, SplitOption, VersionOption
from gnnpmb.outputs import check_output_file

CALIBRATE_HELP = (
    "Learn, per class, the parameters the trackers' models state from a split with annotations and a detector's "
    "boxes on it: position, velocity, heading and size noise with the outlier share, detection probability, "
    "clutter intensity, birth weight and the score threshold. Writes one parameter file every tracker reads "
    "(--params FILE.toml), with a comment per value saying what it was learnt from. Example: gnnpmb calibrate "
    "--split mini_train --detections dets_mini_train.json --out params.toml."
)


def register(app: typer.Typer) -> None:
    """Add ``calibrate`` to the ``gnnpmb`` app."""
    app.command("calibrate", help=CALIBRATE_HELP, short_help="Learn per-class parameters from annotations.")(calibrate)


def calibrate(
    out: Annotated[Path, typer.Option(metavar="FILE.toml", help="Where to write the parameter file (.toml).")],
    split: SplitOption = None,
    dataroot: DatarootOption = None,
    version: VersionOption = None,
    detections: DetectionsOption = None,
    detector: DetectorOption = None,
    seed: SeedOption = 0,
) -> None:
    from gnnpmb.atomic import write_text
    from gnnpmb.calibration import calibrate as learn
    from gnnpmb.calibration import calibration_toml
    from gnnpmb.config import TrackerConfig
    from gnnpmb.data.detections import check_detection_file
    from gnnpmb.data.nuscenes import load_scene, split_scenes
    from gnnpmb.data.simdet_presets import detector_choice
    from gnnpmb.eval.nuscenes_eval import resolve_split, tracking_config
    from gnnpmb.pipeline import get_detections

    target = check_output_file(out, "--out", ".toml", inputs=(("--detections", detections),))
    preset = detector_choice(detections, detector, "centerpoint")
    if detections is not None:
        check_detection_file(detections)
    location, split = resolve_split(dataroot, version, split)
    scenes = [load_scene(location, name) for name in split_scenes(split, location)]
    dets = [get_detections(scene, detections, preset, seed) for scene in scenes]
    cfg = tracking_config()
    learnt, notes, with_noise = learn(scenes, dets, TrackerConfig(), cfg.class_range, cfg.dist_th_tp)
    source = f"detections {detections}" if detections is not None else f"simulated detector {preset}, seed {seed}"
    header = (
        f"Learnt by 'gnnpmb calibrate' from split {split} of {location.dataroot} ({location.version}, "
        f"{len(scenes)} scenes) and the {source}.\n"
        f"Matching: the evaluation's {cfg.dist_th_tp:g} m centre distance, class ranges and point filter "
        "(gnnpmb/calibration.py says how each value is learnt).\n"
        "Use with --params FILE.toml; every tracker reads the keys of its own models."
    )
    write_text(target, calibration_toml(learnt, notes, with_noise, header))
    n = sum(len(v) for v in learnt.values())
    typer.echo(f"calibrate: {n} per-class values from {len(scenes)} scenes of {split} -> {out}")
