"""Why the solver chose an association: conflicts, chosen pairs, best alternatives and margins.

Works on the events alone (``CostMatrix`` + ``Assignment`` of one class and frame), for every tracker whose
matrix has the shared layout: rows are measurements, columns are existing tracks followed by one new-track
column per measurement; every row is assigned to exactly one column, a track column at most once, and a track
whose column is unused is missed (cost 0, the reference the PMB costs are relative to).

A *conflict* is a connected group of tracks and measurements linked through *competitive* pairs: a pair links
when its cost is at most ``LINK_SLACK`` above the measurement's own new-track cost. A pair costlier than that
never appears in an assignment within ``LINK_SLACK`` of the best one (swapping that measurement to its own,
always free, new-track column is cheaper by more than the slack), so the conflicts are exact for every decision
closer than the slack, and stay small even when wide gates of low-existence candidates overlap everything.
For every chosen pair the *margin* is how much the best assignment of the conflict gets worse when that pair is
forbidden (re-solved with the Hungarian algorithm), capped at ``LINK_SLACK``: a margin near 0 is a close call,
the usual cause of an ID switch. A greedy matcher's choices are not a best total (``CostScale.optimal`` False):
its margin is the detection's next cheapest column that no other detection took minus its chosen one (a cheaper
column another detection took was not there to take). What counts as close is the matrix's own
``CostScale.close_call`` (nats, metres, ...). A box tracker's Hungarian runs over every pair and then drops the
pairs past its threshold (``assign.matching.solve_then_threshold``), while the matrix it reports holds those
pairs as +inf: its choice can then cost more than the best assignment of the matrix (a choice *undercut*: the
cheaper column went, in the solve, to a detection whose pair was then dropped). Such a choice is no close call,
and its margin (clipped at 0) says nothing; the other choices' margins are then measured from the conflict's best
total, not from the dearer chosen one.
"""

from __future__ import annotations

import math
import operator
from dataclasses import dataclass

import numpy as np

from gnnpmb.assign.hungarian import InfeasibleAssignment, solve
from gnnpmb.events import NATS, Assignment, AxisKind, AxisLabel, CostMatrix, CostScale, CostTerms, PairTerms

_KIND = operator.attrgetter("kind")
_REF = operator.attrgetter("ref")
LINK_SLACK = 5.0
"""Pairs costlier than the measurement's new-track cost plus this do not link a conflict; margins are capped at
it (in cost units: nats for the PMB family)."""
UNDERCUT_TOL = 1e-9
"""How far below the chosen total a best total without the pair must lie for the choice to count as undercut
(rounding in the solver's sums is far below it)."""


@dataclass(frozen=True, slots=True)
class PairChoice:
    """One measurement's decision: the chosen column and its cost; the row's cheapest other column
    (None if it had no other) and its cost; margin = best total without this pair minus the chosen total
    (inf when no other assignment is possible); undercut: the best total without this pair is lower than the
    chosen total (module docstring: the solver ran before a threshold dropped pairs). terms: the matrix's
    ``CostTerms`` (None if it has none), read at this row (``row``) and the chosen / alternative columns
    (``chosen_col``, ``alternative_col``; -1: none) by ``chosen_terms`` and ``alternative_terms``, only when
    asked."""

    meas: AxisLabel
    chosen: AxisLabel
    chosen_cost: float
    alternative: AxisLabel | None
    alternative_cost: float
    margin: float
    terms: CostTerms | None = None
    row: int = -1
    chosen_col: int = -1
    alternative_col: int = -1
    scale: CostScale = NATS
    undercut: bool = False

    @property
    def close_call(self) -> bool:
        """Whether another column came within the matrix's close-call margin (``CostScale.close_call``); an
        undercut choice is not one (module docstring)."""
        return self.alternative is not None and self.margin < self.scale.close_call and not self.undercut

    @property
    def chosen_terms(self) -> PairTerms | None:
        """What the chosen cost is made of, if the chosen column is a track and the matrix says."""
        return self._terms(self.chosen, self.chosen_col)

    @property
    def alternative_terms(self) -> PairTerms | None:
        """What the alternative's cost is made of, if it is a track and the matrix says."""
        return self._terms(self.alternative, self.alternative_col)

    def _terms(self, label: AxisLabel | None, col: int) -> PairTerms | None:
        if self.terms is None or label is None or label.kind is not AxisKind.TRACK or col < 0 or self.row < 0:
            return None
        return self.terms.pair(self.row, col)


