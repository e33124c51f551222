"""``gnnpmb-viz``: track one nuScenes scene and watch every step of the tracker(s) in Rerun.

``gnnpmb-viz SCENE [--tracker A --tracker B ...]`` runs every tracker on the same preprocessed detections and
logs them into one recording: one 3D view per tracker side by side, the comparison of the trackers (where they
disagree, judged against the ground truth), each tracker's failures found with the devkit's matching, and the
provenance of the run (command line, versions, parameters, inputs and their hashes, digests of the tracks).
``gnnpmb-viz reproduce FILE.rrd`` reads that provenance back, re-runs the trackers on the same inputs and says
whether the tracks are identical. Typer cannot mix a positional SCENE with a subcommand, so ``main``
dispatches on the first argument being ``reproduce``.

Everything the user typed is checked before a recording is opened (names, --frames, files, the dataset), so a
mistake costs one line on stderr and leaves no ``.rrd`` behind. Without ``--save`` or ``--serve`` the run needs
a display for the spawned viewer; without one it stops at once with a hint instead of hanging.
"""

from __future__ import annotations

import contextvars
import functools
import os
import re
import sys
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Annotated

import typer

from cli.errors import check_version_flag, exit_now_on_failure, run_app
from cli.options import DatarootOption, DetectionsOption, ParamsOption, SeedOption, VersionOption, tidy_help
from cli.outputs import check_output_file
from cli.serve import DEFAULT_GRPC_PORT, DEFAULT_WEB_PORT, ServeTarget, check_display, check_serve_ports
from gnnpmb.classes import TRACKING_CLASSES
from gnnpmb.errors import DataError, GnnpmbError
from gnnpmb.registry import TRACKER_NAMES, check_classes, check_tracker

if TYPE_CHECKING:  # numpy, the devkit and rerun load only on the paths that use them (fast --help)
    from gnnpmb.compare import Comparison
    from gnnpmb.config import TrackerConfig
    from gnnpmb.data.nuscenes import DatasetLocation
    from gnnpmb.data.scene import SceneData
    from gnnpmb.eval.failures import FailureReport
    from gnnpmb.focus import FocusTarget
    from gnnpmb.pipeline import TrackingRun
    from gnnpmb.provenance import DetectionsSource, Provenance, TrackDigest
    from gnnpmb.types import Boxes, FrameDetections

PROG = "gnnpmb-viz"
DEFAULT_TRACKER = "gnnpmb"
DEFAULT_DETECTOR = "centerpoint"
EXIT_DIFFERENT = 1
_FRAMES_RE = re.compile(r"^\s*(\d*)\s*:\s*(\d*)\s*$")
_COMMAND_LINE: contextvars.ContextVar[tuple[str, ...] | None] = contextvars.ContextVar("command_line", default=None)
"""The command line ``main`` was given, recorded in the provenance (else ``sys.argv`` is used)."""

tidy_help()
app = typer.Typer(
    add_completion=False,
    rich_markup_mode=None,
    help="Track a nuScenes scene and inspect every step of the tracker(s) in the Rerun viewer.",
    pretty_exceptions_enable=False,
)
reproduce_app = typer.Typer(
    add_completion=False,
    rich_markup_mode=None,
    help="Re-run the trackers of a recording saved by gnnpmb-viz and check its tracks.",
    pretty_exceptions_enable=False,
)


@dataclass(frozen=True, slots=True)
class ViewRequest:
    """Everything one ``gnnpmb-viz`` run needs, checked: no recording is opened before this exists.

    source: where the detections came from, with their hash; seed: the simulated detector's seed;
    argv: the command line, for the provenance; serve: the ports of the web viewer (None: save or spawn).
    """

    scene: SceneData
    location: DatasetLocation
    trackers: tuple[str, ...]
    classes: tuple[str, ...]
    frame_range: range
    config: TrackerConfig
    detections: dict[str, Boxes]
    frame_detections: list[FrameDetections]
    save: Path | None
    source: DetectionsSource
    seed: int
    argv: tuple[str, ...]
    focus: str | None = None
    serve: ServeTarget | None = None


