"""TO-PMB: the track-oriented PMB filter, which merges every local hypothesis by its marginal probability.

Williams, "Marginal multi-Bernoulli filters: RFS derivation of MHT, JIPDA and association-based MeMBer",
IEEE T-AES 51(3), 2015; the GNN-PMB paper (Liu et al., IEEE T-IV 2023), sec. III-C. Instead of keeping one
(GNN-PMB) or N_h (PMBM) global hypotheses, the PMBM posterior of the single prior hypothesis is approximated by
one PMB: each Bernoulli becomes the mixture of its single-target hypotheses weighted by their marginal
association probabilities, computed by loopy belief propagation (``gnnpmb.assign.lbp``).

Association weights (``cost`` module): ratio_kj = l_kj / l_k0 = exp(det_log_lik - miss_log_lik) and
new_weight_j = l_j = exp(new.log_likelihood). A joint association weighs prod_k ratio_{k,a_k} prod_{j unused} l_j
(times the constant prod_k l_k0), so only ratio and new weight *together* may be rescaled per measurement
(``assign.marginals``); the logs are handed to LBP, which normalises each column by l_j itself.

Posterior of existing Bernoulli k with marginals p_k0 (missed) and p_kj:
  r'_k = p_k0 r_k,miss + sum_j p_kj            (missed component keeps r_miss, detected ones have r = 1)
  x'_k ~ moment match of { beta_0 = p_k0 r_k,miss / r'_k: N(m_k, P_k);  beta_j = p_kj / r'_k: N(m_kj, P_k|z) },
i.e. mean = sum_c beta_c m_c and cov = sum_c beta_c (P_c + (m_c - mean)(m_c - mean)^T). Two close targets that
share two measurements therefore pull towards each other: this is the coalescence the paper attributes to TO-PMB,
and the ``Merged`` events show it. (LBP is the Bethe approximation: on such a 2 x 2 loop with confident
detections it leans towards the dominant assignment, so the pull is weaker than exact marginals would give.)
The box fields, score and meas_index come from the most probable single-target hypothesis (unchanged and -1
when "missed" is the most probable); the local key is ``combine_keys(parent key, that outcome)``.

New Bernoulli of measurement j: r = p_new_j r_j with the state of ``poisson.new_track_hypotheses``; it gets a
track id only when r > 0 reaches the pruning threshold (``UpdateContext.prune_existence``), so ids are not spent
on Bernoullis the core would prune at once.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from gnnpmb.assign.lbp import keep_most_likely, lbp_marginals_log
from gnnpmb.assign.marginals import AssociationMarginals
from gnnpmb.config import LbpParams
from gnnpmb.detection_fields import DetectionFields
from gnnpmb.events import Assignment, AxisKind, AxisLabel, Marginals, Merged, Panel, Pruned, PruneReason, axis_labels
from gnnpmb.kalman import symmetrize
from gnnpmb.pmb.bernoulli import Bernoullis
from gnnpmb.pmb.core import (
    GlobalHypothesis,
    UpdateContext,
    assignment_pairs,
    combine_keys,
    new_bernoullis,
)
from gnnpmb.pmb.cost import LocalHypotheses, detected_means

MAX_BERNOULLIS = 1500
"""Per-frame budget of TO-PMB: at most this many Bernoullis per class leave an update (the most likely, by
existence; ties keep the first). In a dense crowd every detection adds a birth each frame while missed
Bernoullis decay only by P_S per frame, so without a cap the LBP graph (and the time per frame) grows without
bound; the dropped ones are reported as ``Pruned`` (``CAPPED``). The demo data never reaches it."""

MAX_GATED_PER_TRACK = 32
"""Per-frame budget of TO-PMB: each Bernoulli's association is computed over at most this many gated
measurements (its most likely ones, by l_kj / l_k0); less likely ones get marginal 0. Bounds the LBP graph to
K x 32 edges when inflated gates span a crowd; the demo data never reaches it."""

MERGE_REPORT_WEIGHT = 0.05
"""A ``Merged`` event is emitted for a track when at least two of its components have at least this existence
mass (``Components``), so Bernoullis with negligible existence do not flood the event log."""


class MarginalMerge:
    """TO-PMB hypothesis strategy: marginal association probabilities by LBP, one merged Bernoulli per track."""

    name = "marginals"
    panels = (Panel.MARGINALS,)
    chooses_assignment = False

    def __init__(self, params: LbpParams, max_bernoullis: int = MAX_BERNOULLIS):
        if max_bernoullis < 1:
            raise ValueError(f"max_bernoullis must be >= 1, got {max_bernoullis}")
        self.params = params
        self.max_bernoullis = max_bernoullis

    def update(
        self, priors: list[GlobalHypothesis], locals_: list[LocalHypotheses], ctx: UpdateContext
    ) -> list[GlobalHypothesis]:
        """The single posterior PMB hypothesis (weight 1) from the single prior hypothesis ``locals_[0]``."""
        local = locals_[0]
        log_ratio = keep_most_likely(local.det_log_lik - local.miss_log_lik[:, None], MAX_GATED_PER_TRACK)
        marg = lbp_marginals_log(log_ratio, local.new.log_likelihood, self.params.max_iterations, self.params.tolerance)
        tracks, components = merged_bernoullis(local, marg)
        r_new = marg.p_new * local.new.existence
        new_j = np.flatnonzero((r_new > 0.0) & (r_new >= ctx.prune_existence))
        births = new_bernoullis(local, new_j, ctx)
        births = replace(births, existence=r_new[new_j]) if len(new_j) else births
        if ctx.sink.enabled:
            _emit(local, marg, components, ctx)
        posterior = Bernoullis.concatenate([tracks, births]) if len(births) else tracks  # keeps the state dimension
        return [GlobalHypothesis(0.0, _capped(posterior, self.max_bernoullis, ctx))]


def _capped(bernoullis: Bernoullis, limit: int, ctx: UpdateContext) -> Bernoullis:
    """The ``limit`` most likely Bernoullis (stable by existence, original order kept); the others are reported
    as ``Pruned`` with reason ``CAPPED`` (``MAX_BERNOULLIS``)."""
    if len(bernoullis) <= limit:
        return bernoullis
    order = np.argsort(-bernoullis.existence, kind="stable")
    keep = np.sort(order[:limit])
    if ctx.sink.enabled:
        for i in np.sort(order[limit:]).tolist():
            ctx.sink.emit(
                Pruned(
                    ctx.class_name,
                    int(bernoullis.track_id[i]),
                    PruneReason.CAPPED,
                    float(bernoullis.existence[i]),
                )
            )
    return bernoullis.subset(keep)


@dataclass(frozen=True, slots=True)
class Components:
    """The single-target hypotheses merged into each posterior Bernoulli, by the existence mass they contribute:
    missed (K,) = p_k0 r_k,miss, and detected (E,) = p_kj for the E (track, measurement) pairs with p_kj > 0,
    pair e being (track_index[e], meas_index[e]) in local indices. A track's masses sum to its posterior r."""

    missed: np.ndarray
    track_index: np.ndarray
    meas_index: np.ndarray
    detected: np.ndarray


