"""``murty.ColumnSubsets`` ranks a block cut to some of its columns exactly as ``murty.rank`` ranks the cut
matrix: the same assignments with the same float costs in the same order, ties included."""

from __future__ import annotations

import functools
import itertools
import math

import numpy as np
import pytest

from gnnpmb.assign import murty


def all_solutions(ranking: murty.Ranking) -> list[tuple[list[int], float]]:
    out = []
    while (found := ranking.solution(len(out))) is not None:
        out.append((found[0].tolist(), found[1]))
    return out


@pytest.mark.parametrize("shared_cache", [False, True])
@pytest.mark.parametrize("max_increase", [math.inf, 1.5])
@pytest.mark.parametrize("enumeration_limit", [1024, 8])
def test_rank_of_a_column_subset_equals_rank_of_the_cut_matrix(
    shared_cache, max_increase, enumeration_limit, monkeypatch
):
    monkeypatch.setattr(murty, "ENUMERATION_LIMIT", enumeration_limit)
    rng = np.random.default_rng(5)
    checked = 0
    cache: murty.BlockCache | None = {} if shared_cache else None
    for trial in range(100):
        # a PMB-like block: K track columns, then one private (new-track) column per row, always present
        n_rows, n_tracks = int(rng.integers(1, 5)), int(rng.integers(1, 7))
        integer = trial % 2 == 0  # small integers: many equal costs
        shape = (n_rows, n_tracks)
        tracks = rng.integers(0, 4, size=shape).astype(float) if integer else rng.random(shape)
        tracks[rng.random(shape) < 0.3] = np.inf
        private = np.full((n_rows, n_rows), np.inf)
        private[np.arange(n_rows), np.arange(n_rows)] = rng.integers(0, 4, size=n_rows) if integer else 1.0
        cost = np.hstack([tracks, private])
        subsets = murty.ColumnSubsets(cost, max_increase, cache)
        for _ in range(4):
            present = np.concatenate([rng.random(n_tracks) < 0.7, np.ones(n_rows, dtype=bool)])
            want = all_solutions(murty.rank(cost[:, present], max_increase=max_increase))
            assert all_solutions(subsets.rank(present)) == want
            checked += len(want) > 1
    assert checked > 60


def test_block_cache_ranks_a_repeated_block_once(monkeypatch):
    monkeypatch.setattr(murty, "ENUMERATION_LIMIT", 0)  # split into blocks, each ranked by Murty
    rng = np.random.default_rng(8)
    block = rng.random((2, 3))
    cost = np.full((4, 6), np.inf)
    cost[:2, :3] = cost[2:, 3:] = block  # two independent blocks with equal costs
    cache: murty.BlockCache = {}
    ranking = murty.rank(cost, max_increase=math.inf, cache=cache)
    assert isinstance(ranking, murty.Product)
    (_, _, first), (_, _, second) = ranking.parts
    assert first is second and len(cache) == 1
    assert all_solutions(ranking) == all_solutions(murty.rank(cost, max_increase=math.inf))


@pytest.mark.parametrize("known", [0, 1, 2, 3])
def test_product_with_a_known_prefix_equals_the_plain_product(known, monkeypatch):
    monkeypatch.setattr(murty, "ENUMERATION_LIMIT", 0)  # keep the blocks apart: a Product of 3 parts
    rng = np.random.default_rng(9)
    for _ in range(30):
        cost = np.full((6, 9), np.inf)
        for b in range(3):
            block = rng.integers(0, 3, size=(2, 3)).astype(float)  # ties between and within parts
            cost[2 * b : 2 * b + 2, 3 * b : 3 * b + 3] = block
        plain = murty.rank(cost)
        assert isinstance(plain, murty.Product) and len(plain.parts) == 3
        summary = murty.PartsSummary.of(plain.parts[:known])
        assert len(summary.best_costs) == known
        with_prefix = murty.Product(plain.base, plain.parts, math.inf, summary)
        assert all_solutions(with_prefix) == all_solutions(plain)


