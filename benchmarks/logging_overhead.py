"""Tracker alone vs tracker + Rerun logger, per frame, on the same demo frames (issue: logging overhead <= 1.5x).

Each tracker runs over a demo scene three times without a sink, three times with a ``ListSink`` (the events
are built, nothing is drawn: what the tracker itself pays for being watched) and three times with a
``TrackerLogger`` writing a recording to a temp file (opening, ``finish`` and closing included), the way
``gnnpmb-viz --save`` does (rows sent at the end; ``--live``: every ``FLUSH_FRAMES`` frames, as for a viewer).
The best of three wall times per mode is printed as ms per frame with the ratios to the tracker alone, plus the
recording's chunk count.

    uv run python benchmarks/logging_overhead.py [--scene scene-0103] [--detector centerpoint] [--tracker gnnpmb]
        [--live]
"""

from __future__ import annotations

import argparse
import tempfile
import time
from pathlib import Path

from rerun.chunk import RrdReader

from gnnpmb.config import TrackerConfig
from gnnpmb.data.demo import ensure_demo_dataset
from gnnpmb.data.nuscenes import load_scene, open_nuscenes, resolve_dataroot
from gnnpmb.events import ListSink
from gnnpmb.pipeline import get_detections, preprocess_frames, run_tracker
from gnnpmb.types import TRACKING_CLASSES
from viz.logger import FLUSH_FRAMES, TrackerLogger
from viz.recording import close_recording, open_recording


def timed_run(
    scene, detections, frames, tracker: str, config: TrackerConfig, out: Path | None, flush_frames: int | None
) -> float:
    """Wall seconds of one run; with ``out`` the run logs into a recording saved there."""
    start = time.perf_counter()
    if out is None:
        run_tracker(scene, detections, tracker, config, frame_detections=frames)
        return time.perf_counter() - start
    stream = open_recording("bench", out, None)
    logger = TrackerLogger(stream, tracker, flush_frames=flush_frames)
    run_tracker(scene, detections, tracker, config, sink=logger, frame_detections=frames)
    logger.finish()
    close_recording(stream, out)
    return time.perf_counter() - start


def events_run(scene, detections, frames, tracker: str, config: TrackerConfig) -> float:
    """Wall seconds of one run whose events are built and kept (``ListSink``), not drawn."""
    start = time.perf_counter()
    run_tracker(scene, detections, tracker, config, sink=ListSink(), frame_detections=frames)
    return time.perf_counter() - start


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
    scene = load_scene(open_nuscenes(location), location, args.scene)
    config = TrackerConfig()
    detections = get_detections(scene, None, args.detector, 0)
    frames = preprocess_frames(scene, detections, config, TRACKING_CLASSES)
    n = len(scene.keyframes)
    flush_frames = FLUSH_FRAMES if args.live else None
    mode = f"rows sent every {FLUSH_FRAMES} frames (live)" if args.live else "rows sent at the end (--save)"
    print(f"{args.scene}, {args.detector}, {n} frames, best of {args.repeats}, {mode}")
    print(
        f"{'tracker':8} {'alone ms/frame':>15} {'+ events ms/frame':>18} {'ratio':>6} "
        f"{'+ logger ms/frame':>18} {'ratio':>6} {'chunks':>7}"
    )
    with tempfile.TemporaryDirectory() as tmp:
        for tracker in args.tracker or ["gnnpmb", "pmbm", "gnn"]:
            out = Path(tmp) / f"{tracker}.rrd"
            repeats = range(args.repeats)
            alone = min(timed_run(scene, detections, frames, tracker, config, None, None) for _ in repeats)
            events = min(events_run(scene, detections, frames, tracker, config) for _ in repeats)
            logged = min(timed_run(scene, detections, frames, tracker, config, out, flush_frames) for _ in repeats)
            chunks = sum(1 for _ in RrdReader(out).store().stream())
            print(
                f"{tracker:8} {1000 * alone / n:15.2f} {1000 * events / n:18.2f} {events / alone:6.2f} "
                f"{1000 * logged / n:18.2f} {logged / alone:6.2f} {chunks:7d}"
            )


if __name__ == "__main__":
    main()
