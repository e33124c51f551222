"""JPDA: joint probabilistic data association with M/N track logic.

Fortmann, Bar-Shalom & Scheffe, "Sonar tracking of multiple targets using joint probabilistic data
association", IEEE J. Oceanic Eng. 8(3), 1983; Bar-Shalom, Daum & Huang, "The probabilistic data association
approach", IEEE Control Systems Magazine 29(6), 2009 (cited as BDH below).

Association probabilities. A joint event assigns every measurement to at most one track and every track at
most one measurement. With detection probability P_D, gate probability P_G and Poisson clutter intensity kappa
(the parametric clutter model of BDH), an event's weight is

    prod_(k <- j) P_D N(z_j; H m_k, S_k)  *  prod_(missed k) (1 - P_D P_G)  *  prod_(unassigned j) kappa,

which is the weight of ``gnnpmb.assign.marginals`` with ratio_kj = P_D N(z_j; H m_k, S_k) / (1 - P_D P_G)
inside the gate (0 outside) and new_weight_j = kappa. The marginals beta_kj = P(track k <- measurement j) and
beta_k0 = P(track k missed) factorise over the gated clusters (``clusters``) and are computed per cluster:

- one track: the closed-form PDA probabilities of BDH, beta_kj = e_j / (1 + sum_i e_i),
  beta_k0 = 1 / (1 + sum_i e_i) with e_j = ratio_kj / kappa, vectorised over all such clusters;
- at most ``exact_cluster_max`` tracks and at most ``EXACT_ASSOCIATION_BUDGET`` joint events (bounded by
  prod_k (1 + number of gated measurements of k)): exact enumeration (``assign.exact_marginals``);
- otherwise loopy belief propagation (``assign.lbp``, Williams & Lau 2014), settings from ``[lbp]``.

PDA update (BDH, the combined-innovation update): with innovations nu_kj = z_j - H m_k and gain W_k,
    nu_k = sum_j beta_kj nu_kj,      m_k+ = m_k + W_k nu_k,
    P_k+ = beta_k0 P_k + (1 - beta_k0) P_k^c + W_k (sum_j beta_kj nu_kj nu_kj^T - nu_k nu_k^T) W_k^T,
with P_k^c the (Joseph-form) Kalman posterior covariance. The last term, the spread of the innovations, is
positive semi-definite, so P_k+ stays symmetric positive-definite.

Track logic (``track_logic``): track k has a *hit* when it was more likely detected than missed,
1 - beta_k0 > 0.5; it then takes the box fields and score of its most probable measurement. A measurement
starts a tentative track when it is more likely unassociated than associated,
p_new_j = 1 - sum_k beta_kj > 0.5: no track, nor all tracks together, claims it with probability 0.5 or
more.
"""

from __future__ import annotations

import numpy as np

from gnnpmb.assign.clusters import gate_clusters
from gnnpmb.assign.exact_marginals import exact_marginals_log
from gnnpmb.assign.lbp import keep_most_likely, lbp_marginals_log
from gnnpmb.events import AxisKind, AxisLabel, EventSink, Marginals, Panel, axis_labels
from gnnpmb.kalman import Innovation, log_likelihood, mean_update, residuals, symmetrize
from gnnpmb.skeleton import Gating
from gnnpmb.types import Measurements
from gnnpmb.vector.tracks import Association, VectorTracker, VectorTracks

MAX_GATED_PER_TRACK = 32
"""Per-frame budget of JPDA: each track's association probabilities are computed over at most this many gated
measurements (its most likely); the others get probability 0. In a dense crowd the PDA covariances inflate and
the gates, hence the LBP graph, would grow every frame; the demo data never reaches it."""

EXACT_ASSOCIATION_BUDGET = 5000
"""A multi-track cluster is enumerated exactly only if prod_k (1 + gated measurements of k) is at most this;
the product bounds the number of joint events (about 1 ms to enumerate a cluster at the budget, measured)."""


def log_ratios(log_lik: np.ndarray, inside: np.ndarray, p_detect: float, gate_chi2: float) -> np.ndarray:
    """(K, M) log ratio_kj = log[P_D N(z_j; H m_k, S_k) / (1 - P_D P_G)], -inf outside the gate.

    P_G = 1 - exp(-G / 2) is the probability that a 2-D Gaussian measurement falls inside the gate d^2 < G.
    """
    p_gate = -np.expm1(-0.5 * gate_chi2)
    offset = np.log(p_detect) - np.log1p(-p_detect * p_gate)
    return np.where(inside, log_lik + offset, -np.inf)


