"""``gnnpmb``: batch tracking into a nuScenes submission, the official evaluation, and the failure finder.

Commands: ``track`` (every scene of a split -> tracking submission .json), ``eval`` (the devkit's TrackingEval
on a submission, with our own table), ``failures`` (one scene: which frames and ids the metrics blame) and
``demo-data`` (write the synthetic demo dataset). User mistakes end with one line on stderr and exit code 2.
"""

from __future__ import annotations

import time
from pathlib import Path
from typing import Annotated

import typer

from cli.calibrate import register as register_calibrate
from cli.diff import register as register_diff
from cli.errors import entry_point
from cli.failures import register as register_failures
from cli.options import (
    DEFAULT_SOURCE,
    AddressOption,
    DatarootOption,
    ProgressOption,
    Source,
    SplitOption,
    TrackerOption,
    VerboseOption,
    VersionOption,
    source_options,
    stdout_console,
    tidy_help,
)
from cli.study import register
from cli.tune import register as register_tune
from gnnpmb.outputs import check_output_dir, check_output_file
from gnnpmb.stages.request import DEFAULT_DETECTOR, DEFAULT_TRACKER

__all__ = ["app", "main"]

app = typer.Typer(
    add_completion=False,
    rich_markup_mode=None,
    pretty_exceptions_enable=False,
    help="Batch tracking on nuScenes splits, the official tracking evaluation, and the failure finder.",
)

tidy_help()


@app.command(short_help="Track a split into a nuScenes tracking submission.")
@source_options
def track(
    out: Annotated[Path, typer.Option(metavar="FILE.json", help="Where to write the tracking submission (.json).")],
    source: Source = DEFAULT_SOURCE,
    split: SplitOption = None,
    tracker: TrackerOption = DEFAULT_TRACKER,
    progress: ProgressOption = True,
    workers: Annotated[
        int, typer.Option(metavar="N", help="Scenes tracked in parallel on Ray; 1 (default) runs in this process.")
    ] = 1,
    address: AddressOption = None,
    verbose: VerboseOption = False,
) -> None:
    """Track every scene of a split (all 7 classes) and write a nuScenes tracking submission."""
    from gnnpmb.data.simdet_presets import detector_choice
    from gnnpmb.registry import check_tracker

    target = check_output_file(out, "--out", inputs=source.input_files)
    check_tracker(tracker)
    preset = detector_choice(source.detections, source.detector, DEFAULT_DETECTOR)

    from cli.progress import progress_bar
    from gnnpmb.config import load_config
    from gnnpmb.data.detections import check_detection_file
    from gnnpmb.stages.inputs import simulated_note
    from gnnpmb.study.runner import execution
    from gnnpmb.study.track import track_to_file

    config = load_config(source.params)
    run = execution(workers, address, verbose)
    if source.detections is not None:  # a bad file fails before a dataset is looked for
        check_detection_file(source.detections)
    data = source.split_data(split, preset)
    note = simulated_note(data.location, None if data.detections else data.detector, data.seed)
    if note:
        typer.echo(f"note: {note}", err=True)
    with progress_bar(progress, transient=True) as bar:
        scenes_task = bar.add_task("scenes", total=len(data.scene_names))
        frames_task = bar.add_task("frames", total=None, visible=not run.uses_ray)
        summary = track_to_file(
            data,
            tracker,
            config,
            target,
            run,
            on_scene=lambda _run: bar.advance(scenes_task),
            on_frame=lambda: bar.advance(frames_task),
        )
    if summary.boxes == 0:
        typer.echo(
            "note: no tracks were output; 'gnnpmb eval' cannot score an empty submission (check the detections "
            "and score_threshold)",
            err=True,
        )
    typer.echo(
        f"{tracker}: {summary.scenes} scenes of {data.split}, {summary.frames} frames, {summary.boxes} boxes, "
        f"{summary.ms_per_frame:.1f} ms/frame -> {out}"
    )


