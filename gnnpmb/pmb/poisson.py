"""The Poisson part of the PMB / PMBM density: a measurement-driven Gaussian-mixture birth intensity.

lambda_b(x) = sum_j w_b N(x; [z_j, v_j], P_b), P_b = diag(s_p^2, s_p^2, s_v^2, s_v^2) (``gnnpmb.models``): one
component per detection of the frame, centred on its BEV position with the detector's velocity (paper sec. V-B,
birth weight 0.1, initial covariance from s_p = 15). Component j only explains measurement j (adaptive birth,
Ristic, Clark, Vo & Vo 2012, "Adaptive target birth intensity for PHD and CPHD filters", IEEE T-AES 48(2)), so a
new track's velocity is its own detection's and never an average over neighbours. As in the paper's
implementation, undetected Poisson mass is not carried to the next frame: the birth intensity is the whole
Poisson component.

New-track hypothesis of measurement j (García-Fernández et al. 2018, eq. 14-15):
l_j = c + w_b P_D N(z_j; H m_j, H P_b H^T + R), r_j = (l_j - c) / l_j, state = Kalman update of component j,
with c the clutter intensity and P_D the detection's score.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from gnnpmb.kalman import gaussian_log_density, innovation, mean_update, paired_mahalanobis2
from gnnpmb.models import BirthIntensity
from gnnpmb.types import Measurements


@dataclass(frozen=True, slots=True)
class NewTrackHypotheses:
    """Per measurement j: log l_j (M,), existence r_j (M,), posterior mean (M, 4) and cov (M, 4, 4)."""

    log_likelihood: np.ndarray
    existence: np.ndarray
    mean: np.ndarray
    cov: np.ndarray


@dataclass(frozen=True, slots=True)
class BirthUpdate:
    """The update of a birth component by its own measurement, the same for every component: all have covariance
    P_b, and the innovation z_j - H m_j is exactly 0 (component j is centred on measurement j, which preprocessing
    keeps finite). log_density: log N(z_j; H m_j, S); mean_increment: K (z_j - H m_j), (4,) signed zeros;
    cov: the posterior covariance (4, 4), read-only."""

    log_density: float
    mean_increment: np.ndarray
    cov: np.ndarray


def birth_update(birth_cov: np.ndarray, R: np.ndarray) -> BirthUpdate:
    """``BirthUpdate`` of components with covariance ``birth_cov`` (4, 4): the arithmetic of
    ``new_track_hypotheses`` on one component with a zero innovation, so each quantity has the bits the
    per-component computation gives."""
    d = R.shape[0]
    inn = innovation(np.zeros((1, birth_cov.shape[0])), birth_cov[None], R)
    nu = np.zeros((1, d))
    log_density = gaussian_log_density(paired_mahalanobis2(inn.S_inv, nu), inn.log_det_S, d)
    increment = mean_update(np.full((1, birth_cov.shape[0]), -0.0), inn.gain, nu)[
        0
    ]  # -0 + x = x, signed zeros included
    cov = inn.cov_post[0]
    increment.flags.writeable = cov.flags.writeable = False
    return BirthUpdate(log_density=float(log_density[0]), mean_increment=increment, cov=cov)


def new_track_hypotheses(
    birth: BirthIntensity,
    meas: Measurements,
    R: np.ndarray,
    clutter_intensity: float,
    shared: BirthUpdate | None = None,
) -> NewTrackHypotheses:
    """Likelihood, existence and state of the Bernoulli each measurement would start (module docstring).

    ``shared``: the update every component shares (``birth_update`` of P_b and R; the PMB filters compute it once
    per class), used instead of a Kalman update per component."""
    m = len(meas)
    if m == 0:
        n = birth.mean.shape[1]
        return NewTrackHypotheses(np.zeros(0), np.zeros(0), np.zeros((0, n)), np.zeros((0, n, n)))
    if shared is None:
        inn = innovation(birth.mean, birth.cov, R)
        nu = meas.z - inn.z_pred  # (M, D): component j explains measurement j only
        log_n = gaussian_log_density(paired_mahalanobis2(inn.S_inv, nu), inn.log_det_S, nu.shape[1])
        mean, cov = mean_update(birth.mean, inn.gain, nu), inn.cov_post
    else:
        log_n = np.full(m, shared.log_density)
        mean, cov = birth.mean + shared.mean_increment, shared.cov[None].repeat(m, axis=0)
    birth_term = birth.weight * meas.boxes.score * np.exp(log_n)
    total = clutter_intensity + birth_term
    return NewTrackHypotheses(log_likelihood=np.log(total), existence=birth_term / total, mean=mean, cov=cov)
