"""The progress bar every command shows on stderr: description, bar, done/total, elapsed time."""

from __future__ import annotations

from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from rich.progress import Progress


def progress_bar(show: bool, *, transient: bool = False) -> Progress:
    """A rich ``Progress`` on stderr (imported here, off the ``--help`` path); ``show`` False disables it;
    ``transient`` removes it when done. A transient bar on a stderr that is no terminal (a pipe, a log file) would
    leave only an empty line, before an ``error:`` line too: it is not shown there."""
    from rich.console import Console
    from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn, TimeElapsedColumn

    console = Console(stderr=True)
    return Progress(
        TextColumn("{task.description}"),
        BarColumn(),
        MofNCompleteColumn(),
        TimeElapsedColumn(),
        console=console,
        disable=not show or (transient and not console.is_terminal),
        transient=transient,
    )
