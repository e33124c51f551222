"""``gnnpmb calibrate``: learn the trackers' per-class model parameters from an annotated split and a detector's
boxes on it, into one parameter file (``gnnpmb.calibration``)."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Annotated

import typer

from cli.options import (
    AddressOption,
    DatarootOption,
    DetectionsOption,
    DetectorOption,
    ProgressOption,
    SeedOption,
    SplitOption,
    VerboseOption,
    VersionOption,
    stdout_console,
)
from cli.progress import progress_bar
from cli.study import WorkersOption
from gnnpmb.outputs import check_output_file

if TYPE_CHECKING:
    from rich.table import Table

    from gnnpmb.calibration_check import CheckResult

CALIBRATE_HELP = (
    "Learn, per class, the parameters the trackers' models state from a split with annotations and a detector's "
    "boxes on it: position, velocity, heading and size noise with the outlier share, detection probability, "
    "clutter intensity, birth weight and the score threshold. Writes one parameter file every tracker reads "
    "(--params FILE.toml), with a comment per value saying what it was learnt from. Then checks them: a k-fold "
    "cross-validation by scenes on the same split, scored with the official evaluation, keeps per class the "
    "defaults unless the learnt values (or the learnt values but one group) beat them (--no-check: write "
    "everything learnt). Example: gnnpmb calibrate --split mini_train --detections dets_mini_train.json "
    "--out params.toml."
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
    check: Annotated[
        bool,
        typer.Option(
            help="Check the learnt values by cross-validation on the split and keep, per class, only what beats the "
            "defaults (gnnpmb/calibration_check.py)."
        ),
    ] = True,
    folds: Annotated[int, typer.Option(metavar="K", help="Folds of the check (scenes per fold: the split's / K).")] = 2,
    workers: WorkersOption = None,
    address: AddressOption = None,
    progress: ProgressOption = True,
    verbose: VerboseOption = False,
) -> None:
    from gnnpmb.atomic import write_text
    from gnnpmb.calibration import calibrate as learn
    from gnnpmb.calibration import calibration_toml
    from gnnpmb.calibration_check import (
        CHECK_TRACKER,
        MARGIN_AMOTA,
        candidate_values,
        check_jobs,
        cross_validate,
        unchecked_note,
    )
    from gnnpmb.config import TrackerConfig
    from gnnpmb.data.detections import check_detection_file
    from gnnpmb.data.nuscenes import load_scene, split_scenes
    from gnnpmb.data.simdet_presets import detector_choice
    from gnnpmb.errors import GnnpmbError
    from gnnpmb.eval.nuscenes_eval import resolve_split, tracking_config
    from gnnpmb.pipeline import get_detections
    from gnnpmb.study.data import StudyData
    from gnnpmb.study.runner import execution, session
    from gnnpmb.types import TRACKING_CLASSES

    target = check_output_file(out, "--out", ".toml", inputs=(("--detections", detections),))
    preset = detector_choice(detections, detector, "centerpoint")
    if detections is not None:
        check_detection_file(detections)
    location, split = resolve_split(dataroot, version, split)
    names = split_scenes(split, location)
    if check and not 2 <= folds <= len(names):
        most = "2" if len(names) == 2 else f"2 to {len(names)}"
        raise GnnpmbError(
            f"--folds {folds}: the check cuts the {len(names)} scenes of split {split} into {most} folds "
            "(or use --no-check to write the learnt values unchecked)"
            if len(names) >= 2
            else f"split {split} has {len(names)} scene{'' if len(names) == 1 else 's'}: the check needs 2 or more "
            "(use --no-check to write the learnt values unchecked)"
        )
    run = execution(workers, address, verbose) if check else None
    scenes = [load_scene(location, name) for name in names]
    dets = [get_detections(scene, detections, preset, seed) for scene in scenes]
    cfg = tracking_config()
    base = TrackerConfig()
    learnt, notes, with_noise = learn(scenes, dets, base, cfg.class_range, cfg.dist_th_tp)
    source = f"detections {detections}" if detections is not None else f"simulated detector {preset}, seed {seed}"
    header = (
        f"Learnt by 'gnnpmb calibrate' from split {split} of {location.dataroot} ({location.version}, "
        f"{len(scenes)} scenes) and the {source}.\n"
        f"Matching: the evaluation's {cfg.dist_th_tp:g} m centre distance, class ranges and point filter "
        "(gnnpmb/calibration.py says how each value is learnt).\n"
        "Use with --params FILE.toml; every tracker reads the keys of its own models."
    )
    withheld: dict[str, list] = {}
    if run is not None:
        data = StudyData(
            location=location,
            split=split,
            scene_names=tuple(names),
            sample_tokens=(),
            detections=None if detections is None else detections.resolve(),
            detector=preset,
            seed=seed,
        )
        with session(run), progress_bar(progress, transient=True) as bar:
            task = bar.add_task(f"checking on {folds} folds", total=check_jobs(folds))
            result = cross_validate(
                scenes, dets, data, base, cfg.class_range, cfg.dist_th_tp, folds, run, lambda: bar.advance(task)
            )
        stdout_console().print(check_table(result))
        for c in TRACKING_CLASSES:
            kept = candidate_values(result.chosen[c], learnt[c])
            withheld[c] = [v for v in learnt[c] if v not in kept]
            learnt[c] = kept
            unchecked = unchecked_note(kept)
            check = [f"check of {CHECK_TRACKER}'s values: {result.reason(c)}", *([unchecked] if unchecked else [])]
            notes[c] = [*check, *notes[c]]
        header += (
            f"\nChecked by a {folds}-fold cross-validation by scenes on the same split with {CHECK_TRACKER}, scored "
            f"with the official evaluation: per class, the defaults unless a candidate beat them by {MARGIN_AMOTA:g} "
            "AMOTA (gnnpmb/calibration_check.py). Values the check left out are comment lines."
        )
    write_text(target, calibration_toml(learnt, notes, with_noise, header, withheld))
    n = sum(len(v) for v in learnt.values())
    left_out = sum(len(v) for v in withheld.values())
    checked = f", {left_out} left out by the check" if run is not None else ""
    typer.echo(f"calibrate: {n} per-class values from {len(scenes)} scenes of {split}{checked} -> {out}")


def check_table(result: CheckResult) -> Table:
    """The check as a table: per class, each candidate's mean AMOTA over the folds, and the choice."""
    from rich.table import Table

    from gnnpmb.calibration_check import candidates
    from gnnpmb.types import TRACKING_CLASSES

    table = Table(title=f"calibrate's check: AMOTA per class, mean of {len(result.folds)} folds (official)")
    table.add_column("class")
    for name in candidates():
        table.add_column(name, justify="right")
    table.add_column("written")
    for c in TRACKING_CLASSES:
        cells = ["-" if result.amota[name][c] is None else f"{result.amota[name][c]:.3f}" for name in candidates()]
        table.add_row(c, *cells, result.chosen[c])
    return table
