"""Exact marginal association probabilities by enumerating every feasible joint association.

For the problem of ``marginals`` (weights w(a) = prod_k ratio[k, a_k] prod_{j unused} new_weight[j]), the
marginals are P(a_k = j) = sum_{a : a_k = j} w(a) / sum_a w(a). The gating graph is first split into connected
clusters of tracks and measurements (clusters are independent: the weight factorises over them), and each cluster
is enumerated breadth-first, one track at a time, in log space. The cost grows exponentially with the cluster size,
so this is for small problems and for checking ``lbp.lbp_marginals``.
"""

from __future__ import annotations

import numpy as np

from gnnpmb.assign.clusters import gate_clusters
from gnnpmb.assign.marginals import (
    AssociationMarginals,
    check_log_inputs,
    from_track_marginals,
    log_inputs,
    trivial_marginals,
)

__all__ = ["AssociationMarginals", "exact_marginals", "exact_marginals_log"]

MAX_ASSOCIATIONS = 1_000_000
"""Default cap on the number of joint associations of one cluster (memory: about 100 MB at the cap)."""


def exact_marginals(
    ratio: np.ndarray, new_weight: np.ndarray, max_associations: int = MAX_ASSOCIATIONS
) -> AssociationMarginals:
    """Exact marginals of ``ratio`` (K, M) >= 0 = l_kj / l_k0 (0 = not gated) and ``new_weight`` (M,) > 0.

    Raises ValueError when a cluster has more than ``max_associations`` feasible joint associations.
    """
    log_ratio, log_new = log_inputs(ratio, new_weight)
    return _exact(log_ratio, log_new, max_associations)


def exact_marginals_log(
    log_ratio: np.ndarray, log_new_weight: np.ndarray, max_associations: int = MAX_ASSOCIATIONS
) -> AssociationMarginals:
    """``exact_marginals`` from log ratios (K, M) (-inf = not gated) and log new weights (M,)."""
    log_ratio, log_new = check_log_inputs(log_ratio, log_new_weight)
    return _exact(log_ratio, log_new, max_associations)


def _exact(log_ratio: np.ndarray, log_new: np.ndarray, max_associations: int) -> AssociationMarginals:
    n_tracks, n_meas = log_ratio.shape
    if n_tracks == 0 or n_meas == 0:
        return trivial_marginals(n_tracks, n_meas, "exact")
    log_w = log_ratio - log_new[None, :]  # column-normalised: unassociated weighs 1
    gated = np.isfinite(log_w)
    p_track = np.zeros((n_tracks, n_meas + 1))
    p_track[:, 0] = 1.0  # tracks without any gated measurement
    for tracks, meas in gate_clusters(gated):
        p_cluster = _enumerate_cluster(log_w[np.ix_(tracks, meas)], max_associations)
        p_track[tracks, 0] = p_cluster[:, 0]
        p_track[np.ix_(tracks, meas + 1)] = p_cluster[:, 1:]
    return from_track_marginals(p_track, 0, "exact")


def _enumerate_cluster(log_w: np.ndarray, max_associations: int) -> np.ndarray:
    """(Kc, Mc + 1) exact marginals of one cluster with column-normalised log weights log_w (Kc, Mc)."""
    kc, mc = log_w.shape
    log_w_ext = np.concatenate([np.zeros((kc, 1)), log_w], axis=1)  # column 0: missed, weight 1
    assign = np.zeros((1, 0), dtype=np.int64)  # (H, tracks so far): 0 = missed, j + 1 = measurement j
    used = np.zeros((1, mc), dtype=bool)
    log_weight = np.zeros(1)
    for t in range(kc):
        options = [np.zeros(len(log_weight), dtype=np.int64)]
        parents = [np.arange(len(log_weight))]
        for j in np.flatnonzero(np.isfinite(log_w[t])):
            free = np.flatnonzero(~used[:, j])
            parents.append(free)
            options.append(np.full(len(free), j + 1, dtype=np.int64))
        parent, option = np.concatenate(parents), np.concatenate(options)
        if len(parent) > max_associations:
            raise ValueError(
                f"a cluster of {kc} tracks and {mc} measurements has more than {max_associations} joint "
                "associations; use lbp.lbp_marginals for problems this large"
            )
        used = used[parent]
        detected = np.flatnonzero(option > 0)
        used[detected, option[detected] - 1] = True
        assign = np.concatenate([assign[parent], option[:, None]], axis=1)
        log_weight = log_weight[parent] + log_w_ext[t, option]
    p = np.exp(log_weight - log_weight.max())
    p /= p.sum()
    return np.stack([np.bincount(assign[:, t], weights=p, minlength=mc + 1) for t in range(kc)])