def merged_bernoullis(local: LocalHypotheses, marg: AssociationMarginals) -> tuple[Bernoullis, Components]:
    """The K posterior Bernoullis of the existing tracks (module docstring) and the components merged into them."""
    prior, meas = local.prior, local.meas
    k = local.n_tracks
    p = marg.p_track
    det_k, det_j = np.nonzero(p[:, 1:] > 0.0)
    comp = Components(
        missed=p[:, 0] * local.miss_existence, track_index=det_k, meas_index=det_j, detected=p[det_k, det_j + 1]
    )
    r_sum = comp.missed + np.bincount(det_k, weights=comp.detected, minlength=k)
    alive = r_sum > 0.0
    norm = np.where(alive, r_sum, 1.0)
    b0 = np.where(alive, comp.missed / norm, 1.0)  # moment-matching weights beta
    bj = comp.detected / norm[det_k]
    det_mean = detected_means(local, det_k, det_j)  # (E, 4)
    mean = b0[:, None] * prior.mean
    np.add.at(mean, det_k, bj[:, None] * det_mean)
    d0 = prior.mean - mean
    d = det_mean - mean[det_k]
    cov = b0[:, None, None] * (prior.cov + d0[:, :, None] * d0[:, None, :])
    cov += (1.0 - b0)[:, None, None] * local.inn.cov_post
    np.add.at(cov, det_k, bj[:, None, None] * d[:, :, None] * d[:, None, :])

    best = np.argmax(p, axis=1)  # 0 = missed, j + 1 = measurement j
    hit = np.flatnonzero(best > 0)
    hit_j = best[hit] - 1
    tracks = Bernoullis(
        track_id=prior.track_id,
        local_key=combine_keys(prior.local_key, best),
        existence=np.clip(r_sum, 0.0, 1.0),
        mean=mean,
        cov=symmetrize(cov),
        det=prior.det.undetected().take(hit, DetectionFields.from_measurements(meas, hit_j)),
        misses=np.where(best > 0, 0, prior.misses),
        detected_score_sum=prior.detected_score_sum + np.bincount(hit, meas.boxes.score[hit_j], minlength=k),
        detected_frames=prior.detected_frames + (best > 0),
    )
    return tracks, comp


