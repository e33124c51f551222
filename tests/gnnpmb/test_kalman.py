import numpy as np

from gnnpmb.config import ClassParams
from gnnpmb.gating import ellipse_outline, gate
from gnnpmb.kalman import (
    innovation,
    log_likelihood,
    mahalanobis2,
    paired_mahalanobis2,
    paired_residuals,
    paired_updated_means,
    predict,
    updated_means,
)
from gnnpmb.models import cv_model

PARAMS = ClassParams(0.1, 0.2, 0.3, 0.4)


def random_spd(rng, n, k):
    A = rng.normal(size=(k, n, n))
    return A @ np.swapaxes(A, 1, 2) + n * np.eye(n)


def test_predict_matches_textbook():
    rng = np.random.default_rng(0)
    m, P = rng.normal(size=(3, 4)), random_spd(rng, 4, 3)
    model = cv_model(0.5, PARAMS)
    m2, P2 = predict(m, P, model)
    for i in range(3):
        np.testing.assert_allclose(m2[i], model.F @ m[i], atol=1e-12)
        np.testing.assert_allclose(P2[i], model.F @ P[i] @ model.F.T + model.Q, atol=1e-12)
    assert model.F[0, 2] == 0.5 and np.allclose(np.diag(model.Q), [0.1, 0.2, 0.1, 0.2])


def test_update_matches_textbook_and_stays_spd():
    rng = np.random.default_rng(1)
    m, P = rng.normal(size=(2, 4)), random_spd(rng, 4, 2)
    R = np.diag([0.3, 0.4])
    z = rng.normal(size=(3, 2))
    inn = innovation(m, P, R)
    H = np.eye(2, 4)
    means = updated_means(m, inn, z)
    d2 = mahalanobis2(inn, z)
    ll = log_likelihood(inn, d2)
    for k in range(2):
        S = H @ P[k] @ H.T + R
        K = P[k] @ H.T @ np.linalg.inv(S)
        np.testing.assert_allclose(inn.cov_post[k], (np.eye(4) - K @ H) @ P[k], atol=1e-10)
        assert np.all(np.linalg.eigvalsh(inn.cov_post[k]) > 0)
        np.testing.assert_allclose(inn.cov_post[k], inn.cov_post[k].T, atol=0)
        for j in range(3):
            nu = z[j] - H @ m[k]
            np.testing.assert_allclose(means[k, j], m[k] + K @ nu, atol=1e-10)
            d = nu @ np.linalg.solve(S, nu)
            assert abs(d2[k, j] - d) < 1e-10
            expect = -0.5 * d - np.log(2 * np.pi) - 0.5 * np.log(np.linalg.det(S))
            assert abs(ll[k, j] - expect) < 1e-10


def test_paired_formulas_equal_the_all_pairs_ones():
    rng = np.random.default_rng(2)
    m, P = rng.normal(size=(3, 4)), random_spd(rng, 4, 3)
    z = rng.normal(size=(4, 2))
    inn = innovation(m, P, np.diag([0.3, 0.4]))
    k_idx, j_idx = np.array([2, 0, 1, 2]), np.array([0, 3, 1, 1])
    np.testing.assert_allclose(
        paired_updated_means(m, inn, z, k_idx, j_idx), updated_means(m, inn, z)[k_idx, j_idx], atol=1e-12
    )
    nu = paired_residuals(inn, z, k_idx, j_idx)
    np.testing.assert_allclose(
        paired_mahalanobis2(inn.S_inv[k_idx], nu), mahalanobis2(inn, z)[k_idx, j_idx], atol=1e-12
    )


def test_gate_and_ellipse_boundary():
    S = np.array([[[4.0, 1.0], [1.0, 2.0]]])
    outline = ellipse_outline(np.array([[1.0, -1.0]]), S, 40.0, n_points=16)
    assert outline.shape == (1, 17, 2)
    nu = outline[0] - [1.0, -1.0]
    d2 = np.einsum("ni,ij,nj->n", nu, np.linalg.inv(S[0]), nu)
    np.testing.assert_allclose(d2, 40.0, rtol=1e-10)
    assert gate(np.array([[39.9, 40.0, 40.1]]), 40.0).tolist() == [[True, False, False]]


def test_innovation_rows_do_not_depend_on_the_batch():
    """A row of a batched innovation is bit for bit the innovation of that row alone (the PMB filters compute a
    birth component's innovation once and repeat it) and S^-1 is the symmetric inverse of S."""
    rng = np.random.default_rng(2)
    m, P = rng.normal(size=(6, 4)), random_spd(rng, 4, 6)
    R = np.diag([0.3, 0.4])
    batch = innovation(m, P, R)
    for k in range(6):
        alone = innovation(m[k : k + 1], P[k : k + 1], R)
        for name in ("z_pred", "S", "S_inv", "log_det_S", "gain", "cov_post"):
            assert getattr(alone, name).tobytes() == getattr(batch, name)[k : k + 1].tobytes(), name
    np.testing.assert_allclose(batch.S_inv @ batch.S, np.broadcast_to(np.eye(2), (6, 2, 2)), atol=1e-12)
    assert np.array_equal(batch.S_inv, np.swapaxes(batch.S_inv, 1, 2))
    assert len(innovation(np.zeros((0, 4)), np.zeros((0, 4, 4)), R)) == 0


def test_cv_model_matrices_are_shared_and_read_only():
    a, b = cv_model(0.5, PARAMS), cv_model(0.5, PARAMS)
    assert a.F is b.F and a.Q is b.Q and a.R is b.R
    assert cv_model(1.0, PARAMS).F[0, 2] == 1.0 and a.F[0, 2] == 0.5
    for matrix in (a.F, a.Q, a.R):
        assert not matrix.flags.writeable
