"""What one change of a track's cost would have made the solver do, found by re-solving the frame's matrix.

A sentence "within d² X, track T would have taken m" or "with a predicted existence above X, ..." is a claim about
the solver, so it is only said when re-solving the matrix with that change gives m to T. Changes, on the costs of
``events.CostTerms`` (C[j, k] = ... + d2[k, j] / 2 + log(1 - r_k P_D) - log r_k):

* d²: entry (j, k) moves by (X - d2[k, j]) / 2;
* existence: every entry of column k moves by the change of log(1 - r P_D) - log r from r_k to X.

The break-even is found by bisection with the optimal solver (``assign.hungarian``: the PMB family's and GNN's);
the value stated is rounded to the safe side (d² down to 0.1, existence up to 0.01, as ``words`` prints them;
more decimals where the current value would print the same) and checked once more. The rival's other detection
(the one the assignment gave it, if any) is part of the re-solve.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from gnnpmb.assign.hungarian import InfeasibleAssignment, solve
from gnnpmb.events import Assignment, AxisKind, CostMatrix

BISECTIONS = 40


@dataclass(frozen=True, slots=True)
class WouldTake:
    """Track ``track`` and detection ``meas`` at one frame: kind "d2" or "existence"; now: its current value;
    needed: the value from which the re-solved assignment gives it the detection, rounded to the safe side (None:
    no value does; a break-even two decimals cannot state safely gives no ``WouldTake`` at all); taken_by: the
    detection the assignment gave the track instead (None: none); digits: the decimals that tell needed from now
    apart (a near tie needs more than the usual one for d², two for an existence)."""

    track: int
    meas: int
    kind: str
    now: float
    needed: float | None
    taken_by: int | None
    digits: int = 1


def _takes(cost: np.ndarray, row: int, col: int) -> bool:
    try:
        cols, _ = solve(cost)
    except InfeasibleAssignment:
        return False
    return int(cols[row]) == col


def _existence_nats(r: float, p_detect: float) -> float:
    return math.log1p(-r * p_detect) - math.log(r)


def would_take(matrix: CostMatrix, assignment: Assignment, meas: int, track: int) -> WouldTake | None:
    """The change that would have given ``meas`` to ``track`` (module docstring); None when the matrix has no
    terms, is not solved optimally, lacks either, or already gives ``meas`` to ``track``."""
    t = matrix.terms
    if t is None or not matrix.scale.optimal:
        return None
    rows = [i for i, r in enumerate(matrix.rows) if r.kind is AxisKind.MEASUREMENT and int(r.ref) == meas]
    cols = [k for k, c in enumerate(matrix.cols) if c.kind is AxisKind.TRACK and int(c.ref) == track]
    if not rows or not cols:
        return None
    row, col = rows[0], cols[0]
    cost = np.array(matrix.cost, dtype=float)
    if not math.isfinite(cost[row, col]) or _takes(cost, row, col):
        return None
    taken_by = next((int(r.ref) for r, c in assignment.pairs if c.kind is AxisKind.TRACK and int(c.ref) == track), None)
    if taken_by == meas:
        return None
    if t.existence is not None and t.miss_log_lik is not None:
        return _by_existence(cost, row, col, t, meas, track, taken_by)
    return _by_d2(cost, row, col, float(np.asarray(t.d2)[col, row]), meas, track, taken_by)


def _by_d2(
    cost: np.ndarray, row: int, col: int, d2: float, meas: int, track: int, taken_by: int | None
) -> WouldTake | None:
    def at(x: float) -> bool:
        c = cost.copy()
        c[row, col] += 0.5 * (x - d2)
        return _takes(c, row, col)

    if not at(0.0):
        return WouldTake(track, meas, "d2", d2, None, taken_by)
    lo, hi = 0.0, d2  # taken at lo, not at hi
    for _ in range(BISECTIONS):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if at(mid) else (lo, mid)
    for digits in (1, 2, 3, 4):
        scale = 10.0**digits
        stated = math.floor(lo * scale) / scale
        if f"{stated:.{digits}f}" != f"{d2:.{digits}f}":
            break
    return WouldTake(track, meas, "d2", d2, stated, taken_by, digits) if at(stated) else None


def _by_existence(
    cost: np.ndarray, row: int, col: int, t, meas: int, track: int, taken_by: int | None
) -> WouldTake | None:
    r = float(np.asarray(t.existence)[col])
    p_detect = -math.expm1(float(np.asarray(t.miss_log_lik)[col])) / r if r > 0 else 0.0
    now = _existence_nats(r, p_detect) if r > 0 else math.inf

    def at(x: float) -> bool:
        if x >= 1.0 / max(p_detect, 1e-300) or not math.isfinite(now):
            return False
        c = cost.copy()
        c[:, col] += _existence_nats(x, p_detect) - now
        return _takes(c, row, col)

    top = min(1.0, 1.0 / p_detect - 1e-9) if p_detect > 0 else 1.0
    if not at(top):
        return WouldTake(track, meas, "existence", r, None, taken_by)
    lo, hi = r, top  # not taken at lo, taken at hi
    for _ in range(BISECTIONS):
        mid = 0.5 * (lo + hi)
        lo, hi = (lo, mid) if at(mid) else (mid, hi)
    for digits in (2, 3, 4):
        scale = 10.0**digits
        stated = math.ceil(hi * scale) / scale
        if f"{stated:.{digits}f}" != f"{r:.{digits}f}":
            break
    if stated <= r or stated >= 1.0 or not at(stated * (1.0 + 1e-6)):
        return None  # no value with that many decimals states it: say nothing
    return WouldTake(track, meas, "existence", r, stated, taken_by, digits)
