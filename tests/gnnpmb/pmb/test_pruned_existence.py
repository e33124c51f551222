import math
from types import SimpleNamespace

import numpy as np

from gnnpmb.pmb.core import _max_existence


def _hypothesis(track_ids: list[int], existence: list[float]) -> SimpleNamespace:
    """The parts of a ``GlobalHypothesis`` that ``_max_existence`` reads (its own store: no shared rows)."""
    return SimpleNamespace(
        store=object(), index=None, track_id=np.array(track_ids, dtype=np.int64), existence=np.array(existence)
    )


def _reference(hypotheses: list[SimpleNamespace]) -> dict[int, float]:
    out: dict[int, float] = {}
    for h in hypotheses:
        for t, r in zip(h.track_id.tolist(), h.existence.tolist(), strict=True):
            out[t] = max(out.get(t, 0.0), r)
    return out


def test_max_existence_equals_the_largest_value_per_track_floored_at_zero():
    rng = np.random.default_rng(7)
    cases = [
        [_hypothesis([4, 9, 2], [0.5, 1e-7, 0.0])],  # one hypothesis, distinct ids (GNN-PMB)
        [_hypothesis([4, 4, 2], [0.2, 0.7, 0.1])],  # repeated id
        [_hypothesis([1, 2], [0.3, 0.9]), _hypothesis([2, 3], [0.95, 0.0])],
        [_hypothesis(rng.integers(0, 40, 300).tolist(), rng.random(300).tolist()) for _ in range(3)],  # > 512 rows
    ]
    for hypotheses in cases:
        assert _max_existence(hypotheses) == _reference(hypotheses)


def test_max_existence_gives_zero_not_negative_zero():
    (value,) = _max_existence([_hypothesis([5], [-0.0])]).values()
    assert value == 0.0 and math.copysign(1.0, value) == 1.0