@dataclass(frozen=True, slots=True)
class ViewResult:
    """What ``run_view`` did: mean tracker ms per frame and track digest per tracker, the comparison (None
    with one tracker) and notices for the user (e.g. failures skipped)."""

    ms_per_frame: dict[str, float]
    digests: dict[str, TrackDigest]
    comparison: Comparison | None
    notices: tuple[str, ...]
    focus: FocusTarget | None = None


def parse_frames(text: str | None) -> tuple[int | None, int | None]:
    """``START:END`` (END exclusive, either side may be empty) -> (start, end); None -> (None, None)."""
    if text is None:
        return None, None
    match = _FRAMES_RE.match(text)
    if match is None:
        raise GnnpmbError(f"bad --frames '{text}': use START:END with keyframe indices, e.g. --frames 0:20")
    start, end = (int(g) if g else None for g in match.groups())
    if start is not None and end is not None and end <= start:
        raise GnnpmbError(f"bad --frames '{text}': END must be greater than START (END is exclusive)")
    return start, end


def frame_range_of(bounds: tuple[int | None, int | None], scene: SceneData) -> range:
    """The keyframes selected by parsed --frames bounds, checked against the scene's length."""
    n = len(scene.keyframes)
    start = 0 if bounds[0] is None else bounds[0]
    end = n if bounds[1] is None else bounds[1]
    if n == 0:
        raise DataError(f"{scene.name} has no keyframes")
    if start >= n or end > n:
        raise GnnpmbError(
            f"--frames {start}:{end} is outside {scene.name}, which has keyframes 0 to {n - 1} (use END <= {n})"
        )
    if end <= start:
        raise GnnpmbError(f"--frames {start}:{end} selects no keyframes; END must be greater than START")
    return range(start, end)


def parse_classes(text: str | None) -> tuple[str, ...]:
    """``car,bus`` -> ("car", "bus"), checked; None -> all seven tracking classes."""
    if text is None:
        return TRACKING_CLASSES
    names = [n.strip() for n in text.split(",") if n.strip()]
    return tuple(dict.fromkeys(check_classes(names)))


def detections_source(
    scene: SceneData, detections: dict[str, Boxes], detections_file: Path | None, detector: str, seed: int
) -> DetectionsSource:
    """Where ``detections`` came from, with the SHA-256 of the file, or of the simulated boxes."""
    from gnnpmb.provenance import DetectionsSource, boxes_sha256, file_sha256

    if detections_file is not None:
        path = Path(detections_file).expanduser().absolute()
        return DetectionsSource("file", file_sha256(path), path=str(path))
    return DetectionsSource("simulated", boxes_sha256(detections, scene.sample_tokens), preset=detector, seed=int(seed))


def command_line() -> tuple[str, ...]:
    """The command line of this run: what ``main`` was given, else this process's arguments."""
    given = _COMMAND_LINE.get()
    return given if given is not None else (PROG, *sys.argv[1:])


def prepare(
    scene_name: str,
    trackers: Sequence[str],
    *,
    dataroot: Path | None = None,
    version: str | None = None,
    detections_file: Path | None = None,
    detector: str | None = None,
    seed: int = 0,
    params: Path | None = None,
    classes: str | None = None,
    frames: str | None = None,
    save: Path | None = None,
    serve: ServeTarget | None = None,
    argv: Sequence[str] = (),
    focus: str | None = None,
) -> ViewRequest:
    """Check every argument and load the scene and detections; raises GnnpmbError with a one-line message.

    The cheap checks (names, --frames, output path, ports, the --detections file) run before the dataset is
    loaded. detector None means the default preset; it cannot be combined with ``detections_file``.
    """
    if detections_file is not None and detector is not None:
        raise GnnpmbError("pass either --detections FILE.json or --detector PRESET, not both")
    if save is not None and serve is not None:
        raise GnnpmbError("pass either --save OUT.rrd or --serve, not both")
    detector = detector or DEFAULT_DETECTOR
    names = tuple(dict.fromkeys(check_tracker(t) for t in (trackers or [DEFAULT_TRACKER])))
    class_names = parse_classes(classes)
    bounds = parse_frames(frames)
    target = check_output_file(save, "--save", ".rrd") if save is not None else None
    if serve is not None:
        check_serve_ports(serve)
    if focus is not None:
        from gnnpmb.focus import parse_focus

        parse_focus(focus)

    from gnnpmb.config import load_config
    from gnnpmb.data.detections import check_detection_file
    from gnnpmb.data.nuscenes import load_scene, open_nuscenes, resolve_dataroot
    from gnnpmb.data.simdet import get_preset
    from gnnpmb.pipeline import get_detections, preprocess_frames

    get_preset(detector)
    config = load_config(params)
    if detections_file is not None:
        check_detection_file(detections_file)
    location = resolve_dataroot(dataroot, version, (scene_name,))
    scene = load_scene(open_nuscenes(location), location, scene_name)
    frame_range = frame_range_of(bounds, scene)
    detections = get_detections(scene, detections_file, detector, seed)
    source = detections_source(scene, detections, detections_file, detector, seed)
    frame_detections = preprocess_frames(scene, detections, config, class_names)
    return ViewRequest(
        scene,
        location,
        names,
        class_names,
        frame_range,
        config,
        detections,
        frame_detections,
        target,
        source,
        int(seed),
        tuple(argv),
        focus=focus,
        serve=serve,
    )