@app.command("eval", short_help="Score a submission with the official evaluation.")
def evaluate(
    results: Annotated[
        Path, typer.Argument(metavar="RESULTS.json", help="Tracking submission .json (e.g. from 'gnnpmb track').")
    ],
    dataroot: DatarootOption = None,
    version: VersionOption = None,
    split: SplitOption = None,
    out: Annotated[
        Path | None,
        typer.Option(
            metavar="DIR", help="Folder for the devkit's metrics files (default: <results>_eval/ next to the file)."
        ),
    ] = None,
) -> None:
    """Score a tracking submission with the official nuScenes evaluation (tracking_nips_2019)."""
    from rich.table import Table

    from gnnpmb.eval.nuscenes_eval import (
        DEVKIT_FILES,
        TABLE_METRICS,
        default_eval_dir,
        evaluate_submission,
        format_metric,
        resolve_split,
    )
    from gnnpmb.eval.submission import check_results_file

    check_results_file(results)
    out = check_output_dir(
        out if out is not None else default_eval_dir(results),
        "--out",
        files=DEVKIT_FILES,
        inputs=(("RESULTS.json", results),),
    )
    location, split = resolve_split(dataroot, version, split)
    start = time.perf_counter()
    scores = evaluate_submission(results, location, split, out)
    table = Table(title=f"{results.name} on {split} ({location.version})")
    table.add_column("class")
    for metric in TABLE_METRICS:
        table.add_column(metric.upper(), justify="right")
    for class_name, metrics in scores.per_class.items():
        table.add_row(class_name, *(format_metric(m, metrics[m]) for m in TABLE_METRICS))
    table.add_section()
    table.add_row("overall", *(format_metric(m, scores.overall[m]) for m in TABLE_METRICS), style="bold")
    console = stdout_console()
    console.print(table)
    console.print(
        f"AMOTA {scores.overall['amota']:.3f}; evaluated in {time.perf_counter() - start:.1f} s; "
        f"metrics in {scores.summary_path}",
        highlight=False,
        soft_wrap=True,
    )


register_failures(app)  # after eval in --help, as before


@app.command("demo-data", short_help="Write the synthetic demo dataset.")
def demo_data(
    out: Annotated[
        Path,
        typer.Option(metavar="DIR", help="Folder to write the demo dataroot into (new, empty or an old demo)."),
    ],
    seed: Annotated[int, typer.Option(metavar="N", min=0, help="Seed of the LiDAR noise (0 or more).")] = 0,
    scenes: Annotated[
        str,
        typer.Option(
            metavar="SCENES",
            help="Comma-separated scene names, or mini_val, staged, mini_train or all (default mini_val,staged).",
        ),
    ] = "mini_val,staged",
    sweeps: Annotated[
        bool, typer.Option(help="Also write the 9 LiDAR sweeps between keyframes (sweeps/LIDAR_TOP; ~10x slower).")
    ] = False,
    images: Annotated[
        bool,
        typer.Option(
            help="Render every camera image now (samples/CAM_*, ~5 s per scene), for tools other than gnnpmb-viz; "
            "without it each scene's images are rendered when first shown."
        ),
    ] = False,
) -> None:
    """Write the synthetic nuScenes-format demo dataset (v1.0-mini; the mini_val scenes scene-0103 and
    scene-0916 and the staged scene-9001 by default, the eight generated mini_train scenes on request)."""
    from gnnpmb.data.demo import DEMO_SCENES, generate_demo_dataset
    from gnnpmb.data.demo_staged import STAGED_SCENES
    from gnnpmb.data.demo_train import TRAIN_SCENES

    groups = {
        "mini_val": DEMO_SCENES,
        "staged": STAGED_SCENES,
        "mini_train": TRAIN_SCENES,
        "all": DEMO_SCENES + STAGED_SCENES + TRAIN_SCENES,
    }
    names = tuple(n for part in scenes.split(",") if part.strip() for n in groups.get(part.strip(), (part.strip(),)))
    path = generate_demo_dataset(check_output_dir(out, "--out"), seed=seed, scenes=names, sweeps=sweeps)
    if images:
        from gnnpmb.data.demo import ensure_scene_images

        for name in dict.fromkeys(names):
            ensure_scene_images(path, name)
    with_sweeps = ", with sweeps" if sweeps else ""
    typer.echo(f"demo dataset (v1.0-mini, seed {seed}, {len(set(names))} scenes{with_sweeps}) -> {path}")


register(app)
register_tune(app)
register_diff(app)
register_calibrate(app)
main = entry_point(app, "gnnpmb")
