"""The models every tracker shares: constant-velocity motion, measurement-driven birth, clutter and survival;
the coordinated-turn motion model of the PMB family (its default; the paper's is constant velocity).

Parameters: per-class noise ``[classes.<class>]`` (``ClassParams``) and the shared ``[models]`` section
(``ModelParams``: P_S, gate, clutter intensity, birth). Motion x_k = F x_{k-1} + w, w ~ N(0, Q),
F = [[I, dt I], [0, I]], Q = diag(q_x, q_y, q_x, q_y); measurement z = H x + v, v ~ N(0, R), R = diag(r_x, r_y)
(paper sec. V-B). Birth: one Gaussian component per detection of the frame,
lambda_b(x) = sum_j w_b N(x; [z_j, v_j], P_b), P_b = diag(s_p^2, s_p^2, s_v^2, s_v^2), centred on its BEV position
with the detector's velocity (adaptive birth, Ristic, Clark, Vo & Vo 2012, IEEE T-AES 48(2)). Clutter: a Poisson
process of intensity kappa per m^2 (per m^2 per (m/s)^2 when the PMB variant also measures velocity).

Coordinated turn (``[models] motion_model = 1``; Bar-Shalom, Li & Kirubarajan 2001, sec. 11.7.1, eq. 11.7.1-4;
constant turn rate and velocity, CTRV, in Cartesian velocity): state [x, y, vx, vy, omega],
  x' = x + (sin(w T) vx - (1 - cos(w T)) vy) / w,   vx' = cos(w T) vx - sin(w T) vy,
  y' = y + ((1 - cos(w T)) vx + sin(w T) vy) / w,   vy' = sin(w T) vx + cos(w T) vy,   w' = a w,
with the limits sin(w T) / w -> T, (1 - cos(w T)) / w -> 0 as w -> 0 (so omega = 0 is the CV model exactly);
Q = diag(q_x, q_y, q_x, q_y, sigma_w^2). The turn rate is a first-order Markov process (``[models]
turn_rate_decay`` a in (0, 1]; a = 1: constant turn rate): while a track coasts, its turn rate returns to 0 and its
variance to at most sigma_w^2 / (1 - a^2), so a long-missed track is not spread along every possible turn. It is
predicted with the extended Kalman filter (``kalman.predict`` with ``MotionModel.transition``); the measurement is
the same [x, y] (or [x, y, vx, vy]).

Coasting (``[models] coast_velocity_decay`` b in (0, 1]; 1 = off): a Bernoulli missed at its last update is
predicted with x' = f(x) followed by v' = b v (the velocity rows of f and of its Jacobian times b, as the turn
rate's w' = a w), so a lost object's predicted box slows down rather than running on at its last velocity; a
detected one is predicted as above (``MotionModel.coast``, ``pmb.bernoulli.predict_bernoullis``).
"""

from __future__ import annotations

import dataclasses
import functools
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from gnnpmb.config import ClassParams, ModelParams, PmbParams
from gnnpmb.types import Measurements

Transition = Callable[[np.ndarray], tuple[np.ndarray, np.ndarray]]
"""A non-linear motion model for one time step: (K, n) means -> (f(m) (K, n), its Jacobian at m (K, n, n))."""


@dataclass(frozen=True, slots=True)
class MotionModel:
    """F (n, n), Q (n, n), R (D, D) for one class and one time step; transition: the non-linear f and its
    Jacobian (extended Kalman predict, ``kalman.predict``), None for a linear model x' = F x (F is then the
    model; for a non-linear one F is its Jacobian at omega = 0, for display only); coast: the model of a track
    missed at its last update (``coasting``), None when ``[models] coast_velocity_decay`` is 1."""

    F: np.ndarray
    Q: np.ndarray
    R: np.ndarray
    transition: Transition | None = None
    coast: MotionModel | None = None

    @property
    def state_dim(self) -> int:
        return int(self.Q.shape[0])


def cv_model(dt_s: float, params: ClassParams, measure_velocity: bool = False) -> MotionModel:
    """F, Q and R (2 x 2 diag(r_x, r_y), or 4 x 4 diag(r_x, r_y, r_vx, r_vy) when ``measure_velocity``).

    The matrices are shared between calls with equal arguments (every class of a frame has the same F) and are
    read-only."""
    Q, R = _noise(params, measure_velocity)
    return MotionModel(F=_transition(dt_s), Q=Q, R=R)


