"""The Gaussian-mixture cardinalised PHD (GM-CPHD) filter.

The CPHD filter propagates the intensity v (a labelled Gaussian mixture, as in ``gmphd``) *and* the cardinality
distribution p(n) = P(n targets), n = 0..N (Vo, Vo & Cantoni 2007, sec. III). Prediction, birth, gating, labels,
reduction and events are those of ``gmphd``; this module replaces the weight update and the extraction.

Prediction of the cardinality (eq. 13): survivors are a binomial thinning of p with P_S, newborn targets are
Poisson with mean sum_j w_b (one birth component per detection), and p_{k|k-1} = p_S * p_birth (convolution).

Update (eq. 17-20). With Xi_z = <1, kappa>/kappa(z) sum_k P_D,k w_k q_k(z) for every measurement z in Z (|Z| = M),
a = sum_k (1 - P_D,k) w_k, b = sum_k w_k and e_j the elementary symmetric function of order j of {Xi_z},

    Y^u[Z](n) = sum_{j=0}^{min(M, n)} (M - j)! p_K(M - j) P^n_{j+u} a^{n-(j+u)} / b^n e_j(Xi_Z),

with P^n_i = n! / (n - i)! and p_K the clutter cardinality pmf, the posterior is

    p(n)            proportional to  Y^0[Z](n) p_{k|k-1}(n),
    missed weight:  (1 - P_D,k) w_k <Y^1[Z], p> / <Y^0[Z], p>,
    detected:       P_D,k w_k q_k(z) <1, kappa>/kappa(z) <Y^1[Z \\ {z}], p> / <Y^0[Z], p>.

Clutter is Poisson in number with mean lambda = kappa V, uniform over a surveillance area V
(``SURVEILLANCE_AREA_M2``), so kappa(z) = kappa and (M - j)! p_K(M - j) = e^-lambda lambda^(M - j). With Poisson
clutter lambda^M e^-lambda factors out of every Y and V cancels from the update (only kappa matters; the tests
check this), so V is a documented convention rather than a tuning knob.

P_D,k is ``[phd] p_detect`` for persistent and 1 for birth components (``gmphd``: a birth component explains
only its own detection and has no misdetection term, so no undetected newborn mass is dropped from the intensity
that the cardinality still counts).

Numerics. Every quantity is computed in log space: Xi_z is about V P_D w q ~ 3e3 for a well-localised target,
so e_j ~ Xi^j C(M, j) overflows a float64 beyond about 80 tracked targets, and the terms of Y span hundreds of
orders of magnitude. The ESFs come from the recursion
e_j(x_1..x_i) = e_j(x_1..x_{i-1}) + x_i e_{j-1}(x_1..x_{i-1}) with logaddexp, truncated at order N (orders above
the cardinality support never enter Y): O(M N). The M contractions <Y^1[Z \\ {z_i}], p> of the leave-one-out ESFs
e_j(Xi_{Z \\ {z_i}}) (convolutions of prefix and suffix ESFs) are built by a suffix recursion in O(M N)
(``_contract_leave_one_out``), so a 1000-detection frame costs milliseconds. The support N is the previous
posterior's support (trimmed where the tail mass drops below 1e-12) plus the birth count's (Poisson tail below
1e-12), at most ``[phd] max_cardinality`` (the CPHD's per-frame budget: the update costs O(M N) and the
cardinality prediction O(N^2)).

Extraction (sec. III-C): the MAP cardinality n^ = argmax_n p(n), then the n^ heaviest components, one estimate
each. ``Extracted.threshold`` is the weight of the lightest extracted component (+inf when n^ = 0). A
``Cardinality`` event carries the posterior pmf every frame.

References: B.-T. Vo, B.-N. Vo and A. Cantoni, "Analytic implementations of the cardinalized probability
hypothesis density filter", IEEE Trans. Signal Processing 55(7), 2007; R. Mahler, "PHD filters of higher order in
target number", IEEE Trans. Aerospace and Electronic Systems 43(4), 2007.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass

import numpy as np
from scipy.special import gammaln, xlogy

from gnnpmb.config import ConfigError, TrackerConfig
from gnnpmb.events import Cardinality, EventSink, Panel
from gnnpmb.phd.gmphd import GmPhdTracker, Prediction, Selection, log_sum_exp, safe_log
from gnnpmb.phd.mixture import GaussianMixture
from gnnpmb.types import IdAllocator, Measurements

SURVEILLANCE_AREA_M2 = math.pi * 50.0**2
"""V: a disc of 50 m radius around the ego, the nuScenes tracking-evaluation range for vehicles (40 m for
pedestrians and bicycles). Clutter cardinality is Poisson with mean kappa V (7.85 per class per frame at the
paper's kappa = 1e-3 / m^2)."""

CARDINALITY_TAIL = 1e-12
"""Probability mass below which the tail of a cardinality pmf is cut off."""


def _esf_tables(log_x: np.ndarray, order: int) -> tuple[np.ndarray, np.ndarray]:
    """Prefix and suffix log-ESFs, each (M + 1, order + 1): pre[i] of x_0..x_{i-1}, suf[i] of x_i..x_{M-1}.

    Both follow e_j(.., x) = e_j(..) + x e_{j-1}(..), advanced together (one logaddexp per step)."""
    m = len(log_x)
    tables = np.full((2, m + 1, order + 1), -np.inf)  # [0] prefix, [1] suffix stored reversed
    tables[:, :, 0] = 0.0
    step_x = np.stack([log_x, log_x[::-1]], axis=1)[:, :, None]  # (M, 2, 1)
    for i in range(m):
        tables[:, i + 1, 1:] = np.logaddexp(tables[:, i, 1:], step_x[i] + tables[:, i, :-1])
    return tables[0], tables[1][::-1]


def _contract_leave_one_out(pre: np.ndarray, log_x: np.ndarray, log_gamma: np.ndarray) -> np.ndarray:
    """(M,) log sum_j gamma_j e_j(x without x_i), in O(M N) instead of the O(M N^2) of expanding every
    leave-one-out ESF.

    With e_j(x without x_i) = sum_k pre_i[k] suf_{i+1}[j - k] (prefix ESF of x_0..x_{i-1}, suffix ESF of
    x_{i+1}..x_{M-1}), the sum is sum_k pre_i[k] g_{i+1}[k] with g_i[k] = sum_l gamma_{k+l} suf_i[l] (k + l <= N).
    The suffix recursion suf_i[l] = suf_{i+1}[l] + x_i suf_{i+1}[l-1] gives g_i[k] = g_{i+1}[k] + x_i g_{i+1}[k+1]
    from g_M = gamma (and g[N + 1] = 0): one logaddexp per measurement.
    pre: (M + 1, N + 1) prefix log-ESFs (``_esf_tables``); log_x: (M,); log_gamma: (N + 1,).
    """
    m = pre.shape[0] - 1
    if not m:
        return np.zeros(0)
    order = pre.shape[1] - 1
    log_g = np.full((m + 1, order + 2), -np.inf)
    log_g[m, : order + 1] = log_gamma
    for i in range(m - 1, -1, -1):
        log_g[i, : order + 1] = np.logaddexp(log_g[i + 1, : order + 1], log_x[i] + log_g[i + 1, 1:])
    return log_sum_exp(pre[:-1] + log_g[1:, : order + 1], axis=1)


@functools.lru_cache(maxsize=256)
def _lags(n_max: int) -> tuple[np.ndarray, np.ndarray]:
    """[a, b] = max(a - b, 0) and a >= b, both (n_max + 1, n_max + 1), read-only (cached)."""
    i = np.arange(n_max + 1)
    lag = i[:, None] - i[None, :]
    valid = lag >= 0
    lag = np.where(valid, lag, 0)
    lag.flags.writeable = False
    valid.flags.writeable = False
    return lag, valid


@functools.lru_cache(maxsize=256)
def _log_falling_factorials(n_max: int) -> tuple[np.ndarray, np.ndarray]:
    """[u, n, j] log P^n_{j+u} = log n! - log (n - j - u)! (-inf where j + u > n) and the exponent n - j - u
    (0 where j + u > n), for u = 0, 1, both (2, n_max + 1, n_max + 1), read-only (cached)."""
    n = np.arange(n_max + 1)
    rest = n[None, :, None] - n[None, None, :] - np.arange(2)[:, None, None]
    valid = rest >= 0
    rest = np.where(valid, rest, 0)
    log_perm = np.where(valid, gammaln(n + 1)[None, :, None] - gammaln(rest + 1), -np.inf)
    log_perm.flags.writeable = False
    rest.flags.writeable = False
    return log_perm, rest


@functools.lru_cache(maxsize=256)
def _log_binomial(n_max: int) -> np.ndarray:
    """[l, n] log C(l, n), -inf where n > l, (n_max + 1, n_max + 1), read-only (cached)."""
    lag, valid = _lags(n_max)
    ell = np.arange(n_max + 1)
    out = np.where(valid, gammaln(ell + 1)[:, None] - gammaln(ell + 1)[None, :] - gammaln(lag + 1), -np.inf)
    out.flags.writeable = False
    return out


def trim_pmf(pmf: np.ndarray, tail: float = CARDINALITY_TAIL) -> np.ndarray:
    """The pmf on 0..n* with n* the largest n whose tail mass sum_{n' >= n} p(n') is at least ``tail``,
    renormalised."""
    tail_mass = np.cumsum(pmf[::-1])[::-1]
    keep = max(1, int(np.count_nonzero(tail_mass >= tail)))
    out = pmf[:keep]
    return out / out.sum()


def poisson_pmf(mean: float, tail: float = CARDINALITY_TAIL) -> np.ndarray:
    """Poisson(mean) pmf on 0..n*, cut where the tail mass drops below ``tail`` (``trim_pmf``)."""
    if mean <= 0.0:
        return np.ones(1)
    n = np.arange(int(math.ceil(mean + 12.0 * math.sqrt(mean) + 30.0)) + 1)
    return trim_pmf(np.exp(-mean + n * math.log(mean) - gammaln(n + 1)), tail)


_LOG_SMALLEST = math.log(np.finfo(float).tiny)
"""Below this log-probability a pmf entry underflows float64."""


def check_birth_fits(birth_mean: float, max_cardinality: int) -> None:
    """Refuse a Poisson birth count whose pmf on 0..max_cardinality underflows to zero (its largest entry there,
    at n = max_cardinality once the mean is beyond it, is below float64's smallest number): the predicted
    cardinality would be 0 / 0."""
    if birth_mean <= max_cardinality:
        return
    n = max_cardinality
    if -birth_mean + n * math.log(birth_mean) - float(gammaln(n + 1)) < _LOG_SMALLEST:
        raise ConfigError(
            f"the CPHD's birth count (mean {birth_mean:.4g}: [models] birth_weight x the frame's detections) "
            f"lies beyond [phd] max_cardinality = {max_cardinality}; lower birth_weight or raise max_cardinality"
        )


def predict_cardinality(pmf: np.ndarray, p_survive: float, birth_mean: float, max_cardinality: int) -> np.ndarray:
    """Vo, Vo & Cantoni 2007, eq. 13: binomial survival thinning of ``pmf`` (N + 1,) convolved with a Poisson birth
    count of mean ``birth_mean``, cut at ``max_cardinality`` and renormalised."""
    check_birth_fits(birth_mean, max_cardinality)
    n_max = len(pmf) - 1
    lag, valid = _lags(n_max)
    ell = np.arange(n_max + 1)
    log_binom = _log_binomial(n_max) + xlogy(ell, p_survive)[None, :] + xlogy(lag, 1.0 - p_survive)
    survivors = np.where(valid, np.exp(log_binom), 0.0).T @ pmf
    predicted = np.convolve(survivors, poisson_pmf(birth_mean))[: max_cardinality + 1]
    return predicted / predicted.sum()


@dataclass(frozen=True, slots=True)
class CphdCorrection:
    """Result of ``cphd_update``: posterior pmf (N + 1,), log missed weights (K,), log detected weights (K, M)."""

    pmf: np.ndarray
    log_missed: np.ndarray
    log_detected: np.ndarray


def _log_power(exponent: np.ndarray, log_base: float) -> np.ndarray:
    """exponent * log_base with 0 * log 0 = 0 (so a^0 = 1 also for a = 0)."""
    if np.isfinite(log_base):
        return exponent * log_base
    return np.where(exponent == 0, 0.0, log_base)


def cphd_update(
    pred_pmf: np.ndarray,
    weight: np.ndarray,
    p_detect: np.ndarray,
    log_lik: np.ndarray,
    clutter_intensity: float,
    area_m2: float = SURVEILLANCE_AREA_M2,
) -> CphdCorrection:
    """GM-CPHD update in log space (module docstring; Vo, Vo & Cantoni 2007, eq. 17-20 with Poisson clutter).

    pred_pmf: (N + 1,) predicted cardinality pmf; weight: (K,) predicted intensity weights; p_detect: (K,) P_D of
    each component; log_lik: (K, M) log q_k(z_j) (-inf = gated out); clutter_intensity: kappa per m^2;
    area_m2: surveillance area V (clutter count Poisson with mean kappa V).
    """
    n_max = len(pred_pmf) - 1
    k, m = log_lik.shape
    if not np.sum(weight) > 0.0:
        return CphdCorrection(np.ones(1), np.full(k, -np.inf), np.full((k, m), -np.inf))
    lam = clutter_intensity * area_m2
    log_lam, log_area = float(safe_log(lam)), float(safe_log(area_m2))
    log_w = safe_log(weight)
    log_a = float(safe_log(np.sum((1.0 - p_detect) * weight)))
    log_b = float(np.log(np.sum(weight)))
    log_det_num = (safe_log(p_detect) + log_w)[:, None] + log_lik  # log P_D w q, (K, M)
    log_xi = log_area + log_sum_exp(log_det_num, axis=0)  # (M,)

    n = np.arange(n_max + 1)
    log_perm, rest = _log_falling_factorials(n_max)
    # coef[u, n, j] = log(P^n_{j+u} a^(n-j-u) / b^n)
    coef = log_perm + _log_power(rest, log_a) - (n * log_b)[None, :, None]
    clutter_rest = np.array([m, m - 1])[:, None] - n[None, :]  # [u, j] = |Z| - u - j
    clutter = np.where(clutter_rest >= 0, _log_power(np.maximum(clutter_rest, 0), log_lam) - lam, -np.inf)
    log_p = safe_log(pred_pmf)
    beta = log_sum_exp(log_p[None, :, None] + coef, axis=1)  # [u, j] log sum_n p(n) P^n_{j+u} a^.. / b^n
    pre, _ = _esf_tables(log_xi, n_max)
    log_e = pre[-1]
    log_u0, log_u1 = log_sum_exp(clutter[0] + beta + log_e, axis=1).tolist()  # log <Y^u[Z], p>
    if not np.isfinite(log_u0):
        raise FloatingPointError(
            "CPHD update: no cardinality explains the measurements (P_D = 1 and P_S = 1 leave no missed targets)"
        )
    log_u1_loo = _contract_leave_one_out(pre, log_xi, clutter[1] + beta[1])  # (M,) log <Y^1[Z \ z_i], p>
    log_y0 = log_sum_exp(coef[0] + (clutter[0] + log_e)[None, :], axis=1)  # [n] log Y^0[Z](n)
    pmf = np.exp(log_p + log_y0 - log_u0)
    pmf /= pmf.sum()
    log_missed = safe_log(1.0 - p_detect) + log_w + (log_u1 - log_u0)
    log_detected = log_det_num + (log_area + log_u1_loo - log_u0)[None, :]
    return CphdCorrection(pmf=pmf, log_missed=log_missed, log_detected=log_detected)


class CphdTracker(GmPhdTracker):
    """One class's GM-CPHD filter: ``gmphd.GmPhdTracker`` with the cardinalised update and MAP extraction.

    ``cardinality`` is the posterior pmf (N + 1,) of the last frame (``[1.0]`` before the first)."""

    name = "cphd"
    panels = (Panel.CARDINALITY, Panel.INTENSITY)

    def __init__(self, class_name: str, config: TrackerConfig, ids: IdAllocator):
        if not config.models.clutter_intensity > 0.0:
            raise ConfigError(
                f"[models] clutter_intensity must be > 0 for the CPHD filter, got {config.models.clutter_intensity}"
            )
        super().__init__(class_name, config, ids)
        self.cardinality = np.ones(1)

    def idle(self) -> bool:
        """True when the filter is empty and certain of it (cardinality pmf [1.0])."""
        return super().idle() and len(self.cardinality) == 1

    def _correct(self, pred: Prediction, meas: Measurements, sink: EventSink) -> tuple[np.ndarray, np.ndarray]:
        birth_mean = float(np.sum(pred.mixture.weight[pred.n_persistent :]))
        predicted = predict_cardinality(
            self.cardinality, self.config.models.p_survive, birth_mean, self.params.max_cardinality
        )
        corr = cphd_update(
            predicted, pred.mixture.weight, pred.p_detect, pred.log_lik, self.config.models.clutter_intensity
        )
        self.cardinality = trim_pmf(corr.pmf)
        if sink.enabled:
            sink.emit(Cardinality(self.class_name, self.cardinality.copy()))
        return corr.log_missed, corr.log_detected

    def _select(self, mix: GaussianMixture) -> Selection:
        """The n^ = argmax p(n) heaviest components, one estimate each (Vo, Vo & Cantoni 2007, sec. III-C)."""
        n_hat = int(np.argmax(self.cardinality))
        index = np.argsort(-mix.weight, kind="stable")[:n_hat]
        threshold = float(mix.weight[index[-1]]) if len(index) else math.inf
        return Selection(index=index, copies=np.ones(len(index), dtype=np.int64), threshold=threshold)