@dataclass(frozen=True, slots=True)
class Conflict:
    """Tracks and measurements linked through their gates, with the decisions taken inside.

    track_ids / meas_indices: the members; choices: one per measurement (in row order); missed_track_ids:
    member tracks given no measurement; total_cost: the chosen assignment's cost over the conflict.
    """

    class_name: str
    track_ids: tuple[int, ...]
    meas_indices: tuple[int, ...]
    choices: tuple[PairChoice, ...]
    missed_track_ids: tuple[int, ...]
    total_cost: float
    scale: CostScale = NATS

    @property
    def close_call(self) -> bool:
        """Whether one of its choices was a close call (``PairChoice.close_call``)."""
        return any(c.close_call for c in self.choices)

    @property
    def closest_margin(self) -> float:
        """The smallest margin of any choice (inf for a conflict without alternatives)."""
        return min((c.margin for c in self.choices), default=math.inf)

    def involves(self, track_ids: set[int] = frozenset(), meas_indices: set[int] = frozenset()) -> bool:
        return bool(track_ids & set(self.track_ids)) or bool(meas_indices & set(self.meas_indices))


@dataclass(frozen=True, slots=True)
class Decisions:
    """The conflicts of one class and frame (those with at least one track), closest call first, and the
    measurements that could only start a new track (no track's gate held them)."""

    class_name: str
    conflicts: tuple[Conflict, ...]
    births_only: tuple[int, ...]
    description: str
    scale: CostScale = NATS


def _competitive(cost: np.ndarray, n_tracks: int) -> np.ndarray:
    """(R, C) bool: finite entries, track columns only where within LINK_SLACK of the row's new-track cost."""
    finite = np.isfinite(cost)
    if cost.shape[0] == 0:
        return finite
    birth = cost[np.arange(cost.shape[0]), n_tracks + np.arange(cost.shape[0])]
    tracks = finite[:, :n_tracks] & (cost[:, :n_tracks] <= birth[:, None] + LINK_SLACK)
    return np.concatenate([tracks, finite[:, n_tracks:]], axis=1)


def _components(finite: np.ndarray, n_tracks: int) -> list[tuple[np.ndarray, np.ndarray]]:
    """Connected components of the bipartite gate graph: (rows, track columns) per component with at least
    one track and one measurement.

    finite: (R, C) bool; only the first n_tracks columns link rows (new-track columns belong to one row).
    Min-label propagation (each row starts as its own label; rows and columns take the smallest label they are
    linked to until nothing changes): vectorised, and cheaper than a sparse-graph call on these small matrices.
    """
    link = finite[:, :n_tracks]
    n_rows = link.shape[0]
    if n_rows == 0 or n_tracks == 0:
        return []
    none = n_rows  # larger than every row label
    row_label = np.arange(n_rows)
    while True:
        col_label = np.where(link, row_label[:, None], none).min(axis=0)
        new = np.minimum(row_label, np.where(link, col_label[None, :], none).min(axis=1))
        if np.array_equal(new, row_label):
            break
        row_label = new
    rows_of: dict[int, list[int]] = {}
    for i, label in enumerate(row_label.tolist()):
        rows_of.setdefault(label, []).append(i)
    cols_of: dict[int, list[int]] = {}
    linked = np.flatnonzero(col_label < none).tolist()
    for j, label in zip(linked, col_label[linked].tolist(), strict=True):
        cols_of.setdefault(label, []).append(j)
    return [
        (np.array(rows_of[label], dtype=np.intp), np.array(cols_of[label], dtype=np.intp)) for label in sorted(cols_of)
    ]


