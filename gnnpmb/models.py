"""The models every tracker shares: constant-velocity motion, measurement-driven birth, clutter and survival.

Parameters: per-class noise ``[classes.<class>]`` (``ClassParams``) and the shared ``[models]`` section
(``ModelParams``: P_S, gate, clutter intensity, birth). Motion x_k = F x_{k-1} + w, w ~ N(0, Q),
F = [[I, dt I], [0, I]], Q = diag(q_x, q_y, q_x, q_y); measurement z = H x + v, v ~ N(0, R), R = diag(r_x, r_y)
(paper sec. V-B). Birth: one Gaussian component per detection of the frame,
lambda_b(x) = sum_j w_b N(x; [z_j, v_j], P_b), P_b = diag(s_p^2, s_p^2, s_v^2, s_v^2), centred on its BEV position
with the detector's velocity (adaptive birth, Ristic, Clark, Vo & Vo 2012, IEEE T-AES 48(2)). Clutter: a Poisson
process of intensity kappa per m^2 (per m^2 per (m/s)^2 when the PMB variant also measures velocity).
"""

from __future__ import annotations

import functools
from dataclasses import dataclass

import numpy as np

from gnnpmb.config import ClassParams, ModelParams, PmbParams
from gnnpmb.types import Measurements


@dataclass(frozen=True, slots=True)
class MotionModel:
    """F (4, 4), Q (4, 4), R (D, D) for one class and one time step."""

    F: np.ndarray
    Q: np.ndarray
    R: np.ndarray


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


@functools.lru_cache(maxsize=64)
def birth_covariance(models: ModelParams) -> np.ndarray:
    """(4, 4) P_b = diag(s_p^2, s_p^2, s_v^2, s_v^2) of a birth component (shared between calls, read-only)."""
    P_b = np.diag([models.birth_pos_std_m**2] * 2 + [models.birth_vel_std_mps**2] * 2)
    P_b.flags.writeable = False
    return P_b


@dataclass(frozen=True, slots=True)
class BirthIntensity:
    """M Gaussian components: weight (M,), mean (M, 4), cov (M, 4, 4)."""

    weight: np.ndarray
    mean: np.ndarray
    cov: np.ndarray


def measurement_birth(meas: Measurements, models: ModelParams) -> BirthIntensity:
    """One birth component per measurement at [z_j, v_j] with weight w_b and covariance P_b."""
    m = len(meas)
    mean = np.concatenate([meas.boxes.xy, meas.boxes.velocity_mps], axis=1) if m else np.zeros((0, 4))
    cov = birth_covariance(models)[None].repeat(m, axis=0)
    return BirthIntensity(weight=np.full(m, models.birth_weight), mean=mean, cov=cov)


def clutter_intensity(models: ModelParams, pmb: PmbParams) -> float:
    """kappa of the PMB family's measurement space: per m^2, times the clutter velocity density when the
    velocity is measured too (``[pmb] measure_velocity = 1``)."""
    return models.clutter_intensity * (pmb.clutter_velocity_density if pmb.measure_velocity == 1 else 1.0)
