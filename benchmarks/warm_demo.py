"""The warm demo command's time: ``gnnpmb-viz scene-0103 --save demo.rrd`` with every cache warm (issue 30: at
most 2 s wall on 2 cores).

Warm means what a second run of the command finds: the demo dataset generated, its indexes built, the failure
report of the same tracks stored (``gnnpmb.eval.failure_cache``) and Python's bytecode written (the command is
run with ``PYTHONDONTWRITEBYTECODE`` unset). One run warms them, then ``--runs`` runs are timed, one after the
other, each as a user types it. Per run: wall seconds, CPU seconds
(user + sys of the command and every child it waited for, from ``os.wait4``), peak resident MiB and the 1-minute
load average before it (other work on a shared machine shows there); then the medians.

    uv run python benchmarks/warm_demo.py [--runs 5] [--scene scene-0103] [-- more gnnpmb-viz options]
"""

from __future__ import annotations

import argparse
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

COMMAND = Path(sys.executable).parent / "gnnpmb-viz"


def run_once(argv: list[str]) -> tuple[float, float, float]:
    """Wall seconds, CPU seconds (user + sys, children included) and peak resident MiB of one run."""
    env = {k: v for k, v in os.environ.items() if k != "PYTHONDONTWRITEBYTECODE"}
    start = time.perf_counter()
    proc = subprocess.Popen(argv, env=env, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    _, status, usage = os.wait4(proc.pid, 0)
    wall_s = time.perf_counter() - start
    proc.returncode = os.waitstatus_to_exitcode(status)
    err = proc.stderr.read().decode() if proc.stderr is not None else ""
    if proc.returncode != 0:
        raise SystemExit(f"{' '.join(argv)} exited with {proc.returncode}:\n{err}")
    return wall_s, usage.ru_utime + usage.ru_stime, usage.ru_maxrss / 1024


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--runs", type=int, default=5)
    parser.add_argument("--scene", default="scene-0103")
    parser.add_argument("extra", nargs="*", help="more gnnpmb-viz options (after --)")
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        out = Path(tmp) / "demo.rrd"
        argv = [str(COMMAND), args.scene, "--save", str(out), *args.extra]
        run_once(argv)  # warms the dataset, indexes, failure report and bytecode
        print(f"{' '.join([COMMAND.name, *argv[1:]])} (warm), {os.cpu_count()} cores")
        print("run  load  wall s  cpu s  peak MiB")
        rows = []
        for k in range(args.runs):
            load = os.getloadavg()[0]
            rows.append(run_once(argv))
            print(f"{k + 1:>3}  {load:4.1f}  {rows[-1][0]:6.2f}  {rows[-1][1]:5.2f}  {rows[-1][2]:8.0f}")
        wall, cpu, peak = (statistics.median(column) for column in zip(*rows, strict=True))
        print(f"median      {wall:6.2f}  {cpu:5.2f}  {peak:8.0f}")


if __name__ == "__main__":
    main()
