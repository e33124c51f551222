"""GM-PHD against hand-computed updates (Vo & Ma 2006, eq. 20-26) and the label bookkeeping of ``gmphd``."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from gnnpmb.config import ConfigError, PhdParams, TrackerConfig, paper_config
from gnnpmb.detection_fields import DetectionFields
from gnnpmb.events import (
    Born,
    Extracted,
    Gated,
    IntensityWeights,
    ListSink,
    Merged,
    NullSink,
    Posterior,
    Predicted,
    Pruned,
    PruneReason,
)
from gnnpmb.phd.gmphd import GmPhdTracker, log_sum_exp, phd_update
from gnnpmb.phd.mixture import GaussianMixture
from gnnpmb.types import IdAllocator
from tests.gnnpmb.pmb.helpers import make_measurements

CFG = paper_config()  # hand computations use the paper's values (sec. V-B)
P = CFG.models
PD = CFG.phd.p_detect
CAR = CFG.for_class("car")
R = np.diag([CAR.r_x, CAR.r_y])
Q = np.diag([CAR.q_x, CAR.q_y, CAR.q_x, CAR.q_y])


def gauss2(nu: np.ndarray, S: np.ndarray) -> float:
    return float(np.exp(-0.5 * nu @ np.linalg.solve(S, nu)) / (2 * np.pi * np.sqrt(np.linalg.det(S))))


def birth_likelihood() -> float:
    """w_b N(z_j; z_j, P_b[:2, :2] + R): a birth component explaining its own detection (P_D = 1)."""
    return P.birth_weight * gauss2(np.zeros(2), np.diag([P.birth_pos_std_m**2] * 2) + R)


def one_component(weight: float, mean, cov, label: int = 5) -> GaussianMixture:
    return GaussianMixture(
        weight=np.array([weight]),
        mean=np.asarray(mean, dtype=float)[None],
        cov=np.asarray(cov, dtype=float)[None],
        label=np.array([label], dtype=np.int64),
        det=DetectionFields(
            score=np.array([0.7]),
            z_m=np.array([0.5]),
            size_wlh_m=np.array([[1.0, 2.0, 1.0]]),
            quat_wxyz=np.array([[1.0, 0.0, 0.0, 0.0]]),
            meas_index=np.array([-1]),
        ),
    )


def raw_config(**models) -> TrackerConfig:
    """No pruning and no merging, so every component of the update stays visible."""
    return CFG.replace(
        phd=dataclasses.replace(CFG.phd, prune_weight=0.0, merge_threshold=0.0),
        models=dataclasses.replace(CFG.models, **models),
    )


def test_single_target_one_measurement_hand_computed():
    tracker = GmPhdTracker("car", raw_config(), IdAllocator())
    w, m, cov = 0.8, np.array([1.0, 2.0, 0.5, 0.0]), np.diag([0.3, 0.3, 0.5, 0.5])
    tracker.mixture = one_component(w, m, cov)
    z = np.array([1.3, 1.8])
    tracker.step(make_measurements([tuple(z)], 0.6), 0.0, NullSink())

    w_pred, P_pred = P.p_survive * w, cov + Q  # dt = 0: F = I
    S = P_pred[:2, :2] + R
    lik = PD * w_pred * gauss2(z - m[:2], S)
    den = P.clutter_intensity + lik + birth_likelihood()
    K = P_pred[:, :2] @ np.linalg.inv(S)

    mix = tracker.mixture
    track = np.flatnonzero(mix.label == 5)
    missed = track[mix.meas_index[track] == -1][0]
    detected = track[mix.meas_index[track] == 0][0]
    assert mix.weight[missed] == pytest.approx((1 - PD) * w_pred, rel=1e-12)
    assert mix.weight[detected] == pytest.approx(lik / den, rel=1e-10)
    np.testing.assert_allclose(mix.mean[missed], m, atol=1e-12)
    np.testing.assert_allclose(mix.mean[detected], m + K @ (z - m[:2]), atol=1e-12)
    np.testing.assert_allclose(mix.cov[detected], (np.eye(4) - K @ np.eye(2, 4)) @ P_pred, atol=1e-12)
    assert mix.score[detected] == 0.6 and mix.z_m[detected] == 1.0  # box fields of the detection
    birth = np.flatnonzero(mix.label < 0)
    assert len(birth) == 1 and mix.weight[birth[0]] == pytest.approx(birth_likelihood() / den, rel=1e-10)
    assert len(mix) == 3


def test_first_detection_gives_provisional_birth_and_no_id():
    ids = IdAllocator()
    tracker = GmPhdTracker("car", CFG, ids)
    est = tracker.step(make_measurements([(3.0, 4.0)], 0.9, velocity=[(1.0, 0.0)]), 0.0, NullSink())
    lb = birth_likelihood()
    assert est == [] and ids.next_id == 1
    assert tracker.mixture.label.tolist() == [-1]
    assert tracker.mixture.weight[0] == pytest.approx(lb / (P.clutter_intensity + lb), rel=1e-12)
    np.testing.assert_allclose(tracker.mixture.mean[0], [3.0, 4.0, 1.0, 0.0], atol=1e-9)


def test_phd_update_log_space_matches_linear_formula():
    rng = np.random.default_rng(7)
    w = rng.uniform(0.01, 2.0, 6)
    pd = np.array([0.9, 0.9, 0.5, 1.0, 0.9, 1.0])
    log_lik = rng.normal(-2.0, 1.5, (6, 4))
    log_lik[rng.random((6, 4)) < 0.4] = -np.inf
    log_missed, log_det = phd_update(w, pd, log_lik, 1e-3)
    num = (pd * w)[:, None] * np.exp(log_lik)
    np.testing.assert_allclose(np.exp(log_det), num / (1e-3 + num.sum(axis=0)), rtol=1e-12, atol=0)
    np.testing.assert_allclose(np.exp(log_missed), (1 - pd) * w, rtol=1e-12)


def test_log_sum_exp_handles_empty_and_all_minus_infinity():
    a = np.array([[0.0, -np.inf], [np.log(3.0), -np.inf]])
    np.testing.assert_allclose(log_sum_exp(a, axis=0), [np.log(4.0), -np.inf])
    assert log_sum_exp(np.zeros((0, 3)), axis=0).tolist() == [-np.inf] * 3
    big = np.array([1000.0, 1000.0])
    assert log_sum_exp(big, axis=0) == pytest.approx(1000.0 + np.log(2.0))


def run_two_targets(tracker: GmPhdTracker, sink, frames: int = 6) -> list:
    out = []
    for f in range(frames):
        xy = [(2.0 * f, 0.0), (30.0, 10.0 - f)]
        out.append(tracker.step(make_measurements(xy, velocity=[(4.0, 0.0), (0.0, -2.0)]), 0.5 if f else 0.0, sink))
    return out


def test_two_targets_expected_number_is_sum_of_weights():
    tracker = GmPhdTracker("car", CFG, IdAllocator())
    frames = run_two_targets(tracker, NullSink())
    # steady state of one detected target: w = d + (1 - P_D) P_S w with d ~ 1 (the detected part)
    steady = 1.0 / (1.0 - (1.0 - PD) * P.p_survive)
    assert tracker.mixture.weight.sum() == pytest.approx(2 * steady, abs=0.05)
    assert len(frames[-1]) == 2
    assert {e.track_id for e in frames[-1]} == {1, 2}


def test_labels_stay_stable_for_a_moving_target():
    ids = IdAllocator()
    tracker = GmPhdTracker("car", CFG, ids)
    seen = []
    for f in range(8):
        xy = (10.0 + 3.0 * f, -2.0 + 0.5 * f)
        est = tracker.step(make_measurements([xy], 0.8, velocity=[(6.0, 1.0)]), 0.5 if f else 0.0, NullSink())
        seen.append([e.track_id for e in est])
        if est:
            e = est[0]
            assert e.translation_m[:2] == pytest.approx(xy, abs=0.2)
            assert e.velocity_mps == pytest.approx((6.0, 1.0), abs=0.3)
            assert e.score == 0.8 and e.meas_index == 0 and e.existence == pytest.approx(min(1.0, e.existence))
    assert seen[0] == [] and all(s == [1] for s in seen[1:])
    assert ids.next_id == 2


def test_scattered_clutter_burns_no_ids():
    ids = IdAllocator()
    tracker = GmPhdTracker("car", CFG, ids)
    rng = np.random.default_rng(0)
    for f in range(10):
        xy = [tuple(p) for p in rng.uniform(-200.0, 200.0, (3, 2)) + 500.0 * f]
        assert tracker.step(make_measurements(xy, 0.3), 0.5, NullSink()) == []
    assert ids.next_id == 1


def test_shared_label_split_gives_lighter_a_new_id_that_persists():
    ids = IdAllocator()
    tracker = GmPhdTracker("car", CFG, ids)
    tracker.step(make_measurements([(0.0, 0.0)]), 0.0, NullSink())
    # both detections fall inside the gate of the one provisional component
    est = tracker.step(make_measurements([(0.0, 0.0), (1.5, 0.0)]), 0.5, NullSink())
    assert sorted(e.track_id for e in est) == [1, 2]
    by_meas = {e.meas_index: e.track_id for e in est}
    assert by_meas == {0: 1, 1: 2}  # the heavier (closer) component keeps the label
    for _ in range(3):
        est = tracker.step(make_measurements([(0.0, 0.0), (1.5, 0.0)]), 0.5, NullSink())
        assert {e.meas_index: e.track_id for e in est} == by_meas
    assert ids.next_id == 3


def test_component_of_weight_two_gives_two_estimates_with_stable_ids():
    ids = IdAllocator()
    tracker = GmPhdTracker("car", CFG, ids)
    for f in range(3):
        tracker.step(make_measurements([(0.0, 0.0)]), 0.5 if f else 0.0, NullSink())
    assert ids.next_id == 2
    runs = []
    for _ in range(3):
        # two detections at one place: two detected components of label 1, merged into one of weight ~2
        est = tracker.step(make_measurements([(0.0, 0.0), (0.02, 0.0)]), 0.5, NullSink())
        runs.append(sorted(e.track_id for e in est))
    assert tracker.mixture.weight.max() == pytest.approx(2.0, abs=0.2)
    assert runs == [[1, 2]] * 3 and ids.next_id == 3


def test_events_and_pruning_of_an_extracted_track():
    sink = ListSink()
    tracker = GmPhdTracker("car", CFG, IdAllocator())
    for f in range(3):
        tracker.step(make_measurements([(0.0, 0.0)]), 0.5 if f else 0.0, sink)
    for _ in range(8):
        tracker.step(make_measurements([]), 0.5, sink)
    pred = sink.of_type(Predicted)[3]
    assert pred.track_ids.tolist() == [1] and 0 < pred.existence[0] <= 1
    gated = sink.of_type(Gated)[1]
    assert gated.inside.shape == (len(gated.track_ids), 1) and gated.threshold == P.gate_chi2
    born = sink.of_type(Born)
    assert len(born) == 1 and born[0].track_ids.tolist() == [1] and born[0].meas_indices.tolist() == [0]
    pruned = sink.of_type(Pruned)
    assert [(p.track_id, p.reason) for p in pruned] == [(1, PruneReason.LOW_WEIGHT)]
    assert pruned[0].last_existence < CFG.phd.prune_weight
    weights = sink.of_type(IntensityWeights)
    assert len(weights) == 11 and len(weights[-1].weights) == 0 and len(tracker.mixture) == 0
    posterior = sink.of_type(Posterior)[1]
    assert np.all((posterior.existence >= 0) & (posterior.existence <= 1))
    extracted = sink.of_type(Extracted)
    assert [len(e.estimates) for e in extracted[:4]] == [0, 1, 1, 0]
    assert extracted[0].threshold == CFG.phd.extraction_weight


def test_coalescing_tracks_emit_merged_and_pruned_merged():
    sink = ListSink()
    tracker = GmPhdTracker("car", CFG, IdAllocator())
    tracker.mixture = GaussianMixture.concatenate(
        [
            one_component(1.0, [0.0, 0.0, 0.0, 0.0], 0.2 * np.eye(4), label=3),
            one_component(0.9, [0.4, 0.0, 0.0, 0.0], 0.2 * np.eye(4), label=4),
        ]
    )
    tracker.step(make_measurements([]), 0.5, sink)
    merged = sink.of_type(Merged)
    assert len(merged) == 1
    assert merged[0].into_id == 3 and merged[0].from_ids == (3, 4)
    assert merged[0].weights == pytest.approx(((1 - PD) * P.p_survive * 1.0, (1 - PD) * P.p_survive * 0.9))
    assert [(p.track_id, p.reason) for p in sink.of_type(Pruned)] == [(4, PruneReason.MERGED)]
    assert tracker.mixture.label.tolist() == [3]


def test_null_sink_and_list_sink_give_identical_deterministic_tracks():
    a = run_two_targets(GmPhdTracker("car", CFG, IdAllocator()), NullSink())
    b = run_two_targets(GmPhdTracker("car", CFG, IdAllocator()), ListSink())
    assert a == b


def test_empty_frames_on_empty_filter():
    sink = ListSink()
    tracker = GmPhdTracker("car", CFG, IdAllocator())
    assert tracker.step(make_measurements([]), 0.0, sink) == []
    assert tracker.step(make_measurements([]), 0.5, NullSink()) == []
    assert len(sink.of_type(Extracted)) == 1 and len(sink.of_type(Predicted)[0].track_ids) == 0


@pytest.mark.parametrize(
    "field, value",
    [
        ("p_detect", 0.0),
        ("p_detect", 1.5),
        ("prune_weight", -1.0),
        ("merge_threshold", -0.1),
        ("max_components", 0),
        ("extraction_weight", 0.0),
        ("max_cardinality", 0),
    ],
)
def test_phd_params_reject_bad_values(field, value):
    with pytest.raises(ConfigError, match=rf"\[phd\] {field}"):
        PhdParams(**{field: value})


def test_track_that_vanishes_in_the_update_is_reported_pruned():
    cfg = CFG.replace(phd=dataclasses.replace(CFG.phd, p_detect=1.0))
    sink = ListSink()
    tracker = GmPhdTracker("car", cfg, IdAllocator())
    for f in range(3):
        tracker.step(make_measurements([(0.0, 0.0)]), 0.5 if f else 0.0, sink)
    assert [e.track_id for e in sink.of_type(Extracted)[-1].estimates] == [1]
    tracker.step(make_measurements([]), 0.5, sink)  # P_D = 1: a missed target has zero weight
    assert [(p.track_id, p.reason, p.last_existence) for p in sink.of_type(Pruned)] == [
        (1, PruneReason.LOW_WEIGHT, 0.0)
    ]
