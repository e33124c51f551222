"""Optimal 2D assignment (Hungarian / Jonker-Volgenant) via scipy's ``linear_sum_assignment``.

Rows are assigned to distinct columns minimising the summed cost; +inf marks a forbidden pair. scipy's solver
accepts inf entries as long as a finite full row assignment exists and raises ValueError otherwise.
"""

from __future__ import annotations

import math

import numpy as np

from gnnpmb.assign.lsap import linear_sum_assignment


class InfeasibleAssignment(ValueError):
    """No assignment of every row to a distinct column avoids the forbidden (+inf) entries."""


def solve(cost: np.ndarray) -> tuple[np.ndarray, float]:
    """Best assignment of every row of an (R, C) cost matrix, R <= C.

    Returns (col_of_row (R,) int, total cost). Raises InfeasibleAssignment when every full assignment uses a
    forbidden entry.
    """
    n_rows = cost.shape[0]
    if n_rows == 0:
        return np.zeros(0, dtype=np.int64), 0.0
    try:
        rows, cols = linear_sum_assignment(cost)
    except ValueError as exc:
        raise InfeasibleAssignment(str(exc)) from exc
    total = float(cost[rows, cols].sum())
    if not math.isfinite(total):
        raise InfeasibleAssignment("cost matrix is infeasible")
    if len(rows) == n_rows:  # every row assigned: rows is 0..R-1 in order (scipy sorts them)
        return cols.astype(np.int64, copy=False), total
    col_of_row = np.empty(n_rows, dtype=np.int64)
    col_of_row[rows] = cols
    return col_of_row, total