def test_enumerate_assignments_lists_every_assignment_in_lexicographic_order():
    rng = np.random.default_rng(4)
    sizes = set()
    for _ in range(300):
        n_rows, n_cols = int(rng.integers(0, 6)), int(rng.integers(1, 8))
        allowed = rng.random((n_rows, n_cols)) < 0.7
        product = itertools.product(*[np.flatnonzero(row).tolist() for row in allowed])
        want = [c for c in product if len(set(c)) == n_rows]
        got = murty.enumerate_assignments(allowed)
        assert got.dtype == np.int64 and got.shape == (len(want), n_rows) and got.flags.c_contiguous
        assert [tuple(c) for c in got.tolist()] == want
        sizes.add(math.prod(int(n) for n in allowed.sum(axis=1)) <= murty.SMALL_PRODUCT)
    assert sizes == {False, True}  # both ways of listing were checked


def test_enumerated_with_a_root_defers_listing_and_agrees_with_its_listing():
    """With a root, the best is the root and its cost is summed alone; once listed, the root's cost in the
    listing is the same float, and the ranking is that of the eagerly listed block."""
    rng = np.random.default_rng(12)
    for _ in range(300):
        n_rows = int(rng.integers(1, 16))
        cost = np.full((n_rows, n_rows + 3), np.inf)
        cost[:, :3] = rng.normal(0.0, 10.0, size=(n_rows, 3)) * (rng.random((n_rows, 3)) < 0.3)
        cost[np.arange(n_rows), 3 + np.arange(n_rows)] = rng.normal(0.0, 10.0, size=n_rows)
        cost[cost == 0.0] = np.inf
        root, _ = murty.solve(cost)
        lazy = murty.Enumerated(cost, root)
        eager = murty.Enumerated(cost, root, combos=murty.enumerate_assignments(cost < np.inf))
        best = lazy.solution(0)
        assert best is not None and best[0].tolist() == root.tolist()
        assert best[1] == eager.solution(0)[1]  # bit for bit
        assert all_solutions(lazy) == all_solutions(eager)


def _several_subsets_trials() -> list[tuple[np.ndarray, np.ndarray]]:
    """200 PMB-like blocks (cost (R, C)) each with 1 to 5 column subsets (patterns (P, C) bool), seeded."""
    rng = np.random.default_rng(11)
    trials = []
    for trial in range(200):
        n_rows, n_tracks = int(rng.integers(1, 6)), int(rng.integers(1, 8))
        integer = trial % 2 == 0
        shape = (n_rows, n_tracks)
        tracks = rng.integers(0, 4, size=shape).astype(float) if integer else rng.random(shape)
        tracks[rng.random(shape) < 0.3] = np.inf
        private = np.full((n_rows, n_rows), np.inf)
        private[np.arange(n_rows), np.arange(n_rows)] = rng.integers(0, 4, size=n_rows) if integer else 1.0
        private[rng.random((n_rows, n_rows)) < 0.1] = np.inf  # now and then a row with no private column
        cost = np.hstack([tracks, private])
        patterns = rng.random((int(rng.integers(1, 6)), cost.shape[1])) < 0.7
        trials.append((cost, patterns))
    return trials


@functools.cache
def _each_rank_of_several_subsets(max_increase: float) -> list[list[list[tuple[list[int], float]] | None]]:
    """Per trial of ``_several_subsets_trials``, per subset: ``ColumnSubsets.rank``'s solutions, None where it is
    infeasible. ``rank`` of one subset reads neither listing limit, so the cases below, which set only those,
    share it (computed once per worker; the module's tests run on one)."""
    out = []
    for cost, patterns in _several_subsets_trials():
        wants = []
        for present in patterns:
            try:
                wants.append(all_solutions(murty.ColumnSubsets(cost, max_increase).rank(present)))
            except murty.InfeasibleAssignment:
                wants.append(None)
        out.append(wants)
    return out


@pytest.mark.parametrize(("joint_limit", "shared_limit"), [(256, 4096), (0, 4096), (0, 0)])
@pytest.mark.parametrize("max_increase", [math.inf, 1.5])
def test_ranks_of_several_column_subsets_equal_each_rank(max_increase, joint_limit, shared_limit, monkeypatch):
    """``ColumnSubsets.ranks`` (small subsets listed side by side, or from one listing of the block, or each on
    its own) gives what ``rank`` gives for each subset, solution for solution, ties included, None where it is
    infeasible."""
    monkeypatch.setattr(murty, "JOINT_LISTING_LIMIT", joint_limit)
    monkeypatch.setattr(murty, "SHARED_LISTING_LIMIT", shared_limit)
    together = infeasible = 0
    trials = _several_subsets_trials()
    for (cost, patterns), wants in zip(trials, _each_rank_of_several_subsets(max_increase), strict=True):
        got = murty.ColumnSubsets(cost, max_increase).ranks(patterns)
        for ranking, want in zip(got, wants, strict=True):
            assert (None if ranking is None else all_solutions(ranking)) == want
            infeasible += want is None
        together += cost.shape[0] >= 2 and len(patterns) >= 2
    assert together > 50 and infeasible > 10


