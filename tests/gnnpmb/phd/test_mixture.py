"""Gaussian-mixture reduction against hand computations (Vo & Ma 2006, Table II)."""

from __future__ import annotations

import numpy as np
import pytest

from gnnpmb.detection_fields import DetectionFields
from gnnpmb.events import PruneReason
from gnnpmb.phd.mixture import (
    GaussianMixture,
    cap,
    merge,
    pairwise_mahalanobis2,
    prune,
    reduce_mixture,
)


def make_mixture(weights, means, covs=None, labels=None) -> GaussianMixture:
    k = len(weights)
    means = np.asarray(means, dtype=float).reshape(k, 4)
    covs = np.tile(np.eye(4), (k, 1, 1)) if covs is None else np.asarray(covs, dtype=float)
    return GaussianMixture(
        weight=np.asarray(weights, dtype=float),
        mean=means,
        cov=covs,
        label=np.arange(1, k + 1, dtype=np.int64) if labels is None else np.asarray(labels, dtype=np.int64),
        det=DetectionFields(
            score=np.linspace(0.5, 0.9, k),
            z_m=np.arange(k, dtype=float),
            size_wlh_m=np.tile([2.0, 4.5, 1.6], (k, 1)),
            quat_wxyz=np.tile([1.0, 0.0, 0.0, 0.0], (k, 1)),
            meas_index=np.arange(k, dtype=np.int64),
        ),
    )


def random_spd(rng: np.random.Generator, k: int) -> np.ndarray:
    a = rng.normal(size=(k, 4, 4))
    return a @ np.swapaxes(a, 1, 2) + 0.1 * np.eye(4)


def test_pairwise_mahalanobis_matches_direct_loop_in_global_coordinates():
    rng = np.random.default_rng(3)
    k = 7
    mean = rng.normal(size=(k, 4)) * 5.0 + np.array([1500.0, -800.0, 0.0, 0.0])
    cov = random_spd(rng, k)
    d2 = pairwise_mahalanobis2(mean, cov)
    for j in range(k):
        for i in range(k):
            diff = mean[i] - mean[j]
            assert d2[j, i] == pytest.approx(diff @ np.linalg.solve(cov[i], diff), rel=1e-9, abs=1e-8)


def test_prune_drops_light_components_and_reports_them():
    mix = make_mixture([0.5, 1e-6, 0.02], np.zeros((3, 4)), labels=[4, 7, 9])
    kept, removal = prune(mix, 1e-5)
    assert kept.label.tolist() == [4, 9]
    assert removal.reason is PruneReason.LOW_WEIGHT
    assert removal.labels.tolist() == [7] and removal.weights.tolist() == [1e-6]


def test_merge_moment_matches_close_components_and_keeps_heaviest_label():
    means = [[0.0, 0.0, 1.0, 0.0], [1.0, 0.0, 1.0, 0.0], [50.0, 0.0, 0.0, 0.0]]
    mix = make_mixture([0.3, 0.6, 0.9], means, labels=[11, 12, 13])
    merged, record, removal = merge(mix, 4.0)
    # component 2 (w 0.9) leads alone; then 1 (w 0.6) absorbs 0 (d2 = 1 <= 4)
    assert merged.label.tolist() == [13, 12]
    w = 0.3 + 0.6
    m = (0.3 * np.array(means[0]) + 0.6 * np.array(means[1])) / w
    pairs = zip([0.3, 0.6], np.array(means[:2]), strict=True)
    cov = sum(wi * (np.eye(4) + np.outer(m - mi, m - mi)) for wi, mi in pairs) / w
    assert merged.weight[1] == pytest.approx(w)
    np.testing.assert_allclose(merged.mean[1], m, atol=1e-12)
    np.testing.assert_allclose(merged.cov[1], cov, atol=1e-12)
    np.testing.assert_array_equal(merged.cov[0], np.eye(4))
    # box fields come from the heaviest member (index 1)
    assert merged.score[1] == mix.score[1] and merged.z_m[1] == mix.z_m[1]
    groups = record.groups()
    assert len(groups) == 1
    assert groups[0].into_label == 12 and groups[0].from_labels == (12, 11) and groups[0].weights == (0.6, 0.3)
    assert removal.reason is PruneReason.MERGED and removal.labels.tolist() == [11]


