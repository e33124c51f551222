"""Where a live ``gnnpmb-viz`` run is shown: the spawned native viewer needs a display; ``--serve`` serves the
Rerun web viewer instead (HTTP on ``web_port``) reading the recording from an in-process gRPC server
(``grpc_port``), and prints the URL to open (on a remote machine: forward both ports, e.g. ``ssh -L``).

Rerun 0.41: ``RecordingStream.serve_grpc`` buffers the log for viewers that connect late and stops when the
stream is disconnected; ``rerun.serve_web_viewer(connect_to=...)`` hosts the viewer's HTML/Wasm.
"""

from __future__ import annotations

import contextlib
import errno
import os
import socket
import sys
import time
from collections.abc import Iterator
from dataclasses import dataclass
from typing import TYPE_CHECKING
from urllib.parse import quote

from gnnpmb.errors import GnnpmbError

if TYPE_CHECKING:
    import rerun as rr
    import rerun.blueprint as rrb

DEFAULT_WEB_PORT = 9090
DEFAULT_GRPC_PORT = 9876
"""Rerun's own defaults for the web viewer's HTTP port and the gRPC data port."""

_SERVED: list[rr.RecordingStream] = []
"""Streams kept alive (their gRPC servers serving) until ``wait_for_ctrl_c``."""


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


@contextlib.contextmanager
def serving(name: str, target: ServeTarget, blueprint: rrb.BlueprintLike | None) -> Iterator[rr.RecordingStream]:
    """A new recording stream named ``name`` served over gRPC with the web viewer on ``target``; the URL is
    printed on stderr at once. On success the stream stays open until ``wait_for_ctrl_c``; on an error it is
    disconnected (the servers stop)."""
    import rerun as rr

    from viz.recording import APPLICATION_ID, BATCHER

    stream = rr.RecordingStream(APPLICATION_ID, batcher_config=BATCHER)
    stream.set_log_time_enabled(False)
    stream.send_recording_name(name)
    try:
        stream.serve_grpc(grpc_port=target.grpc_port, default_blueprint=blueprint)
        rr.serve_web_viewer(web_port=target.web_port, open_browser=False, connect_to=target.grpc_uri)
    except Exception as exc:
        stream.disconnect()
        raise GnnpmbError(f"cannot serve the web viewer: {exc}") from None
    print(f"web viewer: {target.url}", file=sys.stderr, flush=True)
    try:
        yield stream
    except BaseException:
        stream.disconnect()
        raise
    stream.flush()
    _SERVED.append(stream)


def wait_for_ctrl_c(target: ServeTarget) -> None:
    """Keep serving the finished recording until Ctrl-C, then stop the servers."""
    sys.stdout.flush()
    print(f"serving {target.url} (Ctrl-C to stop)", file=sys.stderr, flush=True)
    try:
        while True:
            time.sleep(1.0)
    except KeyboardInterrupt:
        pass
    finally:
        while _SERVED:
            _SERVED.pop().disconnect()
