"""PMBM hypothesis management: keep up to N_h global hypotheses, each expanded by Murty's k best assignments.

García-Fernández, Williams, Granström & Svensson (2018), "Poisson multi-Bernoulli mixture filter: direct
derivation and implementation", IEEE T-AES 54(4), sec. IV-V; the GNN-PMB paper (Liu et al., T-IV 2023),
sec. III. Prior global hypothesis h with normalised weight w_h and cost matrix C_h (``cost.LocalHypotheses``)
has children a = the H_h = ceil(N_h w_h) best assignments of C_h (``assign.murty``), with

    log w_{h,a} = log w_h + sum_k log l_k0 - C_h(a)        (up to normalisation),

since an assignment's likelihood is the product of its local hypothesis likelihoods. Children that will hold
the same Bernoullis (same multiset of local keys after the core's existence pruning) are merged by adding
weights; then the weights are normalised, sorted (ties keep parent, then rank order), children below
``hypothesis_prune`` dropped, with ``[pmbm] n_scan`` N > 0 those not descending from the best child's ancestor N
frames back dropped (N-scan pruning), at most N_h kept and renormalised. With N_h = 1 this is exactly GNN-PMB
(``gnnpmb.BestAssignment``). With ``[pmbm] duplicate_birth_existence`` r > 0, before that, a child other than the
heaviest that starts a Bernoulli on a measurement inside the gate of a Bernoulli of existence >= r which it leaves
missed is dropped (``_drop_duplicate_births``).

Of a parent's H_h best assignments only those costing at most -log(hypothesis_prune) more than its best are
enumerated: the parent's best child alone outweighs such a child by more than 1 / hypothesis_prune, so its
normalised weight is below the threshold whatever the other children (it could matter only by merging).

Per-frame budget (``murty_block_rows``): Murty's ranking of a gated block of R rows solves up to R assignment
problems per extra solution, so a dense crowd (one block of 1000 detections) would take minutes and gigabytes. A
block with more rows than the budget is given only its best assignment (children differ in the other blocks),
only the ``crowd_hypotheses`` most likely prior hypotheses get children (each needs a Hungarian solve of the
large block), and the frame emits ``BudgetReached``. Frames whose blocks are all within the budget are
unaffected.

Speed: the hypotheses share most Bernoullis, so the core gates them as one union (``core.HypothesisLocals``),
whose cost matrix is split once into gated blocks; every distinct (block, Bernoullis present) sub-problem is
ranked once and shared by all hypotheses that contain it (``murty.Product``). The small sub-problems of all
blocks are listed together, per row count, and larger ones share the rankings of equal smaller
blocks (``murty.subset_rankings``, ``murty.BlockCache``); a ranking goes past its best only when a hypothesis
has more than one child. The best assignments of all hypotheses are assembled block by block, at
once; a hypothesis with more than one child gets a ``Product`` (``SharedRanking``). Posteriors
are built once per distinct (Bernoulli, outcome) into one store that the posterior hypotheses index
(``core.posteriors_from_assignments``, ``core.GlobalHypothesis``). These pieces only share work: each gives
the same assignments, costs and Bernoullis, bit for bit, as the plain computation it replaces (their tests).
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from gnnpmb.assign.clusters import Cluster
from gnnpmb.assign.hungarian import InfeasibleAssignment, solve
from gnnpmb.assign.murty import (
    BlockCache,
    ColumnSubsets,
    PartsSummary,
    Product,
    Ranking,
    blocks,
    forbid_beyond_private,
    k_best,
    subset_rankings,
)
from gnnpmb.config import PmbmParams
from gnnpmb.events import Assignment, BudgetReached, GlobalHypotheses, Panel
from gnnpmb.pmb.core import (
    GlobalHypothesis,
    HypothesisLocals,
    UpdateContext,
    assignment_pairs,
    posteriors_from_assignments,
)
from gnnpmb.pmb.cost import LocalHypotheses

MURTY_BLOCK_ROWS = 60
"""Default per-frame budget of PMBM: gated blocks of the cost matrix with more rows (measurements) than this get
only their best assignment instead of a k-best ranking (module docstring)."""

CROWD_HYPOTHESES = 10
"""Default per-frame budget of PMBM over ``MURTY_BLOCK_ROWS``: in such a frame only this many of the most likely
prior hypotheses get children (each costs a Hungarian solve of the large block); the others are dropped."""

COST_MATRIX_EVENTS = 3
"""Cost matrices are emitted for the first COST_MATRIX_EVENTS prior hypotheses only (the core emits that of
hypothesis 0, the strategy the others), to keep recordings small, plus that of the best posterior's parent."""


