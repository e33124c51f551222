"""Association the way the model-based baselines do it: solve over every pair, then reject pairs past a threshold;
and SimpleTrack's two-stage association.

Solve, then threshold (AB3DMOT, Weng et al. 2020, sec. 3.4; Probabilistic 3D MOT, Chiu et al. 2020; SimpleTrack,
Pang et al. 2021, ``mot_3d/association.py``): the solver assigns detections to tracks over the full (M, K) cost
matrix, every pair allowed; a chosen pair costing more than ``max_cost`` is then dropped, leaving its detection
and track unmatched. With the Hungarian solver this is not the same as forbidding those pairs first: the optimal
full assignment may take a pair past the threshold to free a better pair elsewhere (``tests/gnnpmb/assign/
test_matching.py`` has such a case). With the closest-pair-first greedy solver both orders give the same pairs
(pairs past the threshold come after every pair below it).

Costs may come as ``BoundedCosts``: exact where ``exact``, elsewhere a lower bound of the exact cost past every
threshold in play (such a pair is never matched), with ``resolve`` to compute the exact cost of chosen pairs.
The Hungarian solve is then certified: solve over the bounds; if the chosen assignment uses a bound, resolve
those pairs and solve again; once it uses exact costs only, no assignment can be cheaper (every cost is at
least its bound), so it is the optimal assignment of the exact matrix (up to exact ties). The box trackers use
this to skip the exact GIoU of boxes far apart (``box.cost``).

Two-stage association (SimpleTrack sec. 5.2, its "mm" redundancy mode): the first stage matches the detections
scoring at least ``first_stage_score``; each track it leaves unmatched stays alive, without a detection update,
when some detection scoring above ``second.min_score`` costs at most ``second.max_cost`` with it (any such
detection, matched or not: the second stage is a test per track, not an assignment).
"""

from __future__ import annotations

import enum
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from gnnpmb.assign.greedy import greedy_pairs
from gnnpmb.assign.lsap import linear_sum_assignment


class Solver(enum.Enum):
    """How detections are assigned to tracks over the cost matrix."""

    HUNGARIAN = "Hungarian (optimal)"
    GREEDY = "greedy, closest pair first"


@dataclass(frozen=True, slots=True)
class BoundedCosts:
    """An (R, C) finite cost matrix known exactly where ``exact`` (R, C) bool, elsewhere as a lower bound.

    resolve(rows, cols) -> (P,) the exact costs of P pairs; ``refine`` writes them into ``value`` and ``exact``
    (the arrays are updated in place: a frame's costs are refined while it is solved)."""

    value: np.ndarray
    exact: np.ndarray
    resolve: Callable[[np.ndarray, np.ndarray], np.ndarray] | None = None

    @staticmethod
    def of(matrix: np.ndarray) -> BoundedCosts:
        """A matrix known exactly everywhere."""
        return BoundedCosts(matrix, np.ones(matrix.shape, dtype=bool))

    @property
    def shape(self) -> tuple[int, int]:
        return self.value.shape

    def rows(self, index: np.ndarray) -> BoundedCosts:
        """The costs of the rows ``index`` (a copy; refining it does not refine this one)."""
        resolve = self.resolve
        if resolve is None:
            return BoundedCosts(self.value[index], self.exact[index])
        return BoundedCosts(self.value[index], self.exact[index], lambda r, c: resolve(np.asarray(index)[r], c))

    def refine(self, rows: np.ndarray, cols: np.ndarray) -> None:
        """Make the pairs (rows[p], cols[p]) exact."""
        todo = ~self.exact[rows, cols]
        if not todo.any():
            return
        if self.resolve is None:
            raise ValueError("bounded costs without a resolver")
        r, c = rows[todo], cols[todo]
        self.value[r, c] = self.resolve(r, c)
        self.exact[r, c] = True


