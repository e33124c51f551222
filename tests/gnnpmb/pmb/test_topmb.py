"""TO-PMB (marginal association probabilities, merged Bernoullis) against hand computations."""

from __future__ import annotations

import numpy as np
import pytest

from gnnpmb.assign.exact_marginals import exact_marginals_log
from gnnpmb.config import TrackerConfig, paper_config
from gnnpmb.detection_fields import DetectionFields
from gnnpmb.events import Assignment, AxisKind, ListSink, Marginals, Merged, NullSink, Posterior
from gnnpmb.models import measurement_birth
from gnnpmb.pmb.bernoulli import Bernoullis
from gnnpmb.pmb.core import GlobalHypothesis, PmbCore, UpdateContext
from gnnpmb.pmb.cost import local_hypotheses
from gnnpmb.pmb.gnnpmb import BestAssignment
from gnnpmb.pmb.poisson import new_track_hypotheses
from gnnpmb.pmb.topmb import MarginalMerge as TopmbMarginals
from gnnpmb.types import IdAllocator
from tests.gnnpmb.pmb.helpers import make_measurements

CFG = paper_config()  # hand computations use the paper's values (sec. V-B)
P = CFG.models
CAR = CFG.for_class("car")
R = np.diag([CAR.r_x, CAR.r_y])


def gauss2(nu: np.ndarray, S: np.ndarray) -> float:
    return float(np.exp(-0.5 * nu @ np.linalg.solve(S, nu)) / (2 * np.pi * np.sqrt(np.linalg.det(S))))


def make_prior(means, existence, cov_diag=(0.5, 0.5, 1.0, 1.0), score=0.8) -> Bernoullis:
    k = len(means)
    return Bernoullis(
        track_id=np.arange(1, k + 1),
        local_key=np.arange(1, k + 1),
        existence=np.asarray(existence, dtype=float),
        mean=np.asarray(means, dtype=float).reshape(k, 4),
        cov=np.tile(np.diag(cov_diag), (k, 1, 1)),
        det=DetectionFields(
            score=np.full(k, score),
            z_m=np.zeros(k),
            size_wlh_m=np.ones((k, 3)),
            quat_wxyz=np.tile([1.0, 0.0, 0.0, 0.0], (k, 1)),
            meas_index=np.full(k, -1),
        ),
        misses=np.zeros(k, dtype=np.int64),
        detected_score_sum=np.zeros(k),
        detected_frames=np.zeros(k, dtype=np.int64),
    )


def run_update(prior: Bernoullis, xy, score=0.7, strategy=None, sink=None, prune_existence=CFG.pmb.prune_existence):
    """One strategy update of ``prior`` with car measurements at ``xy``; ids continue after the prior's."""
    meas = make_measurements(xy, score)
    new = new_track_hypotheses(measurement_birth(meas, P), meas, R, P.clutter_intensity)
    local = local_hypotheses(prior, meas, new, R, P.gate_chi2)
    sink = sink if sink is not None else ListSink()
    ctx = UpdateContext("car", sink, IdAllocator(next_id=len(prior) + 1), 1, prune_existence)
    strategy = strategy or TopmbMarginals(CFG.lbp)
    (post,) = strategy.update([GlobalHypothesis(0.0, prior)], [local], ctx)
    return post.bernoullis, sink, ctx


def hand_terms(r, mean, cov, z, score, pd_track=0.8):
    """Missed weight / existence, detected weight and Kalman posterior, new-track weight and existence."""
    l0 = 1.0 - r * pd_track
    r_miss = r * (1.0 - pd_track) / l0
    S = cov[:2, :2] + R
    l_det = r * score * gauss2(z - mean[:2], S)
    K = cov[:, :2] @ np.linalg.inv(S)
    IKH = np.eye(4) - K @ np.eye(2, 4)
    m_det = mean + K @ (z - mean[:2])
    P_det = IKH @ cov @ IKH.T + K @ R @ K.T
    birth = P.birth_weight * score * gauss2(np.zeros(2), np.eye(2) * P.birth_pos_std_m**2 + R)
    l_new = P.clutter_intensity + birth
    return l0, r_miss, l_det, m_det, P_det, l_new, birth / l_new


