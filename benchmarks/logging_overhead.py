"""Tracker alone vs tracker + Rerun logger, per frame, on the same demo frames (issue: logging overhead <= 1.5x).

Each tracker runs over a demo scene without a sink, with a ``ListSink`` (the events are built, nothing is
drawn: what the tracker itself pays for being watched) and with a ``TrackerLogger`` writing a recording to a temp
file (opening, ``finish`` and closing included), the way ``gnnpmb-viz --save`` does (rows sent at the end;
``--live``: every ``FLUSH_FRAMES`` frames, as for a viewer), the three modes interleaved, three times. The best
wall time and the best CPU time of the process (all threads: Rerun's writer too; the fairer figure on a shared
machine) per mode are printed as ms per frame with the ratios to the tracker alone, plus the recording's chunk
count. "sending" is the wall time per frame of the logger's ``finish`` and closing the recording alone (no
drawing; with ``--live`` only the last rows), "budget" what the logger may take per frame on top of the events
for tracker + logger <= 1.5x the tracker alone (wall). Everything loaded before the runs is frozen out of the
garbage collector's reach, as ``gnnpmb-viz`` does (``gnnpmb.stages.inputs.freeze_loaded``).

    uv run python benchmarks/logging_overhead.py [--scene scene-0103] [--detector centerpoint] [--tracker gnnpmb]
        [--live]
"""

from __future__ import annotations

import argparse
import gc
import tempfile
import time
from dataclasses import dataclass
from pathlib import Path

from rerun.chunk import RrdReader

from gnnpmb.config import TrackerConfig
from gnnpmb.data.demo import ensure_demo_dataset
from gnnpmb.data.nuscenes import load_scene, resolve_dataroot
from gnnpmb.events import ListSink
from gnnpmb.pipeline import get_detections, preprocess_frames, run_tracker
from gnnpmb.registry import tracker_has_existence
from gnnpmb.types import TRACKING_CLASSES
from viz.logger import FLUSH_FRAMES, TrackerLogger
from viz.recording import close_recording, open_recording


@dataclass(frozen=True, slots=True)
class Timing:
    """Seconds of one run: wall clock and CPU of this process (all its threads, Rerun's writer included), and
    for a logger run the wall clock of sending alone (``finish`` and closing the recording: the rows are built,
    converted to Arrow and written; no drawing)."""

    wall_s: float
    cpu_s: float
    send_s: float = 0.0

    @staticmethod
    def best(runs: list[Timing]) -> Timing:
        return Timing(min(r.wall_s for r in runs), min(r.cpu_s for r in runs), min(r.send_s for r in runs))


def timed_run(
    scene, frames, tracker: str, config: TrackerConfig, mode: str, out: Path, flush_frames: int | None
) -> Timing:
    """One run: ``alone`` (no sink), ``events`` (``ListSink``: built, not drawn) or ``logger`` (a recording
    saved to ``out``, opening, ``finish`` and closing included)."""
    wall, cpu = time.perf_counter(), time.process_time()
    if mode == "alone":
        run_tracker(scene, frames, tracker, config)
    elif mode == "events":
        run_tracker(scene, frames, tracker, config, sink=ListSink())
    else:
        stream = open_recording("bench", out, None)
        logger = TrackerLogger(stream, tracker, flush_frames=flush_frames, has_existence=tracker_has_existence(tracker))
        run_tracker(scene, frames, tracker, config, sink=logger)
        send = time.perf_counter()
        logger.finish()
        close_recording(stream, out)
        return Timing(time.perf_counter() - wall, time.process_time() - cpu, time.perf_counter() - send)
    return Timing(time.perf_counter() - wall, time.process_time() - cpu)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--scene", default="scene-0103")
    parser.add_argument("--detector", default="centerpoint")
    parser.add_argument("--tracker", action="append", default=None)
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--live", action="store_true", help=f"send rows every {FLUSH_FRAMES} frames (live viewer)")
    args = parser.parse_args()
    ensure_demo_dataset()
    location = resolve_dataroot(None, None)
    scene = load_scene(location, args.scene)
    config = TrackerConfig()
    detections = get_detections(scene, None, args.detector, 0)
    frames = preprocess_frames(scene, detections, config, TRACKING_CLASSES)
    gc.collect()
    gc.freeze()  # as gnnpmb.stages.inputs.load_inputs does: no full collection walks the devkit's tables mid-run
    n = len(scene.keyframes)
    flush_frames = FLUSH_FRAMES if args.live else None
    mode = f"rows sent every {FLUSH_FRAMES} frames (live)" if args.live else "rows sent at the end (--save)"
    print(f"{args.scene}, {args.detector}, {n} frames, best of {args.repeats} (runs interleaved), {mode}")
    print("ms per frame, wall clock / CPU time of the process; ratios to the tracker alone")
    print(
        f"{'tracker':8} {'alone':>13} {'+ events':>13} {'ratio':>11} {'+ logger':>13} {'ratio':>11} {'chunks':>7} "
        f"{'sending':>8} {'budget':>7}"
    )
    modes = ("alone", "events", "logger")
    with tempfile.TemporaryDirectory() as tmp:
        for tracker in args.tracker or ["gnnpmb", "pmbm", "gnn"]:
            out = Path(tmp) / f"{tracker}.rrd"
            runs: dict[str, list[Timing]] = {m: [] for m in modes}
            for _ in range(args.repeats):  # interleaved, so a change of load hits every mode alike
                for m in modes:
                    runs[m].append(timed_run(scene, frames, tracker, config, m, out, flush_frames))
            alone, events, logged = (Timing.best(runs[m]) for m in modes)
            chunks = sum(1 for _ in RrdReader(out).store().stream())
            # What the logger may cost on top of the events for tracker + logger <= 1.5x the tracker alone.
            budget_ms = 1000 * (1.5 * alone.wall_s - events.wall_s) / n
            print(
                f"{tracker:8} {_ms(alone, n)} {_ms(events, n)} {_ratio(events, alone)} {_ms(logged, n)} "
                f"{_ratio(logged, alone)} {chunks:7d} {1000 * logged.send_s / n:8.2f} {budget_ms:7.2f}"
            )


def _ms(t: Timing, n_frames: int) -> str:
    return f"{1000 * t.wall_s / n_frames:6.2f}/{1000 * t.cpu_s / n_frames:6.2f}"


def _ratio(t: Timing, alone: Timing) -> str:
    return f"{t.wall_s / alone.wall_s:5.2f}/{t.cpu_s / alone.cpu_s:5.2f}"


if __name__ == "__main__":
    main()
