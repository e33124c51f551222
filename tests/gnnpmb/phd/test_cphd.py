"""GM-CPHD against first-principles likelihoods, brute-force ESFs and the GM-PHD (Vo, Vo & Cantoni 2007)."""

from __future__ import annotations

import dataclasses
import itertools
import math

import numpy as np
import pytest

from gnnpmb.config import ConfigError, paper_config
from gnnpmb.events import Cardinality, Extracted, ListSink, NullSink
from gnnpmb.phd.cphd import (
    CphdTracker,
    _esf_tables,
    _lags,
    cphd_update,
    poisson_pmf,
    predict_cardinality,
    trim_pmf,
)
from gnnpmb.phd.gmphd import log_sum_exp, phd_update
from gnnpmb.types import IdAllocator
from tests.gnnpmb.pmb.helpers import make_measurements

CFG = paper_config()  # hand computations use the paper's values (sec. V-B)


def log_esf(log_x: np.ndarray, order: int) -> np.ndarray:
    """(order + 1,) log e_j(x), j = 0..order, of x = exp(log_x) (M,): the last prefix row of ``_esf_tables``."""
    return _esf_tables(np.asarray(log_x, dtype=float), order)[0][-1]


def log_esf_leave_one_out(log_x: np.ndarray, order: int) -> np.ndarray:
    """(M, order + 1) log e_j(x without x_i) expanded, e_j^(-i) = sum_k e_k(pre_i) e_{j-k}(suf_{i+1}) from the
    prefix and suffix tables of ``_esf_tables``: the O(M N^2) sum ``_contract_leave_one_out`` shortens."""
    pre, suf = _esf_tables(np.asarray(log_x, dtype=float), order)
    lag, valid = _lags(order)
    terms = pre[:-1, None, :] + suf[1:][:, lag]
    terms[:, ~valid] = -np.inf
    return log_sum_exp(terms, axis=2)


def brute_esf(x: np.ndarray, order: int) -> np.ndarray:
    return np.array([sum(math.prod(c) for c in itertools.combinations(x.tolist(), j)) for j in range(order + 1)])


def test_esf_matches_brute_force_products():
    rng = np.random.default_rng(1)
    x = np.r_[rng.uniform(0.01, 50.0, 6), 0.0]
    with np.errstate(divide="ignore"):
        got = np.exp(log_esf(np.log(x), 8))
    np.testing.assert_allclose(got, brute_esf(x, 8), rtol=1e-12)
    assert got[8] == 0.0 and got[0] == 1.0
    truncated = np.exp(log_esf(np.log(x[:6]), 3))
    np.testing.assert_allclose(truncated, brute_esf(x[:6], 3), rtol=1e-12)


def test_leave_one_out_esf_matches_brute_force():
    rng = np.random.default_rng(2)
    x = rng.uniform(0.001, 1000.0, 7)
    loo = np.exp(log_esf_leave_one_out(np.log(x), 5))
    for i in range(7):
        np.testing.assert_allclose(loo[i], brute_esf(np.delete(x, i), 5), rtol=1e-11)


def test_esf_stays_finite_where_linear_space_overflows():
    log_x = np.full(10, math.log(1e150))
    got = log_esf(log_x, 10)
    expected = [math.log(math.comb(10, j)) + j * math.log(1e150) for j in range(11)]
    np.testing.assert_allclose(got, expected, rtol=1e-13)
    loo = log_esf_leave_one_out(log_x, 10)
    assert np.all(np.isfinite(loo[:, :10])) and np.all(loo[:, 10] == -np.inf)


def first_principles(pmf, w, q, p_d, kappa):
    """One measurement z, n iid targets from v / W (W = sum w, constant P_D), Poisson clutter of intensity kappa.

    Likelihood of Z = {z} given n (divided by e^-lambda): kappa (1 - P_D)^n + n P_D (1 - P_D)^(n-1) sum_k w_k q_k / W.
    Returns the posterior pmf, the detected weights w_k q_k / sum(w q) * P(z is a target's), and the missed weights
    w_k / W * E[number of undetected targets]."""
    W, wq = sum(w), sum(wk * qk for wk, qk in zip(w, q, strict=True))
    qd = 1.0 - p_d
    clutter = [kappa * qd**n for n in range(len(pmf))]
    target = [n * p_d * qd ** (n - 1) * wq / W if n else 0.0 for n in range(len(pmf))]
    joint = [p * (c + t) for p, c, t in zip(pmf, clutter, target, strict=True)]
    total = sum(joint)
    post = [j / total for j in joint]
    p_target = sum(p * t for p, t in zip(pmf, target, strict=True)) / total
    undetected = sum(p * (c * n + t * (n - 1)) for n, (p, c, t) in enumerate(zip(pmf, clutter, target, strict=True)))
    undetected /= total
    detected = [p_target * wk * qk / wq for wk, qk in zip(w, q, strict=True)]
    missed = [undetected * wk / W for wk in w]
    return np.array(post), np.array(detected), np.array(missed)


