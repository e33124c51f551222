"""Row buffering: the Arrow arrays built for a flush equal Rerun's own conversion."""

from __future__ import annotations

import numpy as np
from rerun.components import LineStrip3DBatch

from viz.rows import _strips_array


def test_strips_built_at_once_equal_rerun_s_own_conversion() -> None:
    rng = np.random.default_rng(0)
    ragged = [rng.normal(size=(k, 3)) for k in (2, 5, 1, 11)]
    same_length = rng.normal(size=(3, 33, 3))
    rows = [ragged, same_length, [], [[(0.0, 1.0, 2.0), (3.0, 4.0, 5.0)]]]
    flat = [*ragged, *same_length, np.array([[0.0, 1.0, 2.0], [3.0, 4.0, 5.0]])]
    assert _strips_array(rows).equals(LineStrip3DBatch(flat).as_arrow_array())
    assert _strips_array([]).equals(LineStrip3DBatch([]).as_arrow_array())
