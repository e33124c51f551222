"""The k best 2D assignments by Murty's partitioning, on independent blocks of the cost matrix.

An assignment maps every row of an (R, C) cost matrix, R <= C, to a distinct column; +inf marks a forbidden
pair. Murty (1968), "An algorithm for ranking all the assignments in order of increasing cost", Operations
Research 16(3): the solution space minus the best solution a of a subproblem splits into disjoint subproblems
P_q, q = p .. R-1 (rows < p already pinned): rows < q keep their columns in a, row q may not take a(q). Each
subproblem's best solution is found with scipy's Hungarian / Jonker-Volgenant solver and kept in a priority
queue; the next best solution overall is the queue's minimum.

Speed-ups in the spirit of Miller, Stone & Cox (1997), "Optimizing Murty's ranked assignment method", IEEE
T-AES 33(3): rows pinned by the partition and their columns are removed from the subproblem, a subproblem
whose constrained row has no allowed column is skipped unsolved, a single free row is solved by argmin, a
subproblem is solved only when a lower bound on its cost reaches the front of the queue, and solutions are ranked
lazily, only as deep as asked. Above all, gating makes tracking matrices block diagonal:
rows and columns joined by finite entries form independent blocks (``blocks``), an assignment is one solution
per block and its cost the sum, so the ranked assignments are the smallest sums over per-block rankings
(``Product``, a lazy heap over index tuples). A block is ranked by ``Murty``, or, when its candidate
assignments are few, by listing them all at once (``Enumerated``). ``Ranking`` objects can be shared between
problems that contain the same block (PMBM global hypotheses share most of theirs, ``pmb.pmbm``).

A ranking may be limited to assignments costing at most ``max_increase`` more than the best one (PMBM drops
such hypotheses anyway). Then an entry (i, j) is forbidden before splitting into blocks, which keeps blocks
small, when a lower bound on the cost of any assignment using it already exceeds that: c_ij + sum_{i' != i}
min_j' c_i'j', or the best cost + c_ij - c_ip for a column p that only row i may use
(``forbid_beyond_private``).
"""

from __future__ import annotations

import heapq
import itertools
import math
from dataclasses import dataclass
from typing import Protocol

import numpy as np

from gnnpmb.assign.clusters import Cluster, gate_clusters
from gnnpmb.assign.hungarian import InfeasibleAssignment, solve
from gnnpmb.assign.lsap import linear_sum_assignment

ENUMERATION_LIMIT = 1024
"""A block whose rows' allowed-column counts multiply to at most this is ranked by listing its candidate
assignments at once (a few vectorised steps) instead of by Murty's method."""


class Ranking(Protocol):
    """Assignments of one problem in increasing cost, computed on demand."""

    def solution(self, index: int) -> tuple[np.ndarray, float] | None:
        """The index-th cheapest assignment (col_of_row, cost), or None if there are fewer. Do not modify."""
        ...


def k_best(cost: np.ndarray, k: int, max_increase: float = math.inf) -> list[tuple[np.ndarray, float]]:
    """The k lowest-cost assignments of an (R, C) cost matrix (R <= C, +inf forbidden), cheapest first.

    Returns up to k pairs (col_of_row (R,) int64, total cost); fewer when fewer feasible assignments exist (or
    cost at most ``max_increase`` more than the best), none when no assignment avoids the forbidden entries
    (or R > C). Equal-cost assignments come in a deterministic order. The first is exactly
    ``hungarian.solve(cost)`` (its restriction to every block is optimal there), so a k-best user with k = 1
    behaves like the single-best user.
    """
    cost = np.asarray(cost, dtype=float)
    if cost.ndim != 2:
        raise ValueError(f"cost must be a 2D matrix, got shape {cost.shape}")
    if np.isnan(cost).any() or np.isneginf(cost).any():
        raise ValueError("cost may contain finite values and +inf only")
    n_rows, n_cols = cost.shape
    if k <= 0 or n_rows > n_cols:
        return []
    try:
        first, first_total = solve(cost)
    except InfeasibleAssignment:
        return []
    out = [(first, first_total)]
    if k == 1 or n_rows == 0:
        return out
    ranking = rank(cost, first, max_increase)
    arange = np.arange(n_rows)
    for index in range(1, k):
        found = ranking.solution(index)
        if found is None:
            break
        out.append((found[0].copy(), float(cost[arange, found[0]].sum())))
    return out


BlockCache = dict[tuple[tuple[int, ...], bytes, bytes | None, float], "Ranking"]
"""Block rankings by (shape, cost bytes, root bytes, max_increase): a ranking depends on nothing else."""


