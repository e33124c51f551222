"""SimpleTrack's and ImmortalTracker's published designs, decision by decision on staged scenes: a motorcycle
(2.1 x 0.8 x 1.5 m) riding along x at 10 m/s, 5 m per keyframe."""

import numpy as np
import pytest

from gnnpmb.config import TrackerConfig, with_params
from gnnpmb.events import Assignment, AxisKind, CostMatrix, Posterior, Pruned
from tests.gnnpmb.box.helpers import MOTORCYCLE_WLH, Staged, boxes

NOTHING = boxes([], size_wlh=MOTORCYCLE_WLH, cls="motorcycle")


def moto(x: float, score: float = 0.8):
    return boxes([(x, 0.0)], score=score, velocity=[(10.0, 0.0)], size_wlh=MOTORCYCLE_WLH, cls="motorcycle")


def test_velocity_model_keeps_a_fast_motorcycle_across_a_missed_frame():
    s = Staged("simpletrack", cls="motorcycle")
    assert s.ids(moto(0.0)) == [1]
    (coasting,) = s.step(NOTHING)  # missed: output at its last box moved by its velocity, score x 0.01
    assert coasting.translation_m[0] == pytest.approx(5.0) and coasting.score == pytest.approx(0.008)
    assert s.ids(moto(10.0)) == [1]  # stepped back by its velocity the detection is at 5: GIoU 1
    cost = s.sink.of_type(CostMatrix)[0]
    assert cost.cost[0, 0] == pytest.approx(0.0, abs=1e-12) and cost.scale.similarity == "GIoU"
    post = s.sink.of_type(Posterior)[0]
    assert post.score.tolist() == pytest.approx([0.8]) and post.score_rule.miss_factor == 0.01


def test_the_kalman_model_loses_it_a_new_track_has_no_velocity():
    """giou.yaml: the track's Kalman prediction stays at x = 0; the detection at 10 m: I = 0, U = 2 x 2.52 m^3,
    C = (10 + 2.1) x 0.8 x 1.5: GIoU = 5.04 / 14.52 - 1 = -0.65 < -0.5, a new track."""
    s = Staged("simpletrack", with_params(TrackerConfig(), {"simpletrack.detector_velocity": 0}), cls="motorcycle")
    s.step(moto(0.0))
    s.step(NOTHING)
    assert s.ids(moto(10.0)) == [2]
    assert s.sink.of_type(CostMatrix)[0].cost[0, 0] == np.inf  # 1 - GIoU = 1.65 > 1.5: never matched


def test_second_miss_in_a_row_deletes_the_track():
    s = Staged("simpletrack", cls="motorcycle")
    s.step(moto(0.0))
    s.step(NOTHING)
    assert s.step(NOTHING) == []
    assert [e.track_id for e in s.sink.of_type(Pruned)] == [1]


def test_immortal_keeps_the_track_through_any_gap_and_outputs_it_only_while_missed_once():
    s = Staged("immortal", cls="motorcycle")
    s.step(moto(0.0))
    assert len(s.step(NOTHING)) == 1
    for _ in range(3):
        assert s.step(NOTHING) == []  # missed more than once: kept, predicted, not output
        assert s.sink.of_type(Pruned) == []
    assert s.ids(moto(25.0)) == [1]  # 5 frames later, where its velocity put it


def test_two_stage_keeps_a_track_alive_on_a_low_score_detection():
    """With the second stage on and first-stage detections >= 0.5: a 0.3 detection on the track neither updates
    it nor starts a track, but keeps it from its second miss."""
    cfg = with_params(
        TrackerConfig(),
        {"simpletrack.two_stage": 1, "simpletrack.first_stage_score": 0.5, "simpletrack.second_stage_score": 0.1},
    )
    s = Staged("simpletrack", cfg, cls="motorcycle")
    s.step(moto(0.0))
    s.step(NOTHING)
    s.step(moto(10.0, score=0.3))
    assert s.sink.of_type(Pruned) == [] and s.sink.of_type(Assignment)[0].pairs == ()
    assert s.tracker.tracks.life.misses.tolist() == [0]
    assert s.ids(moto(15.0)) == [1]
    assert [p[1].kind for p in s.sink.of_type(Assignment)[0].pairs] == [AxisKind.TRACK]
