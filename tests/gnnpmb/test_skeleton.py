"""The shared filter steps: the gate every family uses and the events around its update."""

from __future__ import annotations

import numpy as np

from gnnpmb.events import Extracted, Gated, ListSink, Posterior, Predicted
from gnnpmb.kalman import innovation, mahalanobis2
from gnnpmb.skeleton import emit_posterior, emit_prior, gate_tracks


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
    emit_prior(sink, "car", ids, mean, cov, np.ones(1), g, np.array([3]), 40.0)
    emit_posterior(sink, "car", ids, mean, cov, np.ones(1), [], 0.5)
    predicted, gated, posterior, extracted = sink.events
    assert isinstance(predicted, Predicted) and isinstance(posterior, Posterior)
    assert isinstance(gated, Gated) and gated.innovation_cov.shape == (1, 2, 2) and gated.center_xy.shape == (1, 2)
    np.testing.assert_array_equal(gated.innovation_cov[0], np.eye(2) + np.diag([0.1, 0.2]))
    assert isinstance(extracted, Extracted) and extracted.estimates == () and extracted.threshold == 0.5
