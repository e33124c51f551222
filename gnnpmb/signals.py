"""SIGTERM handled like Ctrl-C: what ``timeout``, ``docker stop`` and job schedulers send stops a run the same way.

``install`` makes SIGTERM raise ``KeyboardInterrupt`` in the main thread, so every path that already cleans up
after Ctrl-C (a recording's temporary file deleted, a sweep's finished rows written, Ray's tasks stopped and
its local instance shut down) does the same after SIGTERM. Only the first SIGTERM interrupts: a second one while
cleaning up is ignored (SIGKILL is the way to stop at once). ``exit_code`` and ``stop_reason`` then tell the two
apart: 130 and "Ctrl-C" after SIGINT, 143 and "SIGTERM" after SIGTERM (128 + the signal number, as shells do).
Ray installs its own SIGTERM handler when it starts; ``reinstall`` puts this one back. Code that waits inside
Ray runs ``deferred``: SIGTERM is only recorded there, and ``check`` raises it where stopping is safe (an
interrupt in the middle of Ray's own calls can leave it unable to shut down cleanly).
"""

from __future__ import annotations

import contextlib
import signal
import threading
from collections.abc import Iterator
from types import FrameType

_state: dict[str, int | bool] = {"installed": False, "received": 0, "raised": False, "deferred": 0}


def _on_sigterm(signum: int, frame: FrameType | None) -> None:
    if _state["received"]:
        return
    _state["received"] = signum
    if not _state["deferred"]:
        check()


def check() -> None:
    """Raise ``KeyboardInterrupt`` if SIGTERM arrived and has not been raised yet (see ``deferred``)."""
    if _state["received"] and not _state["raised"]:
        _state["raised"] = True
        raise KeyboardInterrupt


@contextlib.contextmanager
def deferred() -> Iterator[None]:
    """Within the block SIGTERM is only recorded; the block calls ``check`` where it may stop."""
    _state["deferred"] = int(_state["deferred"]) + 1
    try:
        yield
    finally:
        _state["deferred"] = int(_state["deferred"]) - 1


def install() -> None:
    """Handle SIGTERM like Ctrl-C from now on (main thread only; elsewhere nothing changes)."""
    if threading.current_thread() is not threading.main_thread():
        return
    signal.signal(signal.SIGTERM, _on_sigterm)
    _state["installed"] = True


def reinstall() -> None:
    """Put the handler back if ``install`` ran (after a library such as Ray replaced it)."""
    if _state["installed"]:
        install()


def terminated() -> bool:
    """Whether SIGTERM stopped this run."""
    return _state["received"] == signal.SIGTERM


def exit_code() -> int:
    """The exit code of a stopped run: 143 after SIGTERM, else 130 (Ctrl-C)."""
    return 128 + (signal.SIGTERM if terminated() else signal.SIGINT)


def stop_reason() -> str:
    """What stopped the run, for the one line printed: "SIGTERM" or "Ctrl-C"."""
    return "SIGTERM" if terminated() else "Ctrl-C"