@dataclass(frozen=True, slots=True)
class _Child:
    """One posterior hypothesis candidate: its unnormalised log weight, parent index, assignment (M,) as
    columns of the union's cost matrix (``SharedRanking``) and the assignment's cost."""

    log_weight: float
    parent: int
    col_of_row: np.ndarray
    total_cost: float


def log_sum_exp(a: np.ndarray) -> np.float64:
    """log sum_i exp(a_i) of a 1-D float64 array, bit for bit ``scipy.special.logsumexp(a)`` (scipy 1.17: the
    largest terms are taken out of the sum, log1p(s / m) + log m + max a, with m their count; the direct
    log sum exp where that is not finite), with the same NumPy operations on the same array shapes but without
    its array-API dispatch, which cost more than the computation (3 calls per class and frame in PMBM)."""
    if a.size == 0:
        return np.float64(-np.inf)
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        direct = np.log(np.sum(np.exp(a), axis=(0,), keepdims=True))
        a_max = np.max(a, axis=(0,), keepdims=True)
        is_max = a == a_max
        count = np.sum(is_max.astype(a.dtype), axis=(0,), keepdims=True, dtype=a.dtype)
        rest = np.exp(np.where(is_max, -np.inf, a) - a_max)
        s = np.sum(rest, axis=(0,), keepdims=True, dtype=rest.dtype)
        s = np.where(s == 0, s, s / count)
        out = np.log1p(s) + np.log(count) + a_max
    return np.where(np.isfinite(out), out, direct)[0]


def hypothesis_budget(n_hypotheses: int, log_weight: float) -> int:
    """H_h = ceil(N_h w_h) >= 1 children for a prior hypothesis of normalised log weight ``log_weight``
    (a relative 1e-9 slack keeps N_h w_h = 2 + rounding error at 2)."""
    return max(1, math.ceil(n_hypotheses * math.exp(log_weight) * (1.0 - 1e-9)))


