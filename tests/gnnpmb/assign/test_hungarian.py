import numpy as np
import pytest

from gnnpmb.assign.enumerate import all_assignments
from gnnpmb.assign.hungarian import InfeasibleAssignment, solve


def test_solve_is_optimal_against_enumeration():
    rng = np.random.default_rng(0)
    for _ in range(60):
        r = int(rng.integers(1, 4))
        cost = rng.normal(size=(r, r + int(rng.integers(0, 3))))
        cost[rng.random(cost.shape) < 0.3] = np.inf
        feasible = all_assignments(cost)
        if not feasible:
            with pytest.raises(InfeasibleAssignment):
                solve(cost)
            continue
        col_of_row, total = solve(cost)
        assert col_of_row.dtype == np.int64 and col_of_row.shape == (r,)
        assert len(set(col_of_row.tolist())) == r
        assert total == pytest.approx(feasible[0][1]) and total == cost[np.arange(r), col_of_row].sum()


def test_solve_without_rows():
    col_of_row, total = solve(np.zeros((0, 3)))
    assert col_of_row.shape == (0,) and col_of_row.dtype == np.int64 and total == 0.0
