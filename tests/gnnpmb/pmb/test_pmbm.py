"""PMBM (``pmb.pmbm.KBest``): hand-computed hypothesis weights, equality with GNN-PMB at N_h = 1, the paper's
point (a hypothesis GNN-PMB discards wins later), merging, and equality with a plain per-hypothesis
reference."""

from __future__ import annotations

import dataclasses
import itertools
import math
from pathlib import Path

import numpy as np
import pytest
from scipy.special import logsumexp

from gnnpmb.assign import murty
from gnnpmb.assign.clusters import Cluster
from gnnpmb.assign.murty import k_best
from gnnpmb.config import ConfigError, PmbmParams, PmbParams, TrackerConfig, load_config
from gnnpmb.detection_fields import DetectionFields
from gnnpmb.events import Assignment, CostMatrix, GlobalHypotheses, ListSink, NullSink, Pruned, PruneReason
from gnnpmb.pmb.bernoulli import Bernoullis
from gnnpmb.pmb.core import GlobalHypothesis, PmbCore, UpdateContext, posterior_from_assignment
from gnnpmb.pmb.gnnpmb import BestAssignment
from gnnpmb.pmb.pmbm import KBest, SharedRanking, _presence_patterns, _row_keys, hypothesis_budget
from gnnpmb.types import IdAllocator, Measurements
from tests.gnnpmb.pmb.helpers import CFG, P, Q, R, gauss2, make_measurements


def one_track(score: float = 0.9, pos_var: float = 0.1, vel_var: float = 0.5) -> Bernoullis:
    """An established track (r = 1) at the origin, at rest; track id 1."""
    return Bernoullis(
        track_id=np.array([1]),
        local_key=np.array([12345]),
        existence=np.array([1.0]),
        mean=np.zeros((1, 4)),
        cov=np.diag([pos_var, pos_var, vel_var, vel_var])[None],
        det=DetectionFields(
            score=np.array([score]),
            z_m=np.array([1.0]),
            size_wlh_m=np.array([[2.0, 4.5, 1.6]]),
            quat_wxyz=np.array([[1.0, 0.0, 0.0, 0.0]]),
            meas_index=np.array([-1]),
        ),
        misses=np.zeros(1, dtype=np.int64),
        detected_score_sum=np.zeros(1),
        detected_frames=np.zeros(1, dtype=np.int64),
    )


def core_with_track(strategy, config: TrackerConfig = CFG) -> PmbCore:
    core = PmbCore("car", config, strategy, IdAllocator(next_id=2))
    core.hypotheses = [GlobalHypothesis(0.0, one_track())]
    return core


def cluttered_sequence(seed: int, n_frames: int = 12) -> list[Measurements]:
    """Four targets on crossing paths, 1-2 m apart at times, with misses and clutter: ambiguous
    associations."""
    rng = np.random.default_rng(seed)
    start = np.array([[0.0, 0.0], [3.0, 1.0], [1.0, 4.0], [6.0, 2.0]])
    velocity = np.array([[2.0, 0.5], [-1.0, 0.6], [1.5, -1.2], [-2.0, 0.0]])
    frames = []
    for t in range(n_frames):
        xy = start + 0.5 * t * velocity + rng.normal(0.0, 0.25, size=start.shape)
        xy = xy[rng.random(len(xy)) > 0.15]
        clutter = rng.uniform(-2.0, 8.0, size=(int(rng.integers(0, 3)), 2))
        points = np.concatenate([xy, clutter])
        frames.append(make_measurements([tuple(p) for p in points], list(rng.uniform(0.3, 0.95, len(points)))))
    return frames


