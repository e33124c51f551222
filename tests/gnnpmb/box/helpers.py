"""Staged scenes for the box trackers: hand-placed boxes, stepped frame by frame."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from gnnpmb.config import TrackerConfig
from gnnpmb.events import ListSink
from gnnpmb.registry import make_class_tracker
from gnnpmb.skeleton import ClassFilter
from gnnpmb.types import Boxes, IdAllocator, Measurements, TrackEstimate

CAR_WLH = (2.0, 4.5, 1.6)
MOTORCYCLE_WLH = (0.8, 2.1, 1.5)


def boxes(
    xy: Sequence[tuple[float, float]],
    score: float | Sequence[float] = 0.9,
    velocity: Sequence[tuple[float, float]] | None = None,
    size_wlh: tuple[float, float, float] = CAR_WLH,
    cls: str = "car",
) -> Measurements:
    """Upright boxes heading along +x (yaw 0) at the BEV positions ``xy``, centres 1 m up."""
    m = len(xy)
    t = np.zeros((m, 3))
    if m:
        t[:, :2] = np.asarray(xy, dtype=float)
    t[:, 2] = 1.0
    b = Boxes(
        translation_m=t,
        size_wlh_m=np.tile(size_wlh, (m, 1)).astype(float),
        quat_wxyz=np.tile([1.0, 0.0, 0.0, 0.0], (m, 1)),
        velocity_mps=np.asarray(velocity, dtype=float).reshape(m, 2) if velocity else np.zeros((m, 2)),
        score=np.full(m, score, dtype=float) if np.isscalar(score) else np.asarray(score, dtype=float),
        class_name=np.array([cls] * m, dtype=object),
        instance_id=np.array([""] * m, dtype=object),
    )
    return Measurements(boxes=b, source_index=np.arange(m))


class Staged:
    """One class's tracker stepped through hand-made frames (0.5 s apart, the first with dt 0), every event kept."""

    def __init__(self, tracker: str, config: TrackerConfig | None = None, cls: str = "car"):
        self.tracker: ClassFilter = make_class_tracker(tracker, cls, config or TrackerConfig(), IdAllocator())
        self.frames = 0
        self.sink = ListSink()

    def step(self, meas: Measurements) -> list[TrackEstimate]:
        self.sink = ListSink()
        out = self.tracker.step(meas, 0.0 if self.frames == 0 else 0.5, self.sink)
        self.frames += 1
        return out

    def ids(self, meas: Measurements) -> list[int]:
        """The ids output this frame, in output order."""
        return [e.track_id for e in self.step(meas)]
