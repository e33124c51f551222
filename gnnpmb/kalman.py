"""Linear Kalman filter for the constant-velocity model, vectorised over K tracks.

State m = [x, y, vx, vy]; measurement z = H m = [x, y]. Motion x_k = F x_{k-1} + w, w ~ N(0, Q) with
F = [[I, dt I], [0, I]] and Q = diag(q_x, q_y, q_x, q_y) (paper sec. V-B, the authors' per-class values).
Update: S = H P H^T + R, K = P H^T S^-1, m+ = m + K (z - H m), P+ = (I - K H) P (I - K H)^T + K R K^T
(Joseph form, keeps P symmetric positive-definite). References: Bar-Shalom, Li & Kirubarajan, "Estimation with
Applications to Tracking and Navigation", 2001, ch. 5.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from gnnpmb.config import ClassParams

H = np.array([[1.0, 0.0, 0.0, 0.0], [0.0, 1.0, 0.0, 0.0]])
"""Measurement matrix: picks the BEV position."""


@dataclass(frozen=True, slots=True)
class MotionModel:
    """F (4, 4), Q (4, 4), R (2, 2) for one class and one time step."""

    F: np.ndarray
    Q: np.ndarray
    R: np.ndarray


def cv_model(dt_s: float, params: ClassParams) -> MotionModel:
    F = np.eye(4)
    F[0, 2] = F[1, 3] = dt_s
    Q = np.diag([params.q_x, params.q_y, params.q_x, params.q_y])
    R = np.diag([params.r_x, params.r_y])
    return MotionModel(F=F, Q=Q, R=R)


def symmetrize(P: np.ndarray) -> np.ndarray:
    """(P + P^T) / 2 over the last two axes."""
    return 0.5 * (P + np.swapaxes(P, -1, -2))


def predict(mean: np.ndarray, cov: np.ndarray, model: MotionModel) -> tuple[np.ndarray, np.ndarray]:
    """Kalman predict of (K, 4) means and (K, 4, 4) covariances: m' = F m, P' = F P F^T + Q."""
    F = model.F
    return mean @ F.T, symmetrize(F @ cov @ F.T + model.Q)


@dataclass(frozen=True, slots=True)
class Innovation:
    """Per-track quantities of the update, shared by gating, likelihoods and the update itself.

    z_pred: (K, 2) H m; S: (K, 2, 2); S_inv: (K, 2, 2); log_det_S: (K,); gain: (K, 4, 2); cov_post: (K, 4, 4)
    (the posterior covariance does not depend on the measurement value).
    """

    z_pred: np.ndarray
    S: np.ndarray
    S_inv: np.ndarray
    log_det_S: np.ndarray
    gain: np.ndarray
    cov_post: np.ndarray


def innovation(mean: np.ndarray, cov: np.ndarray, R: np.ndarray) -> Innovation:
    """S, S^-1, gain and posterior covariance for (K, 4) means and (K, 4, 4) covariances."""
    z_pred = mean[:, :2]
    PHt = cov[:, :, :2]  # P H^T, (K, 4, 2)
    S = symmetrize(cov[:, :2, :2] + R)
    S_inv = symmetrize(np.linalg.inv(S))
    sign, log_det = np.linalg.slogdet(S)
    if np.any(sign <= 0):
        raise FloatingPointError("innovation covariance is not positive-definite")
    gain = PHt @ S_inv
    IKH = np.eye(4) - gain @ H
    cov_post = symmetrize(IKH @ cov @ np.swapaxes(IKH, -1, -2) + gain @ R @ np.swapaxes(gain, -1, -2))
    return Innovation(z_pred=z_pred, S=S, S_inv=S_inv, log_det_S=log_det, gain=gain, cov_post=cov_post)


def residuals(inn: Innovation, z: np.ndarray) -> np.ndarray:
    """(K, M, 2) innovations z_j - H m_k."""
    return z[None, :, :] - inn.z_pred[:, None, :]


def mahalanobis2(inn: Innovation, z: np.ndarray) -> np.ndarray:
    """(K, M) squared Mahalanobis distances of measurements z (M, 2) to each track's predicted measurement."""
    nu = residuals(inn, z)
    return np.einsum("kmi,kij,kmj->km", nu, inn.S_inv, nu)


def log_likelihood(inn: Innovation, d2: np.ndarray) -> np.ndarray:
    """(K, M) log N(z_j; H m_k, S_k) from squared Mahalanobis distances."""
    return -0.5 * (d2 + inn.log_det_S[:, None] + 2.0 * np.log(2.0 * np.pi))


def updated_means(mean: np.ndarray, inn: Innovation, z: np.ndarray) -> np.ndarray:
    """(K, M, 4) posterior means m_k + K_k (z_j - H m_k) for every track-measurement pair."""
    nu = residuals(inn, z)
    return mean[:, None, :] + np.einsum("kij,kmj->kmi", inn.gain, nu)
