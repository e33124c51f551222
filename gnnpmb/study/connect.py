"""Joining a Ray cluster within a bounded time, and Ray's own messages kept out of the user's terminal.

Ray retries a head that does not answer for minutes, printing a warning every few seconds, and an address that
answers but is no Ray head (another service, an HTTP proxy) keeps it waiting too. So before Ray is asked,
``probe_head`` checks within ``PROBE_TIMEOUT_S`` that the address accepts a connection and speaks HTTP/2 the way
the gRPC servers of a Ray head do (``ray start --head``'s GCS port, and ``ray://`` client servers): it answers the
HTTP/2 connection preface with a SETTINGS frame. Then ``init_within`` gives ``ray.init`` what is left of
``JOIN_DEADLINE_S`` and ends the run with one error line if it has not joined by then.

Ray's C++ core writes its log lines straight to file descriptor 2. ``quiet_stderr`` points that descriptor at a
temporary file while Ray runs (``--verbose`` leaves it alone); Python's ``sys.stderr``, where this program's own
lines and progress bar go, stays on the terminal.
"""

from __future__ import annotations

import contextlib
import io
import os
import socket
import sys
import tempfile
import threading
import time
from collections.abc import Callable, Iterator
from typing import Any

from gnnpmb.errors import GnnpmbError

PROBE_TIMEOUT_S = 5.0
"""How long the address has to accept a connection and answer the HTTP/2 preface."""
JOIN_DEADLINE_S = 30.0
"""How long joining a cluster may take in all, the probe included."""
_EXIT_USER_ERROR = 2
"""Exit code of a run ended by ``init_within`` (the CLI's code for a user's mistake)."""
_PREFACE = b"PRI * HTTP/2.0\r\n\r\nSM\r\n\r\n" + bytes([0, 0, 0, 4, 0, 0, 0, 0, 0])
"""The HTTP/2 client connection preface and an empty SETTINGS frame (RFC 9113, 3.4)."""
_SETTINGS = 4
_HINT = "start it with 'ray start --head' on the head node (its port, default 6379), or drop --address / RAY_ADDRESS"


def _answer(conn: socket.socket, deadline: float) -> bytes:
    """What the server sends back: an HTTP/2 frame header (9 bytes), else up to its first line (80 bytes);
    whatever came before ``deadline`` (a TimeoutError if nothing did)."""
    head = b""
    while len(head) < 9 or (head[3] != _SETTINGS and b"\n" not in head and len(head) < 80):
        conn.settimeout(max(0.05, deadline - time.monotonic()))
        try:
            chunk = conn.recv(80 - len(head))
        except TimeoutError:
            if head:
                break
            raise
        if not chunk:
            break
        head += chunk
    return head


def probe_head(address: str, host: str, port: int, timeout_s: float = PROBE_TIMEOUT_S) -> None:
    """A GnnpmbError (one line) unless ``host:port`` answers like a Ray head within ``timeout_s``."""
    deadline = time.monotonic() + timeout_s
    try:
        with socket.create_connection((host, port), timeout=timeout_s) as conn:
            conn.sendall(_PREFACE)
            head = _answer(conn, deadline)
    except TimeoutError:
        raise GnnpmbError(
            f"cannot reach the Ray cluster at {address}: no answer within {timeout_s:.0f} s (not a Ray head?); {_HINT}"
        ) from None
    except OSError as exc:
        raise GnnpmbError(
            f"cannot reach the Ray cluster at {address} ({exc.strerror or type(exc).__name__}); {_HINT}"
        ) from None
    if len(head) < 9 or head[3] != _SETTINGS:
        first = (head.splitlines() or [b""])[0].decode("ascii", "replace")
        seen = "".join(c for c in first if c.isprintable()).strip() or "it closed the connection"
        raise GnnpmbError(
            f"cannot reach the Ray cluster at {address}: it answers, but not as a Ray head does (got "
            f"'{seen[:40]}'; another service or a proxy?); {_HINT}"
        )


def _give_up(address: str, deadline_s: float) -> None:
    print(
        f"error: cannot join the Ray cluster at {address} within {deadline_s:.0f} s; is it a Ray head of this Ray "
        f"version? {_HINT}",
        file=sys.stderr,
        flush=True,
    )
    os._exit(_EXIT_USER_ERROR)  # ray.init cannot be interrupted; nothing has been written yet


def init_within(init: Callable[..., Any], address: str, deadline_s: float = JOIN_DEADLINE_S, **kwargs: Any) -> None:
    """``init(address=address, **kwargs)`` (``ray.init``); if it has not returned after ``deadline_s``, the run
    ends with one error line and exit code 2."""
    watchdog = threading.Timer(deadline_s, _give_up, (address, deadline_s))
    watchdog.daemon = True
    watchdog.start()
    try:
        init(address=address, **kwargs)
    finally:
        watchdog.cancel()


def _on_fd2(stream: Any) -> bool:
    try:
        return stream.fileno() == 2
    except (AttributeError, OSError, ValueError):
        return False


@contextlib.contextmanager
def quiet_stderr(verbose: bool) -> Iterator[None]:
    """File descriptor 2 to a temporary file for the block (unless ``verbose``), ``sys.stderr`` on the terminal."""
    if verbose:
        yield
        return
    sys.stderr.flush()
    terminal = os.dup(2)
    saved = sys.stderr
    with tempfile.TemporaryFile() as log:
        os.dup2(log.fileno(), 2)
        if _on_fd2(saved):  # else (e.g. captured in a test) it does not write to descriptor 2 anyway
            encoding = getattr(saved, "encoding", None) or "utf-8"
            sys.stderr = io.TextIOWrapper(
                io.FileIO(terminal, "w", closefd=False),
                encoding=encoding,
                errors="backslashreplace",
                line_buffering=True,
            )
        try:
            yield
        finally:
            with contextlib.suppress(OSError, ValueError):
                sys.stderr.flush()
            sys.stderr = saved
            os.dup2(terminal, 2)
            os.close(terminal)
