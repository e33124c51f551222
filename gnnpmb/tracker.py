"""A multi-class tracker: one single-class tracker per nuScenes tracking class, sharing one id space.

The paper tracks every class separately (sec. V-B); ids are allocated from one counter so they are unique across
classes and the same input always gives the same ids.
"""

from __future__ import annotations

from collections.abc import Sequence

from gnnpmb.config import TrackerConfig
from gnnpmb.events import EventSink, MeasurementsReceived
from gnnpmb.registry import check_classes, check_tracker, make_class_tracker
from gnnpmb.types import TRACKING_CLASSES, FrameDetections, IdAllocator, TrackEstimate


class MultiClassTracker:
    """Runs tracker ``name`` for every class in ``classes`` on each frame's kept detections."""

    def __init__(self, name: str, config: TrackerConfig, classes: Sequence[str] = TRACKING_CLASSES):
        self.name = check_tracker(name)
        self.classes = tuple(check_classes(list(classes)))
        self.ids = IdAllocator()
        self.trackers = {c: make_class_tracker(name, c, config, self.ids) for c in self.classes}

    def step(self, frame: FrameDetections, dt_s: float, sink: EventSink) -> list[TrackEstimate]:
        estimates: list[TrackEstimate] = []
        by_class = frame.measurements_by_class(self.classes)
        for class_name, tracker in self.trackers.items():
            meas = by_class[class_name]
            if sink.enabled:
                sink.emit(
                    MeasurementsReceived(class_name, meas.source_index, meas.boxes.translation_m, meas.boxes.score)
                )
            estimates.extend(tracker.step(meas, dt_s, sink))
        return estimates
