"""The 10-D constant-velocity box Kalman filter of AB3DMOT, Probabilistic 3D MOT, SimpleTrack and ImmortalTracker.

State s = [x, y, z, yaw, l, w, h, vx, vy, vz] (global frame; m, rad, m/s), measurement z = H s = [x, y, z, yaw,
l, w, h], a detection box (H = [I_7 0]; Weng et al. 2020, sec. 3.2). Motion over dt seconds: the centre moves
by the velocity, yaw and size stay: F = [[I_7, G dt], [0, I_3]], G picking x, y, z; process noise Q and
measurement noise R diagonal per class (``config.BoxNoise``). A new track starts at [z, 0, 0, 0] with
P_0 = diag(p_scale R, p_vx, p_vy, p_vz).

Heading: a box turned by pi is the same box, and detectors confuse the two. Before an update the predicted yaw
is turned by a multiple of pi to lie within pi/2 of the detection's (``align_heading``: AB3DMOT's orientation
correction), so the yaw residual is in [-pi/2, pi/2]; association residuals use the same convention
(``residuals``). Yaws are kept in [-pi, pi).

The Kalman formulas are ``gnnpmb.kalman``'s: ``predict`` with this F, ``innovation`` with D = 7, and the
paired mean update.
"""

from __future__ import annotations

import functools

import numpy as np

from gnnpmb.config import BoxNoise
from gnnpmb.data.boxes3d import quat_wxyz_from_yaw, yaw_from_quat_wxyz
from gnnpmb.kalman import Innovation, mean_update, paired_mahalanobis2, symmetrize
from gnnpmb.models import MotionModel
from gnnpmb.types import Boxes

STATE_DIM = 10
MEAS_DIM = 7
X, Y, Z, YAW, LENGTH, WIDTH, HEIGHT, VX, VY, VZ = range(STATE_DIM)
VIEW = np.array([X, Y, VX, VY])
_UNIT_NOISE = BoxNoise.uniform(r=1.0, q=0.0, q_size=0.0, q_velocity=0.0, p_velocity=1.0, p_scale=1.0)
"""Any noise: ``moved`` reads only F."""
"""The state entries events show ([x, y, vx, vy], ``skeleton.TrackView``)."""


@functools.lru_cache(maxsize=256)
def box_model(dt_s: float, noise: BoxNoise) -> MotionModel:
    """F (10, 10), Q (10, 10) and R (7, 7) for one class and a step of ``dt_s`` seconds (read-only, shared)."""
    F = np.eye(STATE_DIM)
    F[X, VX] = F[Y, VY] = F[Z, VZ] = dt_s
    n = noise
    Q = np.diag([n.q_x, n.q_y, n.q_z, n.q_yaw, n.q_size, n.q_size, n.q_size, n.q_vx, n.q_vy, n.q_vz])
    R = np.diag([n.r_x, n.r_y, n.r_z, n.r_yaw, n.r_l, n.r_w, n.r_h])
    for a in (F, Q, R):
        a.flags.writeable = False
    return MotionModel(F=F, Q=Q, R=R)


def box_models(dt_s: np.ndarray, noise: BoxNoise) -> MotionModel:
    """``box_model`` for K tracks predicted over their own times ``dt_s`` (K,): F (K, 10, 10), shared Q and R."""
    base = box_model(0.0, noise)
    F = np.broadcast_to(base.F, (len(dt_s), STATE_DIM, STATE_DIM)).copy()
    for pos, vel in ((X, VX), (Y, VY), (Z, VZ)):
        F[:, pos, vel] = dt_s
    return MotionModel(F=F, Q=base.Q, R=base.R)


def initial_state(z: np.ndarray, noise: BoxNoise) -> tuple[np.ndarray, np.ndarray]:
    """Means (M, 10) [z_j, 0, 0, 0] and covariances (M, 10, 10) P_0 of M new tracks from their boxes (M, 7)."""
    m = len(z)
    mean = np.zeros((m, STATE_DIM))
    mean[:, :MEAS_DIM] = z
    n = noise
    p0 = np.diag(
        [n.p_scale * r for r in (n.r_x, n.r_y, n.r_z, n.r_yaw, n.r_l, n.r_w, n.r_h)] + [n.p_vx, n.p_vy, n.p_vz]
    )
    return mean, np.broadcast_to(p0, (m, STATE_DIM, STATE_DIM)).copy()


def moved(mean: np.ndarray, dt_s: float) -> np.ndarray:
    """(K, 10) box states with their centres moved by their velocity over ``dt_s`` (x += vx dt, ...): F s."""
    return mean @ box_model(dt_s, _UNIT_NOISE).F.T


def moved_back(z: np.ndarray, velocity_mps: np.ndarray, dt_s: float) -> np.ndarray:
    """(M, 7) boxes with their BEV centres stepped back by their velocities (M, 2) over ``dt_s``: where a
    detection moving at its detector's velocity was one frame ago (CenterPoint's and SimpleTrack's "velo")."""
    out = z.copy()
    out[:, [X, Y]] -= np.asarray(velocity_mps, dtype=float) * dt_s
    return out


