"""Marginal association probabilities by loopy belief propagation (Williams & Lau, IEEE T-AES 50(4), 2014).

The association problem of ``marginals`` is a bipartite graphical model: one variable a_k per track (which
measurement it takes, 0 = missed), one variable b_j per measurement (which track takes it, 0 = none), and a
consistency constraint a_k = j <=> b_j = k on every gated pair. With the column-normalised, row-scaled weights
w_kj and missed weights q_k of ``marginals.normalised_weights`` (the unassociated weight is 1), the messages,
stored as ratios "a_k = j" : "a_k != j", are

    mu_kj = w_kj / (q_k + sum_{j' != j} w_kj' nu_j'k)       (track k -> measurement j)
    nu_jk = 1 / (1 + sum_{k' != k} mu_k'j)                  (measurement j -> track k)

started from nu = 1, and the track beliefs are P(a_k = j) = w_kj nu_jk / (q_k + sum_j' w_kj' nu_j'k),
P(a_k = 0) = q_k / (same). Williams & Lau prove this iteration converges; it is exact on loop-free gating
graphs (one track, or one measurement) after one iteration. Iteration stops when no marginal changes by more than
``tolerance``. Messages exist only on gated pairs (edges), so a round costs O(edges). The sums that leave one
term out are computed so that they do not cancel catastrophically when one term dominates (ratios spanning many
orders of magnitude; ``_sum_others``).
"""

from __future__ import annotations

import numpy as np

from gnnpmb.assign.marginals import (
    AssociationMarginals,
    check_log_inputs,
    from_track_marginals,
    log_inputs,
    normalised_weights,
    trivial_marginals,
)

__all__ = ["AssociationMarginals", "lbp_marginals", "lbp_marginals_log"]


def lbp_marginals(
    ratio: np.ndarray, new_weight: np.ndarray, max_iterations: int = 100, tolerance: float = 1e-7
) -> AssociationMarginals:
    """Approximate marginals of ``ratio`` (K, M) >= 0 = l_kj / l_k0 (0 = not gated) and ``new_weight`` (M,) > 0.

    Returns p_track (K, M + 1) (column 0 = missed) and p_new (M,) (``marginals.AssociationMarginals``).
    """
    log_ratio, log_new = log_inputs(ratio, new_weight)
    return _lbp(log_ratio, log_new, max_iterations, tolerance)


def lbp_marginals_log(
    log_ratio: np.ndarray, log_new_weight: np.ndarray, max_iterations: int = 100, tolerance: float = 1e-7
) -> AssociationMarginals:
    """``lbp_marginals`` from log ratios (K, M) (-inf = not gated) and log new weights (M,): no exp overflow."""
    log_ratio, log_new = check_log_inputs(log_ratio, log_new_weight)
    return _lbp(log_ratio, log_new, max_iterations, tolerance)


def keep_most_likely(log_ratio: np.ndarray, limit: int) -> np.ndarray:
    """(K, M) log ratios with all but each row's ``limit`` largest entries set to -inf (not gated); ties at the
    cut are kept. The per-frame budget of the trackers that run LBP: at most about K * limit edges."""
    if log_ratio.shape[1] <= limit or (np.isfinite(log_ratio).sum(axis=1) <= limit).all():
        return log_ratio
    cut = -np.partition(-log_ratio, limit - 1, axis=1)[:, limit - 1 : limit]  # each row's limit-th largest
    out = log_ratio.copy()
    out[log_ratio < cut] = -np.inf
    return out


def _lbp(log_ratio: np.ndarray, log_new: np.ndarray, max_iterations: int, tolerance: float) -> AssociationMarginals:
    """LBP on the gated (track, measurement) pairs only: every message lives on one edge of the gating graph, so
    a frame costs O(edges) per round however many tracks and measurements there are."""
    if max_iterations < 1:
        raise ValueError(f"max_iterations must be at least 1, got {max_iterations}")
    n_tracks, n_meas = log_ratio.shape
    if n_tracks == 0 or n_meas == 0:
        return trivial_marginals(n_tracks, n_meas, "lbp")
    rows, cols, w, miss = normalised_weights(log_ratio, log_new)
    if len(rows) == 0:
        return trivial_marginals(n_tracks, n_meas, "lbp")
    weighted = w  # w_kj nu_jk with nu = 1
    p_edge, p_miss = _beliefs(weighted, miss, rows)
    iterations = 0
    while iterations < max_iterations:
        iterations += 1
        mu = w / (miss[rows] + _sum_others(weighted, rows, n_tracks))
        nu = 1.0 / (1.0 + _sum_others(mu, cols, n_meas))
        weighted = w * nu
        p_edge_next, p_miss_next = _beliefs(weighted, miss, rows)
        change = max(float(np.max(np.abs(p_edge_next - p_edge))), float(np.max(np.abs(p_miss_next - p_miss))))
        p_edge, p_miss = p_edge_next, p_miss_next
        if change < tolerance:
            break
    p_track = np.zeros((n_tracks, n_meas + 1))
    p_track[:, 0] = p_miss
    p_track[rows, cols + 1] = p_edge
    return from_track_marginals(p_track, iterations, "lbp")


def _beliefs(weighted: np.ndarray, miss: np.ndarray, rows: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Track beliefs: P(a_k = j) per edge (E,) and P(a_k = 0) (K,), i.e. [q_k, w_kj nu_jk] / (q_k + sum_j ...)."""
    norm = miss + np.bincount(rows, weights=weighted, minlength=len(miss))
    return weighted / norm[rows], miss / norm


_DOMINANT = 1e-3
"""An edge whose own term exceeds (1 - _DOMINANT) of its segment's sum gets the sum of the others recomputed."""


def _sum_others(values: np.ndarray, segment: np.ndarray, n_segments: int) -> np.ndarray:
    """For every edge, the sum of ``values`` over the other edges of its segment (its track or measurement).

    "Segment total minus own value" has relative error about eps * total / others, harmless unless the own value
    dominates; those edges (at most one per segment) get the exact sum of the others instead, so the result is
    accurate to ~1e3 eps even when the values span hundreds of orders of magnitude.
    """
    total = np.bincount(segment, weights=values, minlength=n_segments)[segment]
    others = total - values
    dominant = others < _DOMINANT * total
    if dominant.any():
        exact = np.bincount(segment, weights=np.where(dominant, 0.0, values), minlength=n_segments)[segment]
        others = np.where(dominant, exact, others)
    return others
