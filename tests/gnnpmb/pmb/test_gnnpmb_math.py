"""GNN-PMB against hand-computed single- and two-target cases (García-Fernández et al. 2018 PMB update)."""

from __future__ import annotations

import numpy as np
import pytest

from gnnpmb.config import TrackerConfig
from gnnpmb.events import Assignment, AxisKind, Born, CostMatrix, Gated, ListSink, NullSink, Pruned
from gnnpmb.pmb.core import PmbCore
from gnnpmb.pmb.gnnpmb import BestAssignment
from gnnpmb.types import IdAllocator
from tests.gnnpmb.pmb.helpers import CFG, P, Q, R, gauss2, make_measurements


def birth_state(z, v, score):
    """Hand computation of the new-track hypothesis of one measurement."""
    Pb = np.diag([P.birth_pos_std_m**2] * 2 + [P.birth_vel_std_mps**2] * 2)
    S = Pb[:2, :2] + R
    lik = P.birth_weight * score * gauss2(np.zeros(2), S)
    r = lik / (P.clutter_intensity + lik)
    K = Pb[:, :2] @ np.linalg.inv(S)
    cov = (np.eye(4) - K @ np.eye(2, 4)) @ Pb
    return r, np.array([*z, *v]), cov


def make_core() -> PmbCore:
    return PmbCore("car", CFG, BestAssignment(), IdAllocator())


def test_first_detection_starts_bernoulli_with_hand_computed_existence():
    core = make_core()
    est = core.step(make_measurements([(1.0, 2.0)], 0.9, velocity=[(3.0, 0.5)]), 0.0, NullSink())
    r, mean, cov = birth_state((1.0, 2.0), (3.0, 0.5), 0.9)
    b = core.hypotheses[0].bernoullis
    assert len(b) == 1 and b.track_id[0] == 1
    assert b.existence[0] == pytest.approx(r, rel=1e-12)
    np.testing.assert_allclose(b.mean[0], mean, atol=1e-12)
    np.testing.assert_allclose(b.cov[0], cov, atol=1e-9)
    assert r < CFG.pmb.extraction_threshold and est == []


def test_with_the_defaults_a_new_bernoulli_is_reported_at_once_scored_score_times_existence():
    defaults = TrackerConfig()
    core = PmbCore("car", defaults, BestAssignment(), IdAllocator())
    est = core.step(make_measurements([(1.0, 2.0)], 0.9), 0.0, NullSink())
    r = core.hypotheses[0].bernoullis.existence[0]
    assert defaults.pmb.extraction_threshold <= r < 0.9 and [e.track_id for e in est] == [1]
    assert est[0].score == pytest.approx(0.9 * r, rel=1e-12) and est[0].existence == pytest.approx(r, rel=1e-12)


def test_second_detection_kalman_update_and_existence_one():
    core = make_core()
    core.step(make_measurements([(1.0, 2.0)], 0.9, velocity=[(3.0, 0.5)]), 0.0, NullSink())
    r0, m0, P0 = birth_state((1.0, 2.0), (3.0, 0.5), 0.9)
    dt = 0.5
    F = np.eye(4)
    F[0, 2] = F[1, 3] = dt
    m_pred, P_pred = F @ m0, F @ P0 @ F.T + Q
    z = np.array([2.6, 2.2])
    est = core.step(make_measurements([tuple(z)], 0.8), dt, NullSink())
    S = P_pred[:2, :2] + R
    K = P_pred[:, :2] @ np.linalg.inv(S)
    m_post = m_pred + K @ (z - m_pred[:2])
    P_post = (np.eye(4) - K @ np.eye(2, 4)) @ P_pred
    assert len(est) == 1
    e = est[0]
    assert e.track_id == 1 and e.existence == 1.0 and e.score == pytest.approx(0.8)
    np.testing.assert_allclose([*e.translation_m[:2], *e.velocity_mps], m_post, atol=1e-9)
    b = core.hypotheses[0].bernoullis
    np.testing.assert_allclose(b.cov[0], P_post, atol=1e-9)
    assert np.all(np.linalg.eigvalsh(b.cov[0]) > 0)
    # pass-through box fields from the detection
    assert e.translation_m[2] == 1.0 and e.size_wlh_m == (2.0, 4.5, 1.6)


