"""Marginal association probabilities: the result type and the input normalisation shared by LBP and enumeration.

The association problem (Williams & Lau, "Approximate evaluation of marginal association probabilities with
belief propagation", IEEE T-AES 50(4), 2014): K tracks, M measurements. Track k takes a_k in {0, 1..M}
(0 = missed), every measurement is used by at most one track, and a feasible joint association a has weight

    w(a) = prod_k ratio[k, a_k] * prod_{j unused by a} new_weight[j],      ratio[k, 0] := 1,

with ratio[k, j] = l_kj / l_k0 >= 0 (0 = not gated) and new_weight[j] > 0 the weight of measurement j being
unassociated (new track or clutter). The marginals are P(a_k = j) and P(measurement j unassociated).

Scale invariance: every feasible a contains measurement j exactly once (with one track or unassociated) and
track k exactly once (missed or with one measurement). Dividing column j (ratio[:, j] and new_weight[j]) by the
same c_j, or row k (ratio[k, :] and its implicit missed weight 1) by the same s_k, multiplies every w(a) by one
constant, so the marginals do not change. LBP therefore works on the column-normalised, row-scaled weights of
``normalised_weights`` and enumeration on column-normalised log weights; scaling ratio alone (not new_weight, or
not the missed weight) would change the answer.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

MIN_MISS_WEIGHT = 1e-280
"""Floor of the row-scaled missed weight: a row whose ratios exceed its missed weight by more than 1e280 is
treated as if they exceeded it by exactly 1e280 (keeps the LBP messages finite; the effect is far below 1e-200)."""


@dataclass(frozen=True, slots=True)
class AssociationMarginals:
    """Marginal association probabilities of K tracks and M measurements.

    p_track: (K, M + 1), column 0 = P(track k missed), column j + 1 = P(track k <- measurement j); rows sum to 1.
    p_new: (M,) P(measurement j unassociated: new track or clutter); p_new[j] + p_track[:, j + 1].sum() = 1.
    iterations: message-passing iterations used (0 for enumeration); method: "lbp" or "exact".
    """

    p_track: np.ndarray
    p_new: np.ndarray
    iterations: int
    method: str


def log_inputs(ratio: np.ndarray, new_weight: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Validate ``ratio`` (K, M) >= 0 finite and ``new_weight`` (M,) > 0 finite; return their logs."""
    ratio = np.asarray(ratio, dtype=float)
    new_weight = np.asarray(new_weight, dtype=float)
    _check_shapes(ratio, new_weight)
    if not (np.all(np.isfinite(ratio)) and np.all(ratio >= 0.0)):
        raise ValueError("ratio must be finite and >= 0 (0 = measurement outside the track's gate)")
    if not (np.all(np.isfinite(new_weight)) and np.all(new_weight > 0.0)):
        raise ValueError("new_weight must be finite and > 0")
    with np.errstate(divide="ignore"):
        return np.log(ratio), np.log(new_weight)


def check_log_inputs(log_ratio: np.ndarray, log_new_weight: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Validate ``log_ratio`` (K, M) in [-inf, inf) and ``log_new_weight`` (M,) finite; return them as floats."""
    log_ratio = np.asarray(log_ratio, dtype=float)
    log_new_weight = np.asarray(log_new_weight, dtype=float)
    _check_shapes(log_ratio, log_new_weight)
    if np.any(np.isnan(log_ratio)) or np.any(log_ratio == np.inf):
        raise ValueError("log_ratio must be < +inf and not NaN (-inf = measurement outside the track's gate)")
    if not np.all(np.isfinite(log_new_weight)):
        raise ValueError("log_new_weight must be finite")
    return log_ratio, log_new_weight


def _check_shapes(ratio: np.ndarray, new_weight: np.ndarray) -> None:
    if ratio.ndim != 2 or new_weight.ndim != 1 or ratio.shape[1] != new_weight.shape[0]:
        raise ValueError(f"expected ratio (K, M) and new_weight (M,), got shapes {ratio.shape} and {new_weight.shape}")


def normalised_weights(
    log_ratio: np.ndarray, log_new_weight: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Column-normalised, row-scaled association weights of the gated pairs (module docstring: the marginals are
    unchanged).

    Column j is divided by new_weight[j] (so unassociated weighs 1), then row k by s_k = max(1, max_j ratio_kj /
    new_weight_j). Returns the E gated pairs in row-major order, rows (E,) and cols (E,), their weights w (E,) in
    (0, 1], and miss (K,) = 1 / s_k in [MIN_MISS_WEIGHT, 1]; max(miss_k, max_j w_kj) = 1 for every row, so
    nothing overflows whatever the input's dynamic range.
    """
    rows, cols = np.nonzero(log_ratio > -np.inf)
    log_w = log_ratio[rows, cols] - log_new_weight[cols]
    row_max = np.zeros(log_ratio.shape[0])
    if len(rows):
        starts = np.flatnonzero(np.diff(rows, prepend=-1))
        row_max[rows[starts]] = np.maximum(np.maximum.reduceat(log_w, starts), 0.0)
    w = np.exp(log_w - row_max[rows])
    miss = np.maximum(np.exp(-row_max), MIN_MISS_WEIGHT)
    keep = w > 0.0  # pairs whose weight underflows relative to their row's largest cannot matter
    return rows[keep], cols[keep], w[keep], miss


def trivial_marginals(n_tracks: int, n_meas: int, method: str) -> AssociationMarginals:
    """Every track missed, every measurement unassociated (no track can take any measurement)."""
    p_track = np.zeros((n_tracks, n_meas + 1))
    p_track[:, 0] = 1.0
    return AssociationMarginals(p_track=p_track, p_new=np.ones(n_meas), iterations=0, method=method)


def from_track_marginals(p_track: np.ndarray, iterations: int, method: str) -> AssociationMarginals:
    """Marginals with p_new = 1 - the column sums of p_track (K, M + 1), clipped to [0, 1]."""
    p_new = np.clip(1.0 - p_track[:, 1:].sum(axis=0), 0.0, 1.0)
    return AssociationMarginals(p_track=p_track, p_new=p_new, iterations=iterations, method=method)
