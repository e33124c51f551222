"""Command-line options shared by ``gnnpmb-viz`` and ``gnnpmb`` (``cli.batch`` and ``cli.study``): one spelling
and help text each, and the console tables are printed on."""

from __future__ import annotations

import functools
import inspect
from collections.abc import Callable
from dataclasses import dataclass, fields
from pathlib import Path
from typing import TYPE_CHECKING, Annotated, Any

import typer

from gnnpmb.registry import TRACKER_NAMES
from gnnpmb.stages.request import DEFAULT_DETECTOR

if TYPE_CHECKING:
    from rich.console import Console

    from gnnpmb.study.data import StudyData

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
SceneArgument = Annotated[str, typer.Argument(metavar="SCENE", help="Scene name, e.g. scene-0103.")]
ProgressOption = Annotated[bool, typer.Option(help="Show a progress bar on stderr.")]
VerboseOption = Annotated[bool, typer.Option("--verbose", help="Show Ray's own log lines (hidden by default).")]
AddressOption = Annotated[
    str | None,
    typer.Option(
        metavar="ADDR",
        help="Join the Ray cluster at HOST:PORT (default: $RAY_ADDRESS, else a local Ray instance).",
    ),
]


@dataclass(frozen=True, slots=True)
class Source:
    """Where a command's tracking input comes from: the options --dataroot, --nuscenes-version, --detections,
    --detector, --seed and --params, as typed (checked by the stages that read them)."""

    dataroot: Path | None = None
    version: str | None = None
    detections: Path | None = None
    detector: str | None = None
    seed: int = 0
    params: Path | None = None

    @property
    def input_files(self) -> tuple[tuple[str, Path | None], ...]:
        """(option, file) of the files read, which an output file must not overwrite."""
        return (("--detections", self.detections), ("--params", self.params))

    def request_args(self) -> dict[str, Any]:
        """The keyword arguments of ``gnnpmb.stages.request.check_request`` these options give."""
        return {
            "dataroot": self.dataroot,
            "version": self.version,
            "detections_file": self.detections,
            "detector": self.detector,
            "seed": self.seed,
            "params": self.params,
        }

    def shell_words(self) -> str:
        """The options, as a shell would take them, that give this source again (the defaults left out)."""
        import shlex

        parts = []
        for flag, value in (
            ("--dataroot", self.dataroot),
            ("--nuscenes-version", self.version),
            ("--detections", self.detections),
            ("--detector", self.detector),
            ("--params", self.params),
        ):
            if value is not None:
                parts += [flag, str(value)]
        if self.seed:
            parts += ["--seed", str(self.seed)]
        return shlex.join(parts)

    def split_data(self, split: str | None, preset: str | None) -> StudyData:
        """The scenes of ``split`` (None: the dataset version's evaluation split) and their detections: the file,
        else the simulated detector ``preset`` (``gnnpmb.study.data.resolve_study_data``)."""
        from gnnpmb.eval.nuscenes_eval import resolve_split
        from gnnpmb.study.data import resolve_study_data

        location, split = resolve_split(self.dataroot, self.version, split)
        return resolve_study_data(location, split, self.detections, preset, self.seed)


DEFAULT_SOURCE = Source()
"""The default of a command's ``source`` parameter (``source_options`` replaces it by the options)."""

_SOURCE_OPTIONS = {
    "dataroot": DatarootOption,
    "version": VersionOption,
    "detections": DetectionsOption,
    "detector": DetectorOption,
    "seed": SeedOption,
    "params": ParamsOption,
}


def source_options(command: Callable[..., None]) -> Callable[..., None]:
    """``command`` with the ``Source`` options in place of its parameter ``source: Source`` (typer reads the
    signature), which it is given as one ``Source``."""
    signature = inspect.signature(command, eval_str=True)
    parameters: list[inspect.Parameter] = []
    for parameter in signature.parameters.values():
        if parameter.name != "source":
            parameters.append(parameter)
            continue
        for field in fields(Source):
            option = _SOURCE_OPTIONS[field.name]
            parameters.append(inspect.Parameter(field.name, parameter.kind, default=field.default, annotation=option))

    @functools.wraps(command)
    def with_source(**kwargs: Any) -> None:
        source = Source(**{name: kwargs.pop(name) for name in _SOURCE_OPTIONS})
        return command(source=source, **kwargs)

    with_source.__signature__ = signature.replace(parameters=parameters)  # type: ignore[attr-defined]
    with_source.__annotations__ = {p.name: p.annotation for p in parameters} | {"return": None}
    return with_source


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
