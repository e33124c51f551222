"""The served web viewer of ``gnnpmb-viz --serve`` (``gnnpmb.serve.ServeTarget``): a recording stream served
over gRPC with Rerun's web viewer, kept alive until Ctrl-C.

Rerun 0.41: ``RecordingStream.serve_grpc`` buffers the log for viewers that connect late and stops when the
stream is disconnected; ``rerun.serve_web_viewer(connect_to=...)`` hosts the viewer's HTML/Wasm.
"""

from __future__ import annotations

import contextlib
import sys
import time
from collections.abc import Iterator

import rerun as rr
import rerun.blueprint as rrb

from gnnpmb.errors import GnnpmbError
from gnnpmb.serve import ServeTarget
from viz.recording import APPLICATION_ID, BATCHER

_SERVED: list[rr.RecordingStream] = []
"""Streams kept alive (their gRPC servers serving) until ``wait_for_ctrl_c``."""


@contextlib.contextmanager
def serving(name: str, target: ServeTarget, blueprint: rrb.BlueprintLike | None) -> Iterator[rr.RecordingStream]:
    """A new recording stream named ``name`` served over gRPC with the web viewer on ``target``; the URL is
    printed on stderr at once. On success the stream stays open until ``wait_for_ctrl_c``; on an error it is
    disconnected (the servers stop)."""
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