def test_two_hypotheses_weights_equal_hand_computed_likelihoods():
    """One track, one measurement in its gate: 'detected' vs 'missed + new track' (García-Fernández et al.
    2018, eq. 12-15), with P_D = the detection's score and, for the miss, the track's last score."""
    z, s_z, s_track, dt = np.array([2.2, 0.0]), 0.8, 0.9, 0.5
    core = core_with_track(KBest(CFG.pmbm))
    core.step(make_measurements([tuple(z)], s_z), dt, NullSink())

    F = np.eye(4)
    F[0, 2] = F[1, 3] = dt
    P_pred = F @ np.diag([0.1, 0.1, 0.5, 0.5]) @ F.T + Q
    S = P_pred[:2, :2] + R
    r_pred = P.p_survive
    l_detected = r_pred * s_z * gauss2(z, S)
    l_missed = 1.0 - r_pred * s_track
    birth_S = np.diag([P.birth_pos_std_m**2] * 2) + R
    l_new = P.clutter_intensity + P.birth_weight * s_z * gauss2(np.zeros(2), birth_S)
    w_detected = l_detected / (l_detected + l_missed * l_new)

    hyps = core.hypotheses
    assert len(hyps) == 2
    assert math.exp(hyps[0].log_weight) == pytest.approx(w_detected, rel=1e-9)
    assert math.exp(hyps[1].log_weight) == pytest.approx(1.0 - w_detected, rel=1e-9)
    detected, missed = hyps[0].bernoullis, hyps[1].bernoullis
    assert detected.track_id.tolist() == [1] and detected.existence.tolist() == [1.0]
    K = P_pred[:, :2] @ np.linalg.inv(S)
    np.testing.assert_allclose(detected.mean[0], K @ z, atol=1e-12)
    assert missed.track_id.tolist() == [1, 2]
    assert missed.existence[0] == pytest.approx(r_pred * (1 - s_track) / l_missed, rel=1e-12)
    assert missed.existence[1] == pytest.approx((l_new - P.clutter_intensity) / l_new, rel=1e-12)


def _duplicate_rule(min_existence: float) -> TrackerConfig:
    return CFG.replace(pmbm=dataclasses.replace(CFG.pmbm, duplicate_birth_existence=min_existence))


def _weights_and_tracks(core: PmbCore) -> list[tuple[float, list[int]]]:
    return [(h.log_weight, h.bernoullis.track_id.tolist()) for h in core.hypotheses]


def test_a_birth_inside_the_gate_of_its_missed_track_is_dropped_unless_it_is_the_heaviest():
    """Track 1 (r = 1, predicted r = P_S = 0.7) and one detection inside its gate. At x = 2.2 m 'detected' weighs
    0.749 and 'missed + new track' 0.251 (the hand computation above): with the rule at r >= 0.5 (the record
    ``gnnpmb/params/pmbm_duplicate_birth.toml``) the second,
    a birth inside the gate of the track it leaves missed, is dropped and 'detected' alone has weight 1. At
    r >= 0.8 the track is not sure enough and both stay, weighed as without the rule. At x = 2.6 m 'missed +
    new track' is the heaviest (0.719, d^2 14.3 inside the gate 40), so the rule keeps it and changes nothing."""
    off = core_with_track(KBest(CFG.pmbm))
    off.step(make_measurements([(2.2, 0.0)], 0.8), 0.5, NullSink())
    assert [tracks for _, tracks in _weights_and_tracks(off)] == [[1], [1, 2]]
    record = load_config(Path(__file__).resolve().parents[3] / "gnnpmb" / "params" / "pmbm_duplicate_birth.toml")
    assert record.pmbm.duplicate_birth_existence == 0.5  # Round 19's record (docs/results.md)
    on = core_with_track(KBest(_duplicate_rule(0.5).pmbm), _duplicate_rule(0.5))
    on.step(make_measurements([(2.2, 0.0)], 0.8), 0.5, NullSink())
    assert _weights_and_tracks(on) == [(0.0, [1])]
    assert on.hypotheses[0].bernoullis.mean.tolist() == off.hypotheses[0].bernoullis.mean.tolist()
    unsure = core_with_track(KBest(_duplicate_rule(0.8).pmbm), _duplicate_rule(0.8))
    unsure.step(make_measurements([(2.2, 0.0)], 0.8), 0.5, NullSink())
    assert _weights_and_tracks(unsure) == _weights_and_tracks(off)

    heaviest_off = core_with_track(KBest(CFG.pmbm))
    heaviest_on = core_with_track(KBest(_duplicate_rule(0.5).pmbm), _duplicate_rule(0.5))
    for core in (heaviest_off, heaviest_on):
        core.step(make_measurements([(2.6, 0.0)], 0.8), 0.5, NullSink())
    assert [tracks for _, tracks in _weights_and_tracks(heaviest_on)] == [[1, 2], [1]]
    assert math.exp(heaviest_on.hypotheses[0].log_weight) == pytest.approx(0.719, abs=5e-4)
    assert _weights_and_tracks(heaviest_on) == _weights_and_tracks(heaviest_off)


