"""``gnnpmb-viz``: track one nuScenes scene and watch every step of the tracker(s) in Rerun.

``gnnpmb-viz SCENE [--tracker A --tracker B ...]`` runs every tracker on the same preprocessed detections and
logs them into one recording: one 3D view per tracker side by side, the comparison of the trackers (where they
disagree, judged against the ground truth), each tracker's failures found with the devkit's matching, and the
provenance of the run (command line, versions, parameters, inputs and their hashes, digests of the tracks).
``gnnpmb-viz reproduce FILE.rrd`` reads that provenance back, re-runs the trackers on the same inputs and says
whether the tracks are identical. Typer cannot mix a positional SCENE with a subcommand, so ``main``
dispatches on the first argument being ``reproduce``.

This module only parses and prints: the work is the stages of ``gnnpmb.stages`` (``check_request``,
``load_inputs``) and ``viz.view.run_view``, which a notebook can call the same way
(``examples/notebook_session.py``). Everything the user typed is checked before a
recording is opened (names, --frames, files, the dataset), so a
mistake costs one line on stderr and leaves no ``.rrd`` behind. Without ``--save`` or ``--serve`` the run needs
a display for the spawned viewer; without one it stops at once with a hint instead of hanging.
"""

from __future__ import annotations

import functools
import os
import sys
from collections.abc import Sequence
from pathlib import Path
from typing import Annotated

import typer

from cli.errors import check_version_flag, exit_now_on_failure, run_app
from cli.options import (
    DEFAULT_SOURCE,
    ProgressOption,
    ResultsOption,
    RunsOption,
    SceneArgument,
    Source,
    source_options,
    tidy_help,
)
from cli.progress import progress_bar
from cli.reproduce import COMMAND_LINE, PROG, command_line, reproduce_app
from gnnpmb.classes import TRACKING_CLASSES
from gnnpmb.runs import parse_runs
from gnnpmb.serve import DEFAULT_GRPC_PORT, DEFAULT_WEB_PORT, check_display, serve_target
from gnnpmb.stages.inputs import collect_rarely
from gnnpmb.stages.request import DEFAULT_TRACKER, check_request

tidy_help()
app = typer.Typer(
    add_completion=False,
    rich_markup_mode=None,
    help="Track a nuScenes scene and inspect every step of the tracker(s) in the Rerun viewer.",
    pretty_exceptions_enable=False,
)


VIEW_HELP = (
    "Track SCENE and stream the recording to a Rerun viewer (or save it with --save).\n\n"
    "With several --tracker options every tracker runs on the same detections; the viewer shows them side by "
    "side with where they disagree.\n\n"
    f"To re-run the trackers of a saved recording and check that its tracks are identical: {PROG} reproduce "
    f"FILE.rrd (see {PROG} reproduce --help)."
)


