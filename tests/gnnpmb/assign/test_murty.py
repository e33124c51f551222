"""Murty's k best assignments against exhaustive enumeration (``gnnpmb.assign.enumerate``)."""

from __future__ import annotations

import heapq
import math

import numpy as np
import pytest

from gnnpmb.assign import enumerate as brute
from gnnpmb.assign import murty
from gnnpmb.assign.hungarian import solve


@pytest.fixture(params=["enumerated-blocks", "murty-only"])
def ranking_mode(request, monkeypatch):
    """Run each test with small blocks listed at once (default) and with every block ranked by Murty."""
    if request.param == "murty-only":
        monkeypatch.setattr(murty, "ENUMERATION_LIMIT", 0)
    return request.param


def random_cost(rng: np.random.Generator, n_rows: int, n_cols: int, integer: bool) -> np.ndarray:
    """Random costs (small integers give many ties) with a random share of forbidden entries."""
    cost = rng.integers(0, 4, size=(n_rows, n_cols)).astype(float) if integer else rng.random((n_rows, n_cols))
    cost[rng.random((n_rows, n_cols)) < rng.uniform(0.0, 0.6)] = np.inf
    return cost


def block_diagonal(rng: np.random.Generator, n_blocks: int, integer: bool) -> np.ndarray:
    """Independent random blocks, rows and columns shuffled (what gating makes of a tracking matrix)."""
    sizes = [(int(r), int(r + rng.integers(0, 3))) for r in rng.integers(1, 4, size=n_blocks)]
    cost = np.full((sum(r for r, _ in sizes), sum(c for _, c in sizes)), np.inf)
    i = j = 0
    for r, c in sizes:
        cost[i : i + r, j : j + c] = random_cost(rng, r, c, integer)
        i, j = i + r, j + c
    return cost[rng.permutation(cost.shape[0])][:, rng.permutation(cost.shape[1])]


def assert_same_ranking(got: list[tuple[np.ndarray, float]], cost: np.ndarray, k: int) -> None:
    """Same costs in the same order as brute force; assignments equal as sets within every cost level that k
    does not cut; every total is the assignment's cost; no assignment twice; the first is Hungarian's."""
    full = brute.all_assignments(cost)
    want = full[:k]
    assert len(got) == len(want)
    np.testing.assert_allclose([t for _, t in got], [t for _, t in want], rtol=0, atol=1e-9)
    assert all(b >= a - 1e-12 for (_, a), (_, b) in zip(got, got[1:], strict=False))
    for cols, total in got:
        assert total == pytest.approx(float(cost[np.arange(len(cols)), cols].sum()), abs=1e-12)
    assert len({tuple(c) for c, _ in got}) == len(got)
    cut = round(want[-1][1], 9) if want and len(want) < len(full) else None
    levels_got = {(round(t, 9), tuple(c)) for c, t in got if round(t, 9) != cut}
    levels_want = {(round(t, 9), tuple(c)) for c, t in want if round(t, 9) != cut}
    assert levels_got == levels_want
    if got:
        first, first_total = solve(cost)
        np.testing.assert_array_equal(got[0][0], first)
        assert got[0][1] == first_total


@pytest.mark.parametrize("integer", [False, True])
def test_k_best_equals_brute_force_on_random_matrices(ranking_mode, integer):
    rng = np.random.default_rng(11 + integer)
    for _ in range(250):
        n_rows = int(rng.integers(0, 6))
        n_cols = int(rng.integers(max(n_rows, 1), 8))
        cost = random_cost(rng, n_rows, n_cols, integer)
        k = int(rng.integers(1, 40))
        assert_same_ranking(murty.k_best(cost, k), cost, k)


@pytest.mark.parametrize("integer", [False, True])
def test_k_best_equals_brute_force_on_block_diagonal_matrices(ranking_mode, integer):
    rng = np.random.default_rng(21 + integer)
    for _ in range(120):
        cost = block_diagonal(rng, int(rng.integers(2, 5)), integer)
        k = int(rng.integers(1, 60))
        assert_same_ranking(murty.k_best(cost, k), cost, k)


