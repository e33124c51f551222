"""Run a command-line entry point in-process, as a user would from the shell, and read what it printed."""

from __future__ import annotations

from collections.abc import Callable

import pytest


def run_main(main: Callable[[list[str]], object], argv: list[str], capsys: pytest.CaptureFixture[str]):
    """``main(argv)`` in-process: (exit code, stdout, stderr); a ``SystemExit`` gives its code, a return 0."""
    try:
        main(argv)
        code = 0
    except SystemExit as exc:
        code = int(exc.code or 0)
    out, err = capsys.readouterr()
    return code, out, err
