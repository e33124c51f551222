"""The P_D of a missed Bernoulli learnt online per class (``gnnpmb.pmb.miss_detection``, ``[pmb]
miss_p_detect_online``): hand-computed counts, and the value the tracker's cost events report is the one it used; a
Bernoulli with a neighbour of its class keeps the fixed cap (``miss_detection.crowded``)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from gnnpmb.config import TrackerConfig, load_config, with_params
from gnnpmb.events import CostMatrix, ListSink, NullSink
from gnnpmb.pmb.core import PmbCore
from gnnpmb.pmb.gnnpmb import BestAssignment
from gnnpmb.pmb.miss_detection import MissDetectionCounts, crowded
from gnnpmb.types import IdAllocator
from tests.gnnpmb.pmb.helpers import make_measurements


def _counted(n_bins: int, score_split: float = 0.0) -> MissDetectionCounts:
    """Tracks 1 and 2 over four frames: both detected at frame 1; 1 (last score 0.4) missed at frames 2 and 3 and
    detected again at 4; 2 (score 0.9) detected at every frame; 5 born at frame 4."""
    counts = MissDetectionCounts.empty(n_bins, score_split)
    ids, scores = np.array([1, 2]), np.array([0.4, 0.9])
    counts.count(ids, np.array([0, 0]), scores)  # frame 1: no previous frame, nothing counted
    counts.count(ids, np.array([1, 0]), scores)  # track 2 detected after a detection: D_0 + 1
    counts.count(ids[::-1], np.array([0, 2]), scores[::-1])  # the same, rows in another order
    # 1 closes a gap of 2: D_2 + 1, G_0 + 1, G_1 + 1
    counts.count(np.array([5, 1, 2]), np.array([0, 0, 0]), np.array([0.7, 0.4, 0.9]))
    return counts


def test_counts_and_estimate_by_gap_position_by_hand() -> None:
    """Three bins: D = [3, 0, 1] (track 2 three times after a detection; track 1 once after two misses), G = [1,
    1, 0] (track 1's closed gap: a miss at position 1 and one at 2); the new track 5 adds nothing. With the cap 0.3
    as a prior of 10 frames: P_D = [(3 + 3) / (10 + 3 + 1), (3 + 0) / (10 + 0 + 1), (3 + 1) / (10 + 1 + 0)]."""
    counts = _counted(3)
    assert counts.detected.tolist() == [[3, 0, 1]] and counts.missed.tolist() == [[1, 1, 0]]
    p = counts.p_detect(0.3, 10.0, np.array([0, 1, 2, 5]), np.array([0.1, 0.9, 0.5, 0.5]))
    np.testing.assert_allclose(p, [6 / 14, 3 / 11, 4 / 11, 4 / 11])


def test_one_bin_pools_every_frame_and_two_bins_pool_the_tail() -> None:
    """One bin: D = 4 detections, G = 2 misses, P_D = (3 + 4) / (10 + 6). Two bins: the gap of 2 ends in the
    last bin (D = [3, 1]) and its second miss falls in it too (G = [1, 1])."""
    one = _counted(1)
    assert one.detected.tolist() == [[4]] and one.missed.tolist() == [[2]]
    np.testing.assert_allclose(one.p_detect(0.3, 10.0, np.array([0, 7]), np.array([0.2, 0.8])), [7 / 16, 7 / 16])
    two = _counted(2)
    assert two.detected.tolist() == [[3, 1]] and two.missed.tolist() == [[1, 1]]
    p = two.p_detect(0.3, 10.0, np.array([0, 1, 4]), np.ones(3))
    np.testing.assert_allclose(p, [6 / 14, 4 / 12, 4 / 12])


def test_a_score_split_counts_weak_and_strong_tracks_apart() -> None:
    """Split 0.5, two miss bins: track 1 (last score 0.4, below the split) closed its gap of 2 (D_00 = 0, D_01 =
    1, G_00 = G_01 = 1); track 2 (0.9) was detected three times after a detection (D_10 = 3). A weak track after
    no miss: (3 + 0) / (10 + 0 + 1); after misses: (3 + 1) / (10 + 1 + 1); a strong one after no miss:
    (3 + 3) / (10 + 3), after misses the prior 0.3. The bin is the score of the track's last detection before
    the gap: a score at the split is strong."""
    counts = _counted(2, 0.5)
    assert counts.detected.tolist() == [[0, 1], [3, 0]] and counts.missed.tolist() == [[1, 1], [0, 0]]
    p = counts.p_detect(0.3, 10.0, np.array([0, 3, 0, 1]), np.array([0.49, 0.2, 0.5, 0.9]))
    np.testing.assert_allclose(p, [3 / 11, 4 / 12, 6 / 13, 0.3])


def test_nothing_counted_gives_the_prior_mean() -> None:
    empty = MissDetectionCounts.empty(3, 0.5)
    np.testing.assert_allclose(empty.p_detect(0.3, 10.0, np.array([0, 1, 9]), np.array([0.1, 0.6, 0.9])), [0.3] * 3)


def _car(t: int) -> object:
    return make_measurements([(1.0 * t, 0.0)], 0.8, velocity=[(2.0, 0.0)])


def _run(cfg: TrackerConfig) -> tuple[PmbCore, float]:
    """A car detected at frames 0-2, missed at 3 and 4, detected at 5, then missed at 6 (a far detection starts
    another track): the P_D its miss used at frame 6, read from that frame's ``CostMatrix`` event."""
    core = PmbCore("car", cfg, BestAssignment(), IdAllocator())
    frames = [_car(0), _car(1), _car(2), make_measurements([], 0.8), make_measurements([], 0.8), _car(5)]
    for t, meas in enumerate(frames):
        core.step(meas, 0.5 if t else 0.0, NullSink())
    (track,) = core.hypotheses[0].bernoullis.track_id.tolist()
    sink = ListSink()
    core.step(make_measurements([(80.0, 0.0)], 0.8, velocity=[(2.0, 0.0)]), 0.5, sink)
    (costs,) = [e for e in sink.events if isinstance(e, CostMatrix)]
    terms = costs.terms
    assert terms is not None
    col = terms.column_of(track)
    assert col is not None
    return core, terms.pair(0, col).p_detect


def test_the_tracker_misses_with_the_learnt_p_d_and_its_event_reports_it() -> None:
    """One bin, prior 0.3 of 10 frames: detections at frames 1, 2, 5 of the existing track (D = 3) and the two
    misses of the gap frame 5 closed (G = 2): P_D = (3 + 3) / (10 + 5) = 0.4 at frame 6, below the last score
    0.8, so the miss uses 0.4 and the cost event says 0.4."""
    cfg = with_params(TrackerConfig(), {"pmb.miss_p_detect_online": 1, "pmb.miss_p_detect_bins": 1})
    core, p_detect = _run(cfg)
    assert core.miss_counts.detected.tolist() == [[3]] and core.miss_counts.missed.tolist() == [[2]]
    assert p_detect == pytest.approx(0.4, rel=1e-9)


def test_a_class_s_fixed_cap_wins_over_the_online_estimate() -> None:
    """``gnnpmb calibrate`` writes a learnt cap with ``miss_p_detect_online = 0`` per class: that class misses
    with its cap (0.72 here) whatever the default does."""
    cfg = with_params(
        TrackerConfig(),
        {
            "pmb.miss_p_detect_online": 1,
            "classes.car.pmb.miss_p_detect_max": 0.72,
            "classes.car.pmb.miss_p_detect_online": 0,
        },
    )
    _, p_detect = _run(cfg.resolved("car"))
    assert p_detect == pytest.approx(0.72, rel=1e-9)


def test_crowded_by_hand() -> None:
    """Four Bernoullis on a line at x = 0, 1.5, 10, 11 m, existence 0.9, 0.9, 0.9, 0.3; neighbours within 2 m of
    existence >= 0.5: the first two see each other; the third's only neighbour (1 m) has r = 0.3, so it is alone;
    the fourth sees the third. The same track in another hypothesis is no neighbour, and 0 m turns it off."""
    xy = np.array([[0.0, 0.0], [1.5, 0.0], [10.0, 0.0], [11.0, 0.0]])
    r = np.array([0.9, 0.9, 0.9, 0.3])
    assert crowded(xy, r, np.array([1, 2, 3, 4]), 2.0, 0.5).tolist() == [True, True, False, True]
    assert crowded(xy, r, np.array([1, 1, 3, 4]), 2.0, 0.5).tolist() == [False, False, False, True]
    assert crowded(xy, r, np.array([1, 2, 3, 4]), 1.4, 0.5).tolist() == [False, False, False, True]
    assert not crowded(xy, r, np.array([1, 2, 3, 4]), 0.0, 0.5).any()


def _pair_p_detect(cfg: TrackerConfig) -> tuple[PmbCore, float]:
    """Cars A at y = 0 and B at y = 1.8 m, side by side: both detected at frames 0-2, A missed at 3 and 4 and
    detected at 5, B detected at every frame; at frame 6 A is missed again: the P_D its miss used (``CostMatrix``)."""
    core = PmbCore("car", cfg, BestAssignment(), IdAllocator())

    def frame(t: int, with_a: bool) -> object:
        xy = [(1.0 * t, 0.0), (1.0 * t, 1.8)] if with_a else [(1.0 * t, 1.8)]
        return make_measurements(xy, 0.8, velocity=[(2.0, 0.0)] * len(xy))

    for t in range(6):
        core.step(frame(t, t not in (3, 4)), 0.5 if t else 0.0, NullSink())
    a = int(core.hypotheses[0].bernoullis.track_id[np.argmin(core.hypotheses[0].bernoullis.mean[:, 1])])
    sink = ListSink()
    core.step(frame(6, False), 0.5, sink)
    (costs,) = [e for e in sink.events if isinstance(e, CostMatrix)]
    assert costs.terms is not None
    col = costs.terms.column_of(a)
    assert col is not None
    return core, costs.terms.pair(0, col).p_detect


def test_a_missed_track_next_to_another_keeps_the_fixed_cap() -> None:
    """One bin, prior 0.3 of 10 frames. Counts before frame 6: D = 8 (B detected after a detection at frames
    1-5, A at 1 and 2, and A's return at 5), G = 2 (A's gap): the learnt P_D is (3 + 8) / (10 + 10) = 0.55, which
    A's miss uses with the neighbour rule off; with it (B, r = 1, 1.8 m away, within 2 m) A keeps the cap 0.3."""
    base = {"pmb.miss_p_detect_online": 1, "pmb.miss_p_detect_bins": 1}
    _, p_off = _pair_p_detect(with_params(TrackerConfig(), {**base, "pmb.miss_p_detect_neighbour_m": 0.0}))
    assert p_off == pytest.approx(0.55, rel=1e-9)
    _, p_on = _pair_p_detect(with_params(TrackerConfig(), {**base, "pmb.miss_p_detect_neighbour_m": 2.0}))
    assert p_on == pytest.approx(0.3, rel=1e-9)


def test_the_round_17_record_reads_as_screened() -> None:
    """``gnnpmb/params/miss_pd_score_split.toml`` (Issue 32, Round 17, not adopted) sets the split and drops the
    score cap for every class."""
    cfg = load_config(Path(__file__).resolve().parents[3] / "gnnpmb" / "params" / "miss_pd_score_split.toml")
    car = cfg.resolved("car").pmb
    assert car.miss_p_detect_score_split == 0.5 and car.miss_p_detect_last_score == 0
