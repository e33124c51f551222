"""Solve-then-threshold association, its certified solve over bounded costs, two-stage association, greedy
orders."""

import itertools

import numpy as np
import pytest

from gnnpmb.assign.greedy import greedy_pairs, greedy_rows
from gnnpmb.assign.matching import BoundedCosts, SecondStage, Solver, solve_then_threshold, two_stage_match


def test_hungarian_solves_over_every_pair_then_drops_pairs_past_the_threshold():
    """AB3DMOT's order: the optimal full assignment takes det 0 -> track 1 (cost 0.91, past 0.9) to give det 1
    track 0 (0.55): 0.91 + 0.55 < 0.5 + 1.0. Forbidding pairs first would keep det 0 -> track 0 instead."""
    cost = np.array([[0.5, 0.91], [0.55, 1.0]])
    assert solve_then_threshold(BoundedCosts.of(cost), 0.9, Solver.HUNGARIAN).tolist() == [-1, 0]


def test_greedy_takes_the_closest_pair_first_and_respects_the_threshold():
    cost = np.array([[0.5, 0.4], [0.45, 2.0]])
    assert solve_then_threshold(BoundedCosts.of(cost), 1.0, Solver.GREEDY).tolist() == [1, 0]
    assert solve_then_threshold(BoundedCosts.of(cost), 0.42, Solver.GREEDY).tolist() == [1, -1]


def _brute_force(cost: np.ndarray) -> float:
    m, k = cost.shape
    if m <= k:
        return min(sum(cost[i, p[i]] for i in range(m)) for p in itertools.permutations(range(k), m))
    return min(sum(cost[p[j], j] for j in range(k)) for p in itertools.permutations(range(m), k))


def test_certified_solve_over_bounds_equals_the_solve_over_exact_costs():
    """Entries known only as a lower bound are resolved until the assignment uses exact costs only; the result is
    the exact matrix's optimum (continuous costs: unique)."""
    rng = np.random.default_rng(0)
    for _ in range(200):
        m, k = int(rng.integers(1, 5)), int(rng.integers(1, 6))
        exact = rng.uniform(0.0, 2.0, (m, k))
        known = rng.random((m, k)) < 0.3
        resolved = []

        def resolve(r, c, exact=exact, resolved=resolved):
            resolved.append(len(r))
            return exact[r, c]

        bounds = BoundedCosts(np.where(known, exact, exact - rng.uniform(0.0, 0.5, (m, k))), known.copy(), resolve)
        got = solve_then_threshold(bounds, 10.0, Solver.HUNGARIAN)
        full = solve_then_threshold(BoundedCosts.of(exact), 10.0, Solver.HUNGARIAN)
        assert got.tolist() == full.tolist()
        rows = np.flatnonzero(got >= 0)
        assert exact[rows, got[rows]].sum() == pytest.approx(_brute_force(exact))


def test_two_stage_keeps_alive_a_track_near_a_low_score_detection():
    """Stage 1 uses detections scoring >= 0.5: det 0 (0.9) takes track 0. Track 1 is near det 1 (0.3) only:
    stage 2 keeps it alive; det 1 starts no track (not a first-stage detection)."""
    cost = BoundedCosts.of(np.array([[0.2, 1.9], [1.9, 0.4]]))
    score = np.array([0.9, 0.3])
    one = two_stage_match(cost, score, 0.5, 1.5, Solver.HUNGARIAN, None)
    assert one.track_of_meas.tolist() == [0, -1] and one.first_stage.tolist() == [True, False]
    assert one.kept_alive.tolist() == [False, False]
    two = two_stage_match(cost, score, 0.5, 1.5, Solver.HUNGARIAN, SecondStage(min_score=0.1, max_cost=1.5))
    assert two.track_of_meas.tolist() == [0, -1] and two.kept_alive.tolist() == [False, True]
    assert two.meas_of_track.tolist() == [0, -1]
    low = two_stage_match(cost, score, 0.5, 1.5, Solver.HUNGARIAN, SecondStage(min_score=0.3, max_cost=1.5))
    assert low.kept_alive.tolist() == [False, False]  # 0.3 is not above the second stage's 0.3


def test_greedy_rows_go_in_row_order_each_taking_its_cheapest_free_column():
    """CenterPoint's order (detections in file order) against the closest pair first: row 0 takes column 0 before
    row 1, whose 0.05 is the closest pair overall."""
    cost = np.array([[0.1, 0.2], [0.05, 0.3]])
    assert greedy_rows(cost).tolist() == [[0, 0], [1, 1]]
    assert greedy_pairs(cost).tolist() == [[1, 0], [0, 1]]
    assert greedy_rows(np.array([[0.5, 0.2], [0.1, np.inf], [0.3, 0.4]])).tolist() == [[0, 1], [1, 0]]
    assert greedy_rows(np.array([[np.inf], [1.0]])).tolist() == [[1, 0]]
    assert greedy_rows(np.zeros((2, 0))).shape == (0, 2)
