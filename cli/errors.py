"""One place that turns user mistakes into one line on stderr and exit code 2, without a traceback.

Three kinds reach ``run_app``: usage errors from the command-line parser (a typo'd option, a missing argument,
``--seed abc``), a ``GnnpmbError`` raised by our own checks, and an ``OSError`` while writing an output (disk
full, permission denied). Each becomes ``error: <what is wrong and how to fix it>``. The locked typer parses with
its own bundled copy of click (``typer._click``), whose exceptions are not ``click``'s: both are caught.
"""

from __future__ import annotations

import contextlib
import os
import sys
from collections.abc import Callable, Sequence
from pathlib import Path

import typer

from gnnpmb import signals
from gnnpmb.errors import GnnpmbError

EXIT_USER_ERROR = 2
EXIT_INTERRUPTED = 130
DIST_NAME = "gnnpmb-viz"
"""The distribution whose version ``--version`` prints."""


def _click_exception_types() -> tuple[type[Exception], ...]:
    """The parser's exception base classes: typer's bundled click and, when installed, click itself."""
    types: list[type[Exception]] = []
    try:
        from typer._click.exceptions import ClickException as TyperClickException

        types.append(TyperClickException)
    except ImportError:
        pass
    try:
        from click.exceptions import ClickException

        types.append(ClickException)
    except ImportError:
        pass
    return tuple(types)


def program_version() -> str:
    """The installed version of this program (the ``gnnpmb-viz`` distribution)."""
    from importlib import metadata

    try:
        return metadata.version(DIST_NAME)
    except metadata.PackageNotFoundError:
        return "unknown (not installed)"


def check_version_flag(args: Sequence[str], prog: str) -> None:
    """``--version`` anywhere prints the program's version and exits 0, before anything else is imported.

    ``--version VALUE`` was the dataset version option before it became ``--nuscenes-version``: that use gets
    a one-line error saying so instead of silently printing the program's version.
    """
    for i, arg in enumerate(args):
        if arg == "--":
            return
        if arg.startswith("--version="):
            _fail(f"--version takes no value; the dataset version is --nuscenes-version {arg.split('=', 1)[1]}")
        if arg != "--version":
            continue
        following = args[i + 1] if i + 1 < len(args) else None
        if following is not None and not following.startswith("-") and following.startswith("v"):
            _fail(f"--version takes no value; the dataset version is --nuscenes-version {following}")
        print(f"{prog} {program_version()}")
        sys.exit(0)


def usage_line(exc: Exception) -> str:
    """The parser's error as one line: what is wrong, and where the help is."""
    ctx = getattr(exc, "ctx", None)
    command = ctx.command_path if ctx is not None else ""
    if ctx is not None and (type(exc).__name__ == "NoArgsIsHelpError" or str(exc).startswith("Missing command")):
        names = ctx.command.list_commands(ctx) if hasattr(ctx.command, "list_commands") else []
        return f"missing a command ({', '.join(names)}); see '{command} --help'"
    format_message = getattr(exc, "format_message", None)
    text = format_message() if callable(format_message) else str(exc)
    text = " ".join(text.split()).rstrip(".")
    if text[:1].isupper() and not text[1:2].isupper():
        text = text[0].lower() + text[1:]
    return f"{text}; see '{command} --help'" if command else text


def symlink_loop_line(exc: RuntimeError) -> str | None:
    """pathlib's ``RuntimeError("Symlink loop from '<path>'")`` (Python 3.11's ``Path.resolve``) as one line, or
    None for any other RuntimeError."""
    text = str(exc)
    if not text.startswith(_PATHLIB_LOOP):
        return None
    from gnnpmb.symlinks import loop_line

    return loop_line(Path(text[len(_PATHLIB_LOOP) :].strip("'\"")), "path")


_PATHLIB_LOOP = "Symlink loop from "


def demo_hint(exc: GnnpmbError, args: Sequence[str]) -> str:
    """What to add to the line of an input file that does not fit the dataset (``NotThisDatasetError``) when the
    dataset was the built-in demo only because neither --dataroot nor $NUSCENES_DATAROOT was given: most likely
    the user's own file, read against the demo's samples. Empty otherwise."""
    from gnnpmb.data.nuscenes import DATAROOT_ENV
    from gnnpmb.errors import NotThisDatasetError

    if not isinstance(exc, NotThisDatasetError) or os.environ.get(DATAROOT_ENV):
        return ""
    if any(a == "--dataroot" or a.startswith("--dataroot=") for a in args):
        return ""
    return (
        f" (no --dataroot or ${DATAROOT_ENV} was given, so this is the built-in demo dataset: for your own data "
        "pass --dataroot DIR, the folder that holds v1.0-*/)"
    )


