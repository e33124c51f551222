"""Global hypotheses that index one shared Bernoulli store (``core.GlobalHypothesis`` with ``index``) behave as
hypotheses that hold their own copies: same union, same members, same pruning."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from gnnpmb.detection_fields import DetectionFields
from gnnpmb.pmb.bernoulli import Bernoullis
from gnnpmb.pmb.core import GlobalHypothesis, _without_existence_below, hypothesis_union


def random_store(rng: np.random.Generator, n: int, keys: np.ndarray) -> Bernoullis:
    return Bernoullis(
        track_id=rng.integers(0, 50, size=n),
        local_key=keys,
        existence=rng.random(n),
        mean=rng.normal(size=(n, 4)),
        cov=rng.normal(size=(n, 4, 4)),
        det=DetectionFields(
            score=rng.random(n),
            z_m=rng.random(n),
            size_wlh_m=rng.random((n, 3)),
            quat_wxyz=rng.random((n, 4)),
            meas_index=rng.integers(-1, 5, size=n),
        ),
        misses=np.zeros(n, dtype=np.int64),
        detected_score_sum=np.zeros(n),
        detected_frames=np.zeros(n, dtype=np.int64),
    )


def assert_same_bernoullis(a: Bernoullis, b: Bernoullis) -> None:
    for field in dataclasses.fields(Bernoullis):
        x, y = getattr(a, field.name), getattr(b, field.name)
        if isinstance(x, DetectionFields):
            for inner in dataclasses.fields(DetectionFields):
                np.testing.assert_array_equal(getattr(x, inner.name), getattr(y, inner.name))
        else:
            np.testing.assert_array_equal(x, y)


@pytest.mark.parametrize("duplicate_keys", [False, True])
def test_union_of_indexed_hypotheses_equals_union_of_their_copies(duplicate_keys):
    rng = np.random.default_rng(2)
    for _ in range(50):
        n = int(rng.integers(1, 30))
        keys = rng.permutation(10 * n)[:n].astype(np.int64) - 5 * n
        store = random_store(rng, n, keys)
        if duplicate_keys:  # rows with equal keys hold equal Bernoullis (a key names one component)
            copy_from = rng.integers(0, n, size=n)
            store = store.subset(copy_from)
        indexed = [
            GlobalHypothesis(float(rng.normal()), store, rng.permutation(n)[: int(rng.integers(0, n + 1))])
            for _ in range(int(rng.integers(2, 6)))
        ]
        copies = [GlobalHypothesis(h.log_weight, h.bernoullis) for h in indexed]
        union, members = hypothesis_union(indexed)
        want_union, want_members = hypothesis_union(copies)
        assert_same_bernoullis(union, want_union)
        assert [m.tolist() for m in members] == [m.tolist() for m in want_members]
        for h, m in zip(indexed, members, strict=True):
            assert_same_bernoullis(union.subset(m), h.bernoullis)


def test_pruning_an_indexed_hypothesis_equals_pruning_its_copy():
    rng = np.random.default_rng(6)
    store = random_store(rng, 12, np.arange(12, dtype=np.int64))
    for _ in range(20):
        h = GlobalHypothesis(0.0, store, rng.permutation(12)[:7])
        threshold = float(rng.random())
        indexed = h.without_existence_below(threshold)
        copied = GlobalHypothesis(0.0, h.bernoullis).without_existence_below(threshold)
        assert_same_bernoullis(indexed.bernoullis, copied.bernoullis)
        assert indexed.n_bernoullis == copied.n_bernoullis == int((h.bernoullis.existence >= threshold).sum())
    assert GlobalHypothesis(0.0, store, np.arange(3)).without_existence_below(0.0).index is not None


def test_pruning_hypotheses_of_one_store_at_once_equals_pruning_each():
    rng = np.random.default_rng(7)
    store = random_store(rng, 12, np.arange(12, dtype=np.int64))
    for threshold in [0.0, *rng.random(10).tolist(), 1.5]:
        hypotheses = [GlobalHypothesis(float(w), store, rng.permutation(12)[:7]) for w in rng.random(5)]
        want = [h.without_existence_below(threshold) for h in hypotheses]
        got = _without_existence_below(hypotheses, threshold)
        unchanged = [w is h for w, h in zip(want, hypotheses, strict=True)]
        assert [g is h for g, h in zip(got, hypotheses, strict=True)] == unchanged
        for g, w in zip(got, want, strict=True):
            assert g.log_weight == w.log_weight and g.index.tolist() == w.index.tolist()
