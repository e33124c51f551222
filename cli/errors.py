"""One place that turns user-input errors into one line on stderr and a non-zero exit, without a traceback."""

from __future__ import annotations

import sys
from collections.abc import Callable

import typer

from gnnpmb.errors import GnnpmbError

EXIT_USER_ERROR = 2


def run_app(app: typer.Typer, argv: list[str] | None = None) -> None:
    """Run a typer app; a GnnpmbError (or a JSON/OS error from reading the user's files) ends the process with
    ``error: <message>`` and exit code 2. Ctrl-C exits 130 quietly."""
    try:
        code = app(args=argv, standalone_mode=False)
    except GnnpmbError as exc:
        _fail(str(exc))
    except KeyboardInterrupt:
        sys.exit(130)
    except typer.Exit as exc:
        sys.exit(exc.exit_code)
    except typer.Abort:
        sys.exit(1)
    except Exception as exc:  # click's usage errors are ClickException subclasses
        from click.exceptions import ClickException

        if isinstance(exc, ClickException):
            exc.show()
            sys.exit(exc.exit_code)
        raise
    if isinstance(code, int) and code:
        sys.exit(code)


def _fail(message: str) -> None:
    print(f"error: {message}", file=sys.stderr)
    sys.exit(EXIT_USER_ERROR)


def entry_point(app: typer.Typer) -> Callable[[], None]:
    """A console-script ``main`` for ``app``."""

    def main() -> None:
        run_app(app)

    return main