def test_the_duplicate_rule_off_is_todays_pmbm_and_on_keeps_weights_normalised():
    """At 0 the rule is off: a cluttered sequence gives what the defaults give, bit for bit. On, every frame's
    hypotheses still sum to 1, fall in weight and number at most N_h."""
    default = PmbCore("car", CFG, KBest(CFG.pmbm), IdAllocator())
    off = PmbCore("car", _duplicate_rule(0.0), KBest(_duplicate_rule(0.0).pmbm), IdAllocator())
    on = PmbCore("car", _duplicate_rule(0.5), KBest(_duplicate_rule(0.5).pmbm), IdAllocator())
    fewer = 0
    for meas in cluttered_sequence(seed=4):
        assert default.step(meas, 0.5, NullSink()) == off.step(meas, 0.5, NullSink())
        assert _weights_and_tracks(default) == _weights_and_tracks(off)
        on.step(meas, 0.5, NullSink())
        log_w = np.array([h.log_weight for h in on.hypotheses])
        assert logsumexp(log_w) == pytest.approx(0.0, abs=1e-12) and np.all(np.diff(log_w) <= 0)
        assert 1 <= len(log_w) <= CFG.pmbm.n_hypotheses
        fewer += len(on.hypotheses) < len(default.hypotheses)
    assert fewer > 0


def test_n_h_one_equals_gnnpmb_on_a_multi_target_sequence():
    config = CFG.replace(pmbm=PmbmParams(n_hypotheses=1))
    a = PmbCore("car", config, KBest(config.pmbm), IdAllocator())
    b = PmbCore("car", config, BestAssignment(), IdAllocator())
    for meas in cluttered_sequence(seed=1, n_frames=15):
        assert a.step(meas, 0.5, NullSink()) == b.step(meas, 0.5, NullSink())
        assert len(a.hypotheses) == 1


def test_n_h_one_equals_gnnpmb_on_a_demo_scene(demo_dataroot):
    from gnnpmb.data.nuscenes import load_scene, resolve_dataroot
    from gnnpmb.pipeline import get_detections, preprocess_frames, run_tracker
    from gnnpmb.types import TRACKING_CLASSES

    location = resolve_dataroot(demo_dataroot, "v1.0-mini")
    scene = load_scene(location, "scene-0103")
    detections = get_detections(scene, None, "centerpoint", seed=0)
    config = CFG.replace(pmbm=PmbmParams(n_hypotheses=1))
    frames = preprocess_frames(scene, detections, config, TRACKING_CLASSES)
    a = run_tracker(scene, frames, "pmbm", config)
    b = run_tracker(scene, frames, "gnnpmb", config)
    assert sum(len(f.estimates) for f in b.frames) > 0
    assert [f.estimates for f in a.frames] == [f.estimates for f in b.frames]


def test_a_hypothesis_gnnpmb_discards_wins_later():
    """A track at rest at x = 0 and one detection at x = 2.2: 'the track moved there' is the best hypothesis
    (GNN-PMB keeps only it), 'the track was missed, a new object appeared' the second. Two more frames with
    detections at both 0 and 2.2 make the second hypothesis the most likely: PMBM reports track 1 at 0 and a
    new track at 2.2, GNN-PMB keeps dragging track 1 to 2.2 and starts a new track at 0."""
    a, b = core_with_track(KBest(CFG.pmbm)), core_with_track(BestAssignment())
    first = make_measurements([(2.2, 0.0)], 0.9)
    a.step(first, 0.5, NullSink())
    b.step(first, 0.5, NullSink())
    assert len(a.hypotheses) == 2 and math.exp(a.hypotheses[1].log_weight) > 0.2
    np.testing.assert_allclose(a.hypotheses[0].bernoullis.mean, b.hypotheses[0].bernoullis.mean)
    for _ in range(2):
        both = make_measurements([(0.0, 0.0), (2.2, 0.0)], 0.9)
        ea = a.step(both, 0.5, NullSink())
        eb = b.step(both, 0.5, NullSink())
    x_pmbm = {e.track_id: e.translation_m[0] for e in ea}
    x_gnnpmb = {e.track_id: e.translation_m[0] for e in eb}
    assert x_pmbm[1] == pytest.approx(0.0, abs=0.05) and x_gnnpmb[1] > 2.0
    (new_pmbm,) = set(x_pmbm) - {1}
    (new_gnnpmb,) = set(x_gnnpmb) - {1}
    assert x_pmbm[new_pmbm] == pytest.approx(2.2, abs=0.05) and x_gnnpmb[new_gnnpmb] == pytest.approx(0.0, abs=0.05)


