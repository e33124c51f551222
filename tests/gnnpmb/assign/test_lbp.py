"""LBP and exact marginal association probabilities against hand computations and brute-force enumeration."""

from __future__ import annotations

import itertools

import numpy as np
import pytest

from gnnpmb.assign.exact_marginals import exact_marginals, exact_marginals_log
from gnnpmb.assign.lbp import lbp_marginals, lbp_marginals_log


def brute_force(ratio: np.ndarray, new_weight: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Marginals by summing the weight of every joint association (independent of the module under test)."""
    k, m = ratio.shape
    p_track, p_new, total = np.zeros((k, m + 1)), np.zeros(m), 0.0
    for a in itertools.product(range(m + 1), repeat=k):
        used = [j for j in a if j]
        if len(used) != len(set(used)):
            continue
        weight = 1.0
        for i, j in enumerate(a):
            weight *= ratio[i, j - 1] if j else 1.0
        for j in range(m):
            weight *= 1.0 if j + 1 in used else new_weight[j]
        total += weight
        for i, j in enumerate(a):
            p_track[i, j] += weight
        for j in range(m):
            p_new[j] += 0.0 if j + 1 in used else weight
    return p_track / total, p_new / total


def random_problem(rng: np.random.Generator, max_size: int = 4, gate_prob: float = 0.5):
    """Ratios spanning two orders of magnitude, about half of the pairs outside the gate."""
    k, m = int(rng.integers(1, max_size + 1)), int(rng.integers(1, max_size + 1))
    ratio = rng.uniform(size=(k, m)) * 10.0 ** rng.uniform(-1.0, 1.0, size=(k, m))
    ratio[rng.random((k, m)) > gate_prob] = 0.0
    return ratio, rng.uniform(0.5, 2.0, size=m)


def check_consistent(marg, k: int, m: int) -> None:
    assert marg.p_track.shape == (k, m + 1) and marg.p_new.shape == (m,)
    assert np.all(marg.p_track >= 0.0) and np.all(marg.p_track <= 1.0)
    assert np.all(marg.p_new >= 0.0) and np.all(marg.p_new <= 1.0)
    np.testing.assert_allclose(marg.p_track.sum(axis=1), 1.0, atol=1e-12)
    np.testing.assert_allclose(marg.p_new + marg.p_track[:, 1:].sum(axis=0), 1.0, atol=1e-9)


@pytest.mark.parametrize("solver", [lbp_marginals, exact_marginals])
def test_one_track_one_measurement_by_hand(solver):
    # associations: missed + unassociated (weight 1 * 2), detected (weight 3)
    marg = solver(np.array([[3.0]]), np.array([2.0]))
    np.testing.assert_allclose(marg.p_track, [[0.4, 0.6]], atol=1e-12)
    np.testing.assert_allclose(marg.p_new, [0.4], atol=1e-12)


@pytest.mark.parametrize("solver", [lbp_marginals, exact_marginals])
def test_two_tracks_one_measurement_by_hand(solver):
    # associations: none (new weight 1), track 0 (2), track 1 (1): total 4
    marg = solver(np.array([[2.0], [1.0]]), np.array([1.0]))
    np.testing.assert_allclose(marg.p_track, [[0.5, 0.5], [0.75, 0.25]], atol=1e-12)
    np.testing.assert_allclose(marg.p_new, [0.25], atol=1e-12)


def test_lbp_fixed_point_on_the_smallest_loop_by_hand():
    # 2 x 2, all weights 1: exact P(missed) = 3/7 (7 associations, 3 with track 0 missed). By symmetry the LBP
    # messages satisfy nu = (1 + nu) / (2 + nu), so nu = (sqrt(5) - 1) / 2 and P(missed) = 1 / (1 + 2 nu).
    ratio, new = np.ones((2, 2)), np.ones(2)
    nu = (np.sqrt(5.0) - 1.0) / 2.0
    lbp = lbp_marginals(ratio, new)
    np.testing.assert_allclose(lbp.p_track[:, 0], 1.0 / (1.0 + 2.0 * nu), atol=1e-7)
    np.testing.assert_allclose(exact_marginals(ratio, new).p_track[:, 0], 3.0 / 7.0, atol=1e-12)


def test_exact_matches_brute_force():
    rng = np.random.default_rng(1)
    for _ in range(60):
        ratio, new = random_problem(rng, max_size=4, gate_prob=0.7)
        marg = exact_marginals(ratio, new)
        p_track, p_new = brute_force(ratio, new)
        np.testing.assert_allclose(marg.p_track, p_track, atol=1e-12)
        np.testing.assert_allclose(marg.p_new, p_new, atol=1e-12)
        check_consistent(marg, *ratio.shape)


@pytest.mark.parametrize("shape", [(1, 5), (6, 1)])
def test_lbp_is_exact_without_loops(shape):
    rng = np.random.default_rng(2)
    ratio = rng.uniform(size=shape) * 10.0 ** rng.uniform(-3, 3, size=shape)
    new = 10.0 ** rng.uniform(-2, 2, size=shape[1])
    lbp, exact = lbp_marginals(ratio, new), exact_marginals(ratio, new)
    np.testing.assert_allclose(lbp.p_track, exact.p_track, atol=1e-12)
    np.testing.assert_allclose(lbp.p_new, exact.p_new, atol=1e-12)


def test_lbp_close_to_exact_on_random_gated_problems():
    # LBP is an approximation on loopy gating graphs: over 5000 such problems its worst error was 0.053 and
    # 99.7 % of them were within 0.02 of the exact marginals (stopping after one round: 99th percentile 0.05).
    rng = np.random.default_rng(3)
    errors = []
    for _ in range(300):
        ratio, new = random_problem(rng)
        lbp, exact = lbp_marginals(ratio, new), exact_marginals(ratio, new)
        check_consistent(lbp, *ratio.shape)
        assert lbp.method == "lbp" and lbp.iterations < 100
        errors.append(max(np.abs(lbp.p_track - exact.p_track).max(), np.abs(lbp.p_new - exact.p_new).max()))
    assert np.percentile(errors, 99) < 0.02 and max(errors) < 0.1 and np.mean(errors) < 0.002


def test_scaling_a_column_with_its_new_weight_changes_nothing():
    rng = np.random.default_rng(4)
    ratio, new = random_problem(rng, max_size=5, gate_prob=0.8)
    c = 10.0 ** rng.uniform(-30, 30, size=new.shape)
    for solver in (lbp_marginals, exact_marginals):
        a, b = solver(ratio, new), solver(ratio * c[None, :], new * c)
        np.testing.assert_allclose(a.p_track, b.p_track, atol=1e-10)
    # scaling the ratios alone is a different problem
    a, b = exact_marginals(ratio, new), exact_marginals(ratio * 10.0, new)
    assert np.abs(a.p_track - b.p_track).max() > 1e-3


def test_log_and_linear_entry_points_agree():
    rng = np.random.default_rng(5)
    ratio, new = random_problem(rng, max_size=5)
    with np.errstate(divide="ignore"):
        log_ratio = np.log(ratio)
    np.testing.assert_allclose(
        lbp_marginals_log(log_ratio, np.log(new)).p_track, lbp_marginals(ratio, new).p_track, atol=1e-14
    )
    np.testing.assert_allclose(
        exact_marginals_log(log_ratio, np.log(new)).p_track, exact_marginals(ratio, new).p_track, atol=1e-14
    )


def test_dominant_term_does_not_cancel_small_ones():
    # Track 0 takes the measurement almost surely; its miss probability (1 + 5000 + 1) / (1 + 1e20 + 5000 + 1)
    # needs the sum of the other tracks' messages without track 0's, which "total - own" would round away.
    ratio = np.array([[1e20], [5000.0], [1.0]])
    lbp = lbp_marginals(ratio, np.array([1.0]))
    np.testing.assert_allclose(lbp.p_track[0, 0], 5002.0 / (1e20 + 5002.0), rtol=1e-9)
    np.testing.assert_allclose(lbp.p_track[1, 1], 5000.0 / (1e20 + 5002.0), rtol=1e-9)


def test_extreme_dynamic_range_stays_finite():
    rng = np.random.default_rng(6)
    ratio = 10.0 ** rng.uniform(-300, 300, size=(5, 5))
    ratio[rng.random((5, 5)) < 0.3] = 0.0
    new = 10.0 ** rng.uniform(-300, 300, size=5)
    for solver in (lbp_marginals, exact_marginals):
        check_consistent(solver(ratio, new), 5, 5)
    lbp, exact = lbp_marginals(ratio[:1], new), exact_marginals(ratio[:1], new)
    np.testing.assert_allclose(lbp.p_track, exact.p_track, atol=1e-12)


def test_clusters_are_independent():
    rng = np.random.default_rng(7)
    a, na = random_problem(rng, gate_prob=1.0)
    b, nb = random_problem(rng, gate_prob=1.0)
    ratio = np.zeros((a.shape[0] + b.shape[0], a.shape[1] + b.shape[1]))
    ratio[: a.shape[0], : a.shape[1]] = a
    ratio[a.shape[0] :, a.shape[1] :] = b
    joint = exact_marginals(ratio, np.concatenate([na, nb]))
    ea, eb = exact_marginals(a, na), exact_marginals(b, nb)
    np.testing.assert_allclose(joint.p_track[: a.shape[0], : a.shape[1] + 1], ea.p_track, atol=1e-12)
    np.testing.assert_allclose(joint.p_track[a.shape[0] :, 0], eb.p_track[:, 0], atol=1e-12)
    np.testing.assert_allclose(joint.p_new, np.concatenate([ea.p_new, eb.p_new]), atol=1e-12)


def test_ungated_tracks_and_measurements():
    ratio = np.array([[0.0, 0.0, 0.0], [0.0, 2.0, 0.0]])
    for solver in (lbp_marginals, exact_marginals):
        marg = solver(ratio, np.ones(3))
        np.testing.assert_allclose(marg.p_track, [[1, 0, 0, 0], [1 / 3, 0, 2 / 3, 0]], atol=1e-12)
        np.testing.assert_allclose(marg.p_new, [1, 1 / 3, 1], atol=1e-12)


@pytest.mark.parametrize("shape", [(0, 0), (0, 3), (2, 0)])
@pytest.mark.parametrize("solver", [lbp_marginals, exact_marginals])
def test_empty_problems(solver, shape):
    marg = solver(np.zeros(shape), np.ones(shape[1]))
    check_consistent(marg, *shape)
    assert np.all(marg.p_track[:, 0] == 1.0) and np.all(marg.p_new == 1.0)


@pytest.mark.parametrize(
    ("ratio", "new", "match"),
    [
        (np.array([[-1.0]]), np.array([1.0]), "ratio"),
        (np.array([[np.nan]]), np.array([1.0]), "ratio"),
        (np.array([[1.0]]), np.array([0.0]), "new_weight"),
        (np.array([[1.0, 2.0]]), np.array([1.0]), "shapes"),
    ],
)
@pytest.mark.parametrize("solver", [lbp_marginals, exact_marginals])
def test_invalid_input_raises(solver, ratio, new, match):
    with pytest.raises(ValueError, match=match):
        solver(ratio, new)


def test_exact_refuses_huge_clusters():
    with pytest.raises(ValueError, match="lbp"):
        exact_marginals(np.ones((8, 8)), np.ones(8), max_associations=1000)


def test_lbp_deterministic_and_iteration_cap():
    rng = np.random.default_rng(8)
    ratio, new = rng.uniform(1, 10, size=(6, 6)), np.ones(6)
    a, b = lbp_marginals(ratio, new), lbp_marginals(ratio, new)
    assert np.array_equal(a.p_track, b.p_track) and a.iterations == b.iterations
    one = lbp_marginals(ratio, new, max_iterations=1)
    assert one.iterations == 1
    check_consistent(one, 6, 6)
    with pytest.raises(ValueError, match="max_iterations"):
        lbp_marginals(ratio, new, max_iterations=0)


def test_keep_most_likely_cuts_each_row_to_its_largest_entries():
    from gnnpmb.assign.lbp import keep_most_likely

    inf = np.inf
    log_ratio = np.array([[0.0, -1.0, -2.0, -inf], [5.0, 5.0, 1.0, 0.0], [-inf, 3.0, -inf, -inf]])
    out = keep_most_likely(log_ratio, 2)
    np.testing.assert_array_equal(out, [[0.0, -1.0, -inf, -inf], [5.0, 5.0, -inf, -inf], [-inf, 3.0, -inf, -inf]])
    assert keep_most_likely(log_ratio, 4) is log_ratio
