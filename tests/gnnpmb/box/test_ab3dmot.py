"""AB3DMOT's published design, decision by decision on staged scenes (cars 4.5 x 2 x 1.6 m heading along x)."""

import numpy as np
import pytest

from gnnpmb.events import Assignment, AxisKind, CostMatrix, Posterior, Pruned, PruneReason, TrackLogic
from gnnpmb.events import TrackLogicAction as Action
from tests.gnnpmb.box.helpers import Staged, boxes

NOTHING = boxes([])


def test_output_from_the_third_hit_except_in_the_first_three_frames():
    s = Staged("ab3dmot")
    assert s.ids(boxes([(0.0, 0.0)])) == [1]  # frames 1-3: every track is output
    assert s.ids(boxes([(1.0, 0.0)])) == [1]
    assert s.ids(boxes([(2.0, 0.0)])) == [1]
    assert s.ids(boxes([(3.0, 0.0), (0.0, 50.0)])) == [1]  # track 2 born at frame 4: 1 hit, not output
    assert s.ids(boxes([(4.0, 0.0), (0.0, 50.0)])) == [1]  # 2 hits
    assert s.ids(boxes([(5.0, 0.0), (0.0, 50.0)])) == [1, 2]  # 3rd hit: output
    logic = [(e.track_id, e.action) for e in s.sink.of_type(TrackLogic)]
    assert logic == [(2, Action.CONFIRMED)]


def test_a_missed_track_is_output_once_at_its_prediction_with_its_last_score_then_deleted():
    s = Staged("ab3dmot")
    for x in (0.0, 1.0, 2.0, 3.0):
        s.step(boxes([(x, 0.0)], score=0.7))
    (coasting,) = s.step(NOTHING)
    assert coasting.track_id == 1 and coasting.meas_index == -1 and coasting.score == pytest.approx(0.7)
    assert coasting.translation_m[0] > 3.5  # moved on by the filter's velocity (about 1 m per frame)
    assert s.step(NOTHING) == []  # second miss in a row: deleted
    assert [(e.track_id, e.reason) for e in s.sink.of_type(Pruned)] == [(1, PruneReason.TRACK_LOGIC)]
    assert [e.track_id for e in s.step(boxes([(6.0, 0.0)]))] == []  # a new track (2), not yet confirmed
    assert s.sink.of_type(Assignment)[0].pairs[0][1].kind is AxisKind.NEW_TRACK


@pytest.mark.parametrize(("x", "matched"), [(3.0, True), (4.2, False)])
def test_a_pair_is_matched_iff_its_3d_iou_reaches_0_1(x, matched):
    """A stationary track at x = 0: a box at x = 3 overlaps 1.5 x 2 x 1.6 = 4.8 m^3 of 24 (IoU 0.2); at x = 4.2,
    0.96 of 27.84 (IoU 0.034): a new track."""
    s = Staged("ab3dmot")
    for _ in range(3):
        s.step(boxes([(0.0, 0.0)]))
    s.step(boxes([(x, 0.0)]))
    cost = s.sink.of_type(CostMatrix)[0]
    iou = {3.0: 4.8 / 24.0, 4.2: 0.96 / 27.84}[x]
    assert cost.scale is not None and cost.scale.similarity == "3D IoU" and cost.scale.threshold == pytest.approx(0.9)
    expected = 1.0 - iou if matched else np.inf
    assert cost.cost[0, 0] == pytest.approx(expected, rel=1e-3)  # the prediction stays near x = 0
    chosen = s.sink.of_type(Assignment)[0].pairs[0][1]
    assert (chosen.kind is AxisKind.TRACK) is matched
    post = s.sink.of_type(Posterior)[0]
    assert post.score is not None and post.score_rule is not None and post.score_rule.miss_factor == 1.0
