"""CBMOT's published design (LiDAR, multiplication update, score decay 0.2), decision by decision on staged scenes."""

import pytest

from gnnpmb.events import CostMatrix, Posterior, Pruned, PruneReason, ScoreOnHit
from tests.gnnpmb.box.helpers import Staged, boxes

NOTHING = boxes([])


def test_scores_are_refined_on_hits_and_fade_on_misses_until_deleted():
    """0.9 at birth; a 0.6 detection: 1 - (1 - 0.7)(1 - 0.6) = 0.88; then -0.2 per missed frame: 0.68, 0.48, 0.28,
    0.08, -0.12 -> deleted at the 5th miss."""
    s = Staged("cbmot")
    (born,) = s.step(boxes([(0.0, 0.0)], score=0.9))
    assert born.score == pytest.approx(0.9)
    (hit,) = s.step(boxes([(0.0, 0.0)], score=0.6))
    assert hit.track_id == born.track_id and hit.score == pytest.approx(0.88)
    for expected in (0.68, 0.48, 0.28, 0.08):
        assert s.step(NOTHING) == []  # a missed track is not output
        (post,) = s.sink.of_type(Posterior)
        assert post.score.tolist() == pytest.approx([expected])
        assert post.score_rule.on_hit is ScoreOnHit.FUSED and post.score_rule.decay_step == 0.2
    s.step(NOTHING)
    assert [(e.track_id, e.reason) for e in s.sink.of_type(Pruned)] == [(born.track_id, PruneReason.LOW_SCORE)]


def test_a_returning_object_takes_its_faded_track_back():
    s = Staged("cbmot")
    s.step(boxes([(0.0, 0.0)], score=0.9))
    s.step(NOTHING)
    (again,) = s.step(boxes([(0.0, 0.0)], score=0.5))
    assert again.track_id == 1 and again.score == pytest.approx(1 - (1 - 0.5) * (1 - 0.5))  # 0.9 - 0.2 - 0.2


def test_detections_take_their_nearest_free_track_in_file_order():
    """Tracks at x = 0 and x = 2.5; detections at x = 1.2 (listed first) and x = 1.0. In file order the first takes
    the track at 0 (1.2 m) and the second the one at 2.5 (1.5 m); closest pair first would give 1.0 -> the track
    at 0 and leave 1.2 -> 2.5 (1.3 m)."""
    s = Staged("cbmot")
    s.step(boxes([(0.0, 0.0), (2.5, 0.0)]))
    out = s.step(boxes([(1.2, 0.0), (1.0, 0.0)]))
    assert [e.track_id for e in out] == [1, 2]
    cost = s.sink.of_type(CostMatrix)[0]
    assert cost.scale.unit == "m" and cost.scale.threshold == 3.0  # CBMOT's car distance
    assert cost.cost[0, :2].tolist() == pytest.approx([1.2, 1.3]) and cost.cost[1, :2].tolist() == pytest.approx(
        [1.0, 1.5]
    )