def test_single_target_single_measurement_by_hand():
    mean, cov, r, z = np.array([0.0, 0.0, 1.0, 0.0]), np.diag([0.5, 0.5, 1.0, 1.0]), 0.05, np.array([0.9, 0.3])
    post, sink, ctx = run_update(make_prior([mean], [r]), [tuple(z)])
    l0, r_miss, l_det, m_det, P_det, l_new, r_new = hand_terms(r, mean, cov, z, 0.7)
    p_det = l_det / (l_det + l0 * l_new)  # associations: missed + new (l0 l_new), detected (l_det)
    p_miss = 1.0 - p_det
    r_post = p_miss * r_miss + p_det
    b0, b1 = p_miss * r_miss / r_post, p_det / r_post
    m_post = b0 * mean + b1 * m_det
    d0, d1 = mean - m_post, m_det - m_post
    P_post = b0 * (cov + np.outer(d0, d0)) + b1 * (P_det + np.outer(d1, d1))

    marg = sink.of_type(Marginals)[0]
    np.testing.assert_allclose(marg.probs, [[p_miss, p_det]], atol=1e-12)
    assert marg.method == "lbp" and [c.kind for c in marg.cols] == [AxisKind.MISSED, AxisKind.MEASUREMENT]
    assert [r.ref for r in marg.rows] == [1]
    assert post.track_id.tolist() == [1, 2]  # the track, then the birth of measurement 0 with the next id
    assert post.existence[0] == pytest.approx(r_post, rel=1e-12)
    np.testing.assert_allclose(post.mean[0], m_post, atol=1e-12)
    np.testing.assert_allclose(post.cov[0], P_post, atol=1e-12)
    assert post.existence[1] == pytest.approx(p_miss * r_new, rel=1e-12)
    assert post.meas_index.tolist() == [0, 0] and post.score[0] == pytest.approx(0.7)
    assert ctx.born_ids == {0: 2}
    assert p_miss * r_miss < 0.05 and sink.of_type(Merged) == []  # the missed component is too light to report


def test_single_target_two_measurements_merges_both_by_hand():
    mean, cov, r = np.array([0.0, 0.0, 0.0, 0.0]), np.diag([0.5, 0.5, 1.0, 1.0]), 0.9
    z1, z2 = np.array([-0.6, 0.0]), np.array([0.5, 0.0])
    post, sink, _ = run_update(make_prior([mean], [r]), [tuple(z1), tuple(z2)])
    l0, r_miss, l1, m1, P1, l_new, _ = hand_terms(r, mean, cov, z1, 0.7)
    _, _, l2, m2, _, _, _ = hand_terms(r, mean, cov, z2, 0.7)
    weights = np.array([l0 * l_new * l_new, l1 * l_new, l2 * l_new])  # missed, z1, z2 (other one is new)
    p = weights / weights.sum()
    r_post = p[0] * r_miss + p[1] + p[2]
    beta = np.array([p[0] * r_miss, p[1], p[2]]) / r_post
    m_post = beta[0] * mean + beta[1] * m1 + beta[2] * m2
    np.testing.assert_allclose(sink.of_type(Marginals)[0].probs, [p], atol=1e-12)
    assert post.existence[0] == pytest.approx(r_post, rel=1e-12)
    np.testing.assert_allclose(post.mean[0], m_post, atol=1e-12)
    assert post.meas_index[0] == 1  # z2 is closer: most probable, gives the box fields
    (merged,) = sink.of_type(Merged)
    assert merged.into_id == 1 and merged.from_ids == (0, 1)
    np.testing.assert_allclose(merged.weights, p[1:], atol=1e-12)  # existence mass of each component
    assert p[0] * r_miss < 0.05 < min(p[1:])


