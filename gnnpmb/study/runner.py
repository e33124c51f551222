"""Where study tasks run: in this process (one worker, no Ray, for debugging) or as Ray tasks.

Ray runs locally by default (``ray.init(num_cpus=workers)``, no dashboard, quiet logs); with an address (or
``RAY_ADDRESS``) it joins an existing cluster, and ``workers`` caps how many tasks are in flight. An address
that does not answer like a Ray head within ``connect.PROBE_TIMEOUT_S`` is refused before Ray is asked (Ray
itself retries an unreachable head for minutes), and joining is bounded by ``connect.JOIN_DEADLINE_S``; Ray's
own log lines stay out of the terminal unless ``verbose`` (``connect``). Results are yielded as tasks finish;
Ctrl-C (or SIGTERM, ``gnnpmb.signals``) re-raises, so the caller keeps whatever already finished, and the tasks
still running end with the session (``ray.shutdown``: the local instance's workers are killed; on a cluster the
driver's job ends and Ray stops its tasks).
"""

from __future__ import annotations

import contextlib
import logging
import os
from collections.abc import Callable, Iterable, Iterator
from dataclasses import dataclass
from types import ModuleType
from typing import Any, TypeVar

from gnnpmb import signals
from gnnpmb.errors import GnnpmbError
from gnnpmb.study.connect import init_within, probe_head, quiet_stderr

T = TypeVar("T")
R = TypeVar("R")

ADDRESS_ENV = "RAY_ADDRESS"
_UV_HOOK_ENV = "RAY_ENABLE_UV_RUN_RUNTIME_ENV"
_UNCAPPED = 1 << 16
"""Tasks in flight when no cap is given (a cluster): Ray queues what its CPUs cannot start yet."""
_WAIT_S = 0.5
"""How long one wait for a finished task lasts before a SIGTERM is looked at."""


def import_ray() -> ModuleType:
    """``import ray`` with Ray's ``uv run`` hook off (unless the user set it): under ``uv run`` that hook copies
    the working directory (virtual environment included) to every worker and starts each worker through
    ``uv run``, which took minutes here; workers use the driver's Python (locally) or the one that ran
    ``ray start`` (on a cluster) instead."""
    os.environ.setdefault(_UV_HOOK_ENV, "0")
    import ray

    return ray


@dataclass(frozen=True, slots=True)
class Execution:
    """How to run: ``workers`` parallel tasks (1 = in this process, no Ray) and an optional cluster address.

    workers None (only with an address): no cap of our own, Ray fills the cluster's CPUs. verbose: let Ray's
    own log lines through to the terminal.
    """

    workers: int | None
    address: str | None = None
    verbose: bool = False

    @property
    def uses_ray(self) -> bool:
        return self.address is not None or (self.workers or 0) > 1


def execution(workers: int | None, address: str | None, verbose: bool = False) -> Execution:
    """Check ``--workers`` / ``--address`` (falling back to ``RAY_ADDRESS``). Default workers: the CPU count
    locally, no cap on a cluster."""
    address = address or os.environ.get(ADDRESS_ENV) or None
    if workers is not None and workers < 1:
        raise GnnpmbError(f"--workers must be at least 1, got {workers}")
    if address is not None:
        check_address(address)
    elif workers is None:
        workers = os.cpu_count() or 1
    return Execution(workers=workers, address=address, verbose=verbose)


def check_address(address: str) -> None:
    """Refuse a cluster address whose head does not answer (``host:port``, ``ray://host:port``; ``auto`` and
    ``local`` are left to Ray)."""
    if address in ("auto", "local"):
        return
    hostport = address.removeprefix("ray://")
    host, sep, port = hostport.rpartition(":")
    if not sep or not port.isdigit() or not host:
        raise GnnpmbError(f"Ray address '{address}' must look like HOST:PORT (e.g. 10.0.0.1:6379)")
    probe_head(address, host, int(port))


@contextlib.contextmanager
def ray_session(run: Execution) -> Iterator[None]:
    """A Ray connection for the duration of the block: reuse one that is already up (tests), else start a
    local instance with ``run.workers`` CPUs or join ``run.address`` (within ``connect.JOIN_DEADLINE_S``); shut
    down only what was started here. Ray's log lines go to a temporary file unless ``run.verbose``."""
    ray = import_ray()

    if ray.is_initialized():
        yield
        return
    quiet = {"include_dashboard": False, "logging_level": logging.ERROR, "log_to_driver": False}
    with quiet_stderr(run.verbose):
        if run.address is None:
            ray.init(num_cpus=run.workers, **quiet)
        else:
            try:
                init_within(ray.init, run.address, **quiet)
            except (ConnectionError, RuntimeError) as exc:
                detail = str(exc).splitlines()[0]
                raise GnnpmbError(f"cannot join the Ray cluster at {run.address}: {detail}") from None
        signals.reinstall()  # Ray sets its own SIGTERM handler, which exits without cleaning up
        try:
            yield
        finally:
            with signals.deferred():  # a SIGTERM during the shutdown stops the run once it is done
                ray.shutdown()
            signals.check()


def session(run: Execution) -> contextlib.AbstractContextManager[None]:
    """``ray_session(run)`` when the run uses Ray, else nothing to set up."""
    return ray_session(run) if run.uses_ray else contextlib.nullcontext()


def _unwrap(exc: BaseException) -> BaseException:
    """The user's error inside a failed Ray task (so it still prints as one line)."""
    cause = getattr(exc, "cause", None)
    return cause if isinstance(cause, GnnpmbError) else exc


def run_tasks(fn: Callable[[T], R], items: Iterable[T], run: Execution) -> Iterator[tuple[int, R]]:
    """``(index, fn(item))`` for every item, in finishing order; in this process when ``run.workers == 1``
    without an address, else as Ray tasks with at most ``run.workers`` in flight (one CPU each). ``items`` is
    consumed lazily, one item per task submitted (a task's inputs are read just before it is sent).

    Must be iterated inside ``ray_session(run)`` when ``run.uses_ray``. Closing the iterator early (or Ctrl-C)
    leaves the tasks still running to the session's end. They are not cancelled one by one: in Ray 2.60
    ``ray.cancel`` of a task whose result is arriving at that moment aborts the driver process (a failed
    ``RAY_CHECK``, "Tried to complete task that was not pending", in the driver's log only: the cancel-versus-reply
    race ray-project/ray#54798 fixed on the retry path), which ended a sweep stopped by SIGTERM with exit 1, no
    message and no results file.
    """
    if not run.uses_ray:
        for i, item in enumerate(items):
            yield i, fn(item)
        return
    ray = import_ray()
    remote = ray.remote(num_cpus=1, max_retries=0)(fn)
    cap = run.workers or _UNCAPPED
    pending: dict[Any, int] = {}
    queue = enumerate(items)
    left = True
    while left or pending:
        while left and len(pending) < cap:
            nxt = next(queue, None)
            if nxt is None:
                left = False
                break
            i, item = nxt
            pending[remote.remote(item)] = i
        if not pending:
            break
        with signals.deferred():  # SIGTERM stops the run here, not inside Ray's wait
            done, _ = ray.wait(list(pending), num_returns=1, timeout=_WAIT_S)
        signals.check()
        if not done:
            continue
        ref = done[0]
        i = pending.pop(ref)
        with signals.deferred():  # nor inside Ray's get
            try:
                result = ray.get(ref)
            except ray.exceptions.RayTaskError as exc:
                raise _unwrap(exc) from None
        signals.check()
        yield i, result
