"""The GNN-PMB hypothesis management strategy of the PMB family.

``BestAssignment`` is GNN-PMB (paper sec. IV): of all global hypotheses that follow from the single prior
hypothesis, keep only the most likely one, found as the optimal assignment of the cost matrix
(``cost.LocalHypotheses.cost_matrix``) by the Hungarian algorithm. The result is again a PMB density with one
global hypothesis, whose weight is therefore 1 (log 0). See ``pmbm.KBest`` (PMBM) and ``topmb.MarginalMerge`` (TO-PMB)
for the alternatives.
"""

from __future__ import annotations

from gnnpmb.assign.hungarian import solve
from gnnpmb.events import Assignment, Panel
from gnnpmb.pmb.core import GlobalHypothesis, UpdateContext, assignment_pairs, posterior_from_assignment
from gnnpmb.pmb.cost import LocalHypotheses


class BestAssignment:
    """GNN-PMB: the single best global hypothesis (Hungarian on the PMB cost matrix)."""

    name = "best-assignment"
    panels: tuple[Panel, ...] = ()
    chooses_assignment = True

    def update(
        self, priors: list[GlobalHypothesis], locals_: list[LocalHypotheses], ctx: UpdateContext
    ) -> list[GlobalHypothesis]:
        local = locals_[0]
        col_of_row, total = solve(local.cost_matrix())
        if ctx.sink.enabled:
            pairs, missed = assignment_pairs(local, col_of_row)
            ctx.sink.emit(Assignment(ctx.class_name, pairs, total, missed))
        return [GlobalHypothesis(0.0, posterior_from_assignment(local, col_of_row, ctx))]
