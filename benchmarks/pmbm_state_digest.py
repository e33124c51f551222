"""Digest of PMBM's full state after every step, to check that a speed-up changes nothing, bit for bit.

Usage: uv run python benchmarks/pmbm_state_digest.py > new.txt   (then the same on the old commit, and diff)

Stricter than the submission digests (``tests/gnnpmb/submission_digests.py``): per run it hashes, after every
frame, each class's global hypotheses (log weight and every field of every Bernoulli), the estimates and, for
some runs, every event. Runs: N_h = 100 and 20 on the demo mini_val scenes with each detector preset, and on the
stress frames of ``tracker_speed.py`` (120 and 320 detections). To run an older commit's code with this script,
export it (``git archive``) and put it first on PYTHONPATH from another directory.
"""

from __future__ import annotations

import dataclasses
import enum
import hashlib
from collections.abc import Sequence
from typing import Any

import numpy as np
from tracker_speed import stress_frames

from gnnpmb.config import PmbmParams, TrackerConfig
from gnnpmb.data.nuscenes import load_scene, resolve_dataroot, split_scenes
from gnnpmb.data.preprocess import preprocess
from gnnpmb.data.simdet import PRESETS
from gnnpmb.events import EventSink, ListSink, NullSink
from gnnpmb.pipeline import get_detections, preprocess_frames
from gnnpmb.tracker import MultiClassTracker
from gnnpmb.types import TRACKING_CLASSES, FrameDetections


def feed(h: Any, value: Any) -> None:
    """Add ``value`` (arrays, dataclasses, containers, scalars) to the hash ``h``, bytes for floats."""
    if isinstance(value, np.ndarray):
        h.update(f"{value.dtype}{value.shape}".encode())
        h.update(repr(value.tolist()).encode() if value.dtype == object else np.ascontiguousarray(value).tobytes())
    elif dataclasses.is_dataclass(value) and not isinstance(value, type):
        h.update(type(value).__name__.encode())
        for f in dataclasses.fields(value):
            feed(h, getattr(value, f.name))
    elif isinstance(value, list | tuple):
        h.update(b"[")
        for item in value:
            feed(h, item)
        h.update(b"]")
    elif isinstance(value, dict):
        for key in sorted(value):
            feed(h, key)
            feed(h, value[key])
    elif isinstance(value, float):
        h.update(np.float64(value).tobytes())
    elif isinstance(value, enum.Enum):
        h.update(repr(value).encode())
    else:
        h.update(repr(value).encode())


def state_digest(frames: Sequence[FrameDetections], config: TrackerConfig, events: bool) -> str:
    """Hash of every step of ``pmbm`` on ``frames`` (0.5 s apart): estimates, hypotheses and, if ``events``,
    every event."""
    mot = MultiClassTracker("pmbm", config)
    h = hashlib.sha256()
    for i, frame in enumerate(frames):
        sink: EventSink = ListSink() if events else NullSink()
        feed(h, mot.step(frame, 0.5 if i else 0.0, sink))
        if isinstance(sink, ListSink):
            feed(h, sink.events)
        for tracker in mot.trackers.values():
            for hypothesis in tracker.hypotheses:
                feed(h, hypothesis.log_weight)
                feed(h, hypothesis.bernoullis)
    return h.hexdigest()[:16]


def digests(frames: Sequence[FrameDetections], config: TrackerConfig, with_events: bool) -> list[str]:
    """The state digest without events, and with them if ``with_events``."""
    return [state_digest(frames, config, events) for events in ((False, True) if with_events else (False,))]


def main() -> None:
    location = resolve_dataroot(None, None)
    scenes = [load_scene(location, name) for name in split_scenes("mini_val", location)]
    for n_hypotheses in (100, 20):
        config = TrackerConfig().replace(pmbm=PmbmParams(n_hypotheses=n_hypotheses))
        for preset in PRESETS:
            for scene in scenes:
                frames = preprocess_frames(scene, get_detections(scene, None, preset, seed=0), config, TRACKING_CLASSES)
                with_events = n_hypotheses == 100 and preset == "pointpillars"
                digests = [state_digest(frames, config, False)] + (
                    [state_digest(frames, config, True)] if with_events else []
                )
                print(n_hypotheses, preset, scene.name, *digests, flush=True)
        for n in (120, 320):
            frames = [preprocess(b, config.preprocess, TRACKING_CLASSES) for b in stress_frames(n, 5)]
            with_events = n_hypotheses == 100 and n == 120
            digests = [state_digest(frames, config, False)] + (
                [state_digest(frames, config, True)] if with_events else []
            )
            print(n_hypotheses, "stress", n, *digests, flush=True)


if __name__ == "__main__":
    main()