class KBest:
    """PMBM: at most ``params.n_hypotheses`` global hypotheses from Murty's k best assignments; gated blocks of
    more than ``murty_block_rows`` rows keep only their best assignment (the per-frame budget)."""

    name = "k-best"
    panels = (Panel.HYPOTHESES,)
    chooses_assignment = True

    def __init__(
        self,
        params: PmbmParams,
        murty_block_rows: int = MURTY_BLOCK_ROWS,
        crowd_hypotheses: int = CROWD_HYPOTHESES,
    ):
        if murty_block_rows < 1 or crowd_hypotheses < 1:
            raise ValueError(
                f"murty_block_rows and crowd_hypotheses must be >= 1, got {murty_block_rows}, {crowd_hypotheses}"
            )
        self.params = params
        self.murty_block_rows = murty_block_rows
        self.crowd_hypotheses = crowd_hypotheses
        self._log_prune = math.log(params.hypothesis_prune) if params.hypothesis_prune > 0 else -math.inf
        self._max_increase = -self._log_prune
        self._lineage: list[tuple[int, ...]] = []
        """Per current hypothesis (``n_scan`` > 0): its own serial, then its ancestors' newest first, at most
        ``n_scan`` of them."""
        self._serial = itertools.count()

    def update(
        self, priors: list[GlobalHypothesis], locals_: Sequence[LocalHypotheses], ctx: UpdateContext
    ) -> list[GlobalHypothesis]:
        prior_log_w = np.array([h.log_weight for h in priors])
        prior_log_w = prior_log_w - log_sum_exp(prior_log_w)
        budgets = [hypothesis_budget(self.params.n_hypotheses, lw) for lw in prior_log_w]
        if ctx.sink.enabled:
            for h in range(1, min(COST_MATRIX_EVENTS, len(locals_))):
                ctx.sink.emit(locals_[h].cost_event(ctx.class_name, h))
        union, members = _union_of(locals_)
        largest = union.n_meas  # rows of the largest gated block: at most M, computed only if M is over budget
        if largest > self.murty_block_rows:
            largest = max((len(rows) for rows, _ in blocks(union.cost_matrix())), default=0)
        if largest > self.murty_block_rows:
            budgets = _trim_budgets(budgets, prior_log_w, self.crowd_hypotheses)
            if ctx.sink.enabled:
                ctx.sink.emit(BudgetReached(ctx.class_name, "pmbm murty_block_rows", self.murty_block_rows, largest))
        if len(locals_) == 1 and largest <= self.murty_block_rows:
            ranked = [k_best(locals_[0].cost_matrix(), budgets[0], self._max_increase)]
        else:
            shared = SharedRanking(union, members, self._max_increase, self.murty_block_rows)
            ranked = shared.k_best(budgets)
        children: list[_Child] = []
        bases = (prior_log_w + _sums_of_rows(union.miss_log_lik, members)).tolist()  # + sum_k log l_k0
        for h, assignments in enumerate(ranked):
            children.extend(_Child(bases[h] - total, h, col_of_row, total) for col_of_row, total in assignments)
        merged = _merge_identical(children, union, members, ctx)
        if self.params.duplicate_birth_existence > 0:
            merged = _drop_duplicate_births(merged, union, members, self.params.duplicate_birth_existence)
        kept, log_w = self._select(merged, self._child_lineages(merged, len(priors)))
        store, rows = posteriors_from_assignments(
            union, [members[c.parent] for c in kept], [c.col_of_row for c in kept], ctx
        )
        posteriors = [GlobalHypothesis(float(lw), store, index) for lw, index in zip(log_w, rows, strict=True)]
        if ctx.sink.enabled:
            best = kept[0]
            local = locals_[best.parent]
            if best.parent >= COST_MATRIX_EVENTS:  # the matrix its assignment is explained over
                ctx.sink.emit(local.cost_event(ctx.class_name, best.parent))
            own = _own_columns(best.col_of_row, members[best.parent], union.n_tracks)
            _emit(best.total_cost, own, local, best.parent, posteriors, tuple(c.parent for c in kept), ctx)
        return posteriors

    def _child_lineages(self, children: list[_Child], n_priors: int) -> list[tuple[int, ...]] | None:
        """Each child's lineage (``n_scan`` > 0, else None): a new serial, then its parent's lineage cut to
        ``n_scan`` entries. Prior hypotheses this strategy did not make (the first frame, a state set from
        outside) start lineages of their own."""
        n = self.params.n_scan
        if n == 0:
            return None
        if len(self._lineage) != n_priors:
            self._lineage = [(next(self._serial),) for _ in range(n_priors)]
        return [(next(self._serial), *self._lineage[c.parent][:n]) for c in children]

    def _select(
        self, children: list[_Child], lineages: list[tuple[int, ...]] | None = None
    ) -> tuple[list[_Child], np.ndarray]:
        """Normalise, sort descending (stable), drop below ``hypothesis_prune`` (the best always stays), with
        ``lineages`` drop those whose ancestor ``n_scan`` frames back is not the best one's (N-scan pruning,
        Blackman 2004, "Multiple hypothesis tracking for multiple target tracking", IEEE AES Magazine 19(1),
        sec. IV: the association decision N frames back becomes final), cap to N_h, renormalise. Returns the
        kept children and their normalised log weights."""
        log_w = np.array([c.log_weight for c in children])
        log_w = log_w - log_sum_exp(log_w)
        order = np.argsort(-log_w, kind="stable")
        keep = order[log_w[order] >= self._log_prune]
        keep = keep if len(keep) else order[:1]
        if lineages is not None:
            n = self.params.n_scan
            root = lineages[keep[0]][n : n + 1]
            keep = keep[np.array([lineages[i][n : n + 1] == root for i in keep.tolist()])]
        keep = keep[: self.params.n_hypotheses]
        kept_log_w = log_w[keep] - log_sum_exp(log_w[keep])
        if lineages is not None:
            self._lineage = [lineages[i] for i in keep.tolist()]
        return [children[i] for i in keep], kept_log_w