def rank(
    cost: np.ndarray,
    first: np.ndarray | None = None,
    max_increase: float = math.inf,
    cache: BlockCache | None = None,
) -> Ranking:
    """Lazy ranking of the assignments of ``cost`` (R <= C rows, +inf forbidden) that cost at most
    ``max_increase`` more than the best, split into blocks unless small.

    ``first``: a best assignment to start from (else found here). ``cache``: rankings of blocks met before,
    reused for a block with equal costs and root (and filled). Raises ``InfeasibleAssignment`` when no
    assignment exists.
    """
    n_rows = cost.shape[0]
    if n_rows == 0:
        return Product(np.zeros(0, dtype=np.int64), [], max_increase)
    counts = np.count_nonzero(cost < np.inf, axis=1)
    if float(np.prod(counts, dtype=float)) <= ENUMERATION_LIMIT:
        return _block_ranking(cost, first, max_increase, cache)
    if max_increase < math.inf:
        if first is None:
            first, _ = solve(cost)
        cost = _forbid_hopeless(forbid_beyond_private(cost, max_increase), first, max_increase)
        counts = np.count_nonzero(cost < np.inf, axis=1)
        if float(np.prod(counts, dtype=float)) <= ENUMERATION_LIMIT:
            return _block_ranking(cost, first, max_increase, cache)
    parts: list[tuple[np.ndarray, np.ndarray, Ranking]] = []
    base = np.empty(n_rows, dtype=np.int64)
    local_of_col = np.full(cost.shape[1], -1, dtype=np.int64)
    for rows, cols in blocks(cost):
        if len(rows) == 1:  # a one-row block (the most common): ``block_ranking``'s SingleRow, without a copy
            if not len(cols):
                raise InfeasibleAssignment("a row has no allowed column")
            row = cost[rows[0], cols]
            at = int(np.argmin(row)) if first is None else int(np.searchsorted(cols, first[rows[0]]))
            ranking: Ranking = SingleRow(row, at, max_increase)
            base[rows[0]] = cols[at]
        else:
            root = None
            if first is not None:
                local_of_col[cols] = np.arange(len(cols))
                root = local_of_col[first[rows]]
            candidates = float(np.prod(counts[rows], dtype=float))  # its columns are all its rows' allowed ones
            ranking = _block_ranking(cost[rows[:, None], cols], root, max_increase, cache, candidates)
            base[rows] = cols[ranking.solution(0)[0]]
        parts.append((rows, cols, ranking))
    return Product(base, parts, max_increase)


def _block_ranking(
    cost: np.ndarray,
    root: np.ndarray | None,
    max_increase: float,
    cache: BlockCache | None,
    candidates: float | None = None,
) -> Ranking:
    """``block_ranking``, looked up in and added to ``cache`` if given."""
    if cache is None:
        return block_ranking(cost, root, max_increase, candidates)
    key = (cost.shape, cost.tobytes(), None if root is None else root.tobytes(), max_increase)
    ranking = cache.get(key)
    if ranking is None:
        ranking = cache[key] = block_ranking(cost, root, max_increase, candidates)
    return ranking


def block_ranking(
    cost: np.ndarray, root: np.ndarray | None = None, max_increase: float = math.inf, candidates: float | None = None
) -> Ranking:
    """Ranking of one block (not split): a sorted row for a single row, enumeration when small, else Murty;
    only assignments at most ``max_increase`` costlier than the best. ``root``: a best assignment to rank
    first (else found here); ``candidates``: ``_candidates(cost)`` if known. Raises ``InfeasibleAssignment``."""
    n_rows = cost.shape[0]
    if n_rows == 1:
        if not np.isfinite(cost[0]).any():
            raise InfeasibleAssignment("the only row has no allowed column")
        return SingleRow(cost[0], int(np.argmin(cost[0]) if root is None else root[0]), max_increase)
    if (_candidates(cost) if candidates is None else candidates) <= ENUMERATION_LIMIT:
        return Enumerated(cost, root, max_increase)
    return Murty(cost, solve(cost)[0] if root is None else root, max_increase)


def _candidates(cost: np.ndarray) -> float:
    """Product over rows of the number of allowed columns: an upper bound on the number of assignments."""
    return float(np.prod(np.count_nonzero(cost < np.inf, axis=1), dtype=float))


