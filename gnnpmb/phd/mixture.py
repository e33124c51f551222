"""Labelled Gaussian mixtures for the GM-PHD / GM-CPHD filters, and their reduction (prune, merge, cap).

A PHD intensity is v(x) = sum_i w_i N(x; m_i, P_i) (Vo & Ma 2006, eq. 22). Besides its Gaussian, every component
carries a *label* (the track id it reports under, negative while provisional, see ``gmphd``) and the box fields of
the detection that last updated it (z, size, rotation, score), which pass through to the output (paper sec. V-B).

Reduction follows Vo & Ma 2006, Table II:

1. prune: drop every component with w_i < T;
2. merge: repeatedly take the heaviest remaining component j, gather every remaining i with
   (m_i - m_j)^T P_i^-1 (m_i - m_j) <= U, and replace the group L by its moment-matched Gaussian
   w = sum_L w_i,  m = sum_L w_i m_i / w,  P = sum_L w_i (P_i + (m - m_i)(m - m_i)^T) / w;
   the merged component keeps the label and box fields of j (the heaviest member);
3. cap: keep the J_max heaviest components.

Every step reports what it removed (labels, weights, ``PruneReason``) so the tracker can emit ``Pruned`` and
``Merged`` events.

References: B.-N. Vo and W.-K. Ma, "The Gaussian mixture probability hypothesis density filter", IEEE Trans.
Signal Processing 54(11), 2006.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from gnnpmb.detection_fields import CarriesDetectionFields, DetectionFields
from gnnpmb.events import PruneReason
from gnnpmb.kalman import symmetrize
from gnnpmb.soa import StructOfArrays


@dataclass(frozen=True, slots=True)
class GaussianMixture(CarriesDetectionFields, StructOfArrays):
    """K labelled Gaussian components, struct-of-arrays.

    weight: (K,) w_i >= 0; mean: (K, 4) [x, y, vx, vy]; cov: (K, 4, 4); label: (K,) int64 track label (< 0 =
    provisional, never extracted); det: the fields of the detection that last updated the component
    (``score``, ``z_m``, ... read through as the mixture's own; ``meas_index`` -1 unless updated this frame).
    """

    weight: np.ndarray
    mean: np.ndarray
    cov: np.ndarray
    label: np.ndarray
    det: DetectionFields

    def __len__(self) -> int:
        return int(self.weight.shape[0])

    @staticmethod
    def empty() -> GaussianMixture:
        return GaussianMixture(
            weight=np.zeros(0),
            mean=np.zeros((0, 4)),
            cov=np.zeros((0, 4, 4)),
            label=np.zeros(0, dtype=np.int64),
            det=DetectionFields.empty(),
        )


@dataclass(frozen=True, slots=True)
class MergeGroup:
    """Components of different labels merged into one: the result keeps ``into_label`` (the heaviest member's).

    from_labels / weights: every member, heaviest first (the first is ``into_label``).
    """

    into_label: int
    from_labels: tuple[int, ...]
    weights: tuple[float, ...]


@dataclass(frozen=True, slots=True)
class Removal:
    """Components of one reduction step that left the mixture: labels (R,), weights (R,) and why."""

    reason: PruneReason
    labels: np.ndarray
    weights: np.ndarray


@dataclass(frozen=True, slots=True)
class LostLabel:
    """A label no component carries any more: the reason and weight of its heaviest removed component."""

    label: int
    reason: PruneReason
    weight: float


@dataclass(frozen=True, slots=True)
class Reduction:
    """Result of ``reduce_mixture``: the reduced mixture (sorted by decreasing weight), the merge grouping and the
    components removed by each step (prune, merge, cap)."""

    mixture: GaussianMixture
    merge_record: MergeRecord
    removals: tuple[Removal, ...]

    def merges(self) -> tuple[MergeGroup, ...]:
        """Merges of components with different labels (``MergeRecord.groups``)."""
        return self.merge_record.groups()

    def lost_labels(self) -> tuple[LostLabel, ...]:
        """Labels removed by the reduction that no remaining component carries, in increasing label order.

        A label that lost several components reports its heaviest removed one (reason and weight)."""
        parts = [r for r in self.removals if len(r.labels)]
        if not parts:
            return ()
        labels = np.concatenate([r.labels for r in parts])
        weights = np.concatenate([r.weights for r in parts])
        reasons = np.concatenate([np.full(len(r.labels), i) for i, r in enumerate(parts)])
        gone = ~np.isin(labels, self.mixture.label)
        labels, weights, reasons = labels[gone], weights[gone], reasons[gone]
        order = np.lexsort((-weights, labels))  # by label, heaviest first within a label
        first = np.ones(len(order), dtype=bool)
        first[1:] = labels[order][1:] != labels[order][:-1]
        return tuple(LostLabel(int(labels[i]), parts[int(reasons[i])].reason, float(weights[i])) for i in order[first])


def prune(mix: GaussianMixture, threshold: float) -> tuple[GaussianMixture, Removal]:
    """Drop components with w < threshold (Vo & Ma 2006, Table II, step 1)."""
    keep = mix.weight >= threshold
    gone = ~keep
    return mix.subset(keep), Removal(PruneReason.LOW_WEIGHT, mix.label[gone], mix.weight[gone])


def pairwise_mahalanobis2(mean: np.ndarray, cov: np.ndarray) -> np.ndarray:
    """(K, K) D[j, i] = (m_i - m_j)^T P_i^-1 (m_i - m_j) for means (K, 4) and covariances (K, 4, 4).

    Expanded as c_j^T A_i c_j - 2 c_j^T A_i c_i + c_i^T A_i c_i with A_i = P_i^-1 and c the means centred on
    their average (which keeps the expansion free of cancellation in global coordinates), so the K x K matrix
    costs two matrix products.
    """
    k, dim = mean.shape
    c = mean - mean.mean(axis=0)
    A = symmetrize(np.linalg.inv(cov))
    Ac = np.einsum("iab,ib->ia", A, c)
    self_term = np.einsum("ia,ia->i", c, Ac)
    outer = (c[:, :, None] * c[:, None, :]).reshape(k, dim * dim)
    d2 = outer @ A.reshape(k, dim * dim).T - 2.0 * (c @ Ac.T) + self_term[None, :]
    return np.maximum(d2, 0.0)


@dataclass(frozen=True, slots=True)
class MergeRecord:
    """How ``merge`` grouped its K input components into G output components: labels (K,), weights (K,) of the
    input, group (K,) the output component each went into, lead (G,) the input index of each group's leader."""

    labels: np.ndarray
    weights: np.ndarray
    group: np.ndarray
    lead: np.ndarray

    def groups(self) -> tuple[MergeGroup, ...]:
        """MergeGroup of every group whose members carry more than one distinct label (built on demand)."""
        if len(self.lead) == len(self.group):
            return ()
        order = np.lexsort((-self.weights, self.group))
        g_sorted = self.group[order]
        starts = np.flatnonzero(np.r_[True, g_sorted[1:] != g_sorted[:-1]])
        ends = np.r_[starts[1:], len(order)]
        out: list[MergeGroup] = []
        for s, e in zip(starts.tolist(), ends.tolist(), strict=True):
            members = order[s:e]
            labels = self.labels[members]
            if e - s < 2 or np.all(labels == labels[0]):
                continue
            out.append(
                MergeGroup(
                    into_label=int(self.labels[self.lead[g_sorted[s]]]),
                    from_labels=tuple(int(v) for v in labels),
                    weights=tuple(float(v) for v in self.weights[members]),
                )
            )
        return tuple(out)


def greedy_groups(weight: np.ndarray, close: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Vo & Ma's greedy grouping: visit components by decreasing weight (ties by index); an unassigned one
    leads a new group that takes every unassigned i with close[leader, i]. Returns group (K,) and lead (G,)."""
    k = len(weight)
    rows, cols = np.nonzero(close)
    neighbours: list[list[int]] = [[] for _ in range(k)]
    for a, b in zip(rows.tolist(), cols.tolist(), strict=True):
        neighbours[a].append(b)
    group = [-1] * k
    leaders: list[int] = []
    for j in np.argsort(-weight, kind="stable").tolist():
        if group[j] >= 0:
            continue
        g = len(leaders)
        group[j] = g
        leaders.append(j)
        for i in neighbours[j]:
            if group[i] < 0:
                group[i] = g
    return np.asarray(group, dtype=np.int64), np.asarray(leaders, dtype=np.int64)


def merge(mix: GaussianMixture, threshold: float) -> tuple[GaussianMixture, MergeRecord, Removal]:
    """Greedy moment-matching merge (Vo & Ma 2006, Table II, step 2; module docstring).

    Components are visited by decreasing weight (ties by index, so the result is deterministic). Returns the
    merged mixture (one component per group, in visiting order of the group leaders), the grouping, and the
    absorbed (non-leader) components.
    """
    k = len(mix)
    if k <= 1:
        record = MergeRecord(mix.label, mix.weight, np.zeros(k, dtype=np.int64), np.zeros(k, dtype=np.int64))
        return mix, record, Removal(PruneReason.MERGED, np.zeros(0, dtype=np.int64), np.zeros(0))
    close = pairwise_mahalanobis2(mix.mean, mix.cov) <= threshold
    np.fill_diagonal(close, False)
    group, lead = greedy_groups(mix.weight, close)
    record = MergeRecord(mix.label, mix.weight, group, lead)
    n_groups = len(lead)
    absorbed = np.ones(k, dtype=bool)
    absorbed[lead] = False
    removal = Removal(PruneReason.MERGED, mix.label[absorbed], mix.weight[absorbed])
    leader_fields = mix.subset(lead)
    if n_groups == k:
        return leader_fields, record, removal

    w = mix.weight
    total = np.bincount(group, weights=w, minlength=n_groups)
    safe_total = np.where(total > 0.0, total, 1.0)
    mean = np.zeros((n_groups, mix.mean.shape[1]))
    np.add.at(mean, group, w[:, None] * mix.mean)
    mean /= safe_total[:, None]
    spread = mean[group] - mix.mean
    cov = np.zeros((n_groups,) + mix.cov.shape[1:])
    np.add.at(cov, group, w[:, None, None] * (mix.cov + spread[:, :, None] * spread[:, None, :]))
    cov = symmetrize(cov / safe_total[:, None, None])
    single = np.bincount(group, minlength=n_groups) == 1
    cov[single] = leader_fields.cov[single]
    mean[single] = leader_fields.mean[single]
    merged = replace(leader_fields, weight=total, mean=mean, cov=cov)
    return merged, record, removal


def cap(mix: GaussianMixture, max_components: int) -> tuple[GaussianMixture, Removal]:
    """Keep the ``max_components`` heaviest components, sorted by decreasing weight (ties by index)
    (Vo & Ma 2006, Table II, step 3)."""
    order = np.argsort(-mix.weight, kind="stable")
    keep, gone = order[:max_components], order[max_components:]
    return mix.subset(keep), Removal(PruneReason.CAPPED, mix.label[gone], mix.weight[gone])


def reduce_mixture(mix: GaussianMixture, prune_weight: float, merge_threshold: float, max_components: int) -> Reduction:
    """Prune, merge and cap (Vo & Ma 2006, Table II); the result is sorted by decreasing weight."""
    pruned, low = prune(mix, prune_weight)
    merged, record, absorbed = merge(pruned, merge_threshold)
    capped, over = cap(merged, max_components)
    return Reduction(mixture=capped, merge_record=record, removals=(low, absorbed, over))
