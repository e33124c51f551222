"""CPU seconds per test, for finding what makes the suite slow on a shared machine (wall times there mostly
measure the neighbours).

Load it as a plugin with a folder to write to, then sum, and (``--write``) refresh the modules' costs that
``tests/conftest.py`` orders the modules by::

    CPULOG_DIR=/tmp/cpu bash scripts/test.sh -p tests.cpu_log
    uv run python -m tests.cpu_log /tmp/cpu [--write tests/module_cpu_s.json]

Each test's line is the CPU time of its worker process and of the child processes it waited for (the console
scripts run in real processes; not Chromium's renderer and GPU processes, which Chromium does not reap before it
is killed), from the start of its setup to the end of its teardown: a module fixture counts in its first test;
then that of the children alone (what starting real processes costs: each imports the stack again).
"""

from __future__ import annotations

import argparse
import collections
import json
import os
import resource
import sys
import time
from pathlib import Path

import pytest


def _cpu_s() -> tuple[float, float]:
    """CPU seconds of this process and of the child processes it waited for, and of those children alone."""
    own, children = resource.getrusage(resource.RUSAGE_SELF), resource.getrusage(resource.RUSAGE_CHILDREN)
    child_s = children.ru_utime + children.ru_stime
    return own.ru_utime + own.ru_stime + child_s, child_s


@pytest.hookimpl(hookwrapper=True)
def pytest_runtest_protocol(item: pytest.Item, nextitem: pytest.Item | None):
    folder = os.environ.get("CPULOG_DIR")
    (cpu_s, child_s), wall_s = _cpu_s(), time.monotonic()
    yield
    if folder:
        Path(folder).mkdir(parents=True, exist_ok=True)
        cpu_after, child_after = _cpu_s()
        cells = [f"{cpu_after - cpu_s:.3f}", f"{time.monotonic() - wall_s:.3f}", f"{child_after - child_s:.3f}"]
        with open(Path(folder) / f"{os.getpid()}.tsv", "a") as f:
            f.write("\t".join([item.nodeid, *cells]) + "\n")


def _rows(folder: Path) -> list[tuple[str, float, float, float]]:
    """(test, CPU s, wall s, CPU s of its child processes) per line; logs without the last column count 0 there."""
    rows = []
    for path in sorted(folder.glob("*.tsv")):
        for line in path.read_text().splitlines():
            nodeid, cpu_s, wall_s, *child = line.split("\t")
            rows.append((nodeid, float(cpu_s), float(wall_s), float(child[0]) if child else 0.0))
    return rows


def module_cpu_s(folder: Path) -> dict[str, float]:
    """CPU seconds per test module (its tests summed, module fixtures included), costliest first."""
    modules: collections.Counter[str] = collections.Counter()
    for nodeid, cpu_s, _, _ in _rows(folder):
        modules[nodeid.split("::")[0]] += cpu_s
    return {name: round(cpu_s, 1) for name, cpu_s in modules.most_common()}


def summary(folder: Path, most: int = 30) -> str:
    """The number of tests, their CPU and wall seconds summed, and the ``most`` costliest modules and tests."""
    rows = _rows(folder)
    modules: dict[str, list[float]] = collections.defaultdict(lambda: [0.0, 0.0, 0.0, 0])
    for nodeid, cpu_s, wall_s, child_s in rows:
        module = modules[nodeid.split("::")[0]]
        module[0] += cpu_s
        module[1] += wall_s
        module[2] += child_s
        module[3] += 1
    total = f"{sum(r[1] for r in rows):.1f} s CPU ({sum(r[3] for r in rows):.1f} in child processes)"
    lines = [f"{len(rows)} tests: {total}, {sum(r[2] for r in rows):.1f} s wall summed"]
    lines.append("modules by CPU (s CPU, s wall, s CPU of child processes, tests):")
    for name, (cpu_s, wall_s, child_s, n) in sorted(modules.items(), key=lambda kv: -kv[1][0])[:most]:
        lines.append(f"{cpu_s:8.1f} {wall_s:8.1f} {child_s:8.1f} {int(n):5d}  {name}")
    lines.append("tests by CPU (s CPU, s wall, s CPU of child processes):")
    for nodeid, cpu_s, wall_s, child_s in sorted(rows, key=lambda r: -r[1])[:most]:
        lines.append(f"{cpu_s:8.1f} {wall_s:8.1f} {child_s:8.1f}  {nodeid}")
    return "\n".join(lines)


def main(argv: list[str]) -> None:
    parser = argparse.ArgumentParser(prog="python -m tests.cpu_log", description=__doc__.split("\n\n")[0])
    parser.add_argument("folder", type=Path, help="the CPULOG_DIR of a suite run")
    parser.add_argument("most", type=int, nargs="?", default=30, help="modules and tests to list")
    parser.add_argument("--write", type=Path, help="write the modules' CPU seconds to this JSON file")
    args = parser.parse_args(argv)
    print(summary(args.folder, args.most))
    if args.write:
        tmp = args.write.with_name(f".{args.write.name}.partial")
        tmp.write_text(json.dumps(module_cpu_s(args.folder), indent=0) + "\n")
        os.replace(tmp, args.write)


if __name__ == "__main__":
    main(sys.argv[1:])
