"""Follow one tracker's reasoning in the terminal: a custom EventSink printing births, prunings and assignments.

Usage: uv run python examples/print_events.py [SCENE] [TRACKER]   (defaults: scene-0103 gnnpmb, demo data)
"""

from __future__ import annotations

import sys

from gnnpmb.config import TrackerConfig
from gnnpmb.data.nuscenes import load_scene, resolve_dataroot
from gnnpmb.events import Assignment, AxisKind, Born, Event, FrameStarted, Pruned
from gnnpmb.pipeline import get_detections, run_tracker


class PrintingSink:
    """An EventSink: trackers call ``emit`` for every event when ``enabled`` is true."""

    enabled = True

    def emit(self, event: Event) -> None:
        if isinstance(event, FrameStarted):
            print(f"--- frame {event.frame_index} (dt {event.dt_s:.2f} s)")
        elif isinstance(event, Born):
            for t, j, r in zip(event.track_ids, event.meas_indices, event.existence, strict=True):
                print(f"  {event.class_name:10s} born   track {t} from detection {j} (r={r:.3f})")
        elif isinstance(event, Pruned):
            print(f"  {event.class_name:10s} pruned track {event.track_id}: {event.reason.value}")
        elif isinstance(event, Assignment):
            on_tracks = [(r.ref, c.ref) for r, c in event.pairs if c.kind is AxisKind.TRACK]
            if on_tracks:
                pairs = ", ".join(f"det {j}->track {t}" for j, t in on_tracks)
                print(f"  {event.class_name:10s} assign {pairs}")


def main() -> None:
    scene_name = sys.argv[1] if len(sys.argv) > 1 else "scene-0103"
    tracker = sys.argv[2] if len(sys.argv) > 2 else "gnnpmb"
    location = resolve_dataroot(None, None)
    scene = load_scene(location, scene_name)
    detections = get_detections(scene, None, "centerpoint", seed=0)
    run_tracker(scene, detections, tracker, TrackerConfig(), sink=PrintingSink(), frame_range=range(0, 6))


if __name__ == "__main__":
    main()
