"""The served web viewer of ``gnnpmb-viz --serve`` (``gnnpmb.serve.ServeTarget``): a recording stream served
over gRPC with Rerun's web viewer, kept alive until Ctrl-C.

Rerun 0.41: a ``GrpcServerSink`` on the stream serves it on the target's bind address and buffers the log for
viewers that connect late; it stops when the stream is disconnected. ``rerun.serve_web_viewer`` has no bind
address (it listens on every interface), so the web viewer's HTML/Wasm is hosted by the ``rerun`` program of
``rerun-sdk`` instead (``rerun --serve-web --bind ADDRESS --web-viewer-port PORT URI``: with a URI it starts
no gRPC server of its own), a child process that ends with this one.
"""

from __future__ import annotations

import contextlib
import signal
import socket
import subprocess
import sys
import time
from collections.abc import Iterator
from pathlib import Path

import rerun as rr
import rerun.blueprint as rrb

from gnnpmb.errors import GnnpmbError
from gnnpmb.serve import ServeTarget
from viz.recording import APPLICATION_ID, BATCHER

_SERVED: list[tuple[rr.RecordingStream, subprocess.Popen[bytes] | None]] = []
"""Streams kept alive (their gRPC servers serving), with their web viewer process, until ``wait_for_ctrl_c``."""


@contextlib.contextmanager
def serving(name: str, target: ServeTarget, blueprint: rrb.BlueprintLike | None) -> Iterator[rr.RecordingStream]:
    """A new recording stream named ``name`` served over gRPC with the web viewer on ``target``; the URL is
    printed on stderr once the viewer answers. On success the stream stays open until ``wait_for_ctrl_c``; on an
    error it is disconnected (the servers stop)."""
    stream = rr.RecordingStream(APPLICATION_ID, batcher_config=BATCHER)
    stream.set_log_time_enabled(False)
    stream.send_recording_name(name)
    viewer = None
    try:
        stream.set_sinks(rr.GrpcServerSink(bind_ip=target.bind, port=target.grpc_port), default_blueprint=blueprint)
        viewer = _start_web_viewer(target)
    except Exception as exc:
        stream.disconnect()
        _stop(viewer)
        raise GnnpmbError(f"cannot serve the web viewer: {exc}") from None
    print(f"web viewer: {target.url}", file=sys.stderr, flush=True)
    try:
        yield stream
    except BaseException:
        stream.disconnect()
        _stop(viewer)
        raise
    stream.flush()
    _SERVED.append((stream, viewer))


WEB_VIEWER_START_S = 30.0
"""How long the ``rerun`` program may take to answer on the web viewer's port."""


def _start_web_viewer(target: ServeTarget) -> subprocess.Popen[bytes]:
    """The ``rerun`` child process hosting the web viewer on ``target.bind``, once its port answers."""
    argv = [str(_rerun_program()), "--serve-web", "--bind", target.bind]
    argv += ["--web-viewer-port", str(target.web_port), target.grpc_uri]
    child = subprocess.Popen(
        argv, stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, preexec_fn=_end_with_parent
    )
    deadline = time.monotonic() + WEB_VIEWER_START_S
    while True:
        with contextlib.suppress(OSError):
            socket.create_connection((target.host.strip("[]"), target.web_port), timeout=1.0).close()
            return child
        if child.poll() is not None or time.monotonic() > deadline:
            _stop(child)
            detail = (child.stderr.read() if child.stderr else b"").decode(errors="replace").strip().splitlines()
            raise RuntimeError(f"the rerun web viewer did not start ({detail[-1] if detail else 'no output'})")
        time.sleep(0.1)


def _rerun_program() -> Path:
    """The ``rerun`` binary of the installed ``rerun-sdk`` (not its Python wrapper script, which would run it as a
    grandchild that outlives this process)."""
    import rerun_cli

    return Path(rerun_cli.__file__).parent / ("rerun.exe" if sys.platform.startswith("win") else "rerun")


def _end_with_parent() -> None:
    """In the child: receive SIGTERM when this process dies, even by SIGKILL (Linux), and ignore Ctrl-C (the
    parent stops the child itself)."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    if sys.platform.startswith("linux"):
        import ctypes

        pr_set_pdeathsig = 1
        ctypes.CDLL(None).prctl(pr_set_pdeathsig, signal.SIGTERM)


def _stop(child: subprocess.Popen[bytes] | None) -> None:
    if child is None or child.poll() is not None:
        return
    child.terminate()
    try:
        child.wait(timeout=10)
    except subprocess.TimeoutExpired:
        child.kill()
        child.wait()


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
            stream, viewer = _SERVED.pop()
            stream.disconnect()
            _stop(viewer)
