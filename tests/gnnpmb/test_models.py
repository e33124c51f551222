"""The coordinated-turn model and the extended Kalman predict (``gnnpmb.models``, ``gnnpmb.kalman.predict``)."""

import math

import numpy as np

from gnnpmb.config import PAPER_CLASS_PARAMS, ModelParams
from gnnpmb.kalman import predict
from gnnpmb.models import (
    MotionModel,
    birth_covariance,
    coordinated_turn,
    ct_model,
    cv_model,
    measurement_birth,
    motion_model,
)
from tests.gnnpmb.pmb.helpers import make_measurements

CAR = PAPER_CLASS_PARAMS["car"]


def random_spd(rng: np.random.Generator, k: int, n: int) -> np.ndarray:
    a = rng.standard_normal((k, n, n))
    return a @ a.swapaxes(1, 2) + n * np.eye(n)


def test_extended_predict_with_a_linear_transition_is_the_kalman_predict():
    """f(m) = F m with Jacobian F: the EKF predict equals the KF predict to 1e-12."""
    rng = np.random.default_rng(0)
    cv = cv_model(0.5, CAR)
    linear = MotionModel(cv.F, cv.Q, cv.R, transition=lambda m: (m @ cv.F.T, np.broadcast_to(cv.F, (len(m), 4, 4))))
    mean, cov = rng.standard_normal((6, 4)), random_spd(rng, 6, 4)
    m_kf, p_kf = predict(mean, cov, cv)
    m_ekf, p_ekf = predict(mean, cov, linear)
    assert np.allclose(m_ekf, m_kf, rtol=0, atol=1e-12) and np.allclose(p_ekf, p_kf, rtol=0, atol=1e-12)


def test_coordinated_turn_without_turning_is_constant_velocity():
    """omega = 0 and no turn-rate uncertainty: the [x, y, vx, vy] block is the CV predict to 1e-12."""
    rng = np.random.default_rng(1)
    models = ModelParams(motion_model=1)
    mean4, cov4 = rng.standard_normal((5, 4)), random_spd(rng, 5, 4)
    mean5 = np.column_stack([mean4, np.zeros(5)])
    cov5 = np.zeros((5, 5, 5))
    cov5[:, :4, :4] = cov4
    m_cv, p_cv = predict(mean4, cov4, cv_model(0.5, CAR))
    m_ct, p_ct = predict(mean5, cov5, ct_model(0.5, CAR, models))
    assert np.allclose(m_ct[:, :4], m_cv, rtol=0, atol=1e-12)
    assert np.allclose(p_ct[:, :4, :4], p_cv, rtol=0, atol=1e-12)
    assert np.allclose(m_ct[:, 4], 0.0) and np.isclose(p_ct[0, 4, 4], models.turn_rate_std_rps**2)


def test_quarter_turn_by_hand():
    """Speed v along x, omega T = pi / 2: after T the object is at (v / omega, v / omega) moving along y."""
    T, v = 2.0, 3.0
    w = math.pi / 2 / T
    out, _ = coordinated_turn(np.array([[1.0, -2.0, v, 0.0, w]]), T)
    assert np.allclose(out[0], [1.0 + v / w, -2.0 + v / w, 0.0, v, w], rtol=0, atol=1e-12)


def test_jacobian_matches_finite_differences_at_small_and_large_turn_rates():
    rng = np.random.default_rng(2)
    for w in (0.0, 3e-6, 1e-3, 0.4, -1.3):
        m = np.array([[rng.normal(), rng.normal(), 4.0 * rng.normal(), 4.0 * rng.normal(), w]])
        _, J = coordinated_turn(m, 0.5)
        h = 1e-6
        fd = np.empty((5, 5))
        for i in range(5):
            up, down = m.copy(), m.copy()
            up[0, i] += h
            down[0, i] -= h
            fd[:, i] = (coordinated_turn(up, 0.5)[0][0] - coordinated_turn(down, 0.5)[0][0]) / (2 * h)
        assert np.allclose(J[0], fd, rtol=0, atol=1e-6), w


def test_series_equals_the_closed_form_below_the_switch():
    """At omega T just below the small-turn threshold the series gives the closed form's state to 1e-12."""
    T, w, vx, vy = 0.5, 0.9e-4 / 0.5, 5.0, 2.0
    series, _ = coordinated_turn(np.array([[0.0, 0.0, vx, vy, w]]), T)
    s, c = math.sin(w * T), math.cos(w * T)
    closed = [(s * vx - (1 - c) * vy) / w, ((1 - c) * vx + s * vy) / w, c * vx - s * vy, s * vx + c * vy]
    assert np.allclose(series[0, :4], closed, rtol=0, atol=1e-12)


def test_prediction_stays_symmetric_positive_definite():
    rng = np.random.default_rng(3)
    mean = np.column_stack([rng.standard_normal((8, 2)), 6.0 * rng.standard_normal((8, 2)), rng.normal(0, 0.5, 8)])
    cov = random_spd(rng, 8, 5)
    model = ct_model(0.5, CAR, ModelParams(motion_model=1))
    for _ in range(40):
        mean, cov = predict(mean, cov, model)
    assert np.array_equal(cov, cov.swapaxes(1, 2)) and (np.linalg.eigvalsh(cov) > 0).all()


def test_birth_of_the_turn_state_starts_at_zero_turn_rate():
    models = ModelParams(motion_model=1)
    birth = measurement_birth(make_measurements([(1.0, 2.0), (3.0, 4.0)], 0.8), models, with_turn_rate=True)
    assert birth.mean.shape == (2, 5) and np.array_equal(birth.mean[:, 4], [0.0, 0.0])
    assert np.isclose(birth_covariance(models, True)[4, 4], models.birth_turn_rate_std_rps**2)
    cv = ModelParams(motion_model=0)
    assert motion_model(0.5, CAR, cv).state_dim == 4 and motion_model(0.5, CAR, models).state_dim == 5


def test_a_decaying_turn_rate_by_hand():
    """w' = a w and d(w')/dw = a; the [x, y, vx, vy] step still turns by the current w (module docstring)."""
    m = np.array([[1.0, -2.0, 3.0, 0.0, 0.4]])
    kept, J_kept = coordinated_turn(m, 0.5)
    out, J = coordinated_turn(m, 0.5, decay=0.8)
    assert np.allclose(out[0], [*kept[0, :4], 0.32], rtol=0, atol=1e-12)
    assert J[0, 4, 4] == 0.8 and np.array_equal(J[0, :4], J_kept[0, :4]) and np.array_equal(J[0, 4, :4], [0] * 4)


def test_a_coasting_turn_rate_variance_stays_below_its_stationary_bound():
    """Predicted alone, P_ww follows P' = a^2 P + sigma^2: from 0 it rises to sigma^2 (1 - a^(2n)) / (1 - a^2),
    below sigma^2 / (1 - a^2); with a = 1 it grows as n sigma^2 without bound."""
    a, sigma, n = 0.8, 0.05, 30
    for decay, expected in ((a, sigma**2 * (1 - a ** (2 * n)) / (1 - a**2)), (1.0, n * sigma**2)):
        model = ct_model(0.5, CAR, ModelParams(motion_model=1, turn_rate_std_rps=sigma, turn_rate_decay=decay))
        mean, cov = np.zeros((1, 5)), np.zeros((1, 5, 5))
        for _ in range(n):
            mean, cov = predict(mean, cov, model)
        assert np.isclose(cov[0, 4, 4], expected, rtol=1e-12)
    assert cov[0, 4, 4] > sigma**2 / (1 - a**2)