def box_with_velocity(z: np.ndarray, velocity_mps: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """States (M, 10) [z_j, v_j, 0] of boxes (M, 7) taken as they are with their detector velocities (M, 2),
    for a tracker without a filter; their covariances (M, 10, 10) are a stand-in for the viewer: the box's BEV
    half-diagonal as the position's standard deviation, 1 elsewhere."""
    m = len(z)
    mean = np.zeros((m, STATE_DIM))
    mean[:, :MEAS_DIM] = z
    mean[:, [VX, VY]] = velocity_mps
    cov = np.broadcast_to(np.eye(STATE_DIM), (m, STATE_DIM, STATE_DIM)).copy()
    half_diagonal2 = 0.25 * (z[:, LENGTH] ** 2 + z[:, WIDTH] ** 2)
    cov[:, X, X] = cov[:, Y, Y] = np.maximum(half_diagonal2, 1e-6)
    return mean, cov


def measurements(boxes: Boxes) -> np.ndarray:
    """(M, 7) [x, y, z, yaw, l, w, h] of M detection boxes (sizes are (w, l, h) in ``Boxes``)."""
    size = boxes.size_wlh_m
    yaw = yaw_from_quat_wxyz(boxes.quat_wxyz)
    return np.column_stack([boxes.translation_m, yaw, size[:, 1], size[:, 0], size[:, 2]])


def wrap_angle(a: np.ndarray) -> np.ndarray:
    """Angles in [-pi, pi)."""
    return (np.asarray(a, dtype=float) + np.pi) % (2.0 * np.pi) - np.pi


def half_turn_residual(a: np.ndarray) -> np.ndarray:
    """Angle differences modulo pi, in [-pi/2, pi/2): the yaw residual of boxes that a half turn leaves alike."""
    return (np.asarray(a, dtype=float) + 0.5 * np.pi) % np.pi - 0.5 * np.pi


def align_heading(pred_yaw: np.ndarray, det_yaw: np.ndarray) -> np.ndarray:
    """``pred_yaw`` turned by the multiple of pi that brings it within pi/2 of ``det_yaw`` (orientation
    correction): det_yaw - result is ``half_turn_residual(det_yaw - pred_yaw)``."""
    return np.asarray(det_yaw, dtype=float) - half_turn_residual(np.asarray(det_yaw) - np.asarray(pred_yaw))


def residuals(z_pred: np.ndarray, z: np.ndarray) -> np.ndarray:
    """(K, M, 7) box residuals z_j - H s_k of every track and detection, the yaw one modulo pi in [-pi/2, pi/2)."""
    nu = z[None, :, :] - z_pred[:, None, :]
    nu[..., YAW] = half_turn_residual(nu[..., YAW])
    return nu


def mahalanobis2(inn: Innovation, z: np.ndarray) -> np.ndarray:
    """(K, M) nu^T S_k^-1 nu of every track and detection box (M, 7), heading-aligned residuals."""
    k, m = len(inn.z_pred), len(z)
    if k == 0 or m == 0:
        return np.zeros((k, m))
    nu = residuals(inn.z_pred, z).reshape(k * m, MEAS_DIM)
    return paired_mahalanobis2(np.repeat(inn.S_inv, m, axis=0), nu).reshape(k, m)


def update(mean: np.ndarray, inn: Innovation, z: np.ndarray) -> np.ndarray:
    """(P, 10) posterior means of P tracks (prior means (P, 10), their innovation quantities ``inn`` (P)) updated
    by one box each (P, 7): the predicted yaw aligned to the box's, then m + K (z - H m), yaw wrapped. The
    posterior covariance is ``inn.cov_post`` (it does not depend on z)."""
    prior = mean.copy()
    prior[:, YAW] = align_heading(prior[:, YAW], z[:, YAW])
    post = mean_update(prior, inn.gain, z - prior[:, :MEAS_DIM])
    post[:, YAW] = wrap_angle(post[:, YAW])
    return post


def view(mean: np.ndarray, cov: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """([x, y, vx, vy] (K, 4), their covariance (K, 4, 4)) of K box states, as events show tracks."""
    return mean[:, VIEW], symmetrize(cov[:, VIEW[:, None], VIEW[None, :]])


def box_fields(mean: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(centres (K, 3), sizes (w, l, h) (K, 3), yaws (K,)) of K box states or boxes (K, >= 7)."""
    return mean[:, [X, Y, Z]], mean[:, [WIDTH, LENGTH, HEIGHT]], mean[:, YAW]


def quat_of(mean: np.ndarray) -> np.ndarray:
    """(K, 4) quaternions (w, x, y, z) of the yaws of K box states."""
    return quat_wxyz_from_yaw(mean[:, YAW])
