"""``gnnpmb.calibration``'s floors: a learnt process noise below the base configuration's is raised to it and says
so; one above it is written as learnt."""

from __future__ import annotations

import numpy as np
import pytest

from gnnpmb.calibration import process_noise
from gnnpmb.config import TrackerConfig


def test_process_noise_is_the_velocity_change_variance_never_below_the_base() -> None:
    rng = np.random.default_rng(0)
    base = TrackerConfig()
    dv = np.column_stack([rng.normal(0.0, 1.0, 400), rng.normal(0.0, 0.01, 400), np.zeros(400)])
    q_x, q_y = process_noise("car", dv, base)
    assert (q_x.key, q_y.key) == ("q_x", "q_y")
    assert q_x.value == pytest.approx(np.var(dv[:, 0])) and "raised" not in q_x.source
    assert q_y.value == base.classes["car"].q_y and "raised to the base's" in q_y.source


def test_too_few_velocity_changes_learn_nothing() -> None:
    assert process_noise("car", np.zeros((3, 3)), TrackerConfig()) == []
