"""Where a live ``gnnpmb-viz`` run is shown: the spawned native viewer needs a display; ``--serve`` serves the
Rerun web viewer instead (HTTP on ``web_port``) reading the recording from an in-process gRPC server
(``grpc_port``), and prints the URL to open (on a remote machine: forward both ports, e.g. ``ssh -L``).

This module checks the request (ports, display); ``viz.serving`` opens the served stream.
"""

from __future__ import annotations

import errno
import os
import socket
import sys
from dataclasses import dataclass
from urllib.parse import quote

from gnnpmb.errors import GnnpmbError

DEFAULT_WEB_PORT = 9090
DEFAULT_GRPC_PORT = 9876
"""Rerun's own defaults for the web viewer's HTTP port and the gRPC data port."""


@dataclass(frozen=True, slots=True)
class ServeTarget:
    """The two TCP ports of ``--serve``: the web viewer's HTTP port and the gRPC port it reads data from."""

    web_port: int
    grpc_port: int

    @property
    def grpc_uri(self) -> str:
        return f"rerun+http://localhost:{self.grpc_port}/proxy"

    @property
    def url(self) -> str:
        """The URL to open in a browser: the web viewer, told where the data is."""
        return f"http://localhost:{self.web_port}/?url={quote(self.grpc_uri, safe='')}"


def check_display() -> None:
    """On Linux, a GnnpmbError unless an X11 or Wayland display is set: the spawned viewer needs one (without it,
    Rerun waits for a viewer that never starts and the run hangs)."""
    if not sys.platform.startswith("linux"):
        return
    if os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY"):
        return
    raise GnnpmbError(
        "no display (DISPLAY and WAYLAND_DISPLAY are unset), so the Rerun viewer cannot open; write a recording "
        "with --save OUT.rrd (open it later with 'rerun OUT.rrd') or serve the web viewer with --serve"
    )


def check_serve_ports(target: ServeTarget) -> None:
    """A GnnpmbError naming the option if a port is out of range, the two are equal, or one is in use."""
    for option, port in (("--web-port", target.web_port), ("--grpc-port", target.grpc_port)):
        if not 1 <= port <= 65535:
            raise GnnpmbError(f"{option} {port}: a TCP port is a number from 1 to 65535")
    if target.web_port == target.grpc_port:
        raise GnnpmbError(f"--web-port and --grpc-port are both {target.web_port}; give them different ports")
    for option, port in (("--web-port", target.web_port), ("--grpc-port", target.grpc_port)):
        with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as probe:
            try:
                probe.bind(("0.0.0.0", port))
            except OSError as exc:
                reason = "is in use" if exc.errno == errno.EADDRINUSE else f"cannot be opened ({exc.strerror})"
                raise GnnpmbError(
                    f"{option} {port}: the port {reason} (another gnnpmb-viz --serve or Rerun viewer?); "
                    f"pass {option} with a free port"
                ) from None