@app.command(help=VIEW_HELP)
@source_options
def view(
    scene: SceneArgument,
    tracker: RunsOption = None,
    results: ResultsOption = None,
    source: Source = DEFAULT_SOURCE,
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
            help="Serve the web viewer on 127.0.0.1 (see --bind) and print its URL (for a remote machine or no "
            "display); Ctrl-C stops it.",
        ),
    ] = False,
    web_port: Annotated[
        int, typer.Option(metavar="PORT", help="HTTP port of the web viewer (with --serve).")
    ] = DEFAULT_WEB_PORT,
    grpc_port: Annotated[
        int, typer.Option(metavar="PORT", help="gRPC port the web viewer reads the data from (with --serve).")
    ] = DEFAULT_GRPC_PORT,
    bind: Annotated[
        str | None,
        typer.Option(
            metavar="ADDRESS",
            help="With --serve: listen on this IP address (e.g. 0.0.0.0 for every interface, which exposes the "
            "recording to the network) instead of 127.0.0.1 (this machine only).",
        ),
    ] = None,
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
    progress: ProgressOption = True,
    cameras: Annotated[
        bool, typer.Option(help="Show the camera images with the boxes projected into them (where the data has them).")
    ] = True,
    sweeps: Annotated[
        bool,
        typer.Option(help="Also log the LiDAR sweeps between keyframes, each at its own time (timestamp timeline)."),
    ] = False,
) -> None:
    """Track SCENE into one recording and show or save it (``VIEW_HELP``)."""
    if save is None and not serve:
        parse_runs(tracker or [], results or [], default=DEFAULT_TRACKER)  # a mistyped run first, then the display
        check_display()
    request = check_request(
        scene,
        tracker or [],
        results=results or [],
        **source.request_args(),
        classes=classes,
        frames=frames,
        save=save,
        serve=serve_target(serve, web_port, grpc_port, bind),
        argv=command_line(),
        focus=focus,
    )
    from gnnpmb.stages.inputs import load_inputs
    from viz.view import run_view

    inputs = load_inputs(request)
    if request.serve is not None and request.serve.exposure_warning() is not None:  # after every check passed
        typer.echo(request.serve.exposure_warning(), err=True)
    result = run_view(inputs, progress=progress_bar(progress), failures=failures, cameras=cameras, sweeps=sweeps)
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
    typer.echo(f"{inputs.scene.name}: {len(inputs.frame_range)} frames, {timing}{compared}; {output}")
    if result.focus is None:  # where to look next: --focus ids name the first run's failures
        for k, (name, report) in enumerate(result.reports.items()):
            first = report.first_worth_opening()
            if first is None:
                continue
            spec = inputs.spec(name).text()
            how = f"add --focus {first}" if k == 0 else f"give --tracker {spec} first and add --focus {first}"
            interpolated = sum(f.gt_interpolated for f in report.failures)
            gap = any(not b.annotated for f in report.failures for b in f.boxes if b.is_gt and b.interpolated)
            at_interpolated = (
                f" ({interpolated} at a GT box the evaluation interpolated: the object had no points"
                f"{' or no annotation there' if gap else ''})"
                if interpolated
                else ""
            )
            typer.echo(
                f"{name} failures{report.scope_text()}: {report.totals_text()}{at_interpolated}. To open {first} at "
                f"its frame, {how} to this command; to list them all: "
                f"{failures_command(inputs.scene.name, spec, source, frames, classes)}"
            )
    if request.serve is not None:
        from viz.serving import wait_for_ctrl_c

        wait_for_ctrl_c(request.serve)


def failures_command(scene: str, spec: str, source: Source, frames: str | None, classes: str | None) -> str:
    """The ``gnnpmb failures`` command that lists run ``spec``'s failures with this command's data options."""
    import shlex

    words = ["gnnpmb", "failures", scene, "--tracker", spec]
    words += [w for flag, value in (("--frames", frames), ("--classes", classes)) if value for w in (flag, value)]
    options = source.shell_words()
    return shlex.join(words) + (f" {options}" if options else "")


def main(argv: Sequence[str] | None = None) -> None:
    """The ``gnnpmb-viz`` console script: ``reproduce ...`` goes to the reproduce command, anything else to
    the viewer command (typer cannot have a positional SCENE beside a subcommand). As the script (``argv``
    None) a failed run exits at once (``cli.errors.exit_now_on_failure``)."""
    if argv is None:
        collect_rarely()
        exit_now_on_failure(lambda: _main(sys.argv[1:]))
    else:
        _main(list(argv))


def _main(args: list[str]) -> None:
    """``main`` on the arguments after the program name."""
    check_version_flag(args, PROG)
    os.environ.setdefault("RUST_LOG", "off")  # Rerun's own log lines; our errors say what went wrong
    token = COMMAND_LINE.set((PROG, *args))
    try:
        if args and args[0] == "reproduce":
            run_app(functools.partial(reproduce_app, prog_name=f"{PROG} reproduce"), args[1:])
        else:
            run_app(functools.partial(app, prog_name=PROG), args)
    finally:
        COMMAND_LINE.reset(token)
