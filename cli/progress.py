"""The progress bar every command shows on stderr: description, bar, done/total, elapsed time."""

from __future__ import annotations

from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from rich.progress import Progress


def progress_bar(show: bool, *, transient: bool = False) -> Progress:
    """A rich ``Progress`` on stderr (imported here, off the ``--help`` path); ``show`` False disables it;
    ``transient`` removes it when done."""
    from rich.console import Console
    from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn, TimeElapsedColumn

    return Progress(
        TextColumn("{task.description}"),
        BarColumn(),
        MofNCompleteColumn(),
        TimeElapsedColumn(),
        console=Console(stderr=True),
        disable=not show,
        transient=transient,
    )
