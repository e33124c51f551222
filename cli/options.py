"""Command-line options shared by ``gnnpmb-viz`` and ``gnnpmb`` (``cli.batch`` and ``cli.study``): one spelling
and help text each, and the console tables are printed on."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Annotated

import typer

from gnnpmb.registry import TRACKER_NAMES
from gnnpmb.stages.request import DEFAULT_DETECTOR

if TYPE_CHECKING:
    from rich.console import Console

_TABLE_WIDTH = 160
"""Console width when stdout is not a terminal (pipes, tests), so tables are not squeezed to 80 columns."""

DatarootOption = Annotated[
    Path | None,
    typer.Option(metavar="DIR", help="nuScenes dataroot (default: $NUSCENES_DATAROOT, else the built-in demo)."),
]
VersionOption = Annotated[
    str | None,
    typer.Option(
        "--nuscenes-version",
        metavar="V",
        help="Dataset version folder, e.g. v1.0-mini (default: the only one in the dataroot).",
    ),
]
DetectionsOption = Annotated[
    Path | None,
    typer.Option(metavar="FILE.json", help="nuScenes detection results .json (default: a simulated detector)."),
]
SeedOption = Annotated[int, typer.Option(metavar="N", min=0, help="Seed of the simulated detector (0 or more).")]
RunsOption = Annotated[
    list[str] | None,
    typer.Option(
        "--tracker",
        "-t",
        metavar="NAME",
        help=f"Tracker to run (repeatable): {', '.join(TRACKER_NAMES)}; TRACKER:PARAMS.toml with its own "
        "parameters; NAME=FILE.json a results file (default gnnpmb).",
    ),
]
ResultsOption = Annotated[
    list[str] | None,
    typer.Option(
        "--results",
        metavar="NAME=FILE.json",
        help="Another tracker's results (a nuScenes tracking submission) as a run named NAME; repeatable. "
        "Results runs come first (to order them among trackers, give --tracker NAME=FILE.json instead).",
    ),
]
ParamsOption = Annotated[
    Path | None,
    typer.Option(metavar="FILE.toml", help="Tracker parameter file (.toml) overriding the paper's."),
]


SplitOption = Annotated[
    str | None,
    typer.Option(
        metavar="NAME",
        help="Split: mini_val, val, ... or one in <version>/splits.json (default: from --nuscenes-version).",
    ),
]
DetectorOption = Annotated[
    str | None,
    typer.Option(
        metavar="PRESET",
        help=f"Simulated detector preset: centerpoint, megvii, pointpillars (default {DEFAULT_DETECTOR}).",
    ),
]
TrackerOption = Annotated[
    str, typer.Option("--tracker", "-t", metavar="NAME", help=f"Tracker: {', '.join(TRACKER_NAMES)}.")
]
AddressOption = Annotated[
    str | None,
    typer.Option(
        metavar="ADDR",
        help="Join the Ray cluster at HOST:PORT (default: $RAY_ADDRESS, else a local Ray instance).",
    ),
]


def stdout_console() -> Console:
    """The console tables are printed on: the terminal's width, or ``_TABLE_WIDTH`` columns in a pipe."""
    from rich.console import Console

    console = Console()
    return console if console.is_terminal else Console(width=_TABLE_WIDTH)


def tidy_help() -> None:
    """Help text without typer's type placeholders: ``SCENE`` not ``{scene}``, no ``<bool>`` after a flag and
    no ``<str>`` after an argument that has a metavar (typer 0.29 adds them; click never did)."""
    from typer import core

    if getattr(core, "_gnnpmb_tidy_help", False):
        return
    option_type = core.TyperOption.display_type_rich
    argument_type = core.TyperArgument.display_type_rich

    def option_display_type(self: core.TyperOption, ctx: object) -> str | None:
        return None if self.is_flag else option_type(self, ctx)

    def argument_display_type(self: core.TyperArgument, ctx: object) -> str | None:
        return None if self.metavar is not None else argument_type(self, ctx)

    def usage_name(self: core.TyperArgument) -> str:
        name = self.display_name_raw.upper() if self.metavar is None else self.display_name_raw
        name = name if self.required else f"[{name}]"
        return f"{name}..." if self.nargs != 1 else name

    core.TyperOption.display_type_rich = option_display_type
    core.TyperArgument.display_type_rich = argument_display_type
    core.TyperArgument._usage_display_name = usage_name
    core._gnnpmb_tidy_help = True
