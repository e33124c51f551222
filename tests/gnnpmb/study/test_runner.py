"""Execution settings and the cluster-address check (``gnnpmb.study.runner``); no Ray is started here."""

from __future__ import annotations

import os
import socket
import threading
import time

import pytest

from gnnpmb.errors import GnnpmbError
from gnnpmb.study.connect import probe_head
from gnnpmb.study.runner import Execution, check_address, execution, run_tasks


def test_workers_default_and_in_process_runs(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.delenv("RAY_ADDRESS", raising=False)
    assert execution(None, None) == Execution(workers=os.cpu_count() or 1)
    assert not execution(1, None).uses_ray and execution(2, None).uses_ray
    with pytest.raises(GnnpmbError, match="--workers must be at least 1"):
        execution(0, None)
    assert list(run_tasks(lambda x: x * x, [3, 4], Execution(workers=1))) == [(0, 9), (1, 16)]


class FakeHead:
    """A TCP server on localhost answering each connection with ``reply`` (bytes; None: nothing, ever)."""

    def __init__(self, reply: bytes | None) -> None:
        self.server = socket.socket()
        self.server.bind(("127.0.0.1", 0))
        self.server.listen()
        self.reply = reply
        self.address = f"127.0.0.1:{self.server.getsockname()[1]}"
        self.kept: list[socket.socket] = []
        threading.Thread(target=self._serve, daemon=True).start()

    def _serve(self) -> None:
        while True:
            try:
                conn, _ = self.server.accept()
            except OSError:
                return
            self.kept.append(conn)
            if self.reply is not None:
                conn.sendall(self.reply)

    def close(self) -> None:
        self.server.close()
        for conn in self.kept:
            conn.close()


HTTP2_SETTINGS = bytes([0, 0, 0, 4, 0, 0, 0, 0, 0])


def test_cluster_address_is_checked_before_ray(monkeypatch: pytest.MonkeyPatch) -> None:
    head = FakeHead(HTTP2_SETTINGS)  # a gRPC server (a Ray head) answers the HTTP/2 preface with SETTINGS
    try:
        check_address(head.address)
        monkeypatch.setenv("RAY_ADDRESS", head.address)
        run = execution(None, None)
        assert run == Execution(workers=None, address=head.address) and run.uses_ray
        assert execution(1, None).uses_ray  # one worker on a cluster still goes through Ray
    finally:
        head.close()
    with pytest.raises(GnnpmbError, match="cannot reach the Ray cluster at 127.0.0.1:1 "):
        check_address("127.0.0.1:1")
    with pytest.raises(GnnpmbError, match="must look like HOST:PORT"):
        check_address("somewhere")


@pytest.mark.parametrize(
    ("reply", "message"),
    [(None, "no answer within 1 s"), (b"HTTP/1.0 400 Bad request\r\n\r\n", "got 'HTTP/1.0 400 Bad request'")],
    ids=["silent", "http"],
)
def test_an_address_that_is_no_ray_head_is_refused_in_bounded_time(reply: bytes | None, message: str) -> None:
    head = FakeHead(reply)
    start = time.monotonic()
    try:
        with pytest.raises(GnnpmbError, match=message):
            probe_head(head.address, *head.address.split(":")[:1], int(head.address.split(":")[1]), timeout_s=1.0)
    finally:
        head.close()
    assert time.monotonic() - start < 3.0
