"""GNN tracker against hand-computed Kalman updates, costs and M/N track-logic timing."""

from __future__ import annotations

import numpy as np
import pytest

from gnnpmb.config import TrackerConfig
from gnnpmb.events import (
    Assignment,
    AxisKind,
    Born,
    CostMatrix,
    Extracted,
    Gated,
    ListSink,
    NullSink,
    Posterior,
    Pruned,
    PruneReason,
    TrackLogic,
    TrackLogicAction,
)
from gnnpmb.types import IdAllocator
from gnnpmb.vector.gnn import GnnTracker, best_assignment
from tests.gnnpmb.pmb.helpers import make_measurements
from tests.gnnpmb.vector.helpers import CFG, P, Q, R, V, birth_cov, cv, gauss2, joseph


def make_gnn(config: TrackerConfig = CFG) -> GnnTracker:
    return GnnTracker("car", config, IdAllocator())


def test_single_target_birth_then_hand_computed_kalman_update():
    gnn = make_gnn()
    sink = ListSink()
    est = gnn.step(make_measurements([(1.0, 2.0)], 0.9, velocity=[(3.0, 0.5)]), 0.0, sink)
    assert est == []  # tentative
    t = gnn.tracks
    assert t.track_id.tolist() == [1]
    np.testing.assert_allclose(t.mean[0], [1.0, 2.0, 3.0, 0.5], atol=1e-12)
    np.testing.assert_allclose(t.cov[0], birth_cov(), atol=1e-10)
    born = sink.of_type(Born)[0]
    assert born.track_ids.tolist() == [1] and born.meas_indices.tolist() == [0]

    dt, z = 0.5, np.array([2.6, 2.2])
    m_pred = cv(dt) @ t.mean[0]
    P_pred = cv(dt) @ birth_cov() @ cv(dt).T + Q
    S = P_pred[:2, :2] + R
    K = P_pred[:, :2] @ np.linalg.inv(S)
    m_post = m_pred + K @ (z - m_pred[:2])
    P_post = joseph(P_pred, K)
    sink = ListSink()
    est = gnn.step(make_measurements([tuple(z)], 0.8), dt, sink)

    cost = sink.of_type(CostMatrix)[0]
    expected = -np.log(V.p_detect * gauss2(z - m_pred[:2], S) / ((1 - V.p_detect) * P.clutter_intensity))
    assert cost.cost.shape == (1, 2) and cost.cost[0, 0] == pytest.approx(expected, rel=1e-10)
    assert cost.cost[0, 1] == 0.0
    assert [c.kind for c in cost.cols] == [AxisKind.TRACK, AxisKind.NEW_TRACK]
    assert len(est) == 1
    e = est[0]
    assert e.track_id == 1 and e.existence == 1.0 and e.score == pytest.approx(0.8) and e.meas_index == 0
    np.testing.assert_allclose([*e.translation_m[:2], *e.velocity_mps], m_post, atol=1e-10)
    assert e.translation_m[2] == 1.0 and e.size_wlh_m == (2.0, 4.5, 1.6)
    assert e.quat_wxyz == (1.0, 0.0, 0.0, 0.0)
    np.testing.assert_allclose(gnn.tracks.cov[0], P_post, atol=1e-10)
    assert np.all(np.linalg.eigvalsh(gnn.tracks.cov[0]) > 0)
    logic = sink.of_type(TrackLogic)
    transitions = [(x.track_id, x.action, x.hits, x.window) for x in logic]
    assert transitions == [(1, TrackLogicAction.CONFIRMED, 2, 3)]


def truth(t: float) -> np.ndarray:
    """Two cars on crossing diagonals, 5 m apart at closest (t = 2.5 s); A passes the origin at t = 2."""
    return np.array([[-10 + 5 * t, -10 + 5 * t], [-15 + 5 * t, 15 - 5 * t]])


def test_crossing_targets_keep_their_ids():
    rng = np.random.default_rng(0)
    gnn = make_gnn()
    sink = ListSink()
    velocity = [(5.0, 5.0), (5.0, -5.0)]
    for f in range(13):
        xy = truth(0.5 * f) + rng.normal(0.0, 0.1, size=(2, 2))
        order = [1, 0] if f % 2 else [0, 1]  # measurement order must not matter
        meas = make_measurements([tuple(xy[i]) for i in order], 0.9, velocity=[velocity[i] for i in order])
        est = gnn.step(meas, 0.0 if f == 0 else 0.5, sink)
        if f == 0:
            continue
        by_id = {e.track_id: e for e in est}
        assert set(by_id) == {1, 2}
        for tid, target in ((1, 0), (2, 1)):
            assert np.hypot(*(np.array(by_id[tid].translation_m[:2]) - truth(0.5 * f)[target])) < 0.5
            assert by_id[tid].meas_index == order.index(target)
    gated = sink.of_type(Gated)[1:]
    assert all(g.inside.sum(axis=1).tolist() == [1, 1] for g in gated)  # unambiguous gates


