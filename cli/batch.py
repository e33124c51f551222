"""``gnnpmb``: batch tracking into a nuScenes submission, the official evaluation, and the failure finder.

Commands: ``track`` (every scene of a split -> tracking submission .json), ``eval`` (the devkit's TrackingEval
on a submission, with our own table), ``failures`` (one scene: which frames and ids the metrics blame) and
``demo-data`` (write the synthetic demo dataset). User mistakes end with one line on stderr and exit code 2.
"""

from __future__ import annotations

import time
from collections import defaultdict
from pathlib import Path
from typing import TYPE_CHECKING, Annotated

import typer

from cli.diff import register as register_diff
from cli.errors import entry_point
from cli.options import (
    DEFAULT_DETECTOR,
    DEFAULT_TRACKER,
    AddressOption,
    DatarootOption,
    DetectionsOption,
    DetectorOption,
    ParamsOption,
    ResultsOption,
    RunsOption,
    SeedOption,
    SplitOption,
    TrackerOption,
    VersionOption,
    stdout_console,
    tidy_help,
)
from cli.study import VerboseOption, register
from gnnpmb.eval.nuscenes_eval import default_split
from gnnpmb.outputs import check_output_dir, check_output_file

if TYPE_CHECKING:  # rich, numpy and the devkit load only on the paths that use them (fast --help)
    from rich.console import Console

    from gnnpmb.eval.failures import FailureReport

__all__ = ["app", "default_split", "main"]

app = typer.Typer(
    add_completion=False,
    rich_markup_mode=None,
    pretty_exceptions_enable=False,
    help="Batch tracking on nuScenes splits, the official tracking evaluation, and the failure finder.",
)

tidy_help()


@app.command(short_help="Track a split into a nuScenes tracking submission.")
def track(
    out: Annotated[Path, typer.Option(metavar="FILE.json", help="Where to write the tracking submission (.json).")],
    dataroot: DatarootOption = None,
    version: VersionOption = None,
    split: SplitOption = None,
    detections: DetectionsOption = None,
    detector: DetectorOption = None,
    tracker: TrackerOption = DEFAULT_TRACKER,
    seed: SeedOption = 0,
    params: ParamsOption = None,
    progress: Annotated[bool, typer.Option(help="Show a progress bar on stderr.")] = True,
    workers: Annotated[
        int, typer.Option(metavar="N", help="Scenes tracked in parallel on Ray; 1 (default) runs in this process.")
    ] = 1,
    address: AddressOption = None,
    verbose: VerboseOption = False,
) -> None:
    """Track every scene of a split (all 7 classes) and write a nuScenes tracking submission."""
    from gnnpmb.data.simdet_presets import detector_choice
    from gnnpmb.registry import check_tracker

    target = check_output_file(out, "--out", inputs=(("--detections", detections), ("--params", params)))
    check_tracker(tracker)
    preset = detector_choice(detections, detector, DEFAULT_DETECTOR)

    from cli.progress import progress_bar
    from gnnpmb.config import load_config
    from gnnpmb.data.detections import check_detection_file
    from gnnpmb.data.nuscenes import resolve_dataroot
    from gnnpmb.study.data import resolve_study_data
    from gnnpmb.study.runner import execution
    from gnnpmb.study.track import track_to_file

    config = load_config(params)
    run = execution(workers, address, verbose)
    if detections is not None:  # a bad file fails before a dataset is looked for
        check_detection_file(detections)
    location = resolve_dataroot(dataroot, version, (split,) if split else ())
    data = resolve_study_data(location, split or default_split(location.version), detections, preset, seed)
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

    from gnnpmb.data.nuscenes import resolve_dataroot
    from gnnpmb.eval.nuscenes_eval import (
        DEVKIT_FILES,
        TABLE_METRICS,
        default_eval_dir,
        evaluate_submission,
        format_metric,
    )
    from gnnpmb.eval.submission import check_results_file

    check_results_file(results)
    out = check_output_dir(
        out if out is not None else default_eval_dir(results),
        "--out",
        files=DEVKIT_FILES,
        inputs=(("RESULTS.json", results),),
    )
    location = resolve_dataroot(dataroot, version, (split,) if split else ())
    split = split or default_split(location.version)
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