def forbid_beyond_private(cost: np.ndarray, max_increase: float, usable: np.ndarray | None = None) -> np.ndarray:
    """``cost`` with +inf at every (i, j) with c_ij > c_ip + ``max_increase`` for a column p that only row i
    may use (a private column, like a PMB new-track column). Moving row i to p keeps any assignment feasible,
    so one using (i, j) costs more than ``max_increase`` above the best; the best assignment keeps its
    entries. ``usable``: (C,) bool, the columns that may serve as p (for matrices that later lose columns:
    only those that stay), default all."""
    finite = cost < np.inf
    private = finite & (np.count_nonzero(finite, axis=0) == 1)
    if usable is not None:
        private &= usable
    private_min = np.where(private, cost, np.inf).min(axis=1)
    return np.where(cost <= (private_min + max_increase)[:, None], cost, np.inf)


def _forbid_hopeless(cost: np.ndarray, best: np.ndarray, max_increase: float) -> np.ndarray:
    """``cost`` with +inf at every (i, j) that no assignment within ``max_increase`` of the best one
    (``best``) can use: c_ij + sum_{i' != i} min_j' c_i'j' > cost(best) + max_increase. The best assignment
    stays."""
    row_min = cost.min(axis=1)
    allowed = float(cost[np.arange(cost.shape[0]), best].sum()) + max_increase - (row_min.sum() - row_min)
    return np.where(cost <= allowed[:, None], cost, np.inf)


def blocks(cost: np.ndarray) -> list[Cluster]:
    """(rows, cols) of every connected block of finite entries of ``cost`` (``assign.clusters.gate_clusters``),
    ordered by their first row; a row without a finite entry is a block of its own, a column without one is in
    no block."""
    return gate_clusters(cost < np.inf, with_isolated_tracks=True)


class SingleRow:
    """Ranking of a one-row problem: its finite entries, ``root`` first, then by cost (stable). The entries
    are sorted when a second solution is first asked for (most one-row blocks of PMBM only give their best)."""

    def __init__(self, cost_row: np.ndarray, root: int, max_increase: float = math.inf):
        self._row = cost_row
        self._max_increase = max_increase
        self._best = np.array([root], dtype=np.int64), float(cost_row[root])
        self._cols: np.ndarray | None = None
        self._costs: np.ndarray | None = None

    def solution(self, index: int) -> tuple[np.ndarray, float] | None:
        if index == 0:
            return self._best
        if self._cols is None or self._costs is None:
            cost_row, root = self._row, int(self._best[0][0])
            order = np.argsort(cost_row, kind="stable")
            keep = (cost_row[order] < np.inf) & (cost_row[order] <= cost_row[root] + self._max_increase)
            self._cols = np.concatenate([[root], order[keep & (order != root)]]).astype(np.int64)
            self._costs = cost_row[self._cols]
        if index >= len(self._cols):
            return None
        return self._cols[index : index + 1], float(self._costs[index])


def enumerate_assignments(allowed: np.ndarray) -> np.ndarray:
    """(N, R) every assignment of the R rows of ``allowed`` ((R, C) bool) to distinct allowed columns, in
    lexicographic order of their columns. Up to ``SMALL_PRODUCT`` candidates are combined in Python (fewer
    calls); more with NumPy in a fixed number of calls: every index tuple of the rows' allowed columns in C order
    (``np.indices``, lexicographic), mapped to columns, keeping those whose sorted columns are distinct."""
    n_rows, n_cols = allowed.shape
    rows, cols = np.divmod(np.flatnonzero(allowed), max(n_cols, 1))
    counts = np.bincount(rows, minlength=n_rows)
    if n_rows == 0 or math.prod(counts.tolist()) <= SMALL_PRODUCT:
        bounds = np.concatenate([[0], np.cumsum(counts)]).tolist()
        flat = cols.tolist()
        row_cols = [flat[start:stop] for start, stop in zip(bounds[:-1], bounds[1:], strict=True)]
        listed = [c for c in itertools.product(*row_cols) if len(set(c)) == n_rows]
        return np.array(listed, dtype=np.int64).reshape(len(listed), n_rows)
    table = np.zeros((n_rows, int(counts.max())), dtype=np.int64)
    table[rows, np.arange(len(rows)) - np.repeat(np.cumsum(counts) - counts, counts)] = cols
    combos = table[np.arange(n_rows)[:, None], np.indices(counts.tolist()).reshape(n_rows, -1)].T
    ordered = np.sort(combos, axis=1)
    return np.ascontiguousarray(combos[(ordered[:, 1:] != ordered[:, :-1]).all(axis=1)])


SMALL_PRODUCT = 32
"""``enumerate_assignments`` combines at most this many candidates in Python, more with NumPy (measured on
this machine: 16 vs 36 us for 12 candidates of 2 rows; NumPy is faster from about 100)."""


