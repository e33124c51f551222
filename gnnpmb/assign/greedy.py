"""Greedy one-to-one matching of an (R, C) cost matrix: +inf marks a forbidden pair.

Two orders, both from the baselines of the GNN-PMB paper's comparison:

- ``greedy_pairs``: closest pair first over the whole matrix (Probabilistic 3D MOT, Chiu et al. 2020, sec. IV-D;
  the greedy CenterPoint baseline ``gnnpmb.greedy``);
- ``greedy_rows``: row by row in row order, each row taking its cheapest free column (CenterPoint's public
  ``greedy_assignment``, Yin et al. 2021, as CBMOT runs it: rows are detections in the order of the detection
  file, which detectors write by decreasing score).

Neither is the optimal assignment (``hungarian``); ties go to the lower row, then the lower column index, so the
result is deterministic.
"""

from __future__ import annotations

import numpy as np


def greedy_pairs(dist: np.ndarray) -> np.ndarray:
    """(P, 2) pairs [j, k] taken by increasing finite distance, each row and column at most once; ties are
    broken by row, then column index, so the result is deterministic."""
    rows, cols = np.nonzero(np.isfinite(dist))
    order = np.lexsort((cols, rows, dist[rows, cols]))
    used_r, used_c = set(), set()
    pairs = []
    for j, k in zip(rows[order].tolist(), cols[order].tolist(), strict=True):
        if j not in used_r and k not in used_c:
            used_r.add(j)
            used_c.add(k)
            pairs.append((j, k))
    return np.array(pairs, dtype=np.int64).reshape(-1, 2)


def greedy_rows(cost: np.ndarray) -> np.ndarray:
    """(P, 2) pairs [j, k]: rows in order 0, 1, ..., each taking its cheapest finite column not taken by an
    earlier row (lowest column index on a tie); a row with none left is not matched."""
    n_rows, n_cols = cost.shape
    free = np.ones(n_cols, dtype=bool)
    pairs = []
    for j in range(n_rows):
        row = np.where(free, cost[j], np.inf)
        k = int(np.argmin(row)) if n_cols else -1
        if k >= 0 and np.isfinite(row[k]):
            free[k] = False
            pairs.append((j, k))
    return np.array(pairs, dtype=np.int64).reshape(-1, 2)
