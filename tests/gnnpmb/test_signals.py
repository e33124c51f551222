"""SIGTERM like Ctrl-C (``gnnpmb.signals``): raised at once, or where a deferring block checks for it."""

from __future__ import annotations

import os
import signal

import pytest

from gnnpmb import signals


@pytest.fixture
def installed(monkeypatch: pytest.MonkeyPatch):
    monkeypatch.setattr(signals, "_state", {"installed": False, "received": 0, "raised": False, "deferred": 0})
    previous = signal.getsignal(signal.SIGTERM)
    signals.install()
    yield
    signal.signal(signal.SIGTERM, previous)


def test_sigterm_is_a_keyboard_interrupt_once_and_says_so(installed: None) -> None:
    assert (signals.exit_code(), signals.stop_reason()) == (130, "Ctrl-C")
    with pytest.raises(KeyboardInterrupt):
        os.kill(os.getpid(), signal.SIGTERM)
    os.kill(os.getpid(), signal.SIGTERM)  # a second one while cleaning up is ignored
    assert signals.terminated() and (signals.exit_code(), signals.stop_reason()) == (143, "SIGTERM")


def test_a_deferring_block_stops_where_it_checks(installed: None) -> None:
    with signals.deferred():
        os.kill(os.getpid(), signal.SIGTERM)
        reached = True
    assert reached and signals.terminated()
    with pytest.raises(KeyboardInterrupt):
        signals.check()
    signals.check()  # raised once only