def prepare_reproduction(
    provenance: Provenance,
    *,
    dataroot: Path | None = None,
    detections_file: Path | None = None,
    save: Path | None = None,
    argv: Sequence[str] = (),
) -> ViewRequest:
    """The request that re-runs a recorded run: same dataset (checked by scene token), same detections
    (checked by hash), parameters, classes, frames and trackers. dataroot / detections_file replace the
    recorded paths (e.g. on another machine). Raises a DataError naming the input that is missing or
    changed."""
    from gnnpmb.config import config_from_dict
    from gnnpmb.data.nuscenes import check_dataroot, load_scene, open_nuscenes
    from gnnpmb.pipeline import get_detections, preprocess_frames

    p = provenance
    target = check_output_file(save, "--save", ".rrd") if save is not None else None
    root = Path(dataroot) if dataroot is not None else Path(p.dataroot)
    if not root.exists():
        raise DataError(f"the recorded dataroot {root} does not exist; pass --dataroot DIR with a copy of it")
    location = check_dataroot(root, p.version, "--dataroot" if dataroot is not None else "the recording")
    scene = load_scene(open_nuscenes(location), location, p.scene_name)
    if scene.token != p.scene_token:
        raise DataError(
            f"{p.scene_name} in {location.dataroot} has token {scene.token}, the recorded one "
            f"{p.scene_token}: not the same dataset"
        )
    config = config_from_dict(p.config)
    classes = tuple(check_classes(list(p.classes)))
    trackers = tuple(check_tracker(t) for t in p.trackers)
    frame_range = frame_range_of((p.frame_start, p.frame_end), scene)
    recorded = p.detections
    if recorded.kind == "file":
        path = Path(detections_file) if detections_file is not None else Path(str(recorded.path))
        if not path.is_file():
            raise DataError(f"the recorded detections file {path} is missing; pass --detections FILE.json")
        source = detections_source(scene, {}, path, DEFAULT_DETECTOR, p.seed)
        if source.sha256 != recorded.sha256:
            raise DataError(
                f"detections file {path} has changed since the recording (sha256 {source.sha256[:12]}, "
                f"recorded {recorded.sha256[:12]})"
            )
        detections = get_detections(scene, path, DEFAULT_DETECTOR, p.seed)
    else:
        preset = str(recorded.preset)
        seed = int(recorded.seed if recorded.seed is not None else p.seed)
        detections = get_detections(scene, None, preset, seed)
        source = detections_source(scene, detections, None, preset, seed)
        if source.sha256 != recorded.sha256:
            raise DataError(
                f"the simulated {preset} detector (seed {seed}) now gives other detections than when "
                f"recorded (sha256 {source.sha256[:12]}, recorded {recorded.sha256[:12]})"
            )
    frame_detections = preprocess_frames(scene, detections, config, classes)
    return ViewRequest(
        scene,
        location,
        trackers,
        classes,
        frame_range,
        config,
        detections,
        frame_detections,
        target,
        source,
        p.seed,
        tuple(argv),
    )


