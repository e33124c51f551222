"""Kalman filter for the constant-velocity model (and the extended Kalman predict of a non-linear one),
vectorised over K tracks.

State m = [x, y, vx, vy]; measurement z = H m = [x, y] (D = 2), or [x, y, vx, vy] (D = 4, H = I) for the opt-in
variant that also measures the detector's velocity (``[pmb] measure_velocity = 1``).
Motion x_k = F x_{k-1} + w, w ~ N(0, Q) (``gnnpmb.models.cv_model``); predict: m' = F m, P' = F P F^T + Q.
Update: S = H P H^T + R, K = P H^T S^-1, m+ = m + K (z - H m), P+ = P - K S K^T (symmetrised).
Gaussian log-density of a D-dimensional innovation nu: log N(nu; 0, S) = -(nu^T S^-1 nu + log|S| + D log 2 pi) / 2.

Every Kalman and Gaussian formula the trackers use is here, in two shapes: "all pairs" functions give (K, M)
arrays for every track-measurement pair, "paired" functions take P chosen pairs (track_index[p],
meas_index[p]) and give (P, ...) arrays. Each function's docstring gives its equation.

References: Bar-Shalom, Li & Kirubarajan, "Estimation with Applications to Tracking and Navigation", 2001, ch. 5.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from gnnpmb.soa import StructOfArrays

if TYPE_CHECKING:
    from gnnpmb.models import MotionModel

H = np.array([[1.0, 0.0, 0.0, 0.0], [0.0, 1.0, 0.0, 0.0]])
"""Measurement matrix: picks the BEV position."""


def symmetrize(P: np.ndarray) -> np.ndarray:
    """(P + P^T) / 2 over the last two axes."""
    return 0.5 * (P + P.swapaxes(-1, -2))


def predict(mean: np.ndarray, cov: np.ndarray, model: MotionModel) -> tuple[np.ndarray, np.ndarray]:
    """Kalman predict of (K, n) means and (K, n, n) covariances: m' = F m, P' = F P F^T + Q; F is (n, n), or
    (K, n, n) for one transition per track (tracks predicted over different times). For a non-linear model
    (``model.transition``) the extended Kalman predict: m' = f(m), P' = J P J^T + Q with J the Jacobian of f at m
    (Bar-Shalom, Li & Kirubarajan 2001, sec. 10.3); with a linear f it is the Kalman predict."""
    if model.transition is not None:
        out, J = model.transition(mean)
        return out, symmetrize(J @ cov @ J.swapaxes(-1, -2) + model.Q)
    F = model.F
    if F.ndim == 3:
        return np.einsum("kij,kj->ki", F, mean), symmetrize(F @ cov @ F.swapaxes(-1, -2) + model.Q)
    return mean @ F.T, symmetrize(F @ cov @ F.T + model.Q)


@dataclass(frozen=True, slots=True)
class Innovation(StructOfArrays):
    """Per-track quantities of the update, shared by gating, likelihoods and the update itself.

    z_pred: (K, D) H m; S: (K, D, D); S_inv: (K, D, D); log_det_S: (K,); gain: (K, 4, D); cov_post: (K, 4, 4)
    (the posterior covariance does not depend on the measurement value).
    """

    z_pred: np.ndarray
    S: np.ndarray
    S_inv: np.ndarray
    log_det_S: np.ndarray
    gain: np.ndarray
    cov_post: np.ndarray

    @staticmethod
    def empty(state_dim: int = 4, meas_dim: int = 2) -> Innovation:
        n, d = state_dim, meas_dim
        return Innovation(
            z_pred=np.zeros((0, d)),
            S=np.zeros((0, d, d)),
            S_inv=np.zeros((0, d, d)),
            log_det_S=np.zeros(0),
            gain=np.zeros((0, n, d)),
            cov_post=np.zeros((0, n, n)),
        )


def innovation(mean: np.ndarray, cov: np.ndarray, R: np.ndarray) -> Innovation:
    """S, S^-1, gain and posterior covariance for (K, n) means and (K, n, n) covariances (n = 4, or 5 with a
    turn rate).

    The measurement dimension D is R's (2 or 4; H picks the first D state entries). For D = 2, S's inverse and
    determinant are written out (much faster than batched LAPACK calls for the few tracks of one class).
    P+ = P - K S K^T, symmetrised; it equals the Joseph form for the optimal gain.
    """
    if R.shape[0] != 2:
        return _innovation_general(mean, cov, R)
    if not len(mean):
        return Innovation.empty(mean.shape[1])
    PHt = cov[:, :, :2]  # P H^T, (K, 4, 2)
    S = symmetrize(cov[:, :2, :2] + R)  # the diagonal is exact: (s + s) / 2 = s
    s00, s11, s01 = S[:, 0, 0], S[:, 1, 1], S[:, 0, 1]
    det = s00 * s11 - s01 * s01
    if ((det <= 0) | (s00 <= 0)).any():
        raise FloatingPointError("innovation covariance is not positive-definite")
    S_inv = S[:, ::-1, ::-1] * _ADJUGATE_SIGN / det[:, None, None]  # [[s11, -s01], [-s01, s00]] / det
    gain = PHt @ S_inv
    cov_post = symmetrize(cov - gain @ PHt.swapaxes(-1, -2))
    return Innovation(z_pred=mean[:, :2], S=S, S_inv=S_inv, log_det_S=np.log(det), gain=gain, cov_post=cov_post)


_ADJUGATE_SIGN = np.array([[1.0, -1.0], [-1.0, 1.0]])
"""Signs of the 2 x 2 adjugate [[d, -b], [-c, a]] of [[a, b], [c, d]] read from the matrix reversed on both axes."""


def _innovation_general(mean: np.ndarray, cov: np.ndarray, R: np.ndarray) -> Innovation:
    """``innovation`` for a D-dimensional measurement of the first D state entries, by batched LAPACK."""
    d = R.shape[0]
    PHt = cov[:, :, :d]
    S = symmetrize(cov[:, :d, :d] + R)
    sign, log_det = np.linalg.slogdet(S) if len(S) else (np.ones(0), np.zeros(0))
    if np.any(sign <= 0):
        raise FloatingPointError("innovation covariance is not positive-definite")
    S_inv = symmetrize(np.linalg.inv(S)) if len(S) else np.zeros((0, d, d))
    gain = PHt @ S_inv
    cov_post = symmetrize(cov - gain @ PHt.swapaxes(-1, -2))
    return Innovation(z_pred=mean[:, :d], S=S, S_inv=S_inv, log_det_S=log_det, gain=gain, cov_post=cov_post)


def residuals(inn: Innovation, z: np.ndarray) -> np.ndarray:
    """(K, M, D) innovations nu_kj = z_j - H m_k of every track-measurement pair."""
    return z[None, :, :] - inn.z_pred[:, None, :]


def mahalanobis2(inn: Innovation, z: np.ndarray) -> np.ndarray:
    """(K, M) squared Mahalanobis distances d2_kj = nu_kj^T S_k^-1 nu_kj of measurements z (M, D)."""
    nu = residuals(inn, z)
    return np.einsum("kmi,kij,kmj->km", nu, inn.S_inv, nu)


_LOG_2PI = np.log(2.0 * np.pi)


def gaussian_log_density(d2: np.ndarray, log_det_S: np.ndarray, dim: int) -> np.ndarray:
    """log N(z; H m, S) = -(d2 + log|S| + D log 2 pi) / 2 from squared Mahalanobis distances d2 and log|S|
    (broadcast against each other; any shape) of a ``dim``-dimensional measurement."""
    return -0.5 * (d2 + log_det_S + dim * _LOG_2PI)


def log_likelihood(inn: Innovation, d2: np.ndarray) -> np.ndarray:
    """(K, M) log N(z_j; H m_k, S_k) from (K, M) squared Mahalanobis distances (``gaussian_log_density``)."""
    return gaussian_log_density(d2, inn.log_det_S[:, None], inn.z_pred.shape[1])


def paired_residuals(inn: Innovation, z: np.ndarray, track_index: np.ndarray, meas_index: np.ndarray) -> np.ndarray:
    """(P, D) innovations nu_p = z[meas_index[p]] - H m[track_index[p]] of P chosen pairs."""
    return z[meas_index] - inn.z_pred[track_index]


def paired_mahalanobis2(S_inv: np.ndarray, nu: np.ndarray) -> np.ndarray:
    """(P,) d2_p = nu_p^T S_p^-1 nu_p for (P, D) innovations and their (P, D, D) inverse innovation covariances."""
    return np.einsum("mi,mij,mj->m", nu, S_inv, nu)


def mean_update(mean: np.ndarray, gain: np.ndarray, nu: np.ndarray) -> np.ndarray:
    """(P, 4) posterior means m+ = m + K nu for (P, 4) means, (P, 4, D) gains and (P, D) innovations."""
    return mean + np.einsum("pij,pj->pi", gain, nu)


def paired_updated_means(
    mean: np.ndarray, inn: Innovation, z: np.ndarray, track_index: np.ndarray, meas_index: np.ndarray
) -> np.ndarray:
    """(P, 4) posterior means m_k + K_k (z_j - H m_k) of P pairs (k, j) = (track_index[p], meas_index[p]);
    ``mean`` (K, 4) and ``inn`` (K) are the tracks', ``z`` (M, D) the measurements."""
    nu = paired_residuals(inn, z, track_index, meas_index)
    return mean_update(mean[track_index], inn.gain[track_index], nu)


def updated_means(mean: np.ndarray, inn: Innovation, z: np.ndarray) -> np.ndarray:
    """(K, M, 4) posterior means m_k + K_k (z_j - H m_k) for every track-measurement pair."""
    nu = residuals(inn, z)
    return mean[:, None, :] + np.einsum("kij,kmj->kmi", inn.gain, nu)
