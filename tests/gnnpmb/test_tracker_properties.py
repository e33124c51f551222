"""Property tests (hypothesis): random detection sequences, ordinary and degenerate, fed to every registered
tracker. Whatever the input: no exception, no NaN or infinity in any estimate or event, every covariance
symmetric positive definite, every existence probability in [0, 1], and the same input gives the same output.

Degenerate frames: empty frames, coincident duplicates, scores at 0.1 and 1, objects 5 km away, a zero time
step, and rows with a non-finite or absurd field (which preprocessing must drop before any tracker sees them).
Few, small examples keep this at a few seconds.
"""

from __future__ import annotations

import math
from dataclasses import fields

import numpy as np
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from gnnpmb.config import TrackerConfig
from gnnpmb.data.preprocess import preprocess
from gnnpmb.events import ListSink
from gnnpmb.registry import TRACKER_NAMES
from gnnpmb.tracker import MultiClassTracker
from gnnpmb.types import Boxes

CLASSES = ("car", "pedestrian")
CONFIG = TrackerConfig()

coordinate = st.one_of(st.floats(-60.0, 60.0), st.sampled_from([0.0, 5000.0, -5000.0]))
detection = st.tuples(
    coordinate,
    coordinate,
    st.floats(-15.0, 15.0),
    st.floats(-15.0, 15.0),
    st.one_of(st.floats(0.1, 1.0), st.just(1.0)),
    st.sampled_from(CLASSES),
)
broken_value = st.sampled_from([math.nan, math.inf, -math.inf, 1e308])


@st.composite
def frame(draw: st.DrawFn) -> list[tuple]:
    """One frame: up to 12 detections, maybe with coincident duplicates and a broken row."""
    rows = draw(st.lists(detection, max_size=12))
    if rows and draw(st.booleans()):
        rows += rows[: draw(st.integers(1, len(rows)))]  # coincident duplicates
    if draw(st.integers(0, 4)) == 0:
        bad = list(draw(detection))
        bad[draw(st.integers(0, 4))] = draw(broken_value)
        rows.append(tuple(bad))
    return rows


sequence = st.tuples(st.lists(frame(), min_size=1, max_size=5), st.lists(st.sampled_from([0.5, 0.0, 0.1]), min_size=5))


def to_boxes(rows: list[tuple]) -> Boxes:
    n = len(rows)
    if n == 0:
        return Boxes.empty()
    x, y, vx, vy, score, name = (np.array(c) for c in zip(*rows, strict=True))
    return Boxes(
        translation_m=np.column_stack([x, y, np.ones(n)]).astype(float),
        size_wlh_m=np.tile([0.8, 1.0, 1.7], (n, 1)),
        quat_wxyz=np.tile([1.0, 0.0, 0.0, 0.0], (n, 1)),
        velocity_mps=np.column_stack([vx, vy]).astype(float),
        score=np.minimum(score.astype(float), 1.0),
        class_name=name.astype(object),
        instance_id=np.full(n, "", dtype=object),
    )


def run(tracker: str, frames: list[list[tuple]], dts: list[float]) -> tuple[list[list[tuple]], list]:
    mot = MultiClassTracker(tracker, CONFIG, CLASSES)
    sink = ListSink()
    outputs = []
    for i, rows in enumerate(frames):
        prepared = preprocess(to_boxes(rows), CONFIG.preprocess, CLASSES)
        estimates = mot.step(prepared, dts[i] if i else 0.0, sink)
        outputs.append(
            [(e.track_id, e.class_name, tuple(e.translation_m), tuple(e.velocity_mps), e.score) for e in estimates]
        )
    return outputs, sink.events


def check_event(event: object) -> None:
    """No NaN anywhere; (.., 4, 4) covariances SPD; existence probabilities in [0, 1]."""
    for f in fields(event):
        value = getattr(event, f.name)
        if not isinstance(value, np.ndarray) or value.dtype.kind != "f":
            continue
        finite = value[np.isfinite(value)] if f.name in ("cost", "log_weights", "weights") else value
        assert not np.isnan(finite).any(), (type(event).__name__, f.name)
        if f.name in ("cov",) and value.size:
            assert np.allclose(value, np.swapaxes(value, -1, -2), atol=1e-9), type(event).__name__
            assert (np.linalg.eigvalsh(value) > 0).all(), type(event).__name__
        if f.name == "existence" and value.size:
            assert ((value >= 0.0) & (value <= 1.0)).all(), type(event).__name__


@settings(max_examples=12, deadline=None, derandomize=True, suppress_health_check=[HealthCheck.too_slow])
@given(data=sequence)
def test_every_tracker_stays_finite_and_deterministic(data: tuple[list[list[tuple]], list[float]]) -> None:
    frames, dts = data
    for tracker in TRACKER_NAMES:
        outputs, events = run(tracker, frames, dts)
        for estimates in outputs:
            for _, _, xyz, velocity, score in estimates:
                assert np.isfinite(xyz).all() and np.isfinite(velocity).all(), tracker
                assert 0.0 <= score <= 1.0, tracker
        for event in events:
            check_event(event)
        again, _ = run(tracker, frames, dts)
        assert again == outputs, tracker
