"""Greedy closest-pair tracker (CenterPoint baseline) on hand-made cases."""

from __future__ import annotations

import numpy as np
import pytest

from gnnpmb.config import TrackerConfig, config_from_dict
from gnnpmb.events import Assignment, AxisKind, Born, CostMatrix, ListSink, NullSink, Pruned, PruneReason
from gnnpmb.greedy import GreedyTracker, distance_matrix, greedy_pairs
from gnnpmb.types import IdAllocator
from tests.gnnpmb.pmb.helpers import make_measurements


def make_greedy(config: TrackerConfig | None = None) -> GreedyTracker:
    return GreedyTracker("car", config or TrackerConfig(), IdAllocator())


def test_distance_matrix_projects_detections_back_by_their_velocity():
    det = np.array([[10.0, 0.0], [0.0, 3.0]])
    vel = np.array([[4.0, 0.0], [0.0, 0.0]])
    tracks = np.array([[8.0, 0.0], [0.0, 0.0]])
    dist = distance_matrix(det, vel, 0.5, tracks, 4.0)
    # detection 0 goes back to (8, 0): 0 m from track 0, 8 m (> 4) from track 1; detection 1 stays at (0, 3)
    expected = np.array([[0.0, np.inf], [np.hypot(8.0, 3.0), 3.0]])
    expected[1, 0] = np.inf
    np.testing.assert_allclose(dist, expected)


def test_greedy_pairs_take_the_closest_pair_first_not_the_optimal_assignment():
    # the optimal assignment (0-0, 1-1: 1 + 1 = 2) loses to closest-pair greedy (0-1 at 0.5 first, then 1-0 at 3)
    dist = np.array([[1.0, 0.5], [3.0, 1.0]])
    assert greedy_pairs(dist).tolist() == [[0, 1], [1, 0]]
    assert greedy_pairs(np.array([[np.inf, 2.0], [2.0, np.inf]])).tolist() == [[0, 1], [1, 0]]
    assert greedy_pairs(np.full((2, 0), np.inf)).shape == (0, 2)


def test_ties_are_broken_by_detection_then_track_index():
    assert greedy_pairs(np.array([[1.0, 1.0], [1.0, 1.0]])).tolist() == [[0, 0], [1, 1]]


def test_every_detection_is_output_with_its_box_and_score_and_matches_keep_the_id():
    g = make_greedy()
    est = g.step(
        make_measurements([(0.0, 0.0), (20.0, 0.0)], [0.9, 0.3], velocity=[(2.0, 0.0), (0.0, 0.0)]), 0.0, NullSink()
    )
    assert [e.track_id for e in est] == [1, 2]
    assert [e.score for e in est] == [0.9, 0.3]
    sink = ListSink()
    est = g.step(make_measurements([(21.0, 0.5), (1.0, 0.0)], [0.2, 0.8], velocity=[(0.0, 0.0), (2.0, 0.0)]), 0.5, sink)
    assert [e.track_id for e in est] == [2, 1]
    assert est[0].translation_m == (21.0, 0.5, 1.0) and est[0].score == 0.2
    assert est[1].velocity_mps == (2.0, 0.0) and est[1].meas_index == 1
    cost = sink.of_type(CostMatrix)[0]
    # an infinite entry is beyond the class's distance threshold (dev set scene-1077 megvii greedy id_switch:1 said
    # "outside its gate" of a tracker with no gate)
    assert cost.scale.unit == "m" and cost.scale.threshold == 4.0
    assert [c.kind for c in cost.cols] == [AxisKind.TRACK] * 2 + [AxisKind.NEW_TRACK] * 2
    assert cost.cost[1, 0] == pytest.approx(0.0) and cost.cost[0, 1] == pytest.approx(np.hypot(1.0, 0.5))
    assert cost.cost[0, 2] == 4.0 and np.isinf(cost.cost[0, 3])
    assignment = sink.of_type(Assignment)[0]
    assert [(r.ref, c.ref) for r, c in assignment.pairs] == [(0, 2), (1, 1)]
    assert assignment.missed_track_ids == ()


def test_unmatched_detection_starts_a_new_id_and_class_threshold_applies():
    g = make_greedy()
    g.step(make_measurements([(0.0, 0.0)]), 0.0, NullSink())
    sink = ListSink()
    est = g.step(make_measurements([(4.5, 0.0)]), 0.5, sink)  # 4.5 m > car threshold 4 m
    assert [e.track_id for e in est] == [2]
    born = sink.of_type(Born)[0]
    assert born.track_ids.tolist() == [2] and born.meas_indices.tolist() == [0]
    assert sink.of_type(Assignment)[0].missed_track_ids == (1,)
    wide = config_from_dict({"classes": {"car": {"match_distance_m": 5.0}}})
    g = make_greedy(wide)
    g.step(make_measurements([(0.0, 0.0)]), 0.0, NullSink())
    assert [e.track_id for e in g.step(make_measurements([(4.5, 0.0)]), 0.5, NullSink())] == [1]


def test_coasting_track_moves_by_its_velocity_is_not_output_and_dies_after_max_age_misses():
    g = make_greedy()
    g.step(make_measurements([(0.0, 0.0)], velocity=[(2.0, 0.0)]), 0.0, NullSink())
    assert g.step(make_measurements([]), 0.5, NullSink()) == []
    assert g.tracks.center_xy.tolist() == [[1.0, 0.0]] and g.tracks.misses.tolist() == [1]
    assert g.step(make_measurements([]), 0.5, NullSink()) == []
    # two misses: still alive at (2, 0); a detection at (3, 0) with velocity (2, 0) goes back to (2, 0)
    est = g.step(make_measurements([(3.0, 0.0)], velocity=[(2.0, 0.0)]), 0.5, NullSink())
    assert [e.track_id for e in est] == [1]
    for _ in range(2):
        g.step(make_measurements([]), 0.5, NullSink())
    sink = ListSink()
    g.step(make_measurements([]), 0.5, sink)  # third miss in a row: deleted (max_age = 3)
    assert len(g.tracks) == 0
    pruned = sink.of_type(Pruned)
    assert [(p.track_id, p.reason) for p in pruned] == [(1, PruneReason.TRACK_LOGIC)]
