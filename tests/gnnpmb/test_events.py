import numpy as np

from gnnpmb import events
from gnnpmb.events import AxisKind, AxisLabel, axis_labels, label_positions


def test_axis_labels_equal_constructed_labels_for_arrays_and_lists():
    refs = np.array([7, 3, 7, 120], dtype=np.int64)
    expected = tuple(AxisLabel(AxisKind.TRACK, int(r)) for r in refs)
    assert axis_labels(AxisKind.TRACK, refs) == expected
    assert axis_labels(AxisKind.TRACK, refs.tolist()) == expected
    assert axis_labels(AxisKind.NEW_TRACK, refs)[0] == AxisLabel(AxisKind.NEW_TRACK, 7)
    assert axis_labels(AxisKind.MEASUREMENT, np.zeros(0, dtype=np.int64)) == ()
    assert all(type(label.ref) is int for label in axis_labels(AxisKind.TRACK, refs))


def test_axis_labels_are_cached_per_kind_and_the_cache_is_bounded(monkeypatch):
    first = axis_labels(AxisKind.MISSED, [5])[0]
    assert axis_labels(AxisKind.MISSED, np.array([5]))[0] is first
    monkeypatch.setattr(events, "_LABEL_CACHE_MAX", 2)
    labels = axis_labels(AxisKind.MISSED, [1, 2, 3, 4])
    assert labels == tuple(AxisLabel(AxisKind.MISSED, r) for r in (1, 2, 3, 4))
    assert len(events._LABELS[AxisKind.MISSED]) <= 2


def test_label_positions_match_a_dict_per_kind_last_label_wins():
    rng = np.random.default_rng(3)
    kinds = list(AxisKind)
    pairs = zip(rng.integers(0, 4, 60).tolist(), rng.integers(0, 9, 60).tolist(), strict=True)
    labels = [AxisLabel(kinds[k], r) for k, r in pairs]
    expected: dict[AxisKind, dict[int, int]] = {}
    for j, label in enumerate(labels):
        expected.setdefault(label.kind, {})[label.ref] = j
    assert label_positions(labels) == expected
    assert label_positions(()) == {}