def _emit(local: LocalHypotheses, marg: AssociationMarginals, comp: Components, ctx: UpdateContext) -> None:
    """Marginals, Merged and Assignment events of one update.

    Marginals: rows = the prior tracks (TRACK, track id), columns = [MISSED (ref -1, shared by every row),
    MEASUREMENT (source index) ...]. Merged, for every track that merged >= 2 components of existence mass
    >= 0.05 (``Components``): into_id = the track id, from_ids = those components as measurement source indices
    (-1 = the missed component), weights = their masses (p_k0 r_k,miss for missed, p_kj for measurement j);
    lighter components are merged too but not listed. Assignment: every measurement paired with its most
    probable origin (an existing track, or NEW_TRACK = unassociated); several measurements may name one track.
    """
    meas, prior = local.meas, local.prior
    k, m = local.n_tracks, local.n_meas
    rows = axis_labels(AxisKind.TRACK, prior.track_id)
    cols = (AxisLabel(AxisKind.MISSED, -1),) + axis_labels(AxisKind.MEASUREMENT, meas.source_index)
    ctx.sink.emit(Marginals(ctx.class_name, marg.p_track, rows, cols, marg.method, marg.iterations))

    significant = comp.detected >= MERGE_REPORT_WEIGHT
    missed = comp.missed >= MERGE_REPORT_WEIGHT
    n_significant = missed + np.bincount(comp.track_index[significant], minlength=k)
    for i in np.flatnonzero(n_significant >= 2):
        edges = np.flatnonzero(significant & (comp.track_index == i))
        with_missed = int(missed[i])
        ctx.sink.emit(
            Merged(
                ctx.class_name,
                into_id=int(prior.track_id[i]),
                from_ids=(-1,) * with_missed + tuple(int(j) for j in meas.source_index[comp.meas_index[edges]]),
                weights=(float(comp.missed[i]),) * with_missed + tuple(float(w) for w in comp.detected[edges]),
            )
        )

    if m == 0:
        ctx.sink.emit(Assignment(ctx.class_name, (), 0.0, tuple(int(t) for t in prior.track_id)))
        return
    origin = np.concatenate([marg.p_track[:, 1:], marg.p_new[None, :]], axis=0)  # (K + 1, M)
    best = np.argmax(origin, axis=0)
    col_of_row = np.where(best < k, best, k + np.arange(m))
    pairs, missed = assignment_pairs(local, col_of_row)
    total = float(local.cost_matrix()[np.arange(m), col_of_row].sum())
    ctx.sink.emit(Assignment(ctx.class_name, pairs, total, missed))