@app.command(short_help="List one scene's tracking failures per frame.")
def failures(
    scene: Annotated[str, typer.Argument(metavar="SCENE", help="Scene name, e.g. scene-0103.")],
    tracker: RunsOption = None,
    results: ResultsOption = None,
    dataroot: DatarootOption = None,
    version: VersionOption = None,
    detections: DetectionsOption = None,
    detector: DetectorOption = None,
    seed: SeedOption = 0,
    params: ParamsOption = None,
    json_out: Annotated[
        Path | None, typer.Option("--json", metavar="FILE.json", help="Also write the report as JSON here.")
    ] = None,
    why: Annotated[
        bool,
        typer.Option(
            "--why", help="Explain each failure: whose doing, why and because (with --json: the typed findings)."
        ),
    ] = False,
    frames: Annotated[
        str | None,
        typer.Option(
            metavar="START:END",
            help="Track and evaluate only keyframes START:END (END exclusive), as gnnpmb-viz --frames does; the "
            "ids are those gnnpmb-viz --frames START:END --focus takes.",
        ),
    ] = None,
) -> None:
    """Track one scene and list its failures per frame: ID switches, fragmentations, false tracks, misses,
    coalescence and cascading identity theft (scored with the devkit's own matching). With several runs (--tracker,
    --results) each is listed in turn; --why explains each failure beside the others."""
    from gnnpmb.data.simdet_presets import detector_choice
    from gnnpmb.runs import parse_runs, run_inputs
    from gnnpmb.session import parse_frames

    runs = parse_runs(tracker or [], results or [], default=DEFAULT_TRACKER)
    inputs = (("--detections", detections), ("--params", params), *run_inputs(runs))
    json_target = check_output_file(json_out, "--json", inputs=inputs) if json_out is not None else None
    bounds = parse_frames(frames)
    preset = detector_choice(detections, detector, DEFAULT_DETECTOR)
    foreign: dict = {}
    if len(runs) == 1 and runs[0].tracker is not None and runs[0].params is None:  # one built-in tracker
        reports, findings = _one_tracker(
            scene, runs[0].tracker, dataroot, version, detections, preset, seed, params, why, bounds
        )
    else:  # several runs, a results file or a tracker's own parameters (gnnpmb.session)
        from cli.failures import failure_reports

        reports, findings, request = failure_reports(
            scene,
            tracker or [],
            results or [],
            dataroot=dataroot,
            version=version,
            detections=detections,
            detector=detector,
            seed=seed,
            params=params,
            why=why,
            frames=frames,
        )
        foreign = {name: r.original_ids for name, r in request.foreign.items() if r.original_ids}
    if json_target is not None:
        from gnnpmb.eval.submission import write_json

        write_json(json_target, _report_json(reports, findings, foreign))
    console = stdout_console()
    for name, report in reports.items():
        print_report(report, console)
        if why:
            print_findings(findings[name], console)
    if json_out is not None:
        typer.echo(f"report -> {json_out}")


def _one_tracker(
    scene: str, tracker: str, dataroot, version, detections, preset: str, seed: int, params, why: bool, bounds
):
    """One built-in tracker's report (and findings, with ``why``) on ``scene``, keyed by its name; bounds: the
    ``--frames`` keyframes (``session.parse_frames``)."""
    from gnnpmb.config import load_config
    from gnnpmb.data.detections import check_detection_file
    from gnnpmb.data.nuscenes import resolve_dataroot
    from gnnpmb.registry import tracker_has_existence
    from gnnpmb.study.track import scene_failures
    from gnnpmb.why.facts import FactSink

    config = load_config(params)
    if detections is not None:
        check_detection_file(detections)
    location = resolve_dataroot(dataroot, version, (scene,))
    fact_sink = FactSink(tracker, has_existence=tracker_has_existence(tracker)) if why else None
    found = scene_failures(location, scene, tracker, config, detections, preset, seed, sink=fact_sink, bounds=bounds)
    report = found.report
    findings = []
    if fact_sink is not None:
        from gnnpmb.focus import FRAMES_BEFORE
        from gnnpmb.why.reason import Evidence, explain_failure

        evidence = Evidence(report, fact_sink.facts, found.run)
        findings = [
            explain_failure(
                fid, evidence, found.run.scene, first_frame=max(bounds[0] or 0, f.frame_index - FRAMES_BEFORE)
            )
            for fid, f in zip(report.ids(), report.failures, strict=True)
        ]
    return {tracker: report}, ({tracker: findings} if why else {})