def explain(matrix: CostMatrix, assignment: Assignment) -> Decisions | None:
    """The decisions behind ``assignment`` on ``matrix`` (same class, hypothesis and frame).

    Returns None when the matrix does not have the shared layout or the assignment names a column the matrix
    does not have (e.g. a PMBM child of a prior hypothesis other than the matrix's).
    """
    cost = np.asarray(matrix.cost, dtype=np.float64)
    n_rows = cost.shape[0] if cost.ndim == 2 else 0
    col_kinds = list(map(_KIND, matrix.cols))
    n_tracks = col_kinds.count(AxisKind.TRACK)
    if (
        cost.ndim != 2
        or col_kinds[n_tracks:].count(AxisKind.NEW_TRACK) != len(col_kinds) - n_tracks  # tracks first, then births
        or any(r.kind is not AxisKind.MEASUREMENT for r in matrix.rows)
    ):
        return None
    # Index by ref, one map per kind: hashing AxisLabels (dataclasses holding an enum, whose hash is Python code)
    # costs more than the rest.
    row_of = dict(zip(map(_REF, matrix.rows), range(len(matrix.rows)), strict=True))
    track_col_of = dict(zip(map(_REF, matrix.cols[:n_tracks]), range(n_tracks), strict=True))
    new_col_of = dict(zip(map(_REF, matrix.cols[n_tracks:]), range(n_tracks, len(matrix.cols)), strict=True))
    chosen = np.full(n_rows, -1, dtype=np.int64)
    for row_label, col_label in assignment.pairs:
        if col_label.kind is AxisKind.TRACK:
            cols_of_kind = track_col_of
        elif col_label.kind is AxisKind.NEW_TRACK:
            cols_of_kind = new_col_of
        else:
            return None
        if row_label.kind is not AxisKind.MEASUREMENT or row_label.ref not in row_of:
            return None
        if col_label.ref not in cols_of_kind:
            return None
        chosen[row_of[row_label.ref]] = cols_of_kind[col_label.ref]
    if n_rows and (chosen < 0).any():
        return None
    if cost.shape[1] != n_tracks + n_rows:
        return None
    finite = _competitive(cost, n_tracks)
    finite[np.arange(n_rows), chosen] = np.isfinite(cost[np.arange(n_rows), chosen])  # whatever was chosen links
    conflicts = []
    in_conflict = np.zeros(n_rows, dtype=bool)
    components = _components(finite, n_tracks)
    linked = np.where(finite, cost, np.inf) if components else cost
    for rows, tcols in components:
        in_conflict[rows] = True
        conflicts.append(_conflict(matrix, linked, chosen, rows, tcols, n_tracks))
    conflicts.sort(key=lambda c: (c.closest_margin, c.track_ids))
    births = tuple(int(matrix.rows[i].ref) for i in np.flatnonzero(~in_conflict).tolist())
    return Decisions(matrix.class_name, tuple(conflicts), births, matrix.description, matrix.scale)