def test_two_close_targets_coalesce():
    # Uncertain tracks (position variance 4 m^2) 2 m apart, two detections between them. Exact marginals would
    # give the swapped association 0.45 here; LBP gives 0.28 (on a 2 x 2 loop it leans towards the dominant
    # assignment), which still pulls the two merged states well towards each other.
    prior = make_prior([[0.0, 0.0, 0.0, 0.0], [2.0, 0.0, 0.0, 0.0]], [0.9, 0.9], cov_diag=(4.0, 4.0, 1.0, 1.0))
    xy = [(0.8, 0.0), (1.2, 0.0)]
    topmb, sink, _ = run_update(prior, xy)
    gnn, _, _ = run_update(prior, xy, strategy=BestAssignment())
    gap_topmb = topmb.mean[1, 0] - topmb.mean[0, 0]
    gap_gnn = gnn.mean[1, 0] - gnn.mean[0, 0]
    assert gnn.meas_index[:2].tolist() == [0, 1]
    assert 0.0 < gap_topmb < gap_gnn - 0.1  # both pulled towards the middle, further than by a hard assignment
    assert topmb.mean[0, 0] > gnn.mean[0, 0] and topmb.mean[1, 0] < gnn.mean[1, 0]
    merged = {m.into_id: m for m in sink.of_type(Merged)}
    assert set(merged) == {1, 2} and all(m.from_ids == (0, 1) for m in merged.values())
    # the merged covariance includes the spread of the components: wider than the single Kalman update's
    assert topmb.cov[0, 0, 0] > gnn.cov[0, 0, 0]
    assignment = sink.of_type(Assignment)[0]
    assert {(r.ref, c.kind, c.ref) for r, c in assignment.pairs} == {(0, AxisKind.TRACK, 1), (1, AxisKind.TRACK, 2)}


def test_marginals_event_matches_exact_enumeration_on_a_tree():
    prior = make_prior([[0.0, 0.0, 0.0, 0.0], [5.0, 0.0, 0.0, 0.0]], [0.9, 0.6])
    meas = make_measurements([(0.3, 0.1), (-0.4, 0.0), (5.2, 0.2)], 0.7)
    new = new_track_hypotheses(measurement_birth(meas, P), meas, R, P.clutter_intensity)
    local = local_hypotheses(prior, meas, new, R, P.gate_chi2)
    exact = exact_marginals_log(local.det_log_lik - local.miss_log_lik[:, None], new.log_likelihood)
    _, sink, _ = run_update(prior, [(0.3, 0.1), (-0.4, 0.0), (5.2, 0.2)])
    np.testing.assert_allclose(sink.of_type(Marginals)[0].probs, exact.p_track, atol=1e-12)


def test_far_measurement_births_and_missed_track():
    prior = make_prior([[0.0, 0.0, 0.0, 0.0]], [0.7])
    post, sink, ctx = run_update(prior, [(40.0, 0.0)])
    l0 = 1.0 - 0.7 * 0.8
    assert post.existence[0] == pytest.approx(0.7 * 0.2 / l0, rel=1e-12)
    np.testing.assert_allclose(post.mean[0], prior.mean[0], atol=1e-15)
    np.testing.assert_allclose(post.cov[0], prior.cov[0], atol=1e-15)
    assert post.meas_index[0] == -1 and post.score[0] == 0.8
    alone, _, _ = run_update(make_prior([], []), [(40.0, 0.0)])
    assert ctx.born_ids == {0: 2} and post.existence[1] == pytest.approx(alone.existence[0], rel=1e-12)
    assignment = sink.of_type(Assignment)[0]
    assert assignment.missed_track_ids == (1,) and assignment.pairs[0][1].kind == AxisKind.NEW_TRACK


def test_no_birth_id_below_the_pruning_threshold():
    prior = make_prior([[0.0, 0.0, 0.0, 0.0]], [0.7])
    post, _, ctx = run_update(prior, [(0.05, 0.0)], prune_existence=1e-2)
    assert ctx.born_ids == {} and post.track_id.tolist() == [1]
    post, _, ctx = run_update(prior, [(0.05, 0.0)], prune_existence=1e-6)
    assert ctx.born_ids == {0: 2} and 1e-6 <= post.existence[1] < 1e-2


def test_no_measurements_and_no_tracks():
    post, sink, _ = run_update(make_prior([[0.0, 0.0, 0.0, 0.0]], [0.5]), [])
    assert post.existence[0] == pytest.approx(0.5 * 0.2 / (1 - 0.5 * 0.8), rel=1e-12)
    assert sink.of_type(Marginals)[0].probs.shape == (1, 1)
    post, _, _ = run_update(make_prior([], []), [])
    assert len(post) == 0


