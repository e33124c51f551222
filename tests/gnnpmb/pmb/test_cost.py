from dataclasses import replace

import numpy as np

from gnnpmb.box_likelihood import BoxShapeModel
from gnnpmb.config import paper_config
from gnnpmb.data.boxes3d import quat_wxyz_from_yaw
from gnnpmb.detection_fields import DetectionFields
from gnnpmb.models import measurement_birth
from gnnpmb.pmb.bernoulli import Bernoullis
from gnnpmb.pmb.cost import local_hypotheses
from gnnpmb.pmb.poisson import new_track_hypotheses
from gnnpmb.types import Measurements
from tests.gnnpmb.pmb.helpers import make_measurements

CFG = paper_config()
CAR = CFG.for_class("car")
R = np.diag([CAR.r_x, CAR.r_y])


def bernoullis(xy: list[tuple[float, float]]) -> Bernoullis:
    k = len(xy)
    return Bernoullis(
        track_id=np.arange(1, k + 1),
        local_key=np.arange(k),
        existence=np.linspace(0.5, 0.95, k),
        mean=np.column_stack([np.asarray(xy, dtype=float).reshape(k, 2), np.zeros((k, 2))]),
        cov=np.broadcast_to(np.eye(4), (k, 4, 4)).copy(),
        det=DetectionFields(np.full(k, 0.8), np.zeros(k), np.ones((k, 3)), np.zeros((k, 4)), np.full(k, -1)),
        misses=np.zeros(k, dtype=np.int64),
        detected_score_sum=np.zeros(k),
        detected_frames=np.zeros(k, dtype=np.int64),
    )


def test_cost_matrix_entries():
    """C[j, k] = -(log l_kj - log l_k0) (inf outside the gate), C[j, K + j] = -log l_j, inf elsewhere."""
    for tracks, points in (([(0.0, 0.0), (5.0, 0.0), (60.0, 0.0)], [(0.2, 0.1), (5.5, -0.3)]), ([], [(1.0, 1.0)])):
        for xy in (points, []):
            meas = make_measurements(xy, 0.7)
            new = new_track_hypotheses(measurement_birth(meas, CFG.models), meas, R, CFG.models.clutter_intensity)
            local = local_hypotheses(bernoullis(tracks), meas, new, R, CFG.models.gate_chi2)
            k, m = len(tracks), len(xy)
            expected = np.full((m, k + m), np.inf)
            for j in range(m):
                for i in range(k):
                    expected[j, i] = -(local.det_log_lik[i, j] - local.miss_log_lik[i])
                expected[j, k + j] = -new.log_likelihood[j]
            cost = local.cost_matrix()
            assert cost.shape == (m, k + m) and cost.tobytes() == expected.tobytes()
            assert k == 0 or m == 0 or np.isinf(cost[:, 2]).all()  # the track 60 m away gates nothing


def test_cost_terms_add_up_to_every_gated_entry():
    """existence + spread + distance + score nats = C[j, k] wherever the pair is gated."""
    meas = make_measurements([(0.2, 0.1), (5.5, -0.3), (0.9, 0.4)], 0.7)
    new = new_track_hypotheses(measurement_birth(meas, CFG.models), meas, R, CFG.models.clutter_intensity)
    local = local_hypotheses(bernoullis([(0.0, 0.0), (5.0, 0.0), (1.0, 1.0)]), meas, new, R, CFG.models.gate_chi2)
    cost, terms = local.cost_matrix(), local.cost_terms()
    gated = np.argwhere(np.isfinite(cost[:, : local.n_tracks]))
    assert len(gated) >= 4
    for j, k in gated.tolist():
        assert np.isclose(terms.pair(j, k).total_nats, cost[j, k], rtol=0, atol=1e-12)


def test_cost_terms_by_hand():
    """One track at the origin, r = 0.5, last score 0.8, cov I (S = I + R); a detection of score 0.7 at (1, 0)."""
    meas = make_measurements([(1.0, 0.0)], 0.7)
    new = new_track_hypotheses(measurement_birth(meas, CFG.models), meas, R, CFG.models.clutter_intensity)
    track = bernoullis([(0.0, 0.0)])
    local = local_hypotheses(track, meas, new, R, CFG.models.gate_chi2)
    t = local.cost_terms().pair(0, 0)
    s = np.eye(2) + R
    assert np.isclose(t.existence, 0.5) and np.isclose(t.p_detect, 0.8)
    assert np.isclose(t.existence_nats, np.log(1 - 0.5 * 0.8) - np.log(0.5))
    assert np.isclose(t.score_nats, -np.log(0.7))
    assert np.isclose(t.d2, 1.0 / s[0, 0]) and np.isclose(t.distance_nats, 0.5 / s[0, 0])
    assert np.isclose(t.spread_nats, 0.5 * np.log(np.linalg.det(2 * np.pi * s)))
    assert np.isclose(t.spread_m, np.linalg.det(s) ** 0.25)


