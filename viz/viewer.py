"""The native Rerun viewer a live ``gnnpmb-viz`` run streams to: started, then checked to be alive and listening.

Rerun's own ``spawn`` reports success once it has started the viewer program, whether or not the viewer could open
a window; with a stale ``DISPLAY`` (an ``ssh -X`` session that is gone) the viewer exits at once and the run
either hangs or reports that it streamed to a viewer that never opened. Here the viewer is started as Rerun starts
it (``rerun --port P --memory-limit 75% ...``), its output kept, and the run goes on only once the viewer listens
on its port and is still running ``SETTLE_S`` later; ``check_alive`` asks again before the run reports success.
A viewer already listening on the port (one the user left open) is used as it is.
"""

from __future__ import annotations

import os
import re
import shutil
import socket
import subprocess
import tempfile
import time
from dataclasses import dataclass
from typing import IO

from gnnpmb.errors import GnnpmbError

VIEWER_PORT = 9876
"""Rerun's default port of the native viewer's gRPC server."""
START_DEADLINE_S = 30.0
"""How long the viewer may take to listen on its port."""
SETTLE_S = 1.0
"""How long the viewer must keep running once it listens (a viewer that cannot open its window exits sooner)."""
_SOURCE_AT = re.compile(r"os error at \S+:\d+: ")
"""Where in the viewer's source an OS error was raised (winit names its file and line)."""
_HINT = "write a recording with --save OUT.rrd (open it later with 'rerun OUT.rrd') or serve it with --serve"


class ViewerError(GnnpmbError):
    """The native viewer could not be started or stopped before the recording reached it."""


@dataclass(frozen=True, slots=True)
class Viewer:
    """A viewer listening on ``port``; ``process`` is None when it was already running (not started here)."""

    port: int
    process: subprocess.Popen[bytes] | None
    log: IO[bytes] | None

    @property
    def url(self) -> str:
        return f"rerun+http://127.0.0.1:{self.port}/proxy"

    def alive(self) -> bool:
        """The viewer started here still runs; one already there still listens."""
        return _listening(self.port) if self.process is None else self.process.poll() is None


def _listening(port: int) -> bool:
    with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as probe:
        probe.settimeout(0.5)
        return probe.connect_ex(("127.0.0.1", port)) == 0


def _display() -> str:
    shown = [f"{name}={os.environ[name]}" for name in ("DISPLAY", "WAYLAND_DISPLAY") if os.environ.get(name)]
    return " and ".join(shown) or "no display"


def _last_words(log: IO[bytes] | None) -> str:
    """The viewer's last error line (Rust log lines and ANSI colours left out), or ''."""
    if log is None:
        return ""
    log.seek(0)
    lines = [line.strip() for line in log.read().decode("utf-8", "replace").splitlines()]
    errors = [line for line in lines if line.startswith("Error") or "error" in line.lower()]
    last = (errors or lines or [""])[-1]
    return _SOURCE_AT.sub("", last.removeprefix("Error: "))[:200]


def start_viewer(port: int = VIEWER_PORT) -> Viewer:
    """A native viewer listening on ``port``: the one already there, else a new ``rerun`` process, checked alive
    ``SETTLE_S`` after it started listening. A ViewerError (one line, with the viewer's own reason) otherwise."""
    if _listening(port):
        return Viewer(port, None, None)
    program = shutil.which("rerun")
    if program is None:
        raise ViewerError(f"the Rerun viewer program 'rerun' is not on PATH (run through 'uv run'); or {_HINT}")
    log = tempfile.TemporaryFile()  # noqa: SIM115 (open while the viewer runs: it writes its messages there)
    limits = ["--memory-limit", "75%", "--server-memory-limit", "1GiB"]
    process = subprocess.Popen(
        [program, "--port", str(port), *limits, "--expect-data-soon"],
        stdin=subprocess.DEVNULL,
        stdout=log,
        stderr=log,
        env={**os.environ, "RERUN_APP_ONLY": "true"},
        start_new_session=True,  # the viewer outlives this run and its Ctrl-C
    )
    viewer = Viewer(port, process, log)
    deadline = time.monotonic() + START_DEADLINE_S
    while viewer.alive() and not _listening(port):
        if time.monotonic() > deadline:
            process.kill()
            raise ViewerError(f"the Rerun viewer did not start within {START_DEADLINE_S:.0f} s; {_HINT}")
        time.sleep(0.05)
    settled = time.monotonic() + SETTLE_S
    while viewer.alive() and time.monotonic() < settled:
        time.sleep(0.05)
    check_alive(viewer)
    return viewer


def check_alive(viewer: Viewer) -> None:
    """A ViewerError if the viewer has exited (it could not open its window, or was closed)."""
    if viewer.alive():
        return
    if viewer.process is None:
        raise ViewerError(f"the Rerun viewer on port {viewer.port} was closed before the recording reached it")
    reason = _last_words(viewer.log)
    raise ViewerError(
        f"the Rerun viewer exited ({reason or f'exit code {viewer.process.returncode}'}) on {_display()}; "
        f"is that display reachable (a stale 'ssh -X' session?)? Or {_HINT}"
    )