def test_hypotheses_identical_after_pruning_are_merged():
    """With prune_existence 0.2 the 'missed + new' hypothesis is empty after the ambiguous frame, and after an
    empty frame the other one (its track missed, r = 0.19) is empty too: the two merge into one of weight
    1."""
    config = CFG.replace(pmb=dataclasses.replace(CFG.pmb, prune_existence=0.2))
    core = core_with_track(KBest(config.pmbm), config)
    core.step(make_measurements([(2.2, 0.0)], 0.9), 0.5, NullSink())
    assert len(core.hypotheses) == 2 and len(core.hypotheses[1].bernoullis) == 0
    sink = ListSink()
    core.step(make_measurements([]), 0.5, sink)
    assert len(core.hypotheses) == 1 and core.hypotheses[0].log_weight == 0.0
    assert len(core.hypotheses[0].bernoullis) == 0
    assert [(p.track_id, p.reason) for p in sink.of_type(Pruned)] == [(1, PruneReason.LOW_EXISTENCE)]


class PlainKBest:
    """The PMBM update written out plainly (per hypothesis ``k_best``, merge by building every child's
    Bernoullis and comparing local keys): the reference the shared-block implementation must equal."""

    name = "plain-k-best"

    def __init__(self, params: PmbmParams):
        self.params = params

    def update(self, priors, locals_, ctx):
        log_w = np.array([h.log_weight for h in priors])
        log_w = log_w - logsumexp(log_w)
        limit = -math.log(self.params.hypothesis_prune)
        children: list[list] = []
        signatures: dict[bytes, int] = {}
        for h in range(len(locals_)):
            local = locals_[h]
            budget = hypothesis_budget(self.params.n_hypotheses, log_w[h])
            for cols, total in k_best(local.cost_matrix(), budget, max_increase=limit):
                scratch = UpdateContext(ctx.class_name, NullSink(), IdAllocator(10**9), ctx.frame_serial)
                b = posterior_from_assignment(local, cols, scratch)
                key = np.sort(b.local_key[b.existence >= ctx.prune_existence]).tobytes()
                weight = log_w[h] + local.base_log_weight() - total
                if key in signatures:
                    child = children[signatures[key]]
                    child[0] = np.logaddexp(child[0], weight)
                else:
                    signatures[key] = len(children)
                    children.append([weight, h, cols])
        w = np.array([c[0] for c in children])
        w = w - logsumexp(w)
        order = np.argsort(-w, kind="stable")
        keep = order[w[order] >= math.log(self.params.hypothesis_prune)][: self.params.n_hypotheses]
        keep = keep if len(keep) else order[:1]
        kept_w = w[keep] - logsumexp(w[keep])
        return [
            GlobalHypothesis(float(lw), posterior_from_assignment(locals_[children[i][1]], children[i][2], ctx))
            for i, lw in zip(keep, kept_w, strict=True)
        ]


@pytest.mark.parametrize("prune_existence", [1e-6, 1e-3])
def test_equals_the_plain_per_hypothesis_reference(prune_existence):
    config = CFG.replace(pmb=PmbParams(prune_existence=prune_existence), pmbm=PmbmParams(n_hypotheses=30, n_scan=0))
    a = PmbCore("car", config, KBest(config.pmbm), IdAllocator())
    b = PmbCore("car", config, PlainKBest(config.pmbm), IdAllocator())
    most = 0
    for meas in cluttered_sequence(seed=4, n_frames=12):
        assert a.step(meas, 0.5, NullSink()) == b.step(meas, 0.5, NullSink())
        assert len(a.hypotheses) == len(b.hypotheses)
        most = max(most, len(a.hypotheses))
        for ha, hb in zip(a.hypotheses, b.hypotheses, strict=True):
            assert ha.log_weight == pytest.approx(hb.log_weight, abs=1e-9)
            np.testing.assert_array_equal(ha.bernoullis.local_key, hb.bernoullis.local_key)
            np.testing.assert_array_equal(ha.bernoullis.track_id, hb.bernoullis.track_id)
            np.testing.assert_allclose(ha.bernoullis.mean, hb.bernoullis.mean, atol=1e-12)
    assert most > 10  # the sequence is ambiguous enough to exercise the hypothesis management


