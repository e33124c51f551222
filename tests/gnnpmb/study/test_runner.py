"""Execution settings and the cluster-address check (``gnnpmb.study.runner``); no Ray is started here."""

from __future__ import annotations

import os
import socket

import pytest

from gnnpmb.errors import GnnpmbError
from gnnpmb.study.runner import Execution, check_address, execution, run_tasks


def test_workers_default_and_in_process_runs(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.delenv("RAY_ADDRESS", raising=False)
    assert execution(None, None) == Execution(workers=os.cpu_count() or 1)
    assert not execution(1, None).uses_ray and execution(2, None).uses_ray
    with pytest.raises(GnnpmbError, match="--workers must be at least 1"):
        execution(0, None)
    assert list(run_tasks(lambda x: x * x, [3, 4], Execution(workers=1))) == [(0, 9), (1, 16)]


def test_cluster_address_is_checked_before_ray(monkeypatch: pytest.MonkeyPatch) -> None:
    with socket.socket() as server:
        server.bind(("127.0.0.1", 0))
        server.listen()
        address = f"127.0.0.1:{server.getsockname()[1]}"
        check_address(address)
        monkeypatch.setenv("RAY_ADDRESS", address)
        run = execution(None, None)
        assert run == Execution(workers=None, address=address) and run.uses_ray
        assert execution(1, None).uses_ray  # one worker on a cluster still goes through Ray
    with pytest.raises(GnnpmbError, match="cannot reach the Ray cluster at 127.0.0.1:1 "):
        check_address("127.0.0.1:1")
    with pytest.raises(GnnpmbError, match="must look like HOST:PORT"):
        check_address("somewhere")