def solve_then_threshold(cost: BoundedCosts, max_cost: float, solver: Solver) -> np.ndarray:
    """(R,) column of each row of (R, C) costs, -1 for none: the solver's one-to-one pairs over all entries,
    then every pair costing more than ``max_cost`` dropped (module docstring; bounded costs are refined until
    the Hungarian assignment is certified, or every pair the greedy solver may take is exact)."""
    n_rows, n_cols = cost.shape
    col_of_row = np.full(n_rows, -1, dtype=np.int64)
    if n_rows == 0 or n_cols == 0 or not (cost.value <= max_cost).any():  # every pair past the threshold
        return col_of_row
    if solver is Solver.HUNGARIAN:
        while True:
            rows, cols = linear_sum_assignment(cost.value)
            bounded = ~cost.exact[rows, cols]
            if not bounded.any():
                break
            cost.refine(*_next_candidates(cost, rows[bounded], cols[bounded]))
    elif solver is Solver.GREEDY:
        cost.refine(*np.nonzero(cost.value <= max_cost))
        pairs = greedy_pairs(np.where(cost.value <= max_cost, cost.value, np.inf))
        rows, cols = pairs[:, 0], pairs[:, 1]
    else:
        raise ValueError(f"unknown solver {solver!r}")
    keep = cost.value[rows, cols] <= max_cost
    col_of_row[rows[keep]] = cols[keep]
    return col_of_row


CERTIFY_ROW_PAIRS = 16
"""When a certified solve picks a bounded pair, that row's this many cheapest bounded pairs are resolved with it
(one resolution per round: fewer rounds, each about as costly)."""


def _next_candidates(cost: BoundedCosts, rows: np.ndarray, cols: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The bounded pairs (rows[p], cols[p]) the solve picked and, in each of those rows, the
    ``CERTIFY_ROW_PAIRS`` cheapest bounded pairs (the row's next candidates once its pick turns out dearer)."""
    values = np.where(cost.exact[rows], np.inf, cost.value[rows])  # (R, C): bounded pairs of those rows
    n = min(CERTIFY_ROW_PAIRS, values.shape[1])
    cheapest = np.argpartition(values, n - 1, axis=1)[:, :n]
    keep = np.isfinite(np.take_along_axis(values, cheapest, axis=1))
    r = np.concatenate([rows, np.repeat(rows, n)[keep.ravel()]])
    c = np.concatenate([cols, cheapest.ravel()[keep.ravel()]])
    return r, c


@dataclass(frozen=True, slots=True)
class SecondStage:
    """The second association stage: detections scoring above min_score keep an unmatched track alive when one
    of them costs at most max_cost with it."""

    min_score: float
    max_cost: float


@dataclass(frozen=True, slots=True)
class StageMatches:
    """One frame's association of M detections and K tracks: track_of_meas (M,) the track each detection updates
    (-1: none); first_stage (M,) bool: the detections the first stage used (the others start no track);
    kept_alive (K,) bool: tracks the second stage keeps without an update."""

    track_of_meas: np.ndarray
    first_stage: np.ndarray
    kept_alive: np.ndarray

    @property
    def meas_of_track(self) -> np.ndarray:
        """(K,) the detection updating each track, -1 for none."""
        out = np.full(len(self.kept_alive), -1, dtype=np.int64)
        j = np.flatnonzero(self.track_of_meas >= 0)
        out[self.track_of_meas[j]] = j
        return out


def two_stage_match(
    cost: BoundedCosts,
    score: np.ndarray,
    first_stage_score: float,
    max_cost: float,
    solver: Solver,
    second: SecondStage | None,
) -> StageMatches:
    """Associate M detections (scores (M,)) with K tracks over the (M, K) ``cost`` (module docstring); ``second``
    None: one stage only. Bounded costs must be exact wherever they could be within ``second.max_cost``."""
    m, k = cost.shape
    first = score >= first_stage_score
    rows = np.flatnonzero(first)
    track_of_meas = np.full(m, -1, dtype=np.int64)
    first_costs = cost if len(rows) == m else cost.rows(rows)
    track_of_meas[rows] = solve_then_threshold(first_costs, max_cost, solver)
    kept_alive = np.zeros(k, dtype=bool)
    if second is not None and m and k:
        unmatched = np.ones(k, dtype=bool)
        unmatched[track_of_meas[track_of_meas >= 0]] = False
        candidates = score > second.min_score
        cost.refine(*np.nonzero(candidates[:, None] & (cost.value <= second.max_cost)))
        kept_alive = unmatched & (cost.value[candidates] <= second.max_cost).any(axis=0)
    return StageMatches(track_of_meas, first, kept_alive)