def test_weights_normalised_sorted_and_at_most_n_h():
    config = CFG.replace(pmbm=PmbmParams(n_hypotheses=20, n_scan=0))
    core = PmbCore("car", config, KBest(config.pmbm), IdAllocator())
    sink = ListSink()
    parents = []
    for meas in cluttered_sequence(seed=2):
        start = len(sink.events)
        core.step(meas, 0.5, sink)
        # The best hypothesis' assignment is over the cost matrix of the prior hypothesis it came from: its pairs
        # add up to its total cost in that matrix (missed tracks cost 0).
        step_events = sink.events[start:]
        (assignment,) = [e for e in step_events if isinstance(e, Assignment)]
        matrix = {e.hypothesis: e for e in step_events if isinstance(e, CostMatrix)}[assignment.hypothesis]
        row, col = ({label: i for i, label in enumerate(axis)} for axis in (matrix.rows, matrix.cols))
        picked = sum(matrix.cost[row[r], col[c]] for r, c in assignment.pairs)
        assert picked == pytest.approx(assignment.total_cost, abs=1e-9)
        parents.append(assignment.hypothesis)
        log_w = np.array([h.log_weight for h in core.hypotheses])
        assert 1 <= len(log_w) <= 20
        assert logsumexp(log_w) == pytest.approx(0.0, abs=1e-12)
        assert np.all(np.diff(log_w) <= 0)
        event = sink.of_type(GlobalHypotheses)[-1]
        np.testing.assert_array_equal(event.log_weights, log_w)
        assert event.members == tuple(tuple(h.bernoullis.track_id.tolist()) for h in core.hypotheses)
        assert event.local == tuple(tuple(h.bernoullis.local_key.tolist()) for h in core.hypotheses)
    assert max(len(e.log_weights) for e in sink.of_type(GlobalHypotheses)) == 20
    assert max(parents) > 0  # the best posterior hypothesis did come from another prior hypothesis
    assert {0, 1, 2} <= {e.hypothesis for e in sink.of_type(CostMatrix)}


def test_same_input_same_output():
    def run():
        core = PmbCore("car", CFG, KBest(CFG.pmbm), IdAllocator())
        out = [core.step(meas, 0.5, NullSink()) for meas in cluttered_sequence(seed=3)]
        return out, [(h.log_weight, h.bernoullis.local_key.tolist()) for h in core.hypotheses]

    assert run() == run()


def test_sink_does_not_change_the_result():
    a = PmbCore("car", CFG, KBest(CFG.pmbm), IdAllocator())
    b = PmbCore("car", CFG, KBest(CFG.pmbm), IdAllocator())
    for meas in cluttered_sequence(seed=5):
        assert a.step(meas, 0.5, NullSink()) == b.step(meas, 0.5, ListSink())


def test_invalid_parameters_are_refused():
    with pytest.raises(ConfigError, match="n_hypotheses"):
        PmbmParams(n_hypotheses=0)
    with pytest.raises(ConfigError, match="hypothesis_prune"):
        PmbmParams(hypothesis_prune=1.0)


def test_hypothesis_budget():
    assert hypothesis_budget(100, math.log(0.02)) == 2
    assert hypothesis_budget(100, math.log(1e-9)) == 1
    assert hypothesis_budget(100, 0.0) == 100
    assert hypothesis_budget(1, math.log(0.5)) == 1


class UnionStub:
    """What ``SharedRanking`` reads of the union's local hypotheses: a PMB-shaped cost matrix (M rows,
    U track columns, one private new-track column per row)."""

    def __init__(self, cost: np.ndarray):
        self.n_meas = cost.shape[0]
        self.n_tracks = cost.shape[1] - self.n_meas
        self._cost = cost

    def cost_matrix(self) -> np.ndarray:
        return self._cost


