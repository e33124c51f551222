"""The shared filter steps: the frame loop every family plugs into, the gate it uses and the events around its
update."""

from __future__ import annotations

import numpy as np
import pytest

from gnnpmb.config import TrackerConfig
from gnnpmb.events import EventSink, Extracted, Gated, ListSink, NullSink, Posterior, Predicted
from gnnpmb.kalman import innovation, mahalanobis2
from gnnpmb.registry import TRACKER_NAMES, make_class_tracker
from gnnpmb.skeleton import ClassFilter, Gating, TrackView, emit_posterior, emit_prior, gate_tracks
from gnnpmb.types import Boxes, IdAllocator, Measurements, TrackEstimate


def test_gate_tracks_is_the_mahalanobis_gate_and_handles_empty_sides() -> None:
    rng = np.random.default_rng(4)
    mean = rng.normal(size=(3, 4))
    cov = np.tile(np.eye(4), (3, 1, 1))
    R = np.diag([0.5, 0.5])
    z = rng.normal(size=(5, 2)) * 3.0
    g = gate_tracks(mean, cov, R, z, 4.0)
    d2 = mahalanobis2(innovation(mean, cov, R), z)
    np.testing.assert_array_equal(g.d2, d2)
    np.testing.assert_array_equal(g.inside, d2 < 4.0)
    assert gate_tracks(mean, cov, R, np.zeros((0, 2)), 4.0).inside.shape == (3, 0)
    assert gate_tracks(np.zeros((0, 4)), np.zeros((0, 4, 4)), R, z, 4.0).inside.shape == (0, 5)


def test_emitted_events_carry_the_bev_gate_and_the_estimates() -> None:
    mean = np.array([[1.0, 2.0, 0.0, 0.0]])
    cov = np.eye(4)[None]
    R = np.diag([0.1, 0.2, 0.3, 0.4])  # a velocity-measuring filter: the gate drawn is the x, y block
    g = gate_tracks(mean, cov, R, np.array([[1.0, 2.0, 0.0, 0.0]]), 40.0)
    sink = ListSink()
    ids = np.array([7])
    view = TrackView(ids, mean, cov, np.ones(1))
    emit_prior(sink, "car", view, g, np.array([3]), 40.0)
    emit_posterior(sink, "car", view, [], 0.5)
    predicted, gated, posterior, extracted = sink.events
    assert isinstance(predicted, Predicted) and isinstance(posterior, Posterior)
    assert isinstance(gated, Gated) and gated.innovation_cov.shape == (1, 2, 2) and gated.center_xy.shape == (1, 2)
    np.testing.assert_array_equal(gated.innovation_cov[0], np.eye(2) + np.diag([0.1, 0.2]))
    assert isinstance(extracted, Extracted) and extracted.estimates == () and extracted.threshold == 0.5


class _Recorder(ClassFilter[str, str]):
    """A family whose hooks record their calls: one track at the origin, gated or not (``gated``)."""

    def __init__(self, idle: bool, gated: bool):
        super().__init__("car", TrackerConfig(), IdAllocator())
        self.calls: list[str] = []
        self.is_idle, self.gated = idle, gated
        self.view = TrackView(np.array([7]), np.zeros((1, 4)), np.eye(4)[None], np.ones(1))

    def idle(self) -> bool:
        return self.is_idle

    def predict(self, meas: Measurements, dt_s: float) -> str:
        self.calls.append("predict")
        return "prior"

    def prior_view(self, prior: str) -> tuple[TrackView, Gating | None]:
        self.calls.append("prior_view")
        gating = gate_tracks(self.view.mean, self.view.cov, np.eye(2), np.zeros((0, 2)), 4.0) if self.gated else None
        return self.view, gating

    def update(self, prior: str, meas: Measurements, sink: EventSink) -> str:
        self.calls.append(f"update {prior}")
        return "posterior"

    def extract(self, posterior: str, sink: EventSink) -> tuple[list[TrackEstimate], float]:
        self.calls.append(f"extract {posterior}")
        return [], 0.5

    def posterior_view(self, posterior: str) -> TrackView:
        self.calls.append("posterior_view")
        return self.view


NO_MEAS = Measurements(Boxes.empty(), np.zeros(0, dtype=np.int64))


@pytest.mark.parametrize("gated", [True, False])
def test_step_calls_the_hooks_in_order_and_emits_around_the_update(gated: bool) -> None:
    f, sink = _Recorder(idle=False, gated=gated), ListSink()
    assert f.step(NO_MEAS, 0.5, sink) == []
    assert f.calls == ["predict", "prior_view", "update prior", "extract posterior", "posterior_view"]
    kinds = [type(e) for e in sink.events]
    assert kinds == [Predicted, Gated, Posterior, Extracted] if gated else [Predicted, Posterior, Extracted]
    f.calls.clear()
    f.step(NO_MEAS, 0.5, NullSink())
    assert f.calls == ["predict", "update prior", "extract posterior"]


def test_an_idle_filter_skips_a_frame_without_measurements_only_when_nobody_listens() -> None:
    f = _Recorder(idle=True, gated=True)
    assert f.step(NO_MEAS, 0.5, NullSink()) == [] and f.calls == []
    f.step(NO_MEAS, 0.5, ListSink())
    assert f.calls[0] == "predict"


@pytest.mark.parametrize("name", TRACKER_NAMES)
def test_every_tracker_is_a_class_filter_with_no_frame_loop_of_its_own(name: str) -> None:
    tracker = make_class_tracker(name, "car", TrackerConfig(), IdAllocator())
    assert isinstance(tracker, ClassFilter) and type(tracker).step is ClassFilter.step