def _report_json(reports: dict, findings: dict, track_names: dict) -> dict:
    """The first run's report (and findings), the other runs' under ``other_runs``; a results file's renumbered
    ids under ``track_names`` (``track_names``: run -> track id -> the file's id)."""
    from gnnpmb.why.serialize import finding_json

    def one(name: str) -> dict:
        data = reports[name].to_json()
        if name in findings:
            data["findings"] = [finding_json(f) for f in findings[name]]
        if name in track_names:
            data["track_names"] = {str(t): i for t, i in track_names[name].items()}
        return data

    first, *rest = reports
    data = one(first)
    if rest:
        data["other_runs"] = [one(name) for name in rest]
    return data


def print_findings(findings: list, console: Console) -> None:
    """Each failure's finding: its id and whose doing, then its Why and Because lines (``why.words``)."""
    from gnnpmb.why.words import plain, whose_text, why_lines

    for f in findings:
        console.print(f"{f.failure_id} (frame {f.frame}, {f.class_name}): {whose_text(f)}", highlight=False)
        for line in why_lines(f):
            if line:
                console.print(f"  {plain(line)}", highlight=False, soft_wrap=True)


def print_report(report: FailureReport, console: Console) -> None:
    """The failure report as two tables: per class at its best-MOTA threshold, then failures per frame."""
    from rich.table import Table

    from gnnpmb.eval.failures import FailureKind
    from gnnpmb.eval.nuscenes_eval import format_metric

    classes = Table(title=f"{report.tracker} on {report.scene_name}: devkit counts at the best-MOTA threshold")
    for name in ("class", "threshold", "MOTA", "TP", "FP", "FN", "IDS", "FRAG"):
        classes.add_column(name, justify="left" if name == "class" else "right")
    for c in report.classes:
        threshold = "all" if c.threshold is None else f"{c.threshold:.3f}"
        counts = (format_metric(m, getattr(c, m)) for m in ("tp", "fp", "fn", "ids", "frag"))
        classes.add_row(c.class_name, threshold, format_metric("mota", c.mota), *counts)
    console.print(classes)

    grouped: dict[tuple[int, FailureKind], list[tuple[str, str]]] = defaultdict(list)
    for failure_id, f in zip(report.ids(), report.failures, strict=True):
        grouped[(f.frame_index, f.kind)].append((failure_id, f.describe()))
    rows = Table(title="failures per frame (open one: gnnpmb-viz SCENE --tracker T --focus ID)")
    rows.add_column("frame", justify="right")
    rows.add_column("id")
    rows.add_column("what (GT ids shortened to 6 characters)")
    for (frame, _kind), entries in grouped.items():
        rows.add_row(str(frame), _id_span([i for i, _ in entries]), "; ".join(text for _, text in entries))
    console.print(rows)
    totals = f"{report.scene_name}, {report.tracker}{report.scope_text()}: {report.totals_text()}"
    console.print(totals, highlight=False, soft_wrap=True)


def _id_span(ids: list[str]) -> str:
    """``miss:3`` or ``miss:3-7`` for the ids of one kind in one frame (numbered consecutively)."""
    return ids[0] if len(ids) == 1 else f"{ids[0]}-{ids[-1].split(':')[1]}"


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
register_diff(app)
main = entry_point(app, "gnnpmb")