def recording_name(request: ViewRequest, focus: FocusTarget | None = None) -> str:
    """E.g. "scene-0103 · gnnpmb vs pmbm · synthetic demo", with "· focus id_switch:1" for a focus."""
    data = "synthetic demo" if request.scene.synthetic else f"nuScenes {request.location.version}"
    name = f"{request.scene.name} · {' vs '.join(request.trackers)} · {data}"
    if focus is not None:
        name += f" · focus {focus.failure_id or request.focus}"
    return name


def provenance_of(request: ViewRequest, digests: dict[str, TrackDigest]) -> Provenance:
    """The provenance of a run of ``request`` whose tracks have ``digests``."""
    from gnnpmb.provenance import Provenance, package_versions

    return Provenance(
        argv=request.argv,
        versions=package_versions(),
        config=request.config.as_dict(),
        dataroot=str(request.location.dataroot),
        version=request.location.version,
        synthetic=request.scene.synthetic,
        scene_name=request.scene.name,
        scene_token=request.scene.token,
        detections=request.source,
        seed=request.seed,
        frame_start=request.frame_range.start,
        frame_end=request.frame_range.stop,
        classes=request.classes,
        trackers=request.trackers,
        track_digests=digests,
    )


def run_digest(run: TrackingRun) -> TrackDigest:
    """The track digest of one tracker run."""
    from gnnpmb.provenance import track_digest

    return track_digest([f.keyframe.index for f in run.frames], [f.estimates for f in run.frames])


def compare_runs(runs: Sequence[TrackingRun]) -> Comparison:
    """Per-frame disagreements between tracker runs over the same keyframes (``gnnpmb.compare``), between the
    tracks the viewer draws (existence at least ``viz.logger.SHOW_MIN_EXISTENCE``)."""
    from gnnpmb.compare import compare_trackers
    from viz.logger import SHOW_MIN_EXISTENCE

    frames = runs[0].frames
    return compare_trackers(
        [f.keyframe.gt for f in frames],
        {
            run.tracker: [tuple(e for e in f.estimates if e.existence >= SHOW_MIN_EXISTENCE) for f in run.frames]
            for run in runs
        },
        frame_indices=[f.keyframe.index for f in frames],
    )


def find_reports(
    request: ViewRequest, runs: Sequence[TrackingRun], on_done: Callable[[], None] = lambda: None
) -> tuple[dict[str, FailureReport], list[str]]:
    """Each run's failures found with the devkit's matching, and notices: a scene without ground truth, or one
    the devkit cannot evaluate, gives no reports."""
    from gnnpmb.data.nuscenes import open_nuscenes
    from gnnpmb.eval.failures import find_failures
    from gnnpmb.eval.submission import run_results

    scene = request.scene
    if not any(len(k.gt) for k in scene.keyframes):
        return {}, [f"{scene.name} has no ground-truth boxes (no annotations): failure markers skipped"]
    nusc = open_nuscenes(request.location)
    reports = {}
    for run in runs:
        try:
            reports[run.tracker] = find_failures(nusc, scene.name, run_results(run), run.tracker)
        except DataError as exc:
            return {}, [f"failure markers skipped: {exc}"]
        on_done()
    return reports, []


def resolve_request_focus(request: ViewRequest) -> tuple[FocusTarget, dict[str, FailureReport], list[str]]:
    """Run the trackers without logging, find their failures and resolve ``request.focus``; returns the focus,
    the failure reports and notices. Raises GnnpmbError (one line) when the focus names nothing in this run."""
    from gnnpmb.focus import resolve_focus

    if request.focus is None:
        raise ValueError("the request has no focus")
    runs = rerun_runs(request)
    reports, notices = find_reports(request, runs)
    if not reports and not request.focus.startswith("track:"):
        raise GnnpmbError(f"--focus {request.focus} needs ground truth: {'; '.join(notices)}")
    estimates = {run.tracker: [f.estimates for f in run.frames] for run in runs}
    return resolve_focus(request.focus, request.scene, reports, estimates, request.frame_range), reports, notices


