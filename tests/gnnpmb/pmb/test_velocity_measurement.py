"""The opt-in velocity-measurement variant ([pmb] measure_velocity = 1): z = [x, y, vx, vy], H = I, against a
hand-computed 4-D Kalman update and birth likelihood."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from gnnpmb.config import TrackerConfig, load_config, paper_config, with_params
from gnnpmb.events import Gated, ListSink, NullSink
from gnnpmb.kalman import _innovation_general, innovation
from gnnpmb.models import cv_model
from gnnpmb.pmb.core import PmbCore
from gnnpmb.pmb.gnnpmb import BestAssignment
from gnnpmb.types import IdAllocator
from tests.gnnpmb.pmb.helpers import make_measurements

CFG = with_params(
    TrackerConfig(),
    {
        "pmb.measure_velocity": 1,
        "pmb.birth_weight": 50.0,
        "classes.car.r_vx": 0.3,
        "classes.car.r_vy": 0.4,
        "models.motion_model": 0,  # the hand computation is the constant-velocity filter's
    },
)
P = CFG.models
CAR = CFG.for_class("car")
R4 = np.diag([CAR.r_x, CAR.r_y, 0.3, 0.4])


def gauss(nu: np.ndarray, S: np.ndarray) -> float:
    d = len(nu)
    return float(np.exp(-0.5 * nu @ np.linalg.solve(S, nu)) / np.sqrt((2 * np.pi) ** d * np.linalg.det(S)))


def test_general_innovation_equals_the_closed_form_for_two_dimensions():
    rng = np.random.default_rng(3)
    a = rng.normal(size=(5, 4, 4))
    cov = a @ np.swapaxes(a, 1, 2) + np.eye(4)
    mean = rng.normal(size=(5, 4))
    R = np.diag([0.2, 0.3])
    fast, general = innovation(mean, cov, R), _innovation_general(mean, cov, R)
    for name in ("z_pred", "S", "S_inv", "log_det_S", "gain", "cov_post"):
        np.testing.assert_allclose(getattr(general, name), getattr(fast, name), rtol=1e-10, atol=1e-12)


def test_birth_then_update_with_velocity_measurement_match_hand_computation():
    core = PmbCore("car", CFG, BestAssignment(), IdAllocator())
    z1, v1, s1 = np.array([1.0, 2.0]), np.array([3.0, -1.0]), 0.8
    core.step(make_measurements([tuple(z1)], s1, velocity=[tuple(v1)]), 0.0, NullSink())
    Pb = np.diag([P.birth_pos_std_m**2] * 2 + [P.birth_vel_std_mps**2] * 2)
    lik = P.birth_weight * s1 * gauss(np.zeros(4), Pb + R4)
    b = core.hypotheses[0].bernoullis
    clutter = P.clutter_intensity * CFG.pmb.clutter_velocity_density  # per m^2 per (m/s)^2
    assert b.existence[0] == pytest.approx(lik / (clutter + lik), rel=1e-9)
    K = Pb @ np.linalg.inv(Pb + R4)
    cov1 = (np.eye(4) - K) @ Pb
    np.testing.assert_allclose(b.mean[0], [*z1, *v1], atol=1e-12)
    np.testing.assert_allclose(b.cov[0], cov1, rtol=1e-9, atol=1e-12)

    dt = 0.5
    model = cv_model(dt, CAR, measure_velocity=True)
    m_pred = model.F @ b.mean[0]
    P_pred = model.F @ cov1 @ model.F.T + model.Q
    z2 = np.array([2.4, 1.6, 2.5, -0.8])
    sink = ListSink()
    core.step(make_measurements([tuple(z2[:2])], 0.9, velocity=[tuple(z2[2:])]), dt, sink)
    S = P_pred + R4
    K = P_pred @ np.linalg.inv(S)
    b = core.hypotheses[0].bernoullis
    assert b.existence[0] == 1.0
    np.testing.assert_allclose(b.mean[0], m_pred + K @ (z2 - m_pred), rtol=1e-9)
    gated = sink.of_type(Gated)[0]
    assert gated.center_xy.shape == (1, 2) and gated.innovation_cov.shape == (1, 2, 2)
    np.testing.assert_allclose(gated.innovation_cov[0], S[:2, :2], rtol=1e-9)


def test_the_defaults_measure_velocity_and_the_paper_does_not():
    """Chosen on the mini_train splits of both worlds (issue 32, ``config.PmbParams``), the defaults are
    ``params/velocity.toml``'s model set; ``params/paper.toml`` keeps the paper's position-only model."""
    chosen = load_config(Path(__file__).resolve().parents[3] / "gnnpmb" / "params" / "velocity.toml")
    assert chosen == TrackerConfig()
    assert TrackerConfig().pmb.measure_velocity == 1 and TrackerConfig().pmbm.n_hypotheses == 10
    assert paper_config().pmb.measure_velocity == 0
    assert cv_model(0.5, TrackerConfig().for_class("car")).R.shape == (2, 2)
    assert cv_model(0.5, TrackerConfig().for_class("car"), measure_velocity=True).R.shape == (4, 4)