def _conflict(
    matrix: CostMatrix, cost: np.ndarray, chosen: np.ndarray, rows: np.ndarray, tcols: np.ndarray, n_tracks: int
) -> Conflict:
    """Decisions of one component: its sub-matrix is [its track columns | its rows' new-track columns].

    Every row's chosen column is in the sub-matrix: a chosen track column links its row to the component, and a
    row's own new-track column is always there. The cheapest other column of each row is found for all rows at
    once (first minimum, as ``argmin``); a one-row component, the usual case, is done in plain Python (NumPy's
    per-call overhead dominates on a handful of entries)."""
    if rows.size == 1:
        r = int(rows[0])
        cols_list = [*tcols.tolist(), n_tracks + r]
        sub_row = cost[r, cols_list].tolist()
        c = int(chosen[r])
        j = cols_list.index(c) if c in cols_list else -1
        others = [math.inf if k == j else v for k, v in enumerate(sub_row)]
        k = min(range(len(others)), key=others.__getitem__)  # the first minimum, as argmin
        chosen_list, best_list = [j], [k]
        chosen_costs, best_costs = [sub_row[j]], [others[k]]
        total = sub_row[j]
        rest = others if j >= 0 else sub_row[:-1]  # the row without its chosen entry (as np.delete(row, j))
        bests = [min(rest) if len(sub_row) > 1 else math.inf]
    else:
        cols = np.concatenate([tcols, n_tracks + rows])
        sub = cost[np.ix_(rows, cols)]
        position = {c: k for k, c in enumerate(cols.tolist())}
        chosen_sub = np.array([position.get(c, -1) for c in chosen[rows].tolist()], dtype=np.int64)
        at = np.arange(rows.size)
        chosen_cost = sub[at, chosen_sub]
        total = float(chosen_cost.sum())
        masked = sub.copy()
        kept = chosen_sub >= 0
        masked[at[kept], chosen_sub[kept]] = np.inf
        if not matrix.scale.optimal:  # a greedy matcher's alternatives: only the columns no other detection took
            masked[:, chosen_sub[kept]] = np.inf
        best = np.argmin(masked, axis=1)
        cols_list, chosen_list, best_list = cols.tolist(), chosen_sub.tolist(), best.tolist()
        chosen_costs, best_costs = chosen_cost.tolist(), masked[at, best].tolist()
        if matrix.scale.optimal:
            bests = [_best_without(sub, i, j) for i, j in enumerate(chosen_list)]
        else:  # a greedy matcher: the row's next cheapest free entry against its chosen one
            bests = masked[at, best].tolist()
    # what each margin is measured from: the conflict's total (an optimal solver), the row's own cost (greedy)
    froms = [total] * len(bests) if matrix.scale.optimal or rows.size == 1 else chosen_costs
    # only a solve over every pair before a threshold leaves a choice dearer than the reported matrix's best
    # (a Murty hypothesis other than the best, PMBM's, is another matter and keeps its clipped margin)
    solved_before_threshold = matrix.scale.optimal and matrix.scale.threshold is not None
    # and there a margin is measured from the conflict's best total, which the chosen one can exceed (dev set
    # scene-0916 pointpillars immortal frame 10: chosen 0.079 above it, so "margin 0.87" where re-solving gives 0.94)
    optimum = _best_total(sub) if solved_before_threshold and rows.size > 1 else math.inf
    margin_froms = [min(base, optimum) for base in froms]
    mrows, mcols = matrix.rows, matrix.cols
    choices = []
    for r, j, k, c_chosen, c_best, b, base, margin_from in zip(
        rows.tolist(), chosen_list, best_list, chosen_costs, best_costs, bests, froms, margin_froms, strict=True
    ):
        has_alt = math.isfinite(c_best)
        choices.append(
            PairChoice(
                meas=mrows[r],
                chosen=mcols[cols_list[j]],
                chosen_cost=c_chosen,
                alternative=mcols[cols_list[k]] if has_alt else None,
                alternative_cost=c_best if has_alt else math.inf,
                margin=_capped(b, margin_from),
                terms=matrix.terms,
                row=r,
                chosen_col=cols_list[j],
                alternative_col=cols_list[k] if has_alt else -1,
                scale=matrix.scale,
                undercut=solved_before_threshold and b < base - UNDERCUT_TOL,
            )
        )
    used = {cols_list[j] for j in chosen_list if cols_list[j] < n_tracks}
    track_refs = tuple(int(mcols[c].ref) for c in tcols.tolist())
    missed = tuple(ref for c, ref in zip(tcols.tolist(), track_refs, strict=True) if c not in used)
    return Conflict(
        matrix.class_name,
        track_refs,
        tuple(int(mrows[r].ref) for r in rows.tolist()),
        tuple(choices),
        missed,
        total,
        matrix.scale,
    )


def _capped(best: float, total: float) -> float:
    """``best - total`` clipped to [0, LINK_SLACK]; inf when ``best`` is not finite (no other assignment)."""
    return math.inf if not math.isfinite(best) else min(max(best - total, 0.0), LINK_SLACK)


def _margin(sub: np.ndarray, i: int, j: int, total: float) -> float:
    """Best total of ``sub`` with entry (i, j) forbidden, minus ``total``, clipped (``_capped``)."""
    return _capped(_best_without(sub, i, j), total)


def _best_total(sub: np.ndarray) -> float:
    """Best total of ``sub`` (inf if infeasible)."""
    try:
        _, best = solve(sub)
    except InfeasibleAssignment:
        return math.inf
    return float(best)


def _best_without(sub: np.ndarray, i: int, j: int) -> float:
    """Best total of ``sub`` with entry (i, j) forbidden (inf if then infeasible). A one-row ``sub`` (one
    detection) needs no solver: its best total is its cheapest other entry."""
    if sub.shape[0] == 1:
        return float(np.min(np.delete(sub[0], j))) if sub.shape[1] > 1 else math.inf
    forbidden = sub.copy()
    forbidden[i, j] = np.inf
    return _best_total(forbidden)