_ANNOUNCED: list[str] = []
"""The stop line printed by this run, if any (``announce_stop``)."""


def announce_stop(what: str = "unfinished outputs were not written") -> None:
    """Print the one line of a run stopped by Ctrl-C or SIGTERM (``gnnpmb.signals``), saying ``what`` became of
    its work; only the first call of a run prints."""
    if _ANNOUNCED:
        return
    verb = "terminated" if signals.terminated() else "interrupted"
    _ANNOUNCED.append(f"{verb} by {signals.stop_reason()}: {what}")
    print(_ANNOUNCED[-1], file=sys.stderr)


def run_app(app: Callable[..., object], argv: list[str] | None = None) -> None:
    """Run a typer app (or a partial of one); user mistakes end the process with one ``error:`` line and exit
    code 2, Ctrl-C (or SIGTERM, ``gnnpmb.signals``) with one line and exit 130 (143), a closed stdout pipe
    quietly."""
    _ANNOUNCED.clear()
    try:
        code = app(args=argv, standalone_mode=False)
    except GnnpmbError as exc:
        _fail(str(exc) + demo_hint(exc, sys.argv[1:] if argv is None else argv))
    except KeyboardInterrupt:
        _stopped()
    except typer.Exit as exc:
        sys.exit(exc.exit_code)
    except typer.Abort as exc:
        if isinstance(exc.__cause__, KeyboardInterrupt):  # click turns a Ctrl-C (or SIGTERM) it meets into Abort
            _stopped()
        sys.exit(1)
    except BrokenPipeError:
        _quiet_broken_pipe()
    except OSError as exc:
        from gnnpmb.os_errors import os_error_line

        _fail(os_error_line(exc))
    except RuntimeError as exc:
        line = symlink_loop_line(exc)
        if line is None:
            raise
        _fail(line)
    except Exception as exc:
        if not isinstance(exc, _click_exception_types()):
            raise
        if getattr(exc, "exit_code", EXIT_USER_ERROR) == 0:
            sys.exit(0)
        _fail(usage_line(exc))
    if code == EXIT_INTERRUPTED:  # typer returns Ctrl-C as 130, silently, like a command's own Exit(130)
        _stopped()
    if isinstance(code, int) and code:
        sys.exit(code)


def _quiet_broken_pipe() -> None:
    """Stdout was closed by the reader (``| head``): no traceback, no second error while flushing."""
    devnull = os.open(os.devnull, os.O_WRONLY)
    os.dup2(devnull, sys.stdout.fileno())
    sys.exit(1)


def _stopped() -> None:
    announce_stop()
    sys.exit(signals.exit_code())


def _fail(message: str) -> None:
    print(f"error: {message}", file=sys.stderr)
    sys.exit(EXIT_USER_ERROR)


def exit_now_on_failure(run: Callable[[], None]) -> None:
    """Run a console script's body with SIGTERM handled like Ctrl-C (``gnnpmb.signals``); a failed run
    (SystemExit with a non-zero code) ends the process at once, after flushing stdout and stderr, skipping
    interpreter shutdown: Rerun's exit hook can wait forever on a recording whose file writer died (disk full).
    Every output was already finished or removed."""
    signals.install()
    try:
        try:
            run()
        except KeyboardInterrupt:  # before or after the app ran (e.g. while importing)
            _stopped()
    except SystemExit as exc:
        code = exc.code if isinstance(exc.code, int) else (0 if exc.code is None else 1)
        if code == 0:
            raise
        for stream in (sys.stdout, sys.stderr):
            with contextlib.suppress(OSError, ValueError):
                stream.flush()
        os._exit(code)


def entry_point(app: typer.Typer, prog: str) -> Callable[[], None]:
    """A console-script ``main`` for ``app`` answering ``--version`` itself."""

    def main() -> None:
        check_version_flag(sys.argv[1:], prog)
        exit_now_on_failure(lambda: run_app(app))

    return main
