"""``[models] coast_velocity_decay`` b: a Bernoulli missed at its last update (misses >= 1) is predicted with
x' = F x followed by v' = b v, its covariance with the Jacobian diag(1, 1, b, b) F; a detected one (misses 0) is
predicted as before (values computed by hand)."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from gnnpmb.config import ModelParams, TrackerConfig
from gnnpmb.detection_fields import DetectionFields
from gnnpmb.kalman import predict
from gnnpmb.models import motion_model
from gnnpmb.pmb.bernoulli import Bernoullis, predict_bernoullis

CLASS = dataclasses.replace(TrackerConfig().for_class("bicycle"), q_x=0.1, q_y=0.1)


def _bernoullis(misses: list[int], state_dim: int = 4) -> Bernoullis:
    """Bernoullis at [0, 0, 2, 4] (omega 0 when state_dim is 5) with covariance I."""
    k = len(misses)
    mean = np.zeros((k, state_dim))
    mean[:, 2:4] = (2.0, 4.0)
    return Bernoullis(
        track_id=np.arange(1, k + 1),
        local_key=np.arange(k),
        existence=np.ones(k),
        mean=mean,
        cov=np.broadcast_to(np.eye(state_dim), (k, state_dim, state_dim)).copy(),
        det=DetectionFields(np.full(k, 0.8), np.zeros(k), np.ones((k, 3)), np.zeros((k, 4)), np.full(k, -1)),
        misses=np.asarray(misses, dtype=np.int64),
        detected_score_sum=np.zeros(k),
        detected_frames=np.ones(k, dtype=np.int64),
    )


def _axis_cov(cov: np.ndarray, axis: int) -> np.ndarray:
    """The (position, velocity) 2 x 2 block of x (axis 0) or y (axis 1)."""
    return cov[np.ix_([axis, axis + 2], [axis, axis + 2])]


def test_a_missed_bernoulli_slows_down_and_a_detected_one_is_predicted_as_before():
    """dt 0.5, b 0.5, Q = 0.1 I, m = [0, 0, 2, 4], P = I. Per axis A = [[1, 0.5], [0, 0.5]] for the missed row.
    One prediction: m = [1, 2, 1, 2]; P = A A^T + Q = [[1.35, 0.25], [0.25, 0.35]]. Two: m = [1.5, 3, 0.5, 1];
    A P A^T = [[1.6875, 0.2125], [0.2125, 0.0875]], + Q = [[1.7875, 0.2125], [0.2125, 0.1875]]. The detected row:
    F = [[1, 0.5], [0, 1]], m = [1, 2, 2, 4], P = [[1.35, 0.5], [0.5, 1.1]] (as with b = 1)."""
    model = motion_model(0.5, CLASS, ModelParams(motion_model=0, coast_velocity_decay=0.5))
    one = predict_bernoullis(_bernoullis([1, 0]), model, 0.95)
    np.testing.assert_allclose(one.mean, [[1.0, 2.0, 1.0, 2.0], [1.0, 2.0, 2.0, 4.0]], rtol=1e-12)
    for axis in (0, 1):
        np.testing.assert_allclose(_axis_cov(one.cov[0], axis), [[1.35, 0.25], [0.25, 0.35]], rtol=1e-12)
        np.testing.assert_allclose(_axis_cov(one.cov[1], axis), [[1.35, 0.5], [0.5, 1.1]], rtol=1e-12)
    assert one.cov[0, 0, 1] == one.cov[0, 0, 3] == 0.0
    assert one.misses.tolist() == [2, 1]
    two = predict_bernoullis(one, model, 0.95)
    np.testing.assert_allclose(two.mean[0], [1.5, 3.0, 0.5, 1.0], rtol=1e-12)
    for axis in (0, 1):
        np.testing.assert_allclose(_axis_cov(two.cov[0], axis), [[1.7875, 0.2125], [0.2125, 0.1875]], rtol=1e-12)
    off = predict_bernoullis(_bernoullis([1, 0]), motion_model(0.5, CLASS, ModelParams(motion_model=0)), 0.95)
    np.testing.assert_array_equal(one.mean[1], off.mean[1])
    np.testing.assert_array_equal(one.cov[1], off.cov[1])
    np.testing.assert_allclose(off.mean[0], [1.0, 2.0, 2.0, 4.0], rtol=1e-12)


def test_the_coordinated_turn_model_slows_the_velocity_rows_of_its_jacobian():
    """Coordinated turn at omega 0.3 rad/s: the missed row's mean is diag(1, 1, b, b, 1) f(m) and its covariance
    diag(.) J P J^T diag(.) + Q, with f, J the model's without b; the detected row is unchanged; b = 1 is off."""
    models = ModelParams(coast_velocity_decay=0.6)
    model = motion_model(0.5, CLASS, models)
    b = _bernoullis([3, 0], state_dim=5)
    b = dataclasses.replace(b, mean=b.mean + [0.0, 0.0, 0.0, 0.0, 0.3])
    got = predict_bernoullis(b, model, 0.95)
    plain = motion_model(0.5, CLASS, dataclasses.replace(models, coast_velocity_decay=1.0))
    assert plain.coast is None
    f, J = plain.transition(b.mean)
    D = np.diag([1.0, 1.0, 0.6, 0.6, 1.0])
    np.testing.assert_allclose(got.mean[0], D @ f[0], rtol=1e-12)
    np.testing.assert_allclose(got.cov[0], D @ J[0] @ J[0].T @ D + plain.Q, rtol=1e-12)
    expected_mean, expected_cov = predict(b.mean, b.cov, plain)
    np.testing.assert_array_equal(got.mean[1], expected_mean[1])
    np.testing.assert_array_equal(got.cov[1], expected_cov[1])
    assert got.mean[0, 2] == pytest.approx(0.6 * expected_mean[0, 2], rel=1e-12)
