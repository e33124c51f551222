"""Command-line options shared by ``gnnpmb-viz`` and ``gnnpmb``: one spelling and help text each."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

DatarootOption = Annotated[
    Path | None,
    typer.Option(metavar="DIR", help="nuScenes dataroot (default: $NUSCENES_DATAROOT, else the built-in demo)."),
]
VersionOption = Annotated[str | None, typer.Option(metavar="V", help="Dataset version folder, e.g. v1.0-mini.")]
DetectionsOption = Annotated[
    Path | None,
    typer.Option(metavar="FILE.json", help="nuScenes detection results .json (default: a simulated detector)."),
]
SeedOption = Annotated[int, typer.Option(metavar="N", help="Seed of the simulated detector.")]
ParamsOption = Annotated[
    Path | None,
    typer.Option(metavar="FILE.toml", help="Tracker parameter file (.toml) overriding the paper's."),
]
