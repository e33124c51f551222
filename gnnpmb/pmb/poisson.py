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

from gnnpmb.kalman import Innovation, gaussian_log_density, innovation, mean_update, paired_mahalanobis2
from gnnpmb.models import BirthIntensity
from gnnpmb.types import Measurements


@dataclass(frozen=True, slots=True)
class NewTrackHypotheses:
    """Per measurement j: log l_j (M,), existence r_j (M,), posterior mean (M, 4) and cov (M, 4, 4)."""

    log_likelihood: np.ndarray
    existence: np.ndarray
    mean: np.ndarray
    cov: np.ndarray


def new_track_hypotheses(
    birth: BirthIntensity,
    meas: Measurements,
    R: np.ndarray,
    clutter_intensity: float,
    birth_innovation: Innovation | None = None,
) -> NewTrackHypotheses:
    """Likelihood, existence and state of the Bernoulli each measurement would start (module docstring).

    ``birth_innovation``: the innovation (``kalman.innovation``, one row) of a birth component, whose S, gain and
    posterior covariance every component shares (they all have covariance P_b): given, it is repeated instead of
    computed for each of the M components."""
    m = len(meas)
    if m == 0:
        return NewTrackHypotheses(np.zeros(0), np.zeros(0), np.zeros((0, 4)), np.zeros((0, 4, 4)))
    if birth_innovation is None:
        inn = innovation(birth.mean, birth.cov, R)
    else:
        inn = birth_innovation.subset(np.zeros(m, dtype=np.intp))
    nu = meas.z - birth.mean[:, : R.shape[0]]  # (M, D) z_j - H m_j: component j explains measurement j only
    log_n = gaussian_log_density(paired_mahalanobis2(inn.S_inv, nu), inn.log_det_S, nu.shape[1])
    birth_term = birth.weight * meas.boxes.score * np.exp(log_n)
    total = clutter_intensity + birth_term
    mean = mean_update(birth.mean, inn.gain, nu)
    return NewTrackHypotheses(log_likelihood=np.log(total), existence=birth_term / total, mean=mean, cov=inn.cov_post)