def test_k_larger_than_the_number_of_assignments_returns_all_of_them(ranking_mode):
    cost = np.array([[1.0, 2.0, np.inf], [np.inf, 1.0, 5.0]])
    got = murty.k_best(cost, 10)
    assert [(c.tolist(), t) for c, t in got] == [([0, 1], 2.0), ([0, 2], 6.0), ([1, 2], 7.0)]


def test_infeasible_and_degenerate_inputs():
    assert murty.k_best(np.array([[np.inf, np.inf], [1.0, 2.0]]), 5) == []
    assert murty.k_best(np.array([[1.0, np.inf], [2.0, np.inf]]), 5) == []  # both rows need column 0
    assert murty.k_best(np.ones((3, 2)), 5) == []  # more rows than columns
    assert murty.k_best(np.ones((2, 2)), 0) == []
    ((cols, total),) = murty.k_best(np.zeros((0, 3)), 4)
    assert cols.shape == (0,) and total == 0.0
    with pytest.raises(ValueError, match="finite values and \\+inf"):
        murty.k_best(np.array([[np.nan, 1.0]]), 2)


def test_k_equal_one_is_exactly_the_hungarian_solution():
    rng = np.random.default_rng(3)
    for _ in range(100):
        cost = random_cost(rng, 4, 6, integer=True)
        got = murty.k_best(cost, 1)
        try:
            want = solve(cost)
        except ValueError:
            assert got == []
            continue
        np.testing.assert_array_equal(got[0][0], want[0])
        assert got[0][1] == want[1]


def test_max_increase_keeps_exactly_the_assignments_within_it(ranking_mode):
    rng = np.random.default_rng(5)
    for _ in range(200):
        n_rows = int(rng.integers(1, 6))
        cost = 3.0 * random_cost(rng, n_rows, int(rng.integers(n_rows, 9)), integer=False)
        limit = float(rng.uniform(0.0, 2.0))
        k = int(rng.integers(1, 50))
        full = brute.all_assignments(cost)
        want = [t for _, t in full if t <= full[0][1] + limit][:k] if full else []
        got = murty.k_best(cost, k, max_increase=limit)
        np.testing.assert_allclose([t for _, t in got], want, rtol=0, atol=1e-9)


def test_forbid_beyond_private_keeps_every_assignment_within_the_limit():
    rng = np.random.default_rng(8)
    for _ in range(200):
        n_rows = int(rng.integers(1, 5))
        cost = random_cost(rng, n_rows, n_rows + 3, integer=False) * 4.0
        cost[np.arange(n_rows), np.arange(n_rows) + 3] = rng.uniform(0, 4, n_rows)  # a private column per row
        limit = float(rng.uniform(0.0, 3.0))
        full = brute.all_assignments(cost)
        pruned = murty.forbid_beyond_private(cost, limit)
        kept = {tuple(c) for c, _ in brute.all_assignments(pruned)}
        assert {tuple(c) for c, t in full if t <= full[0][1] + limit} <= kept


def test_forbid_beyond_private_uses_only_usable_private_columns():
    cost = np.array([[5.0, 0.0, 9.0], [5.0, np.inf, 9.0]])  # column 1 is private to row 0 but may disappear
    assert np.isinf(murty.forbid_beyond_private(cost, 1.0)[0, [0, 2]]).all()
    usable = np.array([True, False, True])
    np.testing.assert_array_equal(murty.forbid_beyond_private(cost, 1.0, usable), cost)


def test_blocks_are_the_connected_components_of_finite_entries():
    inf = np.inf
    cost = np.array(
        [
            [1.0, inf, inf, inf, 2.0],
            [inf, inf, 3.0, inf, inf],
            [inf, inf, inf, inf, 4.0],
            [inf, inf, 5.0, 6.0, inf],
        ]
    )
    got = [(r.tolist(), c.tolist()) for r, c in murty.blocks(cost)]
    assert got == [([0, 2], [0, 4]), ([1, 3], [2, 3])]
    assert murty.blocks(np.zeros((0, 3))) == []