def test_confirmed_track_missed_delete_misses_times_is_deleted():
    gnn = make_gnn()
    sink = ListSink()
    z = make_measurements([(0.0, 0.0)])
    gnn.step(z, 0.0, sink)
    assert len(gnn.step(z, 0.5, sink)) == 1
    for miss in range(1, V.delete_misses + 1):
        est = gnn.step(make_measurements([]), 0.5, sink)
        assert est == []  # coasting tracks are not output
        assert len(gnn.tracks) == (1 if miss < V.delete_misses else 0)
    logic = [(e.track_id, e.action, e.hits, e.window) for e in sink.of_type(TrackLogic)]
    assert logic == [
        (1, TrackLogicAction.TENTATIVE, 1, V.confirm_n),
        (1, TrackLogicAction.CONFIRMED, 2, V.confirm_n),
        (1, TrackLogicAction.DELETED, 0, V.delete_misses),
    ]
    pruned = sink.of_type(Pruned)
    assert [(p.track_id, p.reason) for p in pruned] == [(1, PruneReason.TRACK_LOGIC)]
    assert sink.of_type(Posterior)[-1].track_ids.tolist() == []


def test_coasting_track_resumes_under_its_id():
    gnn = make_gnn()
    gnn.step(make_measurements([(0.0, 0.0)], velocity=[(2.0, 0.0)]), 0.0, NullSink())
    gnn.step(make_measurements([(1.0, 0.0)], velocity=[(2.0, 0.0)]), 0.5, NullSink())
    assert gnn.step(make_measurements([]), 0.5, NullSink()) == []
    est = gnn.step(make_measurements([(3.0, 0.05)]), 0.5, NullSink())
    assert [e.track_id for e in est] == [1]


@pytest.mark.parametrize(
    ("frames", "first_output"),
    [
        ([True, True, True], 1),  # hit, hit: confirmed on the second frame
        ([True, False, True, True], 2),  # hit, miss, hit: confirmed on the third frame
        ([True, False, False, True], None),  # hit, miss, miss: tentative track deleted
    ],
)
def test_m_of_n_confirmation_timing(frames, first_output):
    gnn = make_gnn()
    outputs = []
    for f, detected in enumerate(frames):
        meas = make_measurements([(0.0, 0.0)] if detected else [])
        est = gnn.step(meas, 0.0 if f == 0 else 0.5, NullSink())
        outputs.append([e.track_id for e in est])
    if first_output is None:
        assert outputs == [[], [], [], []]  # the last detection starts track 2, tentative
        assert gnn.tracks.track_id.tolist() == [2]
    else:
        assert all(o == [] for o in outputs[:first_output])
        assert all(o == [1] for o in outputs[first_output:])


def test_far_measurement_starts_new_track_and_assignment_event():
    gnn = make_gnn()
    sink = ListSink()
    gnn.step(make_measurements([(0.0, 0.0)]), 0.0, sink)
    gnn.step(make_measurements([(30.0, 0.0), (0.1, 0.0)]), 0.5, sink)
    a = sink.of_type(Assignment)[-1]
    pairs = {(r.ref, c.kind, c.ref) for r, c in a.pairs}
    assert pairs == {(0, AxisKind.NEW_TRACK, 0), (1, AxisKind.TRACK, 1)}
    assert a.missed_track_ids == ()
    cost = sink.of_type(CostMatrix)[-1]
    assert np.isinf(cost.cost[0, 0]) and np.isinf(cost.cost[0, 2]) and np.isinf(cost.cost[1, 1])
    assert a.total_cost == pytest.approx(cost.cost[1, 0])
    assert sink.of_type(Born)[-1].track_ids.tolist() == [2]
    assert [e.track_id for e in sink.of_type(Extracted)[-1].estimates] == [1]


def test_best_assignment_prefers_likelihood_ratio_over_missing():
    inf = np.inf
    # two measurements, two tracks; pair costs > 0 are worse than leaving both unassigned
    cost = np.array([[-3.0, -2.0], [-2.5, inf]])
    track_of_meas, total = best_assignment(cost)
    assert track_of_meas.tolist() == [1, 0] and total == pytest.approx(-4.5)
    track_of_meas, total = best_assignment(np.array([[1.0, inf], [inf, -1.0]]))
    assert track_of_meas.tolist() == [-1, 1] and total == pytest.approx(-1.0)
    track_of_meas, total = best_assignment(np.full((2, 3), inf))
    assert track_of_meas.tolist() == [-1, -1] and total == 0.0


def test_no_sink_and_list_sink_give_identical_tracks():
    def run(sink):
        gnn = make_gnn()
        out = []
        for f in range(6):
            out.append(gnn.step(make_measurements([tuple(p) for p in truth(0.5 * f)]), 0.5 * (f > 0), sink))
        return out

    assert run(NullSink()) == run(ListSink())