def _sums_of_rows(values: np.ndarray, members: list[np.ndarray]) -> np.ndarray:
    """(H,) ``values[members[h]].sum()`` for every h, bit for bit: the members of equal length L are gathered
    into one (n, L) array and summed along its rows, which NumPy sums as it sums each (L,) array."""
    lengths = np.array([len(index) for index in members], dtype=np.int64)
    gathered = values[np.concatenate(members)] if len(members) else values[:0]
    starts = np.cumsum(lengths) - lengths
    out = np.zeros(len(members))
    for length in np.unique(lengths).tolist():
        of_length = np.flatnonzero(lengths == length)
        out[of_length] = gathered[starts[of_length][:, None] + np.arange(length)].sum(axis=1)
    return out


def _trim_budgets(budgets: list[int], log_weights: np.ndarray, keep: int) -> list[int]:
    """Children per prior hypothesis with only the ``keep`` most likely (ties: first) expanded; the others get
    none."""
    kept = set(np.argsort(-log_weights, kind="stable")[:keep].tolist())
    return [k if h in kept else 0 for h, k in enumerate(budgets)]


def _own_columns(col_of_row: np.ndarray, index: np.ndarray, n_union: int) -> np.ndarray:
    """An assignment in union columns (M,) as columns of the cost matrix of the hypothesis holding
    ``index``."""
    column = np.full(n_union + len(col_of_row), -1, dtype=np.int64)
    column[index] = np.arange(len(index))
    column[n_union:] = len(index) + np.arange(len(col_of_row))
    return column[col_of_row]


def _union_of(locals_: Sequence[LocalHypotheses]) -> tuple[LocalHypotheses, list[np.ndarray]]:
    """The local hypotheses of every Bernoulli of every hypothesis, and each hypothesis' rows of it."""
    if isinstance(locals_, HypothesisLocals):
        return locals_.union, locals_.members
    if len(locals_) == 1:
        return locals_[0], [np.arange(locals_[0].n_tracks)]
    raise ValueError("PMBM needs the local hypotheses of several global hypotheses as HypothesisLocals (PmbCore)")