@pytest.mark.parametrize("pmf", [[0.2, 0.5, 0.3], [0.0, 0.1, 0.6, 0.3], [0.05, 0.15, 0.3, 0.3, 0.2]])
def test_one_measurement_with_known_prior_cardinality_hand_computed(pmf):
    w, q, p_d, kappa = [0.7, 0.4], [0.3, 0.05], 0.9, 1e-3
    corr = cphd_update(np.array(pmf), np.array(w), np.full(2, p_d), np.log(np.array(q))[:, None], kappa, area_m2=250.0)
    post, detected, missed = first_principles(pmf, w, q, p_d, kappa)
    np.testing.assert_allclose(corr.pmf, post, rtol=1e-12, atol=1e-15)
    np.testing.assert_allclose(np.exp(corr.log_detected[:, 0]), detected, rtol=1e-12)
    np.testing.assert_allclose(np.exp(corr.log_missed), missed, rtol=1e-12)


def random_problem(seed: int, k: int = 6, m: int = 5):
    rng = np.random.default_rng(seed)
    w = rng.uniform(0.05, 1.2, k + m)
    p_d = np.r_[np.full(k, 0.85), np.ones(m)]
    log_lik = rng.normal(-2.0, 2.0, (k + m, m))
    log_lik[rng.random((k + m, m)) < 0.5] = -np.inf
    log_lik[k + np.arange(m), np.arange(m)] = -6.0  # each birth explains its own measurement
    return w, p_d, log_lik


def test_poisson_predicted_cardinality_reduces_to_phd():
    w, p_d, log_lik = random_problem(4)
    pmf = poisson_pmf(float(w.sum()), tail=1e-300)
    corr = cphd_update(pmf, w, p_d, log_lik, 1e-3)
    log_missed, log_detected = phd_update(w, p_d, log_lik, 1e-3)
    np.testing.assert_allclose(np.exp(corr.log_missed), np.exp(log_missed), rtol=1e-9)
    np.testing.assert_allclose(np.exp(corr.log_detected), np.exp(log_detected), rtol=1e-9, atol=1e-300)


def test_surveillance_area_cancels_with_poisson_clutter():
    w, p_d, log_lik = random_problem(5)
    pmf = np.array([0.05, 0.1, 0.2, 0.3, 0.2, 0.1, 0.05])
    a = cphd_update(pmf, w, p_d, log_lik, 1e-3, area_m2=100.0)
    b = cphd_update(pmf, w, p_d, log_lik, 1e-3, area_m2=50_000.0)
    np.testing.assert_allclose(a.pmf, b.pmf, rtol=1e-9)
    np.testing.assert_allclose(np.exp(a.log_detected), np.exp(b.log_detected), rtol=1e-9)
    np.testing.assert_allclose(np.exp(a.log_missed), np.exp(b.log_missed), rtol=1e-9)


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_posterior_mass_equals_mean_cardinality_and_pmf_is_a_distribution(seed):
    w, p_d, log_lik = random_problem(seed, k=8, m=6)
    rng = np.random.default_rng(seed)
    pmf = rng.uniform(0.0, 1.0, 16)
    pmf /= pmf.sum()
    corr = cphd_update(pmf, w, p_d, log_lik, 1e-3)
    assert np.all(corr.pmf >= 0) and corr.pmf.sum() == pytest.approx(1.0, abs=1e-12)
    mass = np.exp(corr.log_missed).sum() + np.exp(corr.log_detected).sum()
    assert mass == pytest.approx(float(np.arange(16) @ corr.pmf), rel=1e-9)


def test_no_measurements_thins_the_cardinality():
    pmf = np.array([0.2, 0.5, 0.3])
    corr = cphd_update(pmf, np.array([1.1]), np.array([0.9]), np.zeros((1, 0)), 1e-3)
    expected = pmf * 0.1 ** np.arange(3)
    np.testing.assert_allclose(corr.pmf, expected / expected.sum(), rtol=1e-12)


def test_predict_cardinality_hand_computed():
    pmf = np.array([0.2, 0.5, 0.3])
    ps, mu = 0.7, 0.4
    survivors = [0.2 + 0.5 * 0.3 + 0.3 * 0.3**2, 0.5 * 0.7 + 0.3 * 2 * 0.7 * 0.3, 0.3 * 0.7**2]
    births = [math.exp(-mu) * mu**n / math.factorial(n) for n in range(40)]
    expected = [sum(survivors[s] * births[n - s] for s in range(3) if n - s >= 0) for n in range(6)]
    got = predict_cardinality(pmf, ps, mu, max_cardinality=100)
    np.testing.assert_allclose(got[:6], expected, rtol=1e-9)
    assert got.sum() == pytest.approx(1.0) and len(got) < 30
    capped = predict_cardinality(pmf, ps, mu, max_cardinality=2)
    np.testing.assert_allclose(capped, np.array(expected[:3]) / sum(expected[:3]), rtol=1e-9)