def run_view(request: ViewRequest, *, progress: bool = True, failures: bool = True) -> ViewResult:
    """Log the scene, run every tracker into one recording (sharing the preprocessed detections), compare them
    and log failures and provenance. With ``request.focus`` the trackers first run without logging to find the
    focus (``resolve_request_focus``); the recording then holds the keyframes around it and opens on it."""
    import numpy as np

    from cli.progress import progress_bar
    from gnnpmb.data.nuscenes import load_lidar_points
    from gnnpmb.pipeline import run_tracker
    from viz.blueprint import default_blueprint
    from viz.compare import log_comparison
    from viz.failures import log_failures
    from viz.focus import log_focus
    from viz.logger import FLUSH_FRAMES, TrackerLogger
    from viz.provenance import log_provenance
    from viz.recording import recording
    from viz.scene import log_scene
    from viz.timeline import PLAIN_CLOCK, Clock

    scene, frame_range = request.scene, request.frame_range
    focus, reports, notices = None, {}, []
    if request.focus is not None:  # the logged runs below give the same tracks (deterministic): reuse the reports
        focus, reports, notices = resolve_request_focus(request)
    shown = focus.window(frame_range) if focus is not None else frame_range
    clock = Clock(focus_end=focus.frame_index) if focus is not None else PLAIN_CLOCK
    n = len(shown)
    blueprint = default_blueprint(request.trackers, request.classes, focus)
    bar = progress_bar(progress)
    runs: list[TrackingRun] = []
    loggers: dict[str, TrackerLogger] = {}
    comparison = None
    if request.serve is not None:
        from cli.serve import serving

        opened = serving(recording_name(request, focus), request.serve, blueprint)
    else:
        opened = recording(recording_name(request, focus), request.save, blueprint)
    with opened as stream, bar:
        sensors = bar.add_task(f"{scene.name} sensors", total=n)
        log_scene(
            stream,
            scene,
            [request.frame_detections[i] for i in shown],
            shown,
            points_loader=load_lidar_points,
            on_frame=lambda: bar.advance(sensors),
            clock=clock,
        )
        for tracker in request.trackers:
            task = bar.add_task(f"{scene.name} {tracker}", total=len(frame_range))
            logger = loggers[tracker] = TrackerLogger(
                stream,
                tracker,
                gate_z_m=scene.ground_z_m,
                clock=clock,
                log_frames=shown if focus is not None else None,
                focus_tracks=set(focus.track_ids.get(tracker, ())) if focus is not None else None,
                flush_frames=None if request.save is not None else FLUSH_FRAMES,
            )
            runs.append(
                run_tracker(
                    scene,
                    request.frame_detections,
                    tracker,
                    request.config,
                    sink=logger,
                    classes=request.classes,
                    frame_range=frame_range,
                    on_frame=lambda task=task: bar.advance(task),
                )
            )
            logger.finish()
        if len(runs) > 1:
            comparison = compare_runs(runs)
            log_comparison(stream, comparison.within(shown), scene, clock)
        if failures and focus is None:
            task = bar.add_task(f"{scene.name} failures", total=len(runs))
            reports, notices = find_reports(request, runs, lambda: bar.advance(task))
        if failures or focus is not None:
            for name, report in reports.items():
                log_failures(stream, name, report, scene, shown, clock, show_labels=focus is None)
        if focus is not None:
            log_focus(stream, focus, scene, runs, loggers, clock, shown)
        digests = {run.tracker: run_digest(run) for run in runs}
        log_provenance(stream, provenance_of(request, digests))
    ms = {run.tracker: 1000.0 * float(np.mean([f.step_time_s for f in run.frames])) for run in runs}
    return ViewResult(ms, digests, comparison, tuple(notices), focus)


def rerun_runs(request: ViewRequest) -> list[TrackingRun]:
    """Run every tracker of ``request`` without logging."""
    from gnnpmb.pipeline import run_tracker

    return [
        run_tracker(
            request.scene,
            request.frame_detections,
            tracker,
            request.config,
            classes=request.classes,
            frame_range=request.frame_range,
        )
        for tracker in request.trackers
    ]


def rerun_digests(request: ViewRequest) -> dict[str, TrackDigest]:
    """Run every tracker of ``request`` without logging; their track digests."""
    return {run.tracker: run_digest(run) for run in rerun_runs(request)}