@pytest.mark.parametrize("enumeration_limit", [0, murty.ENUMERATION_LIMIT])
@pytest.mark.parametrize("max_increase", [2.0, 9.2, math.inf])
def test_shared_ranking_equals_k_best_of_every_hypothesis(max_increase, enumeration_limit, monkeypatch):
    """Hypotheses hold random subsets of the union's tracks; ranking the union's blocks once per subset
    pattern and combining them must give each hypothesis exactly its own k best (within max_increase)."""
    monkeypatch.setattr(murty, "ENUMERATION_LIMIT", enumeration_limit)
    rng = np.random.default_rng(17)
    for _ in range(40):
        n_meas, n_union = int(rng.integers(1, 6)), int(rng.integers(1, 7))
        tracks = rng.uniform(0.0, 14.0, size=(n_meas, n_union))
        tracks[rng.random(tracks.shape) < 0.5] = np.inf
        new = np.full((n_meas, n_meas), np.inf)
        new[np.arange(n_meas), np.arange(n_meas)] = rng.uniform(3.0, 8.0, n_meas)
        cost = np.concatenate([tracks, new], axis=1)
        members = [np.flatnonzero(rng.random(n_union) < 0.6) for _ in range(int(rng.integers(2, 6)))]
        budgets = [int(rng.integers(1, 30)) for _ in members]
        got = SharedRanking(UnionStub(cost), members, max_increase).k_best(budgets)
        for index, budget, ranked in zip(members, budgets, got, strict=True):
            own = cost[:, np.concatenate([index, n_union + np.arange(n_meas)])]
            want = k_best(own, budget, max_increase)
            np.testing.assert_allclose([t for _, t in ranked], [t for _, t in want], atol=1e-9)
            for cols, total in ranked:  # columns of the union matrix, only the hypothesis' own
                assert total == pytest.approx(cost[np.arange(n_meas), cols].sum(), abs=1e-9)
                assert np.isin(cols[cols < n_union], index).all()


def test_budget_gives_a_large_block_only_its_best_assignment_and_says_so():
    from gnnpmb.events import BudgetReached, ListSink

    unbounded = PmbCore("car", CFG, KBest(CFG.pmbm), IdAllocator())
    budgeted = PmbCore("car", CFG, KBest(CFG.pmbm, murty_block_rows=1, crowd_hypotheses=1), IdAllocator())
    frames = cluttered_sequence(seed=2, n_frames=6)
    sink = ListSink()
    for meas in frames:
        unbounded.step(meas, 0.5, NullSink())
        budgeted.step(meas, 0.5, sink)
    reached = sink.of_type(BudgetReached)
    assert reached and all(e.limit == 1 and e.needed > 1 for e in reached)
    # with every block over budget and one hypothesis expanded, each frame keeps a single global hypothesis
    assert len(budgeted.hypotheses) == 1 < len(unbounded.hypotheses)


def test_budget_not_reached_changes_nothing():
    a = PmbCore("car", CFG, KBest(CFG.pmbm), IdAllocator())
    b = PmbCore("car", CFG, KBest(CFG.pmbm, murty_block_rows=10**6, crowd_hypotheses=10**6), IdAllocator())
    for meas in cluttered_sequence(seed=3, n_frames=10):
        assert a.step(meas, 0.5, NullSink()) == b.step(meas, 0.5, NullSink())


def test_row_keys_sort_as_the_packed_bytes():
    """``pmbm._row_keys`` gives ``np.unique`` the distinct rows in the order of their packed bytes, with the same
    first occurrences and inverse, for narrow (uint64 keys) and wide (void keys) presence arrays."""
    rng = np.random.default_rng(13)
    for n_cols in (1, 5, 8, 9, 40, 64, 65, 100):
        present = rng.random((60, n_cols)) < 0.5
        present[30:] = present[rng.integers(0, 30, size=30)]  # repeated rows
        packed = np.ascontiguousarray(np.packbits(present, axis=1))
        want = np.unique(packed.view(np.dtype((np.void, packed.shape[1]))).ravel(), True, True)
        got = np.unique(_row_keys(present), True, True)
        assert got[1].tolist() == want[1].tolist() and got[2].ravel().tolist() == want[2].ravel().tolist()