def test_rank_is_lazy_and_extends_on_demand():
    rng = np.random.default_rng(9)
    cost = block_diagonal(rng, 3, integer=False)
    ranking = murty.rank(cost)
    full = brute.all_assignments(cost)
    assert ranking.solution(len(full)) is None
    np.testing.assert_allclose([ranking.solution(i)[1] for i in range(len(full))], [t for _, t in full])
    assert math.isclose(ranking.solution(0)[1], full[0][1])


def test_brute_force_reference_on_a_hand_example():
    cost = np.array([[4.0, 1.0, 3.0], [2.0, 0.0, 5.0]])
    got = [(c.tolist(), t) for c, t in brute.all_assignments(cost)]
    assert got == [([1, 0], 3.0), ([2, 1], 3.0), ([0, 1], 4.0), ([2, 0], 5.0), ([1, 2], 6.0), ([0, 2], 9.0)]
    assert [(c.tolist(), t) for c, t in brute.k_best(cost, 2)] == got[:2]


def eager_murty(cost: np.ndarray, root: np.ndarray, max_increase: float, k: int) -> list[tuple[list[int], float]]:
    """Murty's partitioning as first written (every subproblem solved when its parent is partitioned, queued by
    (cost, serial)): the reference ``murty.Murty``'s lazy evaluation must reproduce, ties included."""
    arange = np.arange(cost.shape[0])

    def total(cols: np.ndarray) -> float:
        return float(cost[arange, cols].sum())

    limit = total(root) + max_increase
    out, queue, serial = [(root, total(root))], [], 0
    unexpanded: tuple[np.ndarray, int, tuple[int, ...]] | None = (root, 0, ())
    while len(out) < k:
        if unexpanded is not None:
            sol, pinned, barred = unexpanded
            free = np.ones(cost.shape[1], dtype=bool)
            free[sol[:pinned]] = False
            for q in range(pinned, cost.shape[0]):
                row_barred = (*barred, int(sol[q])) if q == pinned else (int(sol[q]),)
                row = np.where(free, cost[q], np.inf)
                row[list(row_barred)] = np.inf
                if np.isfinite(row).any():
                    child = sol.copy()
                    sub_cols = np.flatnonzero(free)
                    sub = cost[q:, sub_cols]
                    sub[0] = row[sub_cols]
                    try:
                        child[q:] = sub_cols[murty.linear_sum_assignment(sub)[1]]
                    except ValueError:
                        child = None
                    if child is not None and total(child) <= limit and total(child) < np.inf:
                        heapq.heappush(queue, (total(child), serial, child, q, row_barred))
                        serial += 1
                free[sol[q]] = False
        if not queue:
            break
        cost_of, _, sol, pinned, barred = heapq.heappop(queue)
        out.append((sol, cost_of))
        unexpanded = (sol, pinned, barred)
    return [(cols.tolist(), value) for cols, value in out]


@pytest.mark.parametrize("max_increase", [math.inf, 1.0])
def test_lazy_murty_gives_the_eager_order_ties_included(max_increase):
    """``murty.Murty`` solves a subproblem only when its lower bound reaches the front of the queue, yet gives
    the same assignments with the same float costs in the same order as solving every subproblem at once."""
    rng = np.random.default_rng(21)
    checked = 0
    for trial in range(300):
        n_rows = int(rng.integers(2, 7))
        cost = random_cost(rng, n_rows, n_rows + int(rng.integers(0, 4)), integer=trial % 2 == 0)
        try:
            root, _ = solve(cost)
        except murty.InfeasibleAssignment:
            continue
        ranking = murty.Murty(cost, root, max_increase)
        got = []
        while len(got) < 40 and (found := ranking.solution(len(got))) is not None:
            got.append((found[0].tolist(), found[1]))
        assert got == eager_murty(cost, root, max_increase, 40)
        checked += len(got) > 3
    assert checked > 100