def digest_report(recorded: dict[str, TrackDigest], now: dict[str, TrackDigest]) -> tuple[list[str], bool]:
    """One line per tracker ("identical" or its first differing keyframe) and whether all are identical."""
    lines, same = [], True
    for tracker, digest in now.items():
        before = recorded.get(tracker)
        if before is None:
            lines.append(f"{tracker}: no recorded track digest to compare with")
            same = False
            continue
        first = before.first_difference(digest)
        if first is None:
            lines.append(f"{tracker}: identical ({len(digest.frames)} frames)")
        else:
            lines.append(
                f"{tracker}: DIFFERENT from keyframe {first} on "
                f"({before.differing_frames(digest)} of {len(digest.frames)} frames differ)"
            )
            same = False
    return lines, same


def _version_notes(recorded: dict[str, str]) -> list[str]:
    from gnnpmb.provenance import package_versions

    now = package_versions(tuple(recorded))
    return [f"note: recorded with {k} {v}, now {now[k]}" for k, v in recorded.items() if now.get(k) != v]


VIEW_HELP = (
    "Track SCENE and stream the recording to a Rerun viewer (or save it with --save).\n\n"
    "With several --tracker options every tracker runs on the same detections; the viewer shows them side by "
    "side with where they disagree.\n\n"
    f"To re-run the trackers of a saved recording and check that its tracks are identical: {PROG} reproduce "
    f"FILE.rrd (see {PROG} reproduce --help)."
)
REPRODUCE_HELP = (
    "Re-run the trackers of FILE.rrd (saved by gnnpmb-viz SCENE --save FILE.rrd) on the same inputs, checked "
    "by hash, and report per tracker whether the tracks are identical or the first keyframe where they "
    "differ.\n\n"
    "Exit code 0: all identical; 1: some differ; 2: an input is missing or changed."
)


@app.command(help=VIEW_HELP)
def view(
    scene: Annotated[str, typer.Argument(metavar="SCENE", help="Scene name, e.g. scene-0103.")],
    tracker: Annotated[
        list[str] | None,
        typer.Option(
            "--tracker",
            "-t",
            metavar="NAME",
            help=f"Tracker to run; repeat to compare several side by side ({', '.join(TRACKER_NAMES)}).",
        ),
    ] = None,
    dataroot: DatarootOption = None,
    version: VersionOption = None,
    detections: DetectionsOption = None,
    detector: Annotated[
        str | None,
        typer.Option(
            metavar="PRESET",
            help=f"Simulated detector preset: centerpoint, megvii or pointpillars (default {DEFAULT_DETECTOR}).",
        ),
    ] = None,
    seed: SeedOption = 0,
    params: ParamsOption = None,
    classes: Annotated[
        str | None,
        typer.Option(
            metavar="CLASS,...",
            help=f"Comma-separated classes to track (default all: {', '.join(TRACKING_CLASSES)}).",
        ),
    ] = None,
    frames: Annotated[
        str | None, typer.Option(metavar="START:END", help="Keyframes START:END (END exclusive), e.g. 0:20.")
    ] = None,
    save: Annotated[
        Path | None,
        typer.Option(metavar="OUT.rrd", help="Write the recording to this .rrd instead of a viewer."),
    ] = None,
    serve: Annotated[
        bool,
        typer.Option(
            "--serve",
            help="Serve the web viewer on localhost and print its URL (for a remote machine or no display); "
            "Ctrl-C stops it.",
        ),
    ] = False,
    web_port: Annotated[
        int, typer.Option(metavar="PORT", help="HTTP port of the web viewer (with --serve).")
    ] = DEFAULT_WEB_PORT,
    grpc_port: Annotated[
        int, typer.Option(metavar="PORT", help="gRPC port the web viewer reads the data from (with --serve).")
    ] = DEFAULT_GRPC_PORT,
    failures: Annotated[
        bool,
        typer.Option(help="Find and mark each tracker's failures with the devkit's matching (needs GT)."),
    ] = True,
    focus: Annotated[
        str | None,
        typer.Option(
            metavar="ID",
            help="Open on a failure: an id from 'gnnpmb failures' (e.g. id_switch:1), track:ID or gt:TOKEN. "
            "The recording holds the frames around it and opens at it, looking at the place.",
        ),
    ] = None,
    progress: Annotated[bool, typer.Option(help="Show a progress bar on stderr.")] = True,
) -> None:
    """Track SCENE into one recording and show or save it (``VIEW_HELP``)."""
    if save is None and not serve:
        check_display()
    request = prepare(
        scene,
        tracker or [],
        dataroot=dataroot,
        version=version,
        detections_file=detections,
        detector=detector,
        seed=seed,
        params=params,
        classes=classes,
        frames=frames,
        save=save,
        serve=ServeTarget(web_port, grpc_port) if serve else None,
        argv=command_line(),
        focus=focus,
    )
    result = run_view(request, progress=progress, failures=failures)
    if result.focus is not None:
        typer.echo(f"focus: {result.focus.title}")
    for notice in result.notices:
        typer.echo(f"note: {notice}", err=True)
    timing = ", ".join(f"{name} {value:.1f} ms/frame" for name, value in result.ms_per_frame.items())
    compared = ""
    if result.comparison is not None:
        compared = f"; {len(result.comparison.disagreements)} disagreements"
    output = f"saved {request.save}" if request.save is not None else "streamed to the Rerun viewer"
    if request.serve is not None:
        output = f"served at {request.serve.url}"
    typer.echo(f"{request.scene.name}: {len(request.frame_range)} frames, {timing}{compared}; {output}")
    if request.serve is not None:
        from cli.serve import wait_for_ctrl_c

        wait_for_ctrl_c(request.serve)