def test_miss_updates_existence_with_last_score_as_pd():
    core = make_core()
    core.step(make_measurements([(0.0, 0.0)], 0.9), 0.0, NullSink())
    core.step(make_measurements([(0.0, 0.0)], 0.6), 0.5, NullSink())
    assert core.hypotheses[0].bernoullis.existence[0] == 1.0
    est = core.step(make_measurements([]), 0.5, NullSink())
    r_pred = P.p_survive * 1.0
    pd = 0.6
    expected = r_pred * (1 - pd) / (1 - r_pred * pd)
    assert core.hypotheses[0].bernoullis.existence[0] == pytest.approx(expected, rel=1e-12)
    assert est == []  # 0.48 < extraction threshold 0.9


def run_two_targets(sink):
    core = make_core()
    core.step(make_measurements([(0.0, 0.0), (10.0, 0.0)]), 0.0, sink)
    core.step(make_measurements([(0.0, 0.0), (10.0, 0.0)]), 0.5, sink)
    est = core.step(make_measurements([(10.2, 0.1), (0.1, -0.1)]), 0.5, sink)
    return core, est


def test_two_targets_unambiguous_assignment_keeps_ids():
    sink = ListSink()
    core, est = run_two_targets(sink)
    by_id = {e.track_id: e for e in est}
    assert set(by_id) == {1, 2}
    assert by_id[1].translation_m[0] == pytest.approx(0.1, abs=0.1)
    assert by_id[2].translation_m[0] == pytest.approx(10.2, abs=0.1)
    assert by_id[1].meas_index == 1 and by_id[2].meas_index == 0
    last = sink.of_type(Assignment)[-1]
    pairs = {(r.ref, c.kind, c.ref) for r, c in last.pairs}
    assert pairs == {(0, AxisKind.TRACK, 2), (1, AxisKind.TRACK, 1)}
    assert last.missed_track_ids == ()


def test_gate_excludes_far_detection():
    sink = ListSink()
    core = make_core()
    core.step(make_measurements([(0.0, 0.0)]), 0.0, sink)
    core.step(make_measurements([(0.0, 0.0)]), 0.5, sink)
    core.step(make_measurements([(30.0, 0.0)]), 0.5, sink)
    gated = sink.of_type(Gated)[-1]
    assert gated.track_ids.tolist() == [1] and not gated.inside[0, 0]
    cost = sink.of_type(CostMatrix)[-1]
    assert cost.cost.shape == (1, 2) and np.isinf(cost.cost[0, 0]) and np.isfinite(cost.cost[0, 1])
    assert [c.kind for c in cost.cols] == [AxisKind.TRACK, AxisKind.NEW_TRACK]
    born = sink.of_type(Born)[-1]
    assert born.track_ids.tolist() == [2] and born.meas_indices.tolist() == [0]
    b = core.hypotheses[0].bernoullis
    assert b.existence[b.track_id == 1][0] < 1.0  # missed


def test_pruning_reports_low_existence():
    sink = ListSink()
    core = make_core()
    core.step(make_measurements([(0.0, 0.0)], 0.99), 0.0, sink)
    for _ in range(12):
        core.step(make_measurements([]), 0.5, sink)
    pruned = sink.of_type(Pruned)
    assert [p.track_id for p in pruned] == [1]
    assert pruned[0].last_existence < CFG.pmb.prune_existence
    assert len(core.hypotheses[0].bernoullis) == 0


def test_no_sink_and_list_sink_give_identical_tracks():
    _, a = run_two_targets(NullSink())
    _, b = run_two_targets(ListSink())
    assert a == b