def test_presence_patterns_of_many_blocks_equal_each_blocks_unique():
    """``pmbm._presence_patterns`` (the blocks of at most 64 columns at once) gives every wanted block the first
    occurrences and inverse of ``np.unique`` on its own row keys, in the same order."""
    rng = np.random.default_rng(14)
    widths = [1, 3, 8, 9, 30, 64, 65, 90, 2]
    bounds = np.cumsum([0, *widths]).tolist()
    has_column = rng.random((50, bounds[-1])) < 0.6
    has_column[25:] = has_column[rng.integers(0, 25, size=25)]  # repeated hypotheses
    found = [
        Cluster(np.array([b]), np.arange(start, stop)) for b, (start, stop) in enumerate(itertools.pairwise(bounds))
    ]
    wanted = np.array([True, True, False, True, True, True, True, True, True])
    got = _presence_patterns(has_column, found, wanted)
    assert sorted(got) == np.flatnonzero(wanted).tolist()
    for b, (first, pattern) in got.items():
        _, want_first, want_pattern = np.unique(_row_keys(has_column[:, found[b].meas]), True, True)
        assert first.tolist() == want_first.tolist() and pattern.tolist() == want_pattern.ravel().tolist()


def _ancestors_of_kept(n_scan: int, seed: int = 2) -> tuple[list[list[int]], list[int]]:
    """Per frame of ``cluttered_sequence(seed)``: each kept hypothesis' ancestor ``n_scan`` frames back (as an
    index among that frame's hypotheses, from the ``GlobalHypotheses`` events' parents), and the number of
    hypotheses kept, with N-scan pruning at ``n_scan``."""
    config = CFG.replace(pmbm=dataclasses.replace(CFG.pmbm, n_hypotheses=20, n_scan=n_scan))
    core = PmbCore("car", config, KBest(config.pmbm), IdAllocator())
    sink = ListSink()
    for meas in cluttered_sequence(seed=seed):
        core.step(meas, 0.5, sink)
    parents = [e.parents for e in sink.of_type(GlobalHypotheses)]
    ancestors = []
    for k in range(n_scan - 1, len(parents)):
        up = list(range(len(parents[k])))
        for back in range(n_scan):
            up = [parents[k - back][i] for i in up]
        ancestors.append(up)
    return ancestors, [len(p) for p in parents]


@pytest.mark.parametrize("n_scan", [1, 2])
def test_n_scan_keeps_only_the_best_hypothesis_descendants_of_n_frames_back(n_scan):
    """N-scan pruning: after every update, every kept hypothesis descends from the same hypothesis N frames
    back as the best one (García-Fernández et al.'s PMBM keeps any; N-scan makes the decision N frames back
    final). Without it, the same sequence keeps hypotheses of different ancestors."""
    ancestors, sizes = _ancestors_of_kept(n_scan)
    assert all(len(set(a)) == 1 for a in ancestors)
    assert max(sizes) > 1  # alternatives within the last N frames are still kept
    config = CFG.replace(pmbm=dataclasses.replace(CFG.pmbm, n_hypotheses=20))
    core = PmbCore("car", config, KBest(config.pmbm), IdAllocator())
    sink = ListSink()
    for meas in cluttered_sequence(seed=2):
        core.step(meas, 0.5, sink)
    assert any(len(set(e.parents)) > 1 for e in sink.of_type(GlobalHypotheses))


def test_n_scan_longer_than_the_sequence_changes_nothing():
    off = PmbCore("car", CFG, KBest(CFG.pmbm), IdAllocator())
    config = CFG.replace(pmbm=dataclasses.replace(CFG.pmbm, n_scan=50))
    long = PmbCore("car", config, KBest(config.pmbm), IdAllocator())
    for meas in cluttered_sequence(seed=4):
        assert off.step(meas, 0.5, NullSink()) == long.step(meas, 0.5, NullSink())
    assert [h.log_weight for h in off.hypotheses] == [h.log_weight for h in long.hypotheses]


def test_the_overlap_gate_holds_with_several_hypotheses():
    """``[pmb] gate_giou_min`` gates every hypothesis, not only a lone one: a detection 3 m beside a 2 m wide
    track (inside its Mahalanobis gate, no overlap) updates it in no hypothesis when a GIoU >= 0.5 is required."""
    config = CFG.replace(pmb=dataclasses.replace(CFG.pmb, gate_giou_min=0.5))
    beside = make_measurements([(0.0, 3.0)], 0.9)
    for gated, expect_update in ((config, False), (CFG, True)):
        core = core_with_track(KBest(gated.pmbm), gated)
        core.hypotheses = [GlobalHypothesis(math.log(0.6), one_track()), GlobalHypothesis(math.log(0.4), one_track())]
        core.step(beside, 0.5, NullSink())
        updated = [bool((h.bernoullis.track_id == 1)[h.bernoullis.det.meas_index == 0].any()) for h in core.hypotheses]
        assert any(updated) == expect_update
