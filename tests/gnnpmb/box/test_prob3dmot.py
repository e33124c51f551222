"""Probabilistic 3D MOT's published design, decision by decision on staged scenes."""

import numpy as np
import pytest
from scipy.optimize import linear_sum_assignment

from gnnpmb.assign.greedy import greedy_pairs
from gnnpmb.box import kalman
from gnnpmb.events import Assignment, AxisKind, CostMatrix, Gated
from tests.gnnpmb.box.helpers import Staged, boxes


def _two_parked_cars() -> Staged:
    s = Staged("prob3dmot")
    for _ in range(3):
        s.step(boxes([(0.0, 0.0), (0.0, 3.0)]))
    return s


def test_the_cost_is_the_mahalanobis_distance_of_the_7d_box_residual():
    s = _two_parked_cars()
    t = s.tracker.tracks
    model = kalman.box_model(0.5, s.tracker.spec.noise)
    mean, cov = t.mean @ model.F.T, model.F @ t.cov @ model.F.T + model.Q
    det = boxes([(0.0, 1.4)])
    s.step(det)
    z = kalman.measurements(det.boxes)[0]
    H = np.hstack([np.eye(7), np.zeros((7, 3))])
    nu = z - mean[0, :7]
    S = H @ cov[0] @ H.T + model.R
    cost = s.sink.of_type(CostMatrix)[0]
    assert cost.cost[0, 0] == pytest.approx(np.sqrt(nu @ np.linalg.solve(S, nu)))
    assert cost.scale is not None and cost.scale.unit == "sigma" and cost.scale.threshold == 11.0
    gated = s.sink.of_type(Gated)[0]
    assert gated.threshold == pytest.approx(121.0) and gated.inside[0, 0]


def test_greedy_closest_pair_first_not_the_optimal_assignment():
    """Parked cars at y = 0 and y = 3; detections at y = 1.4 and y = -2. Closest pair first takes 1.4 -> the car
    at 0, leaving -2 to the car at 3; the optimal assignment would swap both."""
    s = _two_parked_cars()
    s.step(boxes([(0.0, 1.4), (0.0, -2.0)]))
    cost = s.sink.of_type(CostMatrix)[0]
    track_cost = cost.cost[:, :2]
    assert np.isfinite(track_cost).all()
    greedy = greedy_pairs(track_cost).tolist()
    rows, cols = linear_sum_assignment(track_cost)
    assert greedy == [[0, 0], [1, 1]] and cols.tolist() == [1, 0]
    pairs = s.sink.of_type(Assignment)[0].pairs
    assert [(p[1].kind, p[1].ref) for p in pairs] == [(AxisKind.TRACK, 1), (AxisKind.TRACK, 2)]


def test_a_detection_11_sigma_away_starts_a_new_track():
    s = _two_parked_cars()
    s.step(boxes([(0.0, -9.0)]))
    assert not np.isfinite(s.sink.of_type(CostMatrix)[0].cost[0, :2]).any()
    assert s.sink.of_type(Assignment)[0].pairs[0][1].kind is AxisKind.NEW_TRACK