class Enumerated:
    """Ranking of a small block by listing every assignment (``enumerate_assignments``, or ``combos`` if
    already listed in that order), sorted by cost (stable); ``root``, if given, comes first.

    Work is done on demand: with a ``root``, nothing is listed until a second solution is asked for (the root's
    cost is summed as one row of the listing's cost array); without, the costs are listed and the best is the
    first cheapest (as the stable sort puts it); the rest are sorted when first asked for. ``listed``: the
    listing (N, R) and its costs (N,), already worked out (``subset_rankings``).
    """

    def __init__(
        self,
        cost: np.ndarray,
        root: np.ndarray | None = None,
        max_increase: float = math.inf,
        combos: np.ndarray | None = None,
        listed: tuple[np.ndarray, np.ndarray] | None = None,
    ):
        self._cost = cost
        self._root = root
        self._max_increase = max_increase
        self._listed: np.ndarray | None = None
        self._listed_costs: np.ndarray | None = None
        self._combos: np.ndarray | None = None
        self._costs: np.ndarray | None = None
        if listed is not None:
            self._listed, self._listed_costs = listed
        if root is not None and combos is None:
            self._best = root, float(cost[np.arange(cost.shape[0]), root[None, :]].sum(axis=1)[0])
            return
        listed, costs = self._list(combos)
        at = int(np.argmin(costs) if root is None else np.flatnonzero((listed == root).all(axis=1))[0])
        self._best = listed[at], float(costs[at])

    def _list(self, combos: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
        """Every assignment (N, R) and its cost (N,); raises ``InfeasibleAssignment`` if there is none."""
        if self._listed is None or self._listed_costs is None:
            if combos is None:
                combos = enumerate_assignments(self._cost < np.inf)
            if len(combos) == 0:
                raise InfeasibleAssignment("no assignment avoids the forbidden entries")
            self._listed = combos
            self._listed_costs = self._cost[np.arange(self._cost.shape[0]), combos].sum(axis=1)
        return self._listed, self._listed_costs

    def solution(self, index: int) -> tuple[np.ndarray, float] | None:
        if index == 0:
            return self._best
        if self._combos is None or self._costs is None:
            self._sort()
        if index >= len(self._combos):
            return None
        return self._combos[index], float(self._costs[index])

    def _sort(self) -> None:
        combos, costs = self._list()
        order = np.argsort(costs, kind="stable")
        if self._root is not None:
            at = np.flatnonzero((combos[order] == self._root).all(axis=1))[0]
            order = np.concatenate([order[at : at + 1], order[:at], order[at + 1 :]])
        order = order[costs[order] <= costs[order[0]] + self._max_increase]
        self._combos = combos[order]
        self._costs = costs[order]


class ColumnSubsets:
    """Rankings of the sub-problems of one (R, C) block that keep only some of its columns (PMBM: a gated block
    of the union of all hypotheses' Bernoullis, cut to the Bernoullis one hypothesis holds).

    ``rank(present)`` gives the ranking ``rank(cost[:, present], max_increase=max_increase)`` gives, solution
    for solution. Small sub-problems are listed on their own (``Enumerated``), several at once side by side
    (``subset_rankings``; filtering one listing of the whole block per subset was measured slower, since the
    block's listing is much longer than a subset's). Larger ones are split by ``rank`` into blocks, most of them
    the same for many subsets: ``cache`` (shared, e.g. by every block of a PMBM frame) ranks each distinct one
    once.
    """

    def __init__(self, cost: np.ndarray, max_increase: float = math.inf, cache: BlockCache | None = None):
        self.cost = cost
        self.max_increase = max_increase
        self.cache = cache
        self.allowed = cost < np.inf

    def rank(self, present: np.ndarray) -> Ranking:
        """The ranking of the sub-problem with columns ``present`` ((C,) bool). Raises ``InfeasibleAssignment``."""
        n_rows = self.cost.shape[0]
        counts = np.count_nonzero(self.allowed & present, axis=1)
        if n_rows == 0 or float(np.prod(counts, dtype=float)) > ENUMERATION_LIMIT:
            return rank(self.cost[:, present], max_increase=self.max_increase, cache=self.cache)
        sub = self.cost[:, present]
        if n_rows == 1:
            if not counts[0]:
                raise InfeasibleAssignment("the only row has no allowed column")
            return SingleRow(sub[0], int(np.argmin(sub[0])), self.max_increase)
        return Enumerated(sub, None, self.max_increase)

    def ranks(self, patterns: np.ndarray) -> list[Ranking | None]:
        """``rank(present)`` of every row of ``patterns`` ((P, C) bool), None where it raises
        ``InfeasibleAssignment`` (``subset_rankings``: the small ones found together)."""
        return subset_rankings([self.cost] * len(patterns), list(patterns), self.max_increase, self.cache)


def subset_rankings(
    costs: list[np.ndarray],
    patterns: list[np.ndarray],
    max_increase: float = math.inf,
    cache: BlockCache | None = None,
) -> list[Ranking | None]:
    """``ColumnSubsets(costs[i], max_increase, cache).rank(patterns[i])`` for every i ((R_i, C_i) blocks, (C_i,)
    bool columns kept), None where it raises ``InfeasibleAssignment``.

    Sub-problems with the same number of rows are worked on together, padded with absent columns to the widest:
    those of one row get their ``SingleRow`` from one masked argmin; the small ones of several rows (whose
    candidates ``rank`` would list) are listed together when they have at most ``JOINT_LISTING_LIMIT``
    candidates (``_listed_subsets``; listing a whole block once and masking it per subset costs more when the
    block has many more candidates than its subsets), else on their own; the others are ranked one by one.
    """
    out: list[Ranking | None] = [None] * len(costs)
    by_rows: dict[int, list[int]] = {}
    for i, cost in enumerate(costs):
        by_rows.setdefault(cost.shape[0], []).append(i)
    for n_rows, items in by_rows.items():
        width = max(costs[i].shape[1] for i in items)
        stacked = np.full((len(items), n_rows, width), np.inf)
        present = np.zeros((len(items), width), dtype=bool)
        for k, i in enumerate(items):
            n_cols = costs[i].shape[1]
            stacked[k, :, :n_cols] = costs[i]
            present[k, :n_cols] = patterns[i]
        counts = ((stacked < np.inf) & present[:, None, :]).sum(axis=2)
        small = np.prod(counts, axis=1, dtype=float) <= ENUMERATION_LIMIT
        for k in np.flatnonzero(~small).tolist():
            i = items[k]
            try:
                out[i] = rank(costs[i][:, patterns[i]], max_increase=max_increase, cache=cache)
            except InfeasibleAssignment:
                out[i] = None
        kept = np.flatnonzero(small)
        if not len(kept):
            continue
        if n_rows == 1:
            row = np.where(present[kept], stacked[kept, 0], np.inf)
            cheapest = np.argmin(row, axis=1)
            local = (np.cumsum(present[kept], axis=1) - 1)[np.arange(len(kept)), cheapest]
            for j, (k, c, at) in enumerate(zip(kept.tolist(), cheapest.tolist(), local.tolist(), strict=True)):
                i = items[k]
                if row[j, c] < np.inf:
                    out[i] = SingleRow(costs[i][0, patterns[i]], int(at), max_increase)
            continue
        together = np.prod(counts[kept], axis=1, dtype=float) <= JOINT_LISTING_LIMIT
        of_block: dict[int, list[int]] = {}  # the larger ones, by the block (cost array) they cut
        for k in kept[~together].tolist():
            of_block.setdefault(id(costs[items[k]]), []).append(items[k])
        for cut in of_block.values():
            for i, listed in zip(cut, _block_listings(costs[cut[0]], [patterns[i] for i in cut]), strict=True):
                out[i] = (
                    None if listed is None else Enumerated(costs[i][:, patterns[i]], None, max_increase, listed=listed)
                )
        kept = kept[together]
        for k, listed in zip(kept.tolist(), _listed_subsets(stacked[kept], present[kept]), strict=True):
            i = items[k]
            if listed is not None:
                out[i] = Enumerated(costs[i][:, patterns[i]], max_increase=max_increase, listed=listed)
    return out


def _block_listings(cost: np.ndarray, patterns: list[np.ndarray]) -> list[tuple[np.ndarray, np.ndarray] | None]:
    """The listing and its costs that ``Enumerated(cost[:, present])`` makes of each column subset ``present``
    of one (R, C) block (None where it has no assignment): for several subsets of a block of at most
    ``SHARED_LISTING_LIMIT`` candidates, the block's listing masked per subset (its lexicographic order restricted
    to a subset is the subset's own, and each cost the same sum of the same entries), else each its own."""
    if len(patterns) < 2 or _candidates(cost) > SHARED_LISTING_LIMIT:
        listings = [enumerate_assignments(cost[:, present] < np.inf) for present in patterns]
        return [
            (listed, cost[:, present][np.arange(cost.shape[0]), listed].sum(axis=1)) if len(listed) else None
            for listed, present in zip(listings, patterns, strict=True)
        ]
    listed = enumerate_assignments(cost < np.inf)
    totals = cost[np.arange(cost.shape[0]), listed].sum(axis=1)
    out: list[tuple[np.ndarray, np.ndarray] | None] = []
    for present in patterns:
        valid = present[listed].all(axis=1)
        local = (np.cumsum(present) - 1)[listed[valid]]
        out.append((local, totals[valid]) if valid.any() else None)
    return out


SHARED_LISTING_LIMIT = 4096
"""``_block_listings`` lists a block once for several of its column subsets when it has at most this many
candidates."""

JOINT_LISTING_LIMIT = 256
"""``subset_rankings`` lists sub-problems of at most this many candidates together (``_listed_subsets``), larger
ones on their own (``Enumerated``). Measured on this machine: 51k candidates of 66 sub-problems of 4 rows took
15.5 ms listed together and 7.4 ms listed one by one, while many small sub-problems (the stress frame of
``benchmarks/tracker_speed.py``) gain from one call; of 64, 128, 256 and 1024, 256 was fastest on both."""


def _listed_subsets(costs: np.ndarray, patterns: np.ndarray) -> list[tuple[np.ndarray, np.ndarray] | None]:
    """The listing and its costs that ``Enumerated(costs[p][:, patterns[p]])`` makes, of P sub-problems
    (``costs`` (P, R, C), ``patterns`` (P, C) bool, R >= 2): every assignment (N_p, R), as columns of the
    sub-problem, in lexicographic order, and its cost (N_p,); None where one has no assignment.

    All are listed together, in a fixed number of NumPy calls: sub-problem p's candidates are the index tuples
    of its rows' allowed columns in C order (as ``enumerate_assignments``: lexicographic), numbered
    0 .. n_p - 1 and laid end to end; a tuple's digits are its number in the mixed radix of the rows' counts.
    Each cost is summed from the same entries in the same order as the sub-problem's own listing sums them (an
    (N, R) array reduced along its rows), so the floats are equal. Nothing is sorted here: ``Enumerated``
    finds the best by argmin and sorts only when asked for a second solution, as most are not.
    """
    n_patterns, n_rows = costs.shape[0], costs.shape[1]
    allowed = (costs < np.inf) & patterns[:, None, :]  # (P, R, C)
    counts = allowed.sum(axis=2)  # (P, R)
    _, _, cols = np.nonzero(allowed)  # allowed columns by sub-problem, row, column
    starts = (np.cumsum(counts.ravel()) - counts.ravel()).reshape(counts.shape)
    later = np.cumprod(counts[:, ::-1], axis=1)[:, ::-1]  # (P, R): products of the counts of rows >= r
    n_listed = later[:, 0]
    strides = np.concatenate([later[:, 1:], np.ones((n_patterns, 1), dtype=later.dtype)], axis=1)
    pattern = np.repeat(np.arange(n_patterns), n_listed)
    number = np.arange(len(pattern)) - np.repeat(np.cumsum(n_listed) - n_listed, n_listed)
    digits = (number[:, None] // strides[pattern]) % np.maximum(counts[pattern], 1)
    combos = cols[starts[pattern] + digits]  # (N, R) columns of the block
    ordered = np.sort(combos, axis=1)
    distinct = np.flatnonzero((ordered[:, 1:] != ordered[:, :-1]).all(axis=1))
    combos, pattern = combos[distinct], pattern[distinct]
    total = costs[pattern[:, None], np.arange(n_rows), combos].sum(axis=1)
    bounds = np.searchsorted(pattern, np.arange(n_patterns + 1)).tolist()
    local = (np.cumsum(patterns, axis=1) - 1)[pattern[:, None], combos]
    return [
        (local[start:stop], total[start:stop]) if start < stop else None
        for start, stop in zip(bounds[:-1], bounds[1:], strict=True)
    ]


class Murty:
    """Ranking of one (r, c) block by Murty's partitioning (module docstring); ``root`` is a best assignment.

    A queued subproblem is (key, serial, solved, state): rows < p pinned to the solution's columns, row p may
    not take the columns in ``barred``; ``serial`` (the order subproblems are made in) makes equal costs pop first
    in, first out. The latest solution is partitioned only when a further one is asked for, and a subproblem is
    solved only when it reaches the front of the queue (lazy evaluation, Miller, Stone & Cox 1997): until then
    its key is a lower bound on its cost, the pinned rows' cost plus every other row's cheapest column still
    free, less a margin far above rounding error. A solved one is queued again under its cost, if within the
    root plus ``max_increase``. Keys never exceed costs, so a solved subproblem reaches the front only when every
    unsolved one would cost more, or as much and was made later: the solutions come in the order of solving
    every subproblem at once and queueing them by (cost, serial), as plain Murty does.
    """

    def __init__(self, cost: np.ndarray, root: np.ndarray, max_increase: float = math.inf):
        self.cost = cost
        self._arange = np.arange(cost.shape[0])
        self.solutions: list[tuple[np.ndarray, float]] = [(root, self._total(root))]
        self._limit = self.solutions[0][1] + max_increase
        self._margin = 1e-9 * (1.0 + float(np.abs(cost[cost < np.inf]).sum()))  # >> rounding error of any sum
        self._queue: list[tuple[float, int, bool, tuple]] = []
        self._serial = 0
        self._unexpanded: tuple[np.ndarray, int, tuple[int, ...]] | None = (root, 0, ())

    def _total(self, cols: np.ndarray) -> float:
        return float(self.cost[self._arange, cols].sum())

    def solution(self, index: int) -> tuple[np.ndarray, float] | None:
        while len(self.solutions) <= index:
            if self._unexpanded is not None:
                self._expand(*self._unexpanded)
                self._unexpanded = None
            while True:
                if not self._queue:
                    return None
                key, serial, solved, state = heapq.heappop(self._queue)
                if solved:
                    break
                self._solve(serial, *state)
            sol, pinned, barred = state
            self.solutions.append((sol, key))
            self._unexpanded = (sol, pinned, barred)
        return self.solutions[index]

    def _expand(self, sol: np.ndarray, pinned: int, barred: tuple[int, ...]) -> None:
        """Queue, unsolved, every subproblem P_q, q = pinned .. r-1, that partitions the rest of the subproblem
        (pinned, barred) whose best is ``sol``, keyed by a lower bound on its cost; those with a row that has no
        column left, or whose bound exceeds the limit, are not queued (they have no solution within it)."""
        cost = self.cost
        n_rows = cost.shape[0]
        n_sub = n_rows - pinned
        index = np.arange(n_sub)
        after = index[None, :] > index[:, None]  # (i, i'): row pinned + i' comes after row pinned + i
        free = np.ones((n_sub, cost.shape[1]), dtype=bool)  # row i: the columns free for row pinned + i
        free[:, sol[:pinned]] = False
        earlier, later = np.nonzero(after.T)
        free[earlier, sol[pinned + later]] = False  # rows before pinned + i keep their columns
        rows = np.where(free, cost[pinned:], np.inf)
        rows[index, sol[pinned:]] = np.inf
        rows[0, list(barred)] = np.inf
        taken = cost[self._arange, sol]
        pinned_cost = np.cumsum(taken)[pinned:] - taken[pinned:]
        cheapest_later = np.where(free[:, None, :], cost[None, pinned:, :], np.inf).min(axis=2)  # (i, row)
        bound = pinned_cost + rows.min(axis=1) + np.where(after, cheapest_later, 0.0).sum(axis=1)
        keys = bound - self._margin
        for i in np.flatnonzero(np.isfinite(bound) & (keys <= self._limit)).tolist():
            q = pinned + i
            row_barred = (*barred, int(sol[q])) if i == 0 else (int(sol[q]),)
            key = float(keys[i])
            heapq.heappush(self._queue, (key, self._serial, False, (sol, q, rows[i], free[i], row_barred)))
            self._serial += 1

    def _solve(
        self, serial: int, sol: np.ndarray, q: int, row: np.ndarray, free: np.ndarray, barred: tuple[int, ...]
    ) -> None:
        """Solve P_q: rows < q keep ``sol``, row q costs ``row`` (barred and taken columns at +inf), later
        rows use the free columns; queue its best solution, solved, if one exists within the limit."""
        child = sol.copy()
        if q == len(sol) - 1:
            child[q] = int(np.argmin(row))
        else:
            sub_cols = np.flatnonzero(free)
            sub = self.cost[q:, sub_cols]
            sub[0] = row[sub_cols]
            try:
                _, picked = linear_sum_assignment(sub)
            except ValueError:
                return
            child[q:] = sub_cols[picked]
        total = self._total(child)
        if total <= self._limit and total < np.inf:
            heapq.heappush(self._queue, (total, serial, True, (child, q, barred)))


@dataclass(frozen=True, slots=True)
class PartsSummary:
    """What ``Product`` reads of its first parts, worked out once for products that share them
    (``pmb.pmbm.SharedRanking``): their best costs, in order, and (cost(1) - cost(0), position) of those with a
    second solution."""

    best_costs: tuple[float, ...]
    steps: tuple[tuple[float, int], ...]

    @staticmethod
    def of(parts: list[tuple[np.ndarray, np.ndarray, Ranking]]) -> PartsSummary:
        best = tuple(ranking.solution(0)[1] for _, _, ranking in parts)
        steps = []
        for n, (_, _, ranking) in enumerate(parts):
            second = ranking.solution(1)
            if second is not None:
                steps.append((second[1] - best[n], n))
        return PartsSummary(best, tuple(steps))


class Product:
    """Ranking of a problem made of independent parts (disjoint rows and columns): the smallest sums of one
    solution per part, up to ``max_increase`` above the best.

    base: (R,) the best assignment (every part's solution 0 on its rows; not modified); parts: (rows, cols,
    ranking) with the part's rows in the problem and its local-to-problem column map; ``prefix``: the
    ``PartsSummary`` of the first parts, if known (same result, less work).

    Index tuples t (solution index per part) are ranked with a heap. Parts with a second solution are sorted
    by d_q = cost(1) - cost(0); with q the last nonzero position of t, its successors are t + e_q, t + e_(q+1)
    and, if t_q = 1, t - e_q + e_(q+1). Every tuple then has exactly one parent and costs no less than it (a
    part's costs never decrease and d is sorted), so at most three heap entries are pushed per solution. A
    tuple is held sparse, as its (q, t_q) with t_q > 0 by increasing q, so a step costs O(nonzeros), not
    O(parts).
    """

    def __init__(
        self,
        base: np.ndarray,
        parts: list[tuple[np.ndarray, np.ndarray, Ranking]],
        max_increase: float = math.inf,
        prefix: PartsSummary | None = None,
    ):
        self.base = base
        self.parts = parts
        self._prefix = prefix or PartsSummary((), ())
        known = len(self._prefix.best_costs)
        total = float(sum([*self._prefix.best_costs, *(ranking.solution(0)[1] for _, _, ranking in parts[known:])]))
        self._limit = total + max_increase
        self._varying: list[tuple[np.ndarray, np.ndarray, Ranking]] = []
        self._found: list[tuple[tuple[tuple[int, int], ...], float]] = [((), total)]
        self._solutions: dict[int, tuple[np.ndarray, float]] = {0: (base, total)}
        self._heap: list[tuple[float, int, tuple[tuple[int, int], ...], int]] = []
        self._serial = 0
        self._unexpanded: tuple[tuple[tuple[int, int], ...], float, int] | None = ((), total, -1)

    def solution(self, index: int) -> tuple[np.ndarray, float] | None:
        while len(self._found) <= index:
            if self._unexpanded is not None:
                self._push_successors(*self._unexpanded)
                self._unexpanded = None
            if not self._heap:
                return None
            total, _, choice, last = heapq.heappop(self._heap)
            self._found.append((choice, total))
            self._unexpanded = (choice, total, last)
        if index not in self._solutions:
            choice, total = self._found[index]
            cols = self.base.copy()
            for q, i in choice:
                rows, part_cols, ranking = self._varying[q]
                cols[rows] = part_cols[ranking.solution(i)[0]]
            self._solutions[index] = (cols, total)
        return self._solutions[index]

    def _cost(self, q: int, i: int) -> float:
        return self._varying[q][2].solution(i)[1]

    def _push(self, total: float, choice: tuple[tuple[int, int], ...], last: int) -> None:
        if total <= self._limit:
            heapq.heappush(self._heap, (total, self._serial, choice, last))
            self._serial += 1

    def _push_successors(self, choice: tuple[tuple[int, int], ...], total: float, last: int) -> None:
        if last < 0:
            steps = list(self._prefix.steps)
            for n in range(len(self._prefix.best_costs), len(self.parts)):
                ranking = self.parts[n][2]
                second = ranking.solution(1)
                if second is not None:
                    steps.append((second[1] - ranking.solution(0)[1], n))
            steps.sort()
            self._varying = [self.parts[n] for _, n in steps]
            if steps:
                self._push(total + steps[0][0], ((0, 1),), 0)
            return
        i = choice[-1][1]  # the entry of position ``last``, the last nonzero one
        further = self._varying[last][2].solution(i + 1)
        if further is not None:
            self._push(total + further[1] - self._cost(last, i), (*choice[:-1], (last, i + 1)), last)
        if last + 1 < len(self._varying):
            step = self._cost(last + 1, 1) - self._cost(last + 1, 0)
            self._push(total + step, (*choice, (last + 1, 1)), last + 1)
            if i == 1:
                undo = self._cost(last, 1) - self._cost(last, 0)
                self._push(total - undo + step, (*choice[:-1], (last + 1, 1)), last + 1)
