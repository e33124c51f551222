"""A Bernoulli missed this frame is output only while its existence is at least ``[pmb] coasting_min_existence``;
it stays in the filter, and a detected one is output whatever its existence (values computed by hand)."""

from __future__ import annotations

import pytest

from gnnpmb.config import TrackerConfig, with_params
from gnnpmb.events import NullSink
from gnnpmb.pmb.core import PmbCore
from gnnpmb.pmb.gnnpmb import BestAssignment
from gnnpmb.types import IdAllocator
from tests.gnnpmb.pmb.helpers import make_measurements

FIXED_PD = {"pmb.miss_p_detect_online": 0, "pmb.miss_p_detect_max": 0.8, "models.p_survive": 0.95}


def _detected_three_frames(params: dict[str, float]) -> tuple[PmbCore, int]:
    core = PmbCore("car", with_params(TrackerConfig(), params), BestAssignment(), IdAllocator())
    for t in range(3):
        (est,) = core.step(
            make_measurements([(1.0 * t, 0.0)], 0.8, velocity=[(2.0, 0.0)]), 0.5 if t else 0.0, NullSink()
        )
    assert core.hypotheses[0].bernoullis.existence.tolist() == [1.0]
    return core, est.track_id


def test_a_missed_track_is_hidden_once_its_existence_falls_below_the_bound():
    """P_D = min(score 0.8, cap 0.8) = 0.8, P_S = 0.95. From r = 1: predicted 0.95, after the miss
    0.95 x 0.2 / (1 - 0.95 x 0.8) = 0.19 / 0.24 = 0.791667 (output, >= 0.5); next predicted 0.752083, after the
    miss 0.150417 / 0.398333 = 0.377615 (hidden, < 0.5; still in the filter); the next detection brings the
    track back under its own id."""
    core, track_id = _detected_three_frames(FIXED_PD | {"pmb.coasting_min_existence": 0.5})
    (first,) = core.step(make_measurements([], 0.8), 0.5, NullSink())
    assert first.existence == pytest.approx(0.19 / 0.24, rel=1e-9) and first.track_id == track_id
    assert core.step(make_measurements([], 0.8), 0.5, NullSink()) == []
    b = core.hypotheses[0].bernoullis
    assert b.misses.tolist() == [2] and b.existence[0] == pytest.approx(0.1504167 / 0.3983333, rel=1e-5)
    (back,) = core.step(make_measurements([(6.0, 0.0)], 0.8, velocity=[(2.0, 0.0)]), 0.5, NullSink())
    assert back.track_id == track_id and back.existence == 1.0


def test_off_by_default_the_same_miss_is_output():
    """The default 0 keeps every missed Bernoulli above the extraction threshold: r = 0.377615 is output."""
    core, track_id = _detected_three_frames(FIXED_PD)
    assert TrackerConfig().pmb.coasting_min_existence == 0.0
    core.step(make_measurements([], 0.8), 0.5, NullSink())
    (second,) = core.step(make_measurements([], 0.8), 0.5, NullSink())
    assert second.track_id == track_id and second.existence == pytest.approx(0.1504167 / 0.3983333, rel=1e-5)


def test_a_birth_below_the_bound_is_output():
    """The rule is for missed Bernoullis only: a new track's existence r_b < 1 does not hide it."""
    core = PmbCore(
        "car", with_params(TrackerConfig(), {"pmb.coasting_min_existence": 0.99}), BestAssignment(), IdAllocator()
    )
    (born,) = core.step(make_measurements([(0.0, 0.0)], 0.5, velocity=[(2.0, 0.0)]), 0.0, NullSink())
    assert born.existence < 0.99


def test_a_missed_tracks_p_detect_is_the_cap_alone_without_its_last_score():
    """Last detection scored 0.5, cap 0.8, P_S 0.95, r = 1 before the miss (predicted 0.95). The paper's P_D
    min(0.5, 0.8) = 0.5: r' = 0.95 x 0.5 / (1 - 0.95 x 0.5) = 0.475 / 0.525 = 0.904762; with
    ``[pmb] miss_p_detect_last_score = 0`` the cap 0.8: r' = 0.19 / 0.24 = 0.791667."""
    expected = {1: 0.475 / 0.525, 0: 0.19 / 0.24}
    for switch, r in expected.items():
        core = PmbCore(
            "car",
            with_params(TrackerConfig(), FIXED_PD | {"pmb.miss_p_detect_last_score": switch}),
            BestAssignment(),
            IdAllocator(),
        )
        for t in range(3):
            core.step(make_measurements([(1.0 * t, 0.0)], 0.5, velocity=[(2.0, 0.0)]), 0.5 if t else 0.0, NullSink())
        assert core.hypotheses[0].bernoullis.existence.tolist() == [1.0]
        (missed,) = core.step(make_measurements([], 0.5), 0.5, NullSink())
        assert missed.existence == pytest.approx(r, rel=1e-9)
    assert TrackerConfig().pmb.miss_p_detect_last_score == 1