def test_merge_is_greedy_from_the_heaviest_and_uses_the_candidate_covariance():
    # A (heaviest) at 0, B at 1.5, C at 3: B joins A (d2 = 2.25); C is 3 from A (d2 = 9), so it stays alone
    # although it is within 1.5 of B.
    means = [[0.0, 0, 0, 0], [1.5, 0, 0, 0], [3.0, 0, 0, 0]]
    mix = make_mixture([1.0, 0.5, 0.4], means)
    merged, _, _ = merge(mix, 4.0)
    assert merged.label.tolist() == [1, 3]
    # the distance is measured with the covariance of the candidate: a wide candidate joins a tight leader
    covs = np.stack([0.01 * np.eye(4), 100.0 * np.eye(4)])
    far_wide = make_mixture([1.0, 0.5], [[0.0, 0, 0, 0], [10.0, 0, 0, 0]], covs)
    merged, _, _ = merge(far_wide, 4.0)
    assert len(merged) == 1


def test_merge_of_same_label_components_is_not_reported_as_a_label_merge():
    mix = make_mixture([0.9, 0.1], [[0.0, 0, 0, 0], [0.5, 0, 0, 0]], labels=[5, 5])
    merged, record, _ = merge(mix, 4.0)
    assert len(merged) == 1 and merged.weight[0] == pytest.approx(1.0)
    assert record.groups() == ()


def test_cap_keeps_heaviest_sorted():
    mix = make_mixture([0.1, 0.9, 0.5, 0.7], np.arange(16.0).reshape(4, 4) * 10)
    kept, removal = cap(mix, 2)
    assert kept.weight.tolist() == [0.9, 0.7] and kept.label.tolist() == [2, 4]
    assert removal.reason is PruneReason.CAPPED and removal.labels.tolist() == [3, 1]


def test_reduce_reports_labels_that_vanished_with_their_heaviest_removed_component():
    means = np.zeros((6, 4))
    means[:, 0] = [0.0, 0.2, 40.0, 80.0, 120.0, 160.0]
    # label 1 absorbs label 2 (merge); label 3 has a light part pruned but survives through its other part;
    # label 4 is pruned entirely; label 5 is over the cap.
    mix = make_mixture([1.0, 0.4, 0.8, 1e-7, 0.3, 0.6], means, labels=[1, 2, 3, 4, 5, 3])
    mix = GaussianMixture(
        weight=np.append(mix.weight, 1e-8),
        mean=np.vstack([mix.mean, [[40.0, 0, 0, 0]]]),
        cov=np.concatenate([mix.cov, np.eye(4)[None]]),
        label=np.append(mix.label, 4),
        det=DetectionFields(
            score=np.append(mix.score, 0.5),
            z_m=np.append(mix.z_m, 0.0),
            size_wlh_m=np.vstack([mix.size_wlh_m, [[1.0, 1.0, 1.0]]]),
            quat_wxyz=np.vstack([mix.quat_wxyz, [[1.0, 0, 0, 0]]]),
            meas_index=np.append(mix.meas_index, -1),
        ),
    )
    red = reduce_mixture(mix, prune_weight=1e-5, merge_threshold=4.0, max_components=3)
    assert np.all(np.diff(red.mixture.weight) <= 0)
    assert red.mixture.label.tolist() == [1, 3, 3]
    lost = {x.label: (x.reason, x.weight) for x in red.lost_labels()}
    assert lost == {
        2: (PruneReason.MERGED, 0.4),
        4: (PruneReason.LOW_WEIGHT, 1e-7),
        5: (PruneReason.CAPPED, 0.3),
    }
    assert [g.into_label for g in red.merges()] == [1]