@functools.lru_cache(maxsize=64)
def _transition(dt_s: float) -> np.ndarray:
    """(4, 4) F = [[I, dt I], [0, I]], read-only."""
    F = np.eye(4)
    F[0, 2] = F[1, 3] = dt_s
    F.flags.writeable = False
    return F


@functools.lru_cache(maxsize=256)
def _noise(params: ClassParams, measure_velocity: bool) -> tuple[np.ndarray, np.ndarray]:
    """(4, 4) Q and (D, D) R of one class, read-only."""
    Q = np.diag([params.q_x, params.q_y, params.q_x, params.q_y])
    r = [params.r_x, params.r_y] + ([params.r_vx, params.r_vy] if measure_velocity else [])
    R = np.diag(r)
    Q.flags.writeable = R.flags.writeable = False
    return Q, R


def ct_model(dt_s: float, params: ClassParams, models: ModelParams, measure_velocity: bool = False) -> MotionModel:
    """The coordinated-turn model over ``dt_s`` (module docstring): Q (5, 5), R as ``cv_model``'s, F the CV
    transition with omega appended (the Jacobian at omega = 0), ``transition`` = ``coordinated_turn``."""
    Q, R = _ct_noise(params, models.turn_rate_std_rps, measure_velocity)
    transition = functools.partial(coordinated_turn, dt_s=dt_s, decay=models.turn_rate_decay)
    return MotionModel(F=_ct_linear(dt_s, models.turn_rate_decay), Q=Q, R=R, transition=transition)


def motion_model(dt_s: float, params: ClassParams, models: ModelParams, measure_velocity: bool = False) -> MotionModel:
    """``cv_model`` or ``ct_model`` as ``[models] motion_model`` says (the PMB family's; the other families'
    states are [x, y, vx, vy] and they use ``cv_model``)."""
    model = (
        ct_model(dt_s, params, models, measure_velocity)
        if models.motion_model == 1
        else cv_model(dt_s, params, measure_velocity)
    )
    if models.coast_velocity_decay == 1.0:
        return model
    return dataclasses.replace(model, coast=coasting(model, models.coast_velocity_decay))


def coasting(model: MotionModel, decay: float) -> MotionModel:
    """``model`` followed by v' = ``decay`` v: F (or f and its Jacobian) with its velocity rows times ``decay``;
    Q and R unchanged (module docstring, coasting)."""
    D = np.ones(model.state_dim)
    D[2:4] = decay
    F = D[:, None] * model.F
    F.flags.writeable = False
    transition = None if model.transition is None else functools.partial(_slowed, model.transition, D)
    return MotionModel(F=F, Q=model.Q, R=model.R, transition=transition)