@reproduce_app.command(help=REPRODUCE_HELP)
def reproduce(
    recording_file: Annotated[
        Path,
        typer.Argument(metavar="FILE.rrd", help="A recording saved by gnnpmb-viz SCENE --save FILE.rrd."),
    ],
    dataroot: Annotated[
        Path | None,
        typer.Option(metavar="DIR", help="Use this dataroot instead of the recorded one (a copy)."),
    ] = None,
    detections: Annotated[
        Path | None,
        typer.Option(metavar="FILE.json", help="Use this detections file instead of the recorded path (a copy)."),
    ] = None,
    save: Annotated[
        Path | None, typer.Option(metavar="OUT.rrd", help="Also write the re-run as a new recording.")
    ] = None,
    progress: Annotated[bool, typer.Option(help="Show a progress bar on stderr (with --save).")] = True,
) -> None:
    """Re-run a recording's trackers and compare their track digests (``REPRODUCE_HELP``)."""
    from viz.provenance import read_provenance

    provenance = read_provenance(recording_file)
    request = prepare_reproduction(
        provenance, dataroot=dataroot, detections_file=detections, save=save, argv=command_line()
    )
    for note in _version_notes(provenance.versions):
        typer.echo(note, err=True)
    typer.echo(
        f"{provenance.scene_name} ({provenance.data_source}), keyframes {provenance.frame_start}:"
        f"{provenance.frame_end}, detections: {request.source.describe()} (same as recorded)"
    )
    digests = run_view(request, progress=progress).digests if save is not None else rerun_digests(request)
    lines, same = digest_report(provenance.track_digests, digests)
    for line in lines:
        typer.echo(line)
    if save is not None:
        typer.echo(f"saved {request.save}")
    if not same:
        raise typer.Exit(EXIT_DIFFERENT)


def main(argv: Sequence[str] | None = None) -> None:
    """The ``gnnpmb-viz`` console script: ``reproduce ...`` goes to the reproduce command, anything else to
    the viewer command (typer cannot have a positional SCENE beside a subcommand). As the script (``argv``
    None) a failed run exits at once (``cli.errors.exit_now_on_failure``)."""
    if argv is None:
        exit_now_on_failure(lambda: _main(sys.argv[1:]))
    else:
        _main(list(argv))


def _main(args: list[str]) -> None:
    """``main`` on the arguments after the program name."""
    check_version_flag(args, PROG)
    os.environ.setdefault("RUST_LOG", "off")  # Rerun's own log lines; our errors say what went wrong
    token = _COMMAND_LINE.set((PROG, *args))
    try:
        if args and args[0] == "reproduce":
            run_app(functools.partial(reproduce_app, prog_name=f"{PROG} reproduce"), args[1:])
        else:
            run_app(functools.partial(app, prog_name=PROG), args)
    finally:
        _COMMAND_LINE.reset(token)