def test_trim_pmf_cuts_negligible_tail():
    assert trim_pmf(np.array([0.5, 0.5, 1e-15, 1e-16])).tolist() == [0.5, 0.5]
    assert trim_pmf(np.array([1.0, 0.0])).tolist() == [1.0]


def test_tracker_two_targets_map_cardinality_and_stable_ids():
    sink = ListSink()
    ids = IdAllocator()
    tracker = CphdTracker("car", CFG, ids)
    for f in range(6):
        xy = [(2.0 * f, 0.0), (30.0, 10.0 - f)]
        est = tracker.step(make_measurements(xy, velocity=[(4.0, 0.0), (0.0, -2.0)]), 0.5 if f else 0.0, sink)
    cards = sink.of_type(Cardinality)
    assert len(cards) == 6
    for c in cards:
        assert np.all(c.pmf >= 0) and c.pmf.sum() == pytest.approx(1.0, abs=1e-12)
    assert int(np.argmax(cards[-1].pmf)) == 2 and cards[-1].pmf[2] > 0.9
    assert sorted(e.track_id for e in est) == [1, 2] and ids.next_id == 3
    heaviest = np.sort(tracker.mixture.weight)[::-1][:2]
    assert sorted(e.existence for e in est) == pytest.approx(sorted(np.minimum(heaviest, 1.0)))
    assert sink.of_type(Extracted)[-1].threshold == pytest.approx(heaviest[1])


def test_tracker_extracts_nothing_while_map_cardinality_is_zero():
    sink = ListSink()
    tracker = CphdTracker("car", CFG, IdAllocator())
    assert tracker.step(make_measurements([(0.0, 0.0)]), 0.0, sink) == []
    assert int(np.argmax(tracker.cardinality)) == 0
    assert sink.of_type(Extracted)[0].threshold == math.inf


def test_cardinality_support_respects_max_cardinality():
    cfg = CFG.replace(phd=dataclasses.replace(CFG.phd, max_cardinality=3))
    tracker = CphdTracker("car", cfg, IdAllocator())
    xy = [(20.0 * i, 0.0) for i in range(6)]
    for f in range(4):
        est = tracker.step(make_measurements(xy), 0.5 if f else 0.0, NullSink())
    assert len(tracker.cardinality) <= 4 and len(est) == 3


def test_dense_frame_runs_and_stays_a_distribution():
    rng = np.random.default_rng(11)
    centres = rng.uniform(-40.0, 40.0, (40, 2))
    tracker = CphdTracker("pedestrian", CFG, IdAllocator())
    for f in range(3):
        xy = (np.repeat(centres, 4, axis=0) + rng.normal(0.0, 0.4, (160, 2))).tolist()
        est = tracker.step(
            make_measurements([tuple(p) for p in xy], 0.5, cls="pedestrian"), 0.5 if f else 0.0, NullSink()
        )
    pmf = tracker.cardinality
    assert np.all(np.isfinite(pmf)) and np.all(pmf >= 0) and pmf.sum() == pytest.approx(1.0)
    assert np.all(np.isfinite(tracker.mixture.weight)) and np.all(np.isfinite(tracker.mixture.cov))
    assert len(est) == int(np.argmax(pmf)) <= CFG.phd.max_cardinality


def test_zero_clutter_is_rejected_before_the_cphd_sees_it():
    with pytest.raises(ConfigError, match="clutter_intensity"):
        CphdTracker("car", CFG.replace(models=dataclasses.replace(CFG.models, clutter_intensity=0.0)), IdAllocator())


def test_leave_one_out_contraction_equals_the_expanded_sum():
    from gnnpmb.phd.cphd import _contract_leave_one_out

    rng = np.random.default_rng(4)
    for m, order in [(1, 3), (6, 4), (30, 50)]:
        log_x = rng.normal(5.0, 3.0, size=m)
        log_x[::4] = -np.inf  # gated-out measurements
        log_gamma = rng.normal(0.0, 20.0, size=order + 1)
        pre, _ = _esf_tables(log_x, order)
        expanded = log_sum_exp(log_esf_leave_one_out(log_x, order) + log_gamma[None, :], axis=1)
        np.testing.assert_allclose(_contract_leave_one_out(pre, log_x, log_gamma), expanded, rtol=1e-12, atol=1e-9)