SEVERAL_BLOCKS_ENUMERATION_LIMIT = 16
"""``ENUMERATION_LIMIT`` in ``test_subset_rankings_of_several_blocks_equal_each_rank``: some sub-problems are ranked
one by one."""


def _several_blocks_trials() -> list[tuple[list[np.ndarray], list[np.ndarray]]]:
    """60 seeded trials of 1 to 8 blocks of different shapes (costs), each with one column subset (patterns)."""
    rng = np.random.default_rng(13)
    trials = []
    for trial in range(60):
        costs, patterns = [], []
        for _ in range(int(rng.integers(1, 9))):
            n_rows = int(rng.integers(1, 5))
            n_tracks = int(rng.integers(1, 9 if n_rows > 1 else 30))  # one row: some over the limit
            shape = (n_rows, n_tracks)
            tracks = rng.integers(0, 4, size=shape).astype(float) if trial % 2 == 0 else rng.random(shape)
            tracks[rng.random(shape) < 0.3] = np.inf
            private = np.full((n_rows, n_rows), np.inf)
            private[np.arange(n_rows), np.arange(n_rows)] = rng.integers(0, 4, size=n_rows)
            private[rng.random((n_rows, n_rows)) < 0.1] = np.inf
            costs.append(np.hstack([tracks, private]))
            patterns.append(np.concatenate([rng.random(n_tracks) < 0.7, np.ones(n_rows, dtype=bool)]))
        trials.append((costs, patterns))
    return trials


@functools.cache
def _each_rank_of_several_blocks(max_increase: float) -> list[list[list[tuple[list[int], float]] | None]]:
    """Per trial of ``_several_blocks_trials``, per block: ``ColumnSubsets.rank``'s solutions of its subset (with
    ``ENUMERATION_LIMIT`` at ``SEVERAL_BLOCKS_ENUMERATION_LIMIT``), None where it is infeasible. ``rank`` of one
    subset does not read ``JOINT_LISTING_LIMIT``, so the cases below, which set it, share it (once per worker)."""
    assert murty.ENUMERATION_LIMIT == SEVERAL_BLOCKS_ENUMERATION_LIMIT
    out = []
    for costs, patterns in _several_blocks_trials():
        wants = []
        for cost, present in zip(costs, patterns, strict=True):
            try:
                wants.append(all_solutions(murty.ColumnSubsets(cost, max_increase).rank(present)))
            except murty.InfeasibleAssignment:
                wants.append(None)
        out.append(wants)
    return out


@pytest.mark.parametrize("joint_limit", [4, 256])
@pytest.mark.parametrize("max_increase", [math.inf, 1.5])
def test_subset_rankings_of_several_blocks_equal_each_rank(max_increase, joint_limit, monkeypatch):
    """``subset_rankings`` over blocks of different shapes (worked on together per row count, padded to the
    widest) gives what ``ColumnSubsets.rank`` gives for each, solution for solution, ties included, None where
    it is infeasible; with a small enumeration limit some sub-problems are ranked one by one."""
    monkeypatch.setattr(murty, "ENUMERATION_LIMIT", SEVERAL_BLOCKS_ENUMERATION_LIMIT)
    monkeypatch.setattr(murty, "JOINT_LISTING_LIMIT", joint_limit)  # 4: many listed on their own
    kinds = {"single": 0, "listed": 0, "ranked": 0, "infeasible": 0}
    trials = _several_blocks_trials()
    for (costs, patterns), wants in zip(trials, _each_rank_of_several_blocks(max_increase), strict=True):
        got = murty.subset_rankings(costs, patterns, max_increase)
        for ranking, want in zip(got, wants, strict=True):
            assert (None if ranking is None else all_solutions(ranking)) == want
            if want is None:
                kinds["infeasible"] += 1
            elif isinstance(ranking, murty.SingleRow):
                kinds["single"] += 1
            elif isinstance(ranking, murty.Enumerated):
                kinds["listed"] += 1
            else:
                kinds["ranked"] += 1
    assert min(kinds.values()) > 5, kinds