def association_probabilities(
    log_ratio: np.ndarray,
    clutter_intensity: float,
    exact_cluster_max: int,
    lbp_max_iterations: int,
    lbp_tolerance: float,
) -> tuple[np.ndarray, np.ndarray, str, int]:
    """Marginal association probabilities of K tracks and M measurements (module docstring).

    Returns beta (K, M + 1) (column 0 = missed, rows sum to 1), p_new (M,) = 1 - sum_k beta_kj, the method
    ("exact", "lbp" or "exact+lbp") and the number of LBP iterations used. The multi-track clusters of each
    kind are solved together in one call, as independent components of one problem.
    """
    k, m = log_ratio.shape
    log_kappa = float(np.log(clutter_intensity))
    log_e = log_ratio - log_kappa  # e_kj = ratio_kj / kappa
    # Closed-form PDA for every track as if alone (exact for single-track clusters), in log space.
    row_max = np.maximum(log_e.max(axis=1, initial=0.0), 0.0)
    w = np.exp(log_e - row_max[:, None])
    miss = np.exp(-row_max)
    norm = miss + w.sum(axis=1)
    beta = np.concatenate([miss[:, None], w], axis=1) / norm[:, None]
    gated = np.isfinite(log_ratio)
    log_events = np.log1p(gated.sum(axis=1))  # (K,) log(1 + gated measurements of track k)
    groups: dict[str, tuple[list[np.ndarray], list[np.ndarray]]] = {"exact": ([], []), "lbp": ([], [])}
    methods = []
    for cluster in gate_clusters(gated):
        if len(cluster.tracks) == 1:
            methods = ["exact"]
            continue
        small = len(cluster.tracks) <= exact_cluster_max and (
            log_events[cluster.tracks].sum() <= np.log(EXACT_ASSOCIATION_BUDGET)
        )
        tracks, meas = groups["exact" if small else "lbp"]
        tracks.append(cluster.tracks)
        meas.append(cluster.meas)
    iterations = 0
    for name, (tracks, meas) in groups.items():
        if not tracks:
            continue
        # All clusters of one kind in one call: they stay independent components of the joined problem.
        t, j = np.concatenate(tracks), np.concatenate(meas)
        sub, new = log_ratio[np.ix_(t, j)], np.full(len(j), log_kappa)
        if name == "exact":
            res = exact_marginals_log(sub, new)
        else:
            res = lbp_marginals_log(sub, new, lbp_max_iterations, lbp_tolerance)
            iterations = res.iterations
        beta[t[:, None], np.concatenate([[0], j + 1])[None, :]] = res.p_track
        if name not in methods:
            methods.append(name)
    p_new = np.clip(1.0 - beta[:, 1:].sum(axis=0), 0.0, 1.0) if m else np.zeros(0)
    method = "+".join(methods) or "exact"
    return beta, p_new, method, iterations


def pda_update(
    mean: np.ndarray, cov: np.ndarray, inn: Innovation, z: np.ndarray, beta: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """PDA posterior means (K, 4) and covariances (K, 4, 4) from beta (K, M + 1) (module docstring)."""
    nu = residuals(inn, z)  # (K, M, 2)
    b = beta[:, 1:]
    nu_comb = np.einsum("km,kmi->ki", b, nu)
    spread = np.einsum("km,kmi,kmj->kij", b, nu, nu) - nu_comb[:, :, None] * nu_comb[:, None, :]
    W = inn.gain
    b0 = beta[:, 0, None, None]
    mean_post = mean_update(mean, W, nu_comb)
    cov_post = b0 * cov + (1.0 - b0) * inn.cov_post + W @ spread @ np.swapaxes(W, -1, -2)
    return mean_post, symmetrize(cov_post)


class JpdaTracker(VectorTracker):
    """One class's JPDA tracker (module docstring): ``tracks.VectorTracker`` with this ``_associate``."""

    panels = (Panel.MARGINALS,)
    has_costs = False

    def _associate(self, prior: VectorTracks, gating: Gating, meas: Measurements, sink: EventSink) -> Association:
        inn = gating.inn
        log_ratio = log_ratios(log_likelihood(inn, gating.d2), gating.inside, self.params.p_detect, self.gate_chi2)
        log_ratio = keep_most_likely(log_ratio, MAX_GATED_PER_TRACK)
        beta, p_new, method, iterations = association_probabilities(
            log_ratio,
            self.clutter_intensity,
            self.params.exact_cluster_max,
            self.lbp.max_iterations,
            self.lbp.tolerance,
        )
        mean, cov = pda_update(prior.mean, prior.cov, inn, meas.z, beta)
        meas_of_track = np.full(len(prior), -1, dtype=np.int64)
        if len(meas):
            hit = beta[:, 0] < 0.5
            meas_of_track[hit] = np.argmax(beta[hit, 1:], axis=1)
        if sink.enabled:
            rows = axis_labels(AxisKind.TRACK, prior.track_id)
            cols = (AxisLabel(AxisKind.MISSED, -1),) + axis_labels(AxisKind.MEASUREMENT, meas.source_index)
            sink.emit(Marginals(self.class_name, beta, rows, cols, method, iterations))
        return Association(mean=mean, cov=cov, meas_of_track=meas_of_track, birth=p_new > 0.5)