class SharedRanking:
    """Rankings of the cost matrices of hypotheses cut from one union of Bernoullis.

    Column u < U of the union matrix (M, U + M) is union Bernoulli u, column U + j the new-track column of
    measurement j; hypothesis h holds the Bernoullis ``members[h]``, so its matrix is the union's without the
    absent Bernoullis' columns. Entries that cannot be in any assignment within ``max_increase`` of the best
    are forbidden first, by columns private to one row and present in every hypothesis, like the new-track
    columns (``murty.forbid_beyond_private``). Each gated block of the union matrix is then ranked once per
    distinct set of its Bernoullis present (``murty.rank``), and a hypothesis' ranking is the
    ``murty.Product`` of its blocks. A block of more than ``max_block_rows`` rows is ranked with no increase
    allowed: only its best assignment (the per-frame budget).
    """

    def __init__(
        self,
        union: LocalHypotheses,
        members: list[np.ndarray],
        max_increase: float,
        max_block_rows: int = MURTY_BLOCK_ROWS,
    ):
        self.n_union = union.n_tracks
        self.n_meas = union.n_meas
        self.members = members
        self.max_increase = max_increase
        cost = union.cost_matrix()
        has_column = np.ones((len(members), cost.shape[1]), dtype=bool)
        has_column[:, : self.n_union] = False
        lengths = [len(index) for index in members]
        has_column[np.repeat(np.arange(len(members)), lengths), np.concatenate(members)] = True
        cost = forbid_beyond_private(cost, max_increase, usable=has_column.all(axis=0))
        self.cost = cost
        self.common: list[tuple[np.ndarray, np.ndarray, Ranking | None]] = []
        self.varying: list[tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, ColumnSubsets | None]] = []
        """Per block whose Bernoullis differ between hypotheses: rows, columns, the distinct presence patterns
        (P, columns), each hypothesis' pattern (H,), and the block's ``murty.ColumnSubsets`` (None when only
        the best assignment is ranked). Each (block, pattern) is ranked on first use (``_varying_part``): a
        hypothesis with no children costs nothing."""
        self._parts: dict[tuple[int, int], tuple[np.ndarray, np.ndarray, Ranking | None]] = {}
        self._blocks: BlockCache = {}
        self._common: PartsSummary | None = None
        self._summaries: dict[tuple[int, int], tuple[float, float | None]] = {}
        """Per (varying block, pattern) ranked past its best: its best cost and cost(1) - cost(0) (None if it has
        no second solution), what ``murty.PartsSummary`` reads of it."""
        found = blocks(cost)
        varies = has_column.any(axis=0) & ~has_column.all(axis=0)  # columns only some hypotheses hold
        block_of_col = np.full(cost.shape[1], -1, dtype=np.int64)
        for b, (_, cols) in enumerate(found):
            block_of_col[cols] = b
        is_varying = np.zeros(len(found), dtype=bool)
        is_varying[block_of_col[varies & (block_of_col >= 0)]] = True
        common = _common_parts(cost, found, ~is_varying, has_column[0], max_increase, max_block_rows, self._blocks)
        patterns = _presence_patterns(has_column, found, is_varying)
        for b, (rows, cols) in enumerate(found):
            best_only = len(rows) > max_block_rows
            if not is_varying[b]:
                self.common.append(common[b])
                continue
            first, pattern = patterns[b]
            subsets = None if best_only else ColumnSubsets(cost[rows[:, None], cols], max_increase, self._blocks)
            self.varying.append((rows, cols, has_column[first[:, None], cols], pattern, subsets))
        self.common_base = np.zeros(self.n_meas, dtype=np.int64)
        self.common_ok = all(ranking is not None for _, _, ranking in self.common)
        self.common_best: tuple[float, ...] = ()
        if self.common_ok:
            self.common_best = tuple(ranking.solution(0)[1] for _, _, ranking in self.common)
            for rows, cols, ranking in self.common:
                self.common_base[rows] = cols[ranking.solution(0)[0]]

    def k_best(self, budgets: list[int]) -> list[list[tuple[np.ndarray, float]]]:
        """The budgets[h] best assignments (col_of_row as union columns, cost) of every hypothesis.

        The best assignments of all hypotheses with a budget are assembled at once, block by block
        (``_best_assignments``); only hypotheses with budgets[h] > 1 get a ``murty.Product``."""
        out: list[list[tuple[np.ndarray, float]]] = [[] for _ in budgets]
        active = np.flatnonzero(np.array(budgets, dtype=np.int64) >= 1)
        if not len(active) or not self.common_ok:
            return out
        bases, totals, feasible = self._best_assignments(active)
        for i, h in enumerate(active.tolist()):
            if not feasible[i]:
                continue
            if budgets[h] == 1:
                out[h] = [(bases[i], float(totals[i]))]
            else:
                out[h] = self._ranked(h, budgets[h], bases[i])
        return out

    def _common_summary(self) -> PartsSummary:
        """The ``murty.PartsSummary`` of the common parts, which lead every hypothesis' parts (worked out when
        a hypothesis first has more than one child)."""
        if self._common is None:
            self._common = PartsSummary.of(self.common)
        return self._common

    def _varying_part(self, b: int, p: int) -> tuple[np.ndarray, np.ndarray, Ranking | None]:
        """(rows, columns, ranking or None if infeasible) of varying block ``b`` cut to its presence pattern
        ``p``, ranked on first use."""
        key = (b, p)
        if key not in self._parts:
            rows, cols, patterns, _, subsets = self.varying[b]
            present = patterns[p]
            if subsets is None:
                self._parts[key] = _best_only_part(self.cost, rows, cols, present)
            else:
                try:
                    self._parts[key] = rows, cols[present], subsets.rank(present)
                except InfeasibleAssignment:
                    self._parts[key] = rows, cols[present], None
        return self._parts[key]

    def _best_assignments(self, hypotheses: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Best assignment (H, M) in union columns, its cost (H,) and feasibility (H,) of each of
        ``hypotheses`` (H,): the common parts' best, then per varying block the best of the hypothesis'
        presence pattern. Costs are summed part by part in the order of the parts, as ``murty.Product`` sums
        them (the same float additions in the same order)."""
        bases = np.tile(self.common_base, (len(hypotheses), 1))
        totals = np.zeros(len(hypotheses))
        for best_cost in self.common_best:
            totals += best_cost
        feasible = np.ones(len(hypotheses), dtype=bool)
        used = [np.unique(pattern[hypotheses]).tolist() for _, _, _, pattern, _ in self.varying]
        self._rank_together(used)
        for b, (rows, _, patterns, pattern, _) in enumerate(self.varying):
            of_hypothesis = pattern[hypotheses]
            cols_of = np.zeros((len(patterns), len(rows)), dtype=np.int64)
            cost_of = np.zeros(len(patterns))
            ok_of = np.zeros(len(patterns), dtype=bool)
            for p in used[b]:
                _, part_cols, ranking = self._varying_part(b, p)
                if ranking is not None:
                    best, cost = ranking.solution(0)
                    cols_of[p], cost_of[p], ok_of[p] = part_cols[best], cost, True
            bases[:, rows] = cols_of[of_hypothesis]
            totals += cost_of[of_hypothesis]
            feasible &= ok_of[of_hypothesis]
        return bases, totals, feasible

    def _rank_together(self, used: list[list[int]]) -> None:
        """Rank the patterns ``used[b]`` of every varying block b not ranked yet, all blocks at once
        (``murty.subset_rankings``: the small sub-problems of equal row counts are worked on together)."""
        todo = [
            (b, p)
            for b, patterns in enumerate(used)
            if self.varying[b][4] is not None
            for p in patterns
            if (b, p) not in self._parts
        ]
        costs = [self.varying[b][4].cost for b, _ in todo]
        present = [self.varying[b][2][p] for b, p in todo]
        rankings = subset_rankings(costs, present, self.max_increase, self._blocks)
        for (b, p), keep, ranking in zip(todo, present, rankings, strict=True):
            rows, cols, *_ = self.varying[b]
            self._parts[(b, p)] = rows, cols[keep], ranking

    def _ranked(self, h: int, k: int, base: np.ndarray) -> list[tuple[np.ndarray, float]]:
        """The k best assignments of feasible hypothesis ``h``, whose best is ``base``."""
        common = self._common_summary()
        best_costs, steps = list(common.best_costs), list(common.steps)
        varying = []
        for b, (*_, pattern, _) in enumerate(self.varying):
            p = int(pattern[h])
            varying.append(self._varying_part(b, p))
            if (b, p) not in self._summaries:
                ranking = varying[-1][2]  # not None: a feasible hypothesis' parts are feasible
                best, second = ranking.solution(0)[1], ranking.solution(1)
                self._summaries[(b, p)] = best, None if second is None else second[1] - best
            best, step = self._summaries[(b, p)]
            best_costs.append(best)
            if step is not None:
                steps.append((step, len(self.common) + b))
        summary = PartsSummary(tuple(best_costs), tuple(steps))  # what PartsSummary.of(parts) works out
        product = Product(base, self.common + varying, self.max_increase, summary)
        out = []
        for i in range(k):
            found = product.solution(i)
            if found is None:
                break
            out.append(found)
        return out


class BestOnly:
    """The ranking of a block over the per-frame budget: its best assignment only (one Hungarian solve)."""

    def __init__(self, cost: np.ndarray):
        self._best = solve(cost)

    def solution(self, index: int) -> tuple[np.ndarray, float] | None:
        return self._best if index == 0 else None


def _common_parts(
    cost: np.ndarray,
    found: list[Cluster],
    wanted: np.ndarray,
    present: np.ndarray,
    max_increase: float,
    max_block_rows: int,
    cache: BlockCache,
) -> dict[int, tuple[np.ndarray, np.ndarray, Ranking | None]]:
    """(rows, columns, ranking or None if infeasible) of every ``wanted`` block of ``found`` cut to its
    ``present`` columns, by block index: ``murty.rank`` of the cut matrix up to ``max_increase`` above its best,
    all blocks within the per-frame budget together (``murty.subset_rankings``), or ``_best_only_part``."""
    out: dict[int, tuple[np.ndarray, np.ndarray, Ranking | None]] = {}
    ranked = []
    for b in np.flatnonzero(wanted).tolist():
        rows, cols = found[b]
        if len(rows) > max_block_rows:
            out[b] = _best_only_part(cost, rows, cols, present[cols])
        else:
            ranked.append(b)
    costs = [cost[found[b][0][:, None], found[b][1]] for b in ranked]
    keep = [present[found[b][1]] for b in ranked]
    for b, kept, ranking in zip(ranked, keep, subset_rankings(costs, keep, max_increase, cache), strict=True):
        rows, cols = found[b]
        out[b] = rows, cols[kept], ranking
    return out


def _presence_patterns(
    has_column: np.ndarray, found: list[Cluster], wanted: np.ndarray
) -> dict[int, tuple[np.ndarray, np.ndarray]]:
    """Per ``wanted`` block b of ``found``: ``np.unique(_row_keys(has_column[:, cols]), return_index=True,
    return_inverse=True)``'s first occurrences (P,) and inverse (H,): the hypotheses that first hold each
    distinct set of the block's columns, in the order of the sets' keys, and each hypothesis' set. The blocks of
    at most 64 columns are done together: their keys, sorted column by column (stable, so a set's first
    hypothesis leads it)."""
    out: dict[int, tuple[np.ndarray, np.ndarray]] = {}
    narrow = []
    for b in np.flatnonzero(wanted).tolist():
        cols = found[b][1]
        if len(cols) <= 64:
            narrow.append(b)
            continue
        _, first, pattern = np.unique(_row_keys(has_column[:, cols]), return_index=True, return_inverse=True)
        out[b] = first, pattern.ravel()
    if not narrow:
        return out
    widths = [len(found[b][1]) for b in narrow]
    cols = np.concatenate([found[b][1] for b in narrow])
    starts = np.cumsum(widths) - widths
    shift = (63 - (np.arange(len(cols)) - np.repeat(starts, widths))).astype(np.uint64)
    bits = has_column[:, cols].astype(np.uint64) << shift  # column i of a block at bit 63 - i: ``_row_keys``
    keys = np.bitwise_or.reduceat(bits, starts, axis=1)  # (H, blocks)
    order = np.argsort(keys, axis=0, kind="stable")
    ordered = np.take_along_axis(keys, order, axis=0)
    starts_set = np.ones(keys.shape, dtype=bool)
    starts_set[1:] = ordered[1:] != ordered[:-1]
    pattern = np.empty(keys.shape, dtype=np.int64)
    np.put_along_axis(pattern, order, np.cumsum(starts_set, axis=0) - 1, axis=0)
    for i, b in enumerate(narrow):
        out[b] = order[starts_set[:, i], i], pattern[:, i]
    return out


def _row_keys(present: np.ndarray) -> np.ndarray:
    """(H,) one sortable key per row of an (H, C) bool array, ordered as the rows' packed bytes compare
    (memcmp): the packed bytes as a void scalar, or, for C <= 64, as one big-endian uint64 (zero-padded), which
    ``np.unique`` sorts much faster and in the same order."""
    packed = np.packbits(present, axis=1)
    if packed.shape[1] <= 8:
        padded = np.zeros((len(packed), 8), dtype=np.uint8)
        padded[:, : packed.shape[1]] = packed
        return padded.view(">u8").ravel()
    packed = np.ascontiguousarray(packed)
    return packed.view(np.dtype((np.void, packed.shape[1]))).ravel()


def _best_only_part(
    cost: np.ndarray, rows: np.ndarray, cols: np.ndarray, present: np.ndarray
) -> tuple[np.ndarray, np.ndarray, Ranking | None]:
    """(rows, columns, ranking) of a block of the union matrix over the per-frame budget, with only its
    ``present`` columns: its best assignment alone (``BestOnly``), or None if that sub-problem has none."""
    sub_cols = cols[present]
    try:
        return rows, sub_cols, BestOnly(cost[np.ix_(rows, sub_cols)])
    except InfeasibleAssignment:
        return rows, sub_cols, None


def _merge_identical(
    children: list[_Child], union: LocalHypotheses, members: list[np.ndarray], ctx: UpdateContext
) -> list[_Child]:
    """Children that hold the same Bernoullis once those below ``ctx.prune_existence`` are dropped, merged
    into the first of them (log weights added with logaddexp); order of first appearance is kept.

    Without pruning no two children are identical (their parents differ in some Bernoulli, whose descendant
    they keep; siblings differ in some measurement's fate), so signatures are only computed when a child can
    lose a Bernoulli to pruning: a missed one below the threshold, or a birth below it.
    """
    threshold = ctx.prune_existence
    low_miss = union.miss_existence < threshold
    low_birth = union.new.existence < threshold
    if len(children) == 1 or not (low_miss.any() or low_birth.any()):
        return children
    signatures = _signatures(
        np.stack([c.col_of_row for c in children]),
        np.array([c.parent for c in children]),
        members,
        low_miss,
        low_birth,
    )
    first_of: dict[bytes, int] = {}
    merged: list[_Child] = []
    for child, signature in zip(children, signatures, strict=True):
        at = first_of.get(signature)
        if at is None:
            first_of[signature] = len(merged)
            merged.append(child)
        else:
            into = merged[at]
            merged[at] = _Child(
                float(np.logaddexp(into.log_weight, child.log_weight)),
                into.parent,
                into.col_of_row,
                into.total_cost,
            )
    return merged


def _drop_duplicate_births(
    children: list[_Child], union: LocalHypotheses, members: list[np.ndarray], min_existence: float
) -> list[_Child]:
    """The children without those, other than the heaviest, in which a measurement starts a Bernoulli inside the
    gate of a Bernoulli of predicted existence >= ``min_existence`` that the same child leaves missed: the
    object's own detection told as a second object beside its missed track (``docs/results.md``, Rounds 8 and
    18). Order is kept."""
    n_union = union.n_tracks
    sure = union.prior.existence >= min_existence  # (U,)
    heaviest = int(np.argmax([c.log_weight for c in children]))
    kept: list[_Child] = []
    for i, child in enumerate(children):
        born = np.flatnonzero(child.col_of_row >= n_union)  # rows starting a Bernoulli
        if i != heaviest and len(born):
            missed = np.zeros(n_union, dtype=bool)
            missed[members[child.parent]] = True
            missed[child.col_of_row[child.col_of_row < n_union]] = False
            if union.inside[np.ix_(missed & sure, born)].any():
                continue
        kept.append(child)
    return kept


def _signatures(
    assignments: np.ndarray,
    parents: np.ndarray,
    members: list[np.ndarray],
    low_miss: np.ndarray,
    low_birth: np.ndarray,
) -> list[bytes]:
    """One signature per child: its assignment (M,) in union columns, its parent holding union Bernoullis
    ``members[parent]``. Per union Bernoulli: 0 when absent or pruned, 1 when missed, j + 2 when detected by
    measurement j; then the births that survive pruning. Equal signatures = equal Bernoulli sets after
    pruning."""
    n_meas = assignments.shape[1]
    n_union = len(low_miss)
    present = np.zeros((len(members), n_union), dtype=bool)
    for h, index in enumerate(members):
        present[h, index] = True
    state = (present[parents] & ~low_miss).astype(np.int32)
    child, row = np.divmod(np.flatnonzero(assignments < n_union), n_meas)
    state[child, assignments[child, row]] = row + 2
    births = np.packbits((assignments == n_union + np.arange(n_meas)) & ~low_birth, axis=1)
    return [a.tobytes() + b.tobytes() for a, b in zip(state, births, strict=True)]


def _emit(
    total_cost: float,
    col_of_row: np.ndarray,
    local: LocalHypotheses,
    parent: int,
    posteriors: list[GlobalHypothesis],
    parents: tuple[int, ...],
    ctx: UpdateContext,
) -> None:
    """The best child's ``Assignment`` (``col_of_row`` over the ``local`` columns of its prior hypothesis
    ``parent``, whose ``CostMatrix`` has ``hypothesis=parent``) and the ``GlobalHypotheses`` as the core will keep
    them (after pruning), with each one's prior hypothesis (``parents``)."""
    pairs, missed = assignment_pairs(local, col_of_row)
    ctx.sink.emit(Assignment(ctx.class_name, pairs, total_cost, missed, hypothesis=parent))
    alive = [h.without_existence_below(ctx.prune_existence) for h in posteriors]
    ctx.sink.emit(
        GlobalHypotheses(
            ctx.class_name,
            log_weights=np.array([h.log_weight for h in posteriors]),
            members=tuple(tuple(h.track_id.tolist()) for h in alive),
            local=tuple(tuple(h.local_key.tolist()) for h in alive),
            existence=tuple(tuple(h.existence.tolist()) for h in alive),
            parents=parents,
        )
    )
