"""Exhaustive enumeration of 2D assignments: the reference that ``murty.k_best`` is tested against.

Every map of the R rows of an (R, C) cost matrix to distinct columns that avoids +inf entries, found by depth-
first search over rows (C! / (C - R)! leaves at most, so only for small matrices).
"""

from __future__ import annotations

import numpy as np


def all_assignments(cost: np.ndarray) -> list[tuple[np.ndarray, float]]:
    """Every feasible assignment (col_of_row (R,) int64, total cost), sorted by cost, ties by column tuple."""
    cost = np.asarray(cost, dtype=float)
    n_rows, n_cols = cost.shape
    found: list[tuple[float, tuple[int, ...]]] = []
    allowed = [np.flatnonzero(np.isfinite(cost[i])).tolist() for i in range(n_rows)]

    def extend(prefix: list[int], used: set[int]) -> None:
        i = len(prefix)
        if i == n_rows:
            found.append((float(cost[np.arange(n_rows), prefix].sum()), tuple(prefix)))
            return
        for j in allowed[i]:
            if j not in used:
                used.add(j)
                prefix.append(j)
                extend(prefix, used)
                prefix.pop()
                used.remove(j)

    if n_rows <= n_cols:
        extend([], set())
    found.sort()
    return [(np.array(cols, dtype=np.int64), total) for total, cols in found]


def k_best(cost: np.ndarray, k: int) -> list[tuple[np.ndarray, float]]:
    """The k cheapest assignments by exhaustive enumeration (same contract as ``murty.k_best``)."""
    return all_assignments(cost)[: max(k, 0)]
