"""A multi-class tracker: one single-class tracker per nuScenes tracking class, sharing one id space.

The paper tracks every class separately (sec. V-B); ids are allocated from one counter so they are unique across
classes and the same input always gives the same ids. The per-class filters are made at the first step, so the
configuration goes down to them with the first frame: the tracker is built and stepped on one path.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING

from gnnpmb.config import TrackerConfig
from gnnpmb.events import EventSink, MeasurementsReceived
from gnnpmb.registry import check_classes, check_tracker, make_class_tracker
from gnnpmb.types import TRACKING_CLASSES, FrameDetections, IdAllocator, TrackEstimate

if TYPE_CHECKING:
    from gnnpmb.skeleton import ClassFilter


class MultiClassTracker:
    """Runs tracker ``name`` for every class in ``classes`` on each frame's kept detections; the names are
    checked, and each class's filter made (``registry.make_class_tracker``), at the first step."""

    def __init__(self, name: str, config: TrackerConfig, classes: Sequence[str] = TRACKING_CLASSES):
        self.name = name
        self.config = config
        self.classes = tuple(classes)
        self.ids = IdAllocator()
        self.trackers: dict[str, ClassFilter] = {}

    def step(self, frame: FrameDetections, dt_s: float, sink: EventSink) -> list[TrackEstimate]:
        if not self.trackers:
            name, classes = check_tracker(self.name), check_classes(list(self.classes))
            self.trackers = {c: make_class_tracker(name, c, self.config, self.ids) for c in classes}
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
