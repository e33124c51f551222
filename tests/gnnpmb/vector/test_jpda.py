"""JPDA against hand-computed association probabilities and the combined (PDA) update."""

from __future__ import annotations

import itertools

import numpy as np
import pytest

from gnnpmb.assign.exact_marginals import exact_marginals_log
from gnnpmb.config import TrackerConfig, VectorParams
from gnnpmb.events import AxisKind, Born, ListSink, Marginals, NullSink, Posterior
from gnnpmb.types import IdAllocator
from gnnpmb.vector.jpda import JpdaTracker, association_probabilities
from tests.gnnpmb.pmb.helpers import make_measurements
from tests.gnnpmb.vector.helpers import CFG, P, Q, R, V, birth_cov, cv, gauss2, joseph

KAPPA = P.clutter_intensity
P_GATE = 1.0 - np.exp(-0.5 * P.gate_chi2)


def make_jpda(config: TrackerConfig = CFG) -> JpdaTracker:
    return JpdaTracker("car", config, IdAllocator())


def one_track_two_measurements():
    """Track born at the origin at rest; after 0.5 s two measurements at squared distances 14 and 16."""
    P_pred = cv(0.5) @ birth_cov() @ cv(0.5).T + Q
    S = P_pred[:2, :2] + R
    z = np.array([[np.sqrt(14 * S[0, 0]), 0.0], [0.0, -np.sqrt(16 * S[1, 1])]])
    return P_pred, S, z


def test_one_track_two_measurements_marginals_and_combined_update():
    P_pred, S, z = one_track_two_measurements()
    assert S[0, 1] == 0.0  # diagonal, so the squared distances are exactly 14 and 16
    e = np.array([V.p_detect * gauss2(zj, S) / ((1 - V.p_detect * P_GATE) * KAPPA) for zj in z])
    beta = np.concatenate([[1.0], e]) / (1.0 + e.sum())
    assert beta.min() > 0.05 and beta.max() < 0.95  # a genuinely ambiguous case

    K = P_pred[:, :2] @ np.linalg.inv(S)
    nu = beta[1] * z[0] + beta[2] * z[1]  # predicted measurement is the origin
    m_post = K @ nu
    spread = beta[1] * np.outer(z[0], z[0]) + beta[2] * np.outer(z[1], z[1]) - np.outer(nu, nu)
    P_post = beta[0] * P_pred + (1 - beta[0]) * joseph(P_pred, K) + K @ spread @ K.T

    jpda = make_jpda()
    jpda.step(make_measurements([(0.0, 0.0)]), 0.0, NullSink())
    sink = ListSink()
    est = jpda.step(make_measurements([tuple(z[0]), tuple(z[1])], [0.7, 0.6]), 0.5, sink)
    marg = sink.of_type(Marginals)[0]
    np.testing.assert_allclose(marg.probs, beta[None, :], rtol=1e-10)
    assert marg.method == "exact" and [r.ref for r in marg.rows] == [1]
    assert [c.kind for c in marg.cols] == [AxisKind.MISSED, AxisKind.MEASUREMENT, AxisKind.MEASUREMENT]
    np.testing.assert_allclose(jpda.tracks.mean[0], m_post, atol=1e-12)
    np.testing.assert_allclose(jpda.tracks.cov[0], P_post, atol=1e-12)
    assert np.all(np.linalg.eigvalsh(jpda.tracks.cov[0]) > 0)
    # hit (beta_0 < 0.5): confirmed and output with the box of the most probable measurement
    best = int(np.argmax(e))
    assert [(x.track_id, x.meas_index, x.score) for x in est] == [(1, best, [0.7, 0.6][best])]
    # measurements with p_new = 1 - beta_j > 0.5 start tentative tracks
    born = sink.of_type(Born)
    expected_born = [j for j in range(2) if 1 - beta[j + 1] > 0.5]
    assert expected_born  # the weaker measurement is more likely clutter than the track's
    assert born[0].meas_indices.tolist() == expected_born


def brute_force(log_ratio: np.ndarray, log_kappa: float) -> np.ndarray:
    """(K, M + 1) marginals by listing every joint event (independent of the library's enumeration)."""
    k, m = log_ratio.shape
    probs = np.zeros((k, m + 1))
    total = 0.0
    for a in itertools.product(range(m + 1), repeat=k):
        used = [j for j in a if j]
        if len(used) != len(set(used)):
            continue
        log_w = sum(log_ratio[t, j - 1] for t, j in enumerate(a) if j) + (m - len(used)) * log_kappa
        w = np.exp(log_w)
        total += w
        for t, j in enumerate(a):
            probs[t, j] += w
    return probs / total


def two_tracks_sharing(config: TrackerConfig, sink) -> JpdaTracker:
    jpda = make_jpda(config)
    jpda.step(make_measurements([(0.0, 0.0), (1.6, 0.0)]), 0.0, NullSink())
    jpda.step(make_measurements([(0.7, 0.1), (1.0, -0.1), (30.0, 5.0)]), 0.5, sink)
    return jpda