def test_existence_for_a_cheaper_cost():
    """The existence at which the cost is lower by a gap, put back into the formula, gives exactly that gap;
    a gap larger than any existence can close gives None."""
    meas = make_measurements([(1.0, 0.0)], 0.7)
    new = new_track_hypotheses(measurement_birth(meas, CFG.models), meas, R, CFG.models.clutter_intensity)
    t = local_hypotheses(bernoullis([(0.0, 0.0)]), meas, new, R, CFG.models.gate_chi2).cost_terms().pair(0, 0)
    r = t.existence_for(0.3)
    assert r is not None and 0.5 < r < 1
    assert np.isclose(np.log(1 - r * t.p_detect) - np.log(r), t.existence_nats - 0.3)
    assert t.existence_for(-0.3) < 0.5
    assert t.existence_for(t.existence_nats - np.log(1 - t.p_detect) + 0.01) is None  # beyond r = 1


def test_cost_terms_add_up_with_the_heading_and_size_model():
    """The box log-likelihood ratio enters C[j, k] as its own term (``CostTerms.box_nats``), and the terms still
    add up to every gated entry; the new-track column does not change."""
    box = BoxShapeModel(heading_std_rad=0.1, size_log_std=0.1, size_log_spread=0.2, outlier_prob=0.1)
    meas = make_measurements([(0.2, 0.1), (5.5, -0.3), (0.9, 0.4)], 0.7)
    meas = Measurements(
        replace(meas.boxes, quat_wxyz=quat_wxyz_from_yaw(np.array([0.05, 1.2, -0.1]))), meas.source_index
    )
    new = new_track_hypotheses(measurement_birth(meas, CFG.models), meas, R, CFG.models.clutter_intensity)
    tracks = bernoullis([(0.0, 0.0), (5.0, 0.0), (1.0, 1.0)])
    plain = local_hypotheses(tracks, meas, new, R, CFG.models.gate_chi2)
    local = local_hypotheses(tracks, meas, new, R, CFG.models.gate_chi2, box=box)
    cost, terms = local.cost_matrix(), local.cost_terms()
    k = local.n_tracks
    assert np.array_equal(cost[:, k:], plain.cost_matrix()[:, k:])
    gated = np.argwhere(np.isfinite(cost[:, :k]))
    assert len(gated) >= 4
    for j, i in gated.tolist():
        t = terms.pair(j, i)
        assert t.box_nats != 0.0
        assert np.isclose(t.total_nats, cost[j, i], rtol=0, atol=1e-12)


def test_overlap_gate_keeps_only_pairs_that_overlap_enough():
    """Two detections inside the Mahalanobis gate of a track at the origin (2 x 4.5 m car, heading 0): one 0.5 m
    ahead (GIoU ~0.8), one turned by 90 degrees (GIoU < 0.5); a GIoU gate of 0.5 keeps the first only."""
    meas = make_measurements([(0.5, 0.0), (0.0, 0.3)], 0.7)
    meas = Measurements(
        replace(meas.boxes, quat_wxyz=quat_wxyz_from_yaw(np.array([0.0, np.pi / 2]))), meas.source_index
    )
    new = new_track_hypotheses(measurement_birth(meas, CFG.models), meas, R, CFG.models.clutter_intensity)
    track = bernoullis([(0.0, 0.0)])
    track = replace(
        track, det=replace(track.det, size_wlh_m=np.array([[2.0, 4.5, 1.6]]), quat_wxyz=np.array([[1.0, 0, 0, 0]]))
    )
    plain = local_hypotheses(track, meas, new, R, CFG.models.gate_chi2)
    gated = local_hypotheses(track, meas, new, R, CFG.models.gate_chi2, gate_giou_min=0.5)
    assert plain.inside.tolist() == [[True, True]] and plain.giou is None
    assert gated.inside.tolist() == [[True, False]]
    expected = (2.0 * 4.0) / (2.0 * 5.0)  # I / U with |C| = U: two aligned boxes 0.5 m apart along their length
    assert np.isclose(gated.giou[0, 0], expected, rtol=0, atol=1e-12) and gated.giou[0, 1] < 0.5
    assert np.isinf(gated.cost_matrix()[1, 0]) and np.isfinite(gated.cost_matrix()[0, 0])
