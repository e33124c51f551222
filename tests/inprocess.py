"""Run a command-line entry point in-process, as a user would from the shell, and read what it printed."""

from __future__ import annotations

import contextlib
import functools
import io
import os
import subprocess
import traceback
from collections.abc import Callable, Iterator, Sequence
from pathlib import Path

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


FRESH_PROCESS_STATE = ("_DATASETS", "_CHECKED")
"""``gnnpmb.outputs``' lists of the datasets opened and the outputs checked by this process: empty at the start of
each in-process command, as in a new process."""


def run_script(argv: Sequence[str], capsys: pytest.CaptureFixture[str]) -> subprocess.CompletedProcess[str]:
    """A console script's command line (``gnnpmb-viz ...`` or ``gnnpmb ...``) in-process, as the script runs it
    up to the point where a real process would exit: exit code, stdout and stderr as ``subprocess.run`` gives
    them. An exception escaping the command is printed as the interpreter would (a traceback, exit 1)."""
    from cli.errors import check_version_flag, run_app
    from gnnpmb import outputs

    program, args = argv[0], list(argv[1:])
    if program == "gnnpmb-viz":
        from cli.app import main
    elif program == "gnnpmb":
        from cli.batch import app

        def main(args: list[str]) -> None:
            check_version_flag(args, "gnnpmb")
            run_app(functools.partial(app, prog_name="gnnpmb"), args)
    else:
        raise ValueError(f"not a console script of this project: {program}")
    capsys.readouterr()
    with pytest.MonkeyPatch.context() as patch:
        for name in FRESH_PROCESS_STATE:  # what an earlier command in this process would have left
            patch.setattr(outputs, name, [])
        try:
            code, out, err = run_main(main, args, capsys)
        except Exception:
            out, err = capsys.readouterr()
            code, err = 1, err + traceback.format_exc()
    return subprocess.CompletedProcess(list(argv), code, out, err)


def run_script_captured(argv: Sequence[str]) -> subprocess.CompletedProcess[str]:
    """``run_script`` where no ``capsys`` is at hand (a module fixture): what the command writes to
    ``sys.stdout`` and ``sys.stderr`` is captured by redirecting them."""

    class Captured:
        def __init__(self) -> None:
            self.out, self.err = io.StringIO(), io.StringIO()

        def readouterr(self) -> tuple[str, str]:
            out, err = self.out.getvalue(), self.err.getvalue()
            for stream in (self.out, self.err):
                stream.seek(0)
                stream.truncate()
            return out, err

    captured = Captured()
    with contextlib.redirect_stdout(captured.out), contextlib.redirect_stderr(captured.err):
        return run_script(argv, captured)  # type: ignore[arg-type]


def run_script_with(
    argv: Sequence[str],
    env: dict[str, str],
    cwd: Path,
    monkeypatch: pytest.MonkeyPatch,
    capsys: pytest.CaptureFixture[str],
) -> subprocess.CompletedProcess[str]:
    """``run_script`` with the environment ``env`` (variables not in it unset) in the folder ``cwd``, as
    ``subprocess.run(argv, env=env, cwd=cwd)`` would run it; both are restored after the test."""
    for name in set(os.environ) - set(env):
        monkeypatch.delenv(name)
    for name, value in env.items():
        monkeypatch.setenv(name, value)
    monkeypatch.setenv("RUST_LOG", os.environ.get("RUST_LOG", "off"))  # gnnpmb-viz sets it for Rerun
    monkeypatch.chdir(cwd)
    return run_script(argv, capsys)


@contextlib.contextmanager
def umask(mask: int) -> Iterator[None]:
    """This process's file-creation mask set to ``mask`` (as a shell would have it for a new process), restored
    after."""
    before = os.umask(mask)
    try:
        yield
    finally:
        os.umask(before)