def test_two_tracks_sharing_measurements_match_brute_force():
    sink = ListSink()
    jpda = two_tracks_sharing(CFG, sink)
    marg = sink.of_type(Marginals)[0]
    assert marg.probs.shape == (2, 4) and marg.method == "exact"
    P_pred = cv(0.5) @ birth_cov() @ cv(0.5).T + Q
    S = P_pred[:2, :2] + R
    z = np.array([[0.7, 0.1], [1.0, -0.1]])
    tracks = np.array([[0.0, 0.0], [1.6, 0.0]])
    log_ratio = np.log([[V.p_detect * gauss2(zj - t, S) / (1 - V.p_detect * P_GATE) for zj in z] for t in tracks])
    expected = brute_force(log_ratio, np.log(KAPPA))
    assert expected[:, 1:].max() > 0.2 and expected[:, 1:].min() > 0.05  # both tracks compete for both
    np.testing.assert_allclose(marg.probs[:, :3], expected, rtol=1e-9, atol=1e-15)
    assert np.all(marg.probs[:, 3] == 0.0)  # the far measurement is outside both gates
    assert sink.of_type(Born)[0].meas_indices.tolist() == [2]
    assert jpda.tracks.track_id.tolist() == [1, 2, 3]


def test_clusters_over_exact_cluster_max_use_lbp():
    exact = two_tracks_sharing(CFG, sink := ListSink())
    lbp_cfg = CFG.replace(vector=VectorParams(exact_cluster_max=1))
    loopy = two_tracks_sharing(lbp_cfg, lbp_sink := ListSink())
    m_exact, m_lbp = sink.of_type(Marginals)[0], lbp_sink.of_type(Marginals)[0]
    assert m_lbp.method == "lbp" and m_lbp.iterations >= 1
    np.testing.assert_allclose(m_lbp.probs.sum(axis=1), 1.0, rtol=1e-12)
    # LBP is over-confident on this tight two-track loop (kappa is tiny), but picks the same measurements
    assert m_lbp.probs[:, 1:].max() > m_exact.probs[:, 1:].max()
    assert np.argmax(m_lbp.probs, axis=1).tolist() == np.argmax(m_exact.probs, axis=1).tolist() == [1, 2]
    for jpda in (loopy, exact):
        assert np.all(np.linalg.eigvalsh(jpda.tracks.cov) > 0)


def test_association_probabilities_equal_exact_enumeration_over_many_clusters():
    rng = np.random.default_rng(7)
    for _ in range(10):
        k, m = rng.integers(1, 9, size=2)
        log_ratio = np.where(rng.random((k, m)) < 0.25, rng.normal(2.0, 3.0, size=(k, m)), -np.inf)
        beta, p_new, method, _ = association_probabilities(log_ratio, KAPPA, 8, 100, 1e-9)
        ref = exact_marginals_log(log_ratio, np.full(m, np.log(KAPPA)))
        assert method == "exact"
        np.testing.assert_allclose(beta, ref.p_track, atol=1e-12)
        np.testing.assert_allclose(p_new, ref.p_new, atol=1e-12)


def test_missed_track_keeps_prediction_and_is_not_output():
    jpda = make_jpda()
    jpda.step(make_measurements([(0.0, 0.0)], velocity=[(2.0, 0.0)]), 0.0, NullSink())
    jpda.step(make_measurements([(1.0, 0.0)]), 0.5, NullSink())
    mean, cov = jpda.tracks.mean[0].copy(), jpda.tracks.cov[0].copy()
    sink = ListSink()
    assert jpda.step(make_measurements([(40.0, 0.0)]), 0.5, sink) == []
    np.testing.assert_allclose(jpda.tracks.mean[0], cv(0.5) @ mean, atol=1e-12)
    np.testing.assert_allclose(jpda.tracks.cov[0], cv(0.5) @ cov @ cv(0.5).T + Q, atol=1e-12)
    np.testing.assert_allclose(sink.of_type(Marginals)[0].probs, [[1.0, 0.0]])
    assert sink.of_type(Posterior)[0].track_ids.tolist() == [1, 2]


def test_no_sink_and_list_sink_give_identical_tracks():
    def run(sink):
        jpda = make_jpda()
        rng = np.random.default_rng(1)
        out = []
        for f in range(6):
            xy = np.array([[0.0, 0.0], [1.5, 0.0], [10.0, 3.0]]) + rng.normal(0, 0.2, size=(3, 2))
            out.append(jpda.step(make_measurements([tuple(p) for p in xy]), 0.5 * (f > 0), sink))
        return out

    a, b = run(NullSink()), run(ListSink())
    assert a == b and len(a[-1]) == 3


@pytest.mark.parametrize("k", [0, 3])
def test_no_measurements_or_no_tracks(k):
    jpda = make_jpda()
    if k:
        jpda.step(make_measurements([(0.0, 0.0), (20.0, 0.0), (40.0, 0.0)]), 0.0, NullSink())
    assert jpda.step(make_measurements([]), 0.5, ListSink()) == []
    assert len(jpda.tracks) == k