def _slowed(transition: Transition, D: np.ndarray, mean: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """diag(D) f(m) and diag(D) J (``coasting``)."""
    out, J = transition(mean)
    return out * D, J * D[:, None]


_SMALL_TURN = 1e-4
"""Below this |omega T| (rad) the coordinated-turn coefficients are taken from their Taylor series."""


def coordinated_turn(mean: np.ndarray, dt_s: float, decay: float = 1.0) -> tuple[np.ndarray, np.ndarray]:
    """f(m) (K, 5) and its Jacobian (K, 5, 5) of the coordinated-turn model (module docstring) at K states
    [x, y, vx, vy, omega]; the turn rate steps to ``decay`` w. With a = sin(w T) / w, b = (1 - cos(w T)) / w,
    c = cos(w T), s = sin(w T): d(a)/dw = (T c - a) / w, d(b)/dw = (T s - b) / w, d(c)/dw = -T s, d(s)/dw = T c
    (series for small w T)."""
    vx, vy, w = mean[:, 2], mean[:, 3], mean[:, 4]
    T = dt_s
    wt = w * T
    small = np.abs(wt) < _SMALL_TURN
    w_safe = np.where(small, 1.0, w)
    s, c = np.sin(wt), np.cos(wt)
    wt2 = wt * wt
    a = np.where(small, T * (1.0 - wt2 / 6.0), s / w_safe)
    b = np.where(small, T * wt / 2.0 * (1.0 - wt2 / 12.0), (1.0 - c) / w_safe)
    da = np.where(small, -T * T * wt / 3.0, (T * c - a) / w_safe)
    db = np.where(small, T * T * (0.5 - wt2 / 8.0), (T * s - b) / w_safe)
    out = np.empty_like(mean)
    out[:, 0] = mean[:, 0] + a * vx - b * vy
    out[:, 1] = mean[:, 1] + b * vx + a * vy
    out[:, 2] = c * vx - s * vy
    out[:, 3] = s * vx + c * vy
    out[:, 4] = decay * w
    J = np.zeros((len(mean), 5, 5))
    J[:, 0, 0] = J[:, 1, 1] = 1.0
    J[:, 4, 4] = decay
    J[:, 0, 2], J[:, 0, 3], J[:, 0, 4] = a, -b, da * vx - db * vy
    J[:, 1, 2], J[:, 1, 3], J[:, 1, 4] = b, a, db * vx + da * vy
    J[:, 2, 2], J[:, 2, 3], J[:, 2, 4] = c, -s, -T * (s * vx + c * vy)
    J[:, 3, 2], J[:, 3, 3], J[:, 3, 4] = s, c, T * (c * vx - s * vy)
    return out, J


@functools.lru_cache(maxsize=64)
def _ct_linear(dt_s: float, decay: float = 1.0) -> np.ndarray:
    """(5, 5) the coordinated-turn Jacobian at omega = 0 and zero velocity: the CV F, omega times ``decay``,
    read-only."""
    F = np.eye(5)
    F[:4, :4] = _transition(dt_s)
    F[4, 4] = decay
    F.flags.writeable = False
    return F


@functools.lru_cache(maxsize=256)
def _ct_noise(params: ClassParams, turn_rate_std_rps: float, measure_velocity: bool) -> tuple[np.ndarray, np.ndarray]:
    """(5, 5) Q = diag(q_x, q_y, q_x, q_y, sigma_w^2) and R of one class, read-only."""
    Q4, R = _noise(params, measure_velocity)
    Q = np.zeros((5, 5))
    Q[:4, :4] = Q4
    Q[4, 4] = turn_rate_std_rps**2
    Q.flags.writeable = False
    return Q, R


@functools.lru_cache(maxsize=64)
def birth_covariance(models: ModelParams, with_turn_rate: bool = False) -> np.ndarray:
    """(n, n) P_b = diag(s_p^2, s_p^2, s_v^2, s_v^2) of a birth component, with s_w^2 appended for the
    coordinated-turn state when ``with_turn_rate`` (shared between calls, read-only)."""
    diag = [models.birth_pos_std_m**2] * 2 + [models.birth_vel_std_mps**2] * 2
    if with_turn_rate:
        diag.append(models.birth_turn_rate_std_rps**2)
    P_b = np.diag(diag)
    P_b.flags.writeable = False
    return P_b


@dataclass(frozen=True, slots=True)
class BirthIntensity:
    """M Gaussian components: weight (M,), mean (M, 4), cov (M, 4, 4)."""

    weight: np.ndarray
    mean: np.ndarray
    cov: np.ndarray


def measurement_birth(meas: Measurements, models: ModelParams, with_turn_rate: bool = False) -> BirthIntensity:
    """One birth component per measurement at [z_j, v_j] (and turn rate 0 when ``with_turn_rate``: the
    coordinated-turn state) with weight w_b and covariance P_b."""
    m = len(meas)
    P_b = birth_covariance(models, with_turn_rate)
    mean = np.zeros((m, P_b.shape[0]))
    if m:
        mean[:, :2], mean[:, 2:4] = meas.boxes.xy, meas.boxes.velocity_mps
    cov = P_b[None].repeat(m, axis=0)
    return BirthIntensity(weight=np.full(m, models.birth_weight), mean=mean, cov=cov)


def clutter_intensity(models: ModelParams, pmb: PmbParams) -> float:
    """kappa of the PMB family's measurement space: per m^2, times the clutter velocity density when the
    velocity is measured too (``[pmb] measure_velocity = 1``)."""
    return models.clutter_intensity * (pmb.clutter_velocity_density if pmb.measure_velocity == 1 else 1.0)
