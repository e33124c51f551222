"""Counterfactuals replayed: a frame's cost matrix rebuilt from the raw events with one stated change, solved again
with the tracker's own optimal solver (``gnnpmb.assign.hungarian``), and the stated outcome looked up.

The two changes a sentence can state, on the PMB family's and GNN's costs C[j, k] = ... + d2[k, j] / 2 +
(log(1 - r_k P_D) - log r_k) (``events.CostTerms``):

* "within d² X": entry (j, k) moves by (X - d2[k, j]) / 2;
* "with a predicted existence above X": every entry of column k moves by the change of log(1 - r P_D) - log r
  from r_k to X (P_D from the event's miss log-likelihood, P_D = -expm1(miss) / r_k), tested just above X.

PMBM: the matrix is the one of the prior hypothesis the best posterior hypothesis came from; a change that only
lowers entries of that matrix keeps that hypothesis the best, so the replay within it is the tracker's choice.
Margins: the best total with the chosen pair forbidden minus the best total, uncapped.
"""

from __future__ import annotations

import math

import numpy as np

from gnnpmb.assign.hungarian import InfeasibleAssignment, solve
from gnnpmb.events import Assignment, AxisKind, CostMatrix

ABOVE = 1e-6
"""How far above a stated existence threshold the replay sets the existence (relative)."""


def row_of(m: CostMatrix, meas: int) -> int | None:
    hit = [i for i, r in enumerate(m.rows) if r.kind is AxisKind.MEASUREMENT and int(r.ref) == meas]
    return hit[0] if hit else None


def track_col(m: CostMatrix, track: int) -> int | None:
    hit = [k for k, c in enumerate(m.cols) if c.kind is AxisKind.TRACK and int(c.ref) == track]
    return hit[0] if hit else None


def chosen_col(m: CostMatrix, a: Assignment, meas: int) -> int | None:
    """The column the assignment gave detection ``meas`` (None: none)."""
    for r, c in a.pairs:
        if r.kind is AxisKind.MEASUREMENT and int(r.ref) == meas:
            hit = [k for k, col in enumerate(m.cols) if col.kind is c.kind and int(col.ref) == int(c.ref)]
            return hit[0] if hit else None
    return None


def takes(cost: np.ndarray, row: int, col: int) -> bool | None:
    """Whether the optimal assignment of ``cost`` gives ``row`` column ``col`` (None: infeasible)."""
    try:
        cols, _ = solve(cost)
    except InfeasibleAssignment:
        return None
    return int(cols[row]) == col


def d2_now(m: CostMatrix, row: int, col: int) -> float | None:
    if m.terms is None:
        return None
    k = col  # track columns come first and index the terms
    return float(np.asarray(m.terms.d2)[k, row])


def existence_now(m: CostMatrix, col: int) -> tuple[float, float] | None:
    """(r_k, P_D) of track column ``col``; None when the matrix has no existence terms."""
    t = m.terms
    if t is None or t.existence is None or t.miss_log_lik is None:
        return None
    r = float(np.asarray(t.existence)[col])
    miss = float(np.asarray(t.miss_log_lik)[col])
    return r, (-math.expm1(miss) / r if r > 0 else 0.0)


def replay_d2(m: CostMatrix, row: int, col: int, d2: float) -> bool | None:
    """Whether detection ``row`` goes to track column ``col`` with d2[col, row] set to ``d2``."""
    now = d2_now(m, row, col)
    if now is None:
        return None
    cost = np.array(m.cost, dtype=float)
    cost[row, col] += 0.5 * (d2 - now)
    return takes(cost, row, col)


def existence_nats(r: float, p_detect: float) -> float:
    return math.log1p(-r * p_detect) - math.log(r) if r > 0 and r * p_detect < 1 else math.inf


def replay_existence(m: CostMatrix, row: int, col: int, r_new: float) -> bool | None:
    """Whether detection ``row`` goes to track column ``col`` with that track's predicted existence ``r_new``."""
    now = existence_now(m, col)
    if now is None:
        return None
    r, p_detect = now
    shift = existence_nats(r_new, p_detect) - existence_nats(r, p_detect)
    if not math.isfinite(shift):
        return False
    cost = np.array(m.cost, dtype=float)
    cost[:, col] += shift
    return takes(cost, row, col)


def margin(m: CostMatrix, row: int, col: int) -> float:
    """Best total with (row, col) forbidden minus the best total (inf: no other assignment)."""
    cost = np.array(m.cost, dtype=float)
    try:
        _, best = solve(cost)
    except InfeasibleAssignment:
        return math.nan
    cost[row, col] = np.inf
    try:
        _, other = solve(cost)
    except InfeasibleAssignment:
        return math.inf
    return other - best