def random_scene(rng: np.random.Generator, n_frames: int = 8):
    """Five cars on crossing paths, P_D 0.85, a few clutter detections per frame."""
    start = rng.uniform(-10, 10, size=(5, 2))
    vel = rng.normal(scale=2.0, size=(5, 2))
    frames = []
    for t in range(n_frames):
        pos = start + 0.5 * t * vel
        seen = pos[rng.random(5) < 0.85] + rng.normal(scale=0.3, size=(1, 2))
        clutter = rng.uniform(-15, 15, size=(int(rng.integers(0, 4)), 2))
        xy = np.concatenate([seen, clutter])
        frames.append(([tuple(p) for p in xy], rng.uniform(0.3, 0.95, size=len(xy)).tolist()))
    return frames


def run_core(frames, sink):
    core = PmbCore("car", CFG, TopmbMarginals(CFG.lbp), IdAllocator())
    dts = [0.0] + [0.5] * (len(frames) - 1)
    steps = zip(frames, dts, strict=True)
    return core, [core.step(make_measurements(xy, score), dt, sink) for (xy, score), dt in steps]


def test_existence_in_unit_interval_and_covariances_positive_definite():
    sink = ListSink()
    run_core(random_scene(np.random.default_rng(11)), sink)
    posteriors = sink.of_type(Posterior)
    assert len(posteriors) == 8
    for post in posteriors:
        assert np.all((post.existence >= 0.0) & (post.existence <= 1.0))
        assert np.all(np.isfinite(post.mean)) and np.all(np.isfinite(post.cov))
        np.testing.assert_allclose(post.cov, np.swapaxes(post.cov, 1, 2), atol=1e-12)
        assert np.all(np.linalg.eigvalsh(post.cov) > 0.0)
    for marg in sink.of_type(Marginals):
        np.testing.assert_allclose(marg.probs.sum(axis=1), 1.0, atol=1e-12)


def test_deterministic_and_sink_independent():
    frames = random_scene(np.random.default_rng(12))
    _, a = run_core(frames, NullSink())
    _, b = run_core(frames, ListSink())
    assert a == b and any(len(est) for est in a)


def test_demo_scene_runs_without_nan(demo_dataroot):
    from gnnpmb.data.nuscenes import load_scene, resolve_dataroot
    from gnnpmb.pipeline import get_detections, run_tracker

    loc = resolve_dataroot(demo_dataroot, None)
    scene = load_scene(loc, "scene-0103")
    run = run_tracker(scene, get_detections(scene, None, "centerpoint", seed=0), "topmb", TrackerConfig())
    estimates = [e for f in run.frames for e in f.estimates]
    assert estimates
    for e in estimates:
        assert np.all(np.isfinite(e.translation_m)) and np.all(np.isfinite(e.velocity_mps))
        assert 0.0 <= e.existence <= 1.0 and 0.0 <= e.score <= 1.0


def test_a_missed_tracks_detection_probability_is_capped_by_miss_p_detect_max() -> None:
    """Hand-computed misdetection hypothesis: r = 0.95, last score 0.9. Paper (no cap): l0 = 1 - 0.855 = 0.145,
    r' = 0.095 / 0.145 = 0.655; capped at 0.3: l0 = 1 - 0.285 = 0.715, r' = 0.665 / 0.715 = 0.930. The default
    config caps (``PmbParams.miss_p_detect_max``); the paper's file does not."""
    prior = make_prior([[0.0, 0.0, 0.0, 0.0]], [0.95], score=0.9)
    meas = make_measurements([(30.0, 0.0)], 0.7)  # outside the gate: only the misdetection matters
    new = new_track_hypotheses(measurement_birth(meas, P), meas, R, P.clutter_intensity)
    paper = local_hypotheses(prior, meas, new, R, P.gate_chi2)
    capped = local_hypotheses(prior, meas, new, R, P.gate_chi2, miss_p_detect_max=0.3)
    np.testing.assert_allclose(np.exp(paper.miss_log_lik), [0.145])
    np.testing.assert_allclose(paper.miss_existence, [0.095 / 0.145])
    np.testing.assert_allclose(np.exp(capped.miss_log_lik), [0.715])
    np.testing.assert_allclose(capped.miss_existence, [0.665 / 0.715])
    assert CFG.pmb.miss_p_detect_max == 1.0
    from gnnpmb.config import TrackerConfig

    assert TrackerConfig().pmb.miss_p_detect_max == 0.3
