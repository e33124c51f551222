"""The 10-D box Kalman filter: model matrices, heading alignment, update and Mahalanobis distance against the
textbook formulas written out."""

import math

import numpy as np
import pytest

from gnnpmb.box import kalman
from gnnpmb.config import NUSCENES_BOX_NOISE, BoxNoise
from gnnpmb.kalman import innovation, predict
from gnnpmb.types import Boxes

NOISE = NUSCENES_BOX_NOISE["car"]


def test_model_moves_the_centre_by_the_velocity_and_keeps_yaw_and_size():
    model = kalman.box_model(0.5, NOISE)
    s = np.array([1.0, 2.0, 0.5, 0.3, 4.5, 1.9, 1.6, 2.0, -4.0, 0.2])
    np.testing.assert_allclose(model.F @ s, [2.0, 0.0, 0.6, 0.3, 4.5, 1.9, 1.6, 2.0, -4.0, 0.2])
    assert np.diag(model.Q).tolist() == [
        NOISE.q_x,
        NOISE.q_y,
        NOISE.q_z,
        NOISE.q_yaw,
        0.0,
        0.0,
        0.0,
        NOISE.q_vx,
        NOISE.q_vy,
        NOISE.q_vz,
    ]
    assert np.diag(model.R).tolist() == [NOISE.r_x, NOISE.r_y, NOISE.r_z, NOISE.r_yaw, NOISE.r_l, NOISE.r_w, NOISE.r_h]
    per_track = kalman.box_models(np.array([0.5, 1.0]), NOISE)
    np.testing.assert_array_equal(per_track.F[1], kalman.box_model(1.0, NOISE).F)
    mean, cov = kalman.initial_state(np.zeros((2, 7)), NOISE)
    one_by_one = [
        predict(mean[i : i + 1], cov[i : i + 1], kalman.box_model(dt, NOISE)) for i, dt in enumerate((0.5, 1.0))
    ]
    batched = predict(mean, cov, per_track)
    np.testing.assert_allclose(batched[1], np.concatenate([c for _, c in one_by_one]))


def test_initial_state_starts_at_the_box_with_zero_velocity():
    z = np.array([[1.0, 2.0, 0.5, 0.3, 4.5, 1.9, 1.6]])
    mean, cov = kalman.initial_state(z, NOISE)
    assert mean[0].tolist() == [*z[0], 0.0, 0.0, 0.0]
    assert np.diag(cov[0]).tolist() == pytest.approx(
        [
            NOISE.r_x,
            NOISE.r_y,
            NOISE.r_z,
            NOISE.r_yaw,
            NOISE.r_l,
            NOISE.r_w,
            NOISE.r_h,
            NOISE.p_vx,
            NOISE.p_vy,
            NOISE.p_vz,
        ]
    )


@pytest.mark.parametrize(
    ("pred", "det", "aligned"),
    [
        (0.0, math.pi, math.pi),
        (0.1, 3.0, 0.1 + math.pi),
        (0.1, -3.0, 0.1 - math.pi),
        (0.2, 0.5, 0.2),
        (3.1, -3.1, 3.1 - 2 * math.pi),
    ],
)
def test_align_heading_turns_the_prediction_by_multiples_of_pi(pred, det, aligned):
    got = kalman.align_heading(np.array([pred]), np.array([det]))[0]
    assert got == pytest.approx(aligned)
    assert abs(det - got) <= math.pi / 2 + 1e-12


def test_update_is_the_kalman_update_with_the_aligned_heading():
    rng = np.random.default_rng(0)
    mean, cov = kalman.initial_state(rng.normal(size=(3, 7)), NOISE)
    mean[:, kalman.VX :] = rng.normal(size=(3, 3))
    mean, cov = predict(mean, cov, kalman.box_model(0.5, NOISE))
    z = mean[:, :7] + rng.normal(scale=0.2, size=(3, 7))
    z[0, kalman.YAW] = kalman.wrap_angle(mean[0, kalman.YAW] + math.pi + 0.1)  # a flipped detection
    R = kalman.box_model(0.0, NOISE).R
    inn = innovation(mean, cov, R)
    post = kalman.update(mean, inn, z)
    H = np.hstack([np.eye(7), np.zeros((7, 3))])
    for k in range(3):
        m = mean[k].copy()
        m[kalman.YAW] = kalman.align_heading(m[kalman.YAW], z[k, kalman.YAW])
        S = H @ cov[k] @ H.T + R
        gain = cov[k] @ H.T @ np.linalg.inv(S)
        expected = m + gain @ (z[k] - H @ m)
        expected[kalman.YAW] = kalman.wrap_angle(expected[kalman.YAW])
        np.testing.assert_allclose(post[k], expected, atol=1e-10)
        np.testing.assert_allclose(inn.cov_post[k], cov[k] - gain @ S @ gain.T, atol=1e-10)
    assert abs(post[0, kalman.YAW] - kalman.wrap_angle(z[0, kalman.YAW])) < 0.2  # flipped with the detection


def test_mahalanobis2_uses_heading_residuals_modulo_pi():
    rng = np.random.default_rng(1)
    mean, cov = kalman.initial_state(rng.normal(size=(2, 7)), NOISE)
    inn = innovation(mean, cov, kalman.box_model(0.0, NOISE).R)
    z = mean[:, :7] + rng.normal(scale=0.3, size=(2, 7))
    flipped = z.copy()
    flipped[:, kalman.YAW] += math.pi
    d2 = kalman.mahalanobis2(inn, z)
    for k in range(2):
        for j in range(2):
            nu = z[j] - mean[k, :7]
            nu[kalman.YAW] = (nu[kalman.YAW] + math.pi / 2) % math.pi - math.pi / 2
            assert d2[k, j] == pytest.approx(nu @ np.linalg.inv(inn.S[k]) @ nu)
    np.testing.assert_allclose(kalman.mahalanobis2(inn, flipped), d2)


def test_measurements_read_boxes_in_the_state_order():
    boxes = Boxes(
        translation_m=np.array([[1.0, 2.0, 3.0]]),
        size_wlh_m=np.array([[1.9, 4.5, 1.6]]),
        quat_wxyz=np.array([[math.cos(0.15), 0.0, 0.0, math.sin(0.15)]]),
        velocity_mps=np.array([[1.0, 0.0]]),
        score=np.array([0.9]),
        class_name=np.array(["car"], dtype=object),
        instance_id=np.array([""], dtype=object),
    )
    np.testing.assert_allclose(kalman.measurements(boxes)[0], [1.0, 2.0, 3.0, 0.3, 4.5, 1.9, 1.6])
    np.testing.assert_allclose(
        kalman.moved_back(kalman.measurements(boxes), boxes.velocity_mps, 0.5)[0, :2], [0.5, 2.0]
    )


def test_uniform_noise_is_what_ab3dmot_and_simpletrack_set_by_hand():
    n = BoxNoise.uniform(r=1.0, q=1.0, q_size=1.0, q_velocity=0.04, p_velocity=4e4, p_scale=10.0)
    model = kalman.box_model(0.5, n)
    assert np.diag(model.Q).tolist() == [1.0] * 7 + [0.04] * 3 and np.diag(model.R).tolist() == [1.0] * 7
    _, cov = kalman.initial_state(np.zeros((1, 7)), n)
    assert np.diag(cov[0]).tolist() == [10.0] * 7 + [4e4] * 3
