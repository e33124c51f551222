"""``gnnpmb-viz reproduce FILE.rrd``: read a recording's provenance back, re-run its trackers on the same inputs
(checked by hash) and say per tracker whether the tracks are identical. ``cli.app.main`` dispatches here when
the first argument is ``reproduce`` (typer cannot mix a positional SCENE with a subcommand)."""

from __future__ import annotations

import contextvars
import sys
from pathlib import Path
from typing import Annotated

import typer

from cli.progress import progress_bar

PROG = "gnnpmb-viz"
EXIT_DIFFERENT = 1
COMMAND_LINE: contextvars.ContextVar[tuple[str, ...] | None] = contextvars.ContextVar("command_line", default=None)
"""The command line ``cli.app.main`` was given, recorded in the provenance (else ``sys.argv`` is used)."""
REPRODUCE_HELP = (
    "Re-run the trackers of FILE.rrd (saved by gnnpmb-viz SCENE --save FILE.rrd) on the same inputs, checked "
    "by hash, and report per tracker whether the tracks are identical or the first keyframe where they "
    "differ.\n\n"
    "Exit code 0: all identical; 1: some differ; 2: an input is missing or changed."
)
reproduce_app = typer.Typer(
    add_completion=False,
    rich_markup_mode=None,
    help="Re-run the trackers of a recording saved by gnnpmb-viz and check its tracks.",
    pretty_exceptions_enable=False,
)


def command_line() -> tuple[str, ...]:
    """The command line of this run: what ``cli.app.main`` was given, else this process's arguments."""
    given = COMMAND_LINE.get()
    return given if given is not None else (PROG, *sys.argv[1:])


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
    from gnnpmb.outputs import check_output_file
    from gnnpmb.provenance import SOURCE_KEY, code_differs, digest_report, source_digest, version_notes
    from gnnpmb.stages.inputs import reproduction_inputs
    from gnnpmb.stages.runs import run_all, run_digests
    from viz.provenance import read_provenance
    from viz.view import run_view

    if save is not None:  # the recording read must not be the one written
        check_output_file(save, "--save", ".rrd", inputs=(("FILE.rrd", recording_file), ("--detections", detections)))
    provenance = read_provenance(recording_file)
    inputs = reproduction_inputs(
        provenance, dataroot=dataroot, detections_file=detections, save=save, argv=command_line()
    )
    for note in version_notes(provenance.versions):
        typer.echo(note, err=True)
    typer.echo(
        f"{provenance.scene_name} ({provenance.data_source}), keyframes {provenance.frame_start}:"
        f"{provenance.frame_end}, detections: {inputs.source.describe()} (same as recorded)"
    )
    rerun = run_view(inputs, progress=progress_bar(progress)) if save is not None else None
    digests = rerun.digests if rerun is not None else run_digests(run_all(inputs, record=False))
    lines, same = digest_report(provenance.track_digests, digests)
    for line in lines:
        typer.echo(line)
    if not same and code_differs(provenance.versions):
        typer.echo(
            f"the gnnpmb code differs from the recording's (source digest {provenance.versions[SOURCE_KEY]}, now "
            f"{source_digest()}): run the recorded code to tell a change of code from one of data"
        )
    if save is not None:
        typer.echo(f"saved {inputs.save}")
    if not same:
        raise typer.Exit(EXIT_DIFFERENT)
