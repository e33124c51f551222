"""M/N track logic: confirmation timing, tentative and confirmed deletion, events."""

from __future__ import annotations

import numpy as np
import pytest

from gnnpmb.config import ConfigError, VectorParams
from gnnpmb.events import ListSink, TrackLogic, TrackLogicAction
from gnnpmb.vector.track_logic import LogicState, advance, emit_transitions


def run(hits: list[bool], params: VectorParams) -> list[tuple[bool, bool, bool]]:
    """One track born on frame 1, then ``hits`` on frames 2, 3, ...: per frame (confirmed_now, deleted,
    confirmed), up to the deletion."""
    state = LogicState.born(1, params)
    out = []
    for h in hits:
        up = advance(state, np.array([h]), params)
        out.append((bool(up.confirmed_now[0]), bool(up.deleted[0]), bool(up.state.confirmed[0])))
        if up.deleted[0]:
            break
        state = up.state
    return out


def test_two_of_three_confirms_on_second_hit():
    p = VectorParams(confirm_m=2, confirm_n=3)
    assert run([True], p) == [(True, False, True)]
    assert run([False, True], p) == [(False, False, False), (True, False, True)]


def test_tentative_deleted_as_soon_as_m_is_unreachable():
    p = VectorParams(confirm_m=2, confirm_n=3)
    assert run([False, False], p) == [(False, False, False), (False, True, False)]
    p = VectorParams(confirm_m=3, confirm_n=4)
    # born (1 hit), miss -> 1 hit with 2 frames left: still possible; miss -> 1 + 1 < 3: deleted
    assert run([False, False], p) == [(False, False, False), (False, True, False)]
    # born, miss, hit, hit -> 3 hits in the first 4 frames: confirmed on frame 4
    assert run([False, True, True], p) == [(False, False, False), (False, False, False), (True, False, True)]
    # born, hit, miss, miss -> 2 hits after 4 frames: deleted on frame 4
    assert run([True, False, False], p)[-1] == (False, True, False)


def test_confirmed_track_deleted_after_consecutive_misses_only():
    p = VectorParams(confirm_m=2, confirm_n=3, delete_misses=3)
    frames = run([True, False, False, True, False, False, False], p)
    assert [d for _, d, _ in frames] == [False, False, False, False, False, False, True]
    assert len(frames) == 7


def test_m_equal_one_confirms_at_birth_and_emits_both_events():
    p = VectorParams(confirm_m=1, confirm_n=1)
    born = LogicState.born(2, p)
    assert born.confirmed.tolist() == [True, True]
    sink = ListSink()
    up = advance(LogicState.empty(), np.zeros(0, dtype=bool), p)
    emit_transitions("car", np.zeros(0, dtype=np.int64), up, np.array([7]), p, sink)
    assert [(e.track_id, e.action) for e in sink.of_type(TrackLogic)] == [
        (7, TrackLogicAction.TENTATIVE),
        (7, TrackLogicAction.CONFIRMED),
    ]


def test_vectorised_over_tracks_and_events_report_hits():
    p = VectorParams(confirm_m=2, confirm_n=3, delete_misses=2)
    # track 10: tentative, 1 hit, age 1; track 11: tentative age 2 with one miss; track 12: confirmed, 1 miss
    state = LogicState(
        confirmed=np.array([False, False, True]),
        history=np.array([0b1, 0b10, 0b110]),
        age=np.array([1, 2, 5]),
        misses=np.array([0, 1, 1]),
    )
    up = advance(state, np.array([True, False, False]), p)
    assert up.confirmed_now.tolist() == [True, False, False]
    assert up.deleted.tolist() == [False, True, True]
    assert up.state.history.tolist() == [0b11, 0b100, 0b1100]
    assert up.state.misses.tolist() == [0, 2, 2]
    sink = ListSink()
    emit_transitions("car", np.array([10, 11, 12]), up, np.array([13]), p, sink)
    events = [(e.track_id, e.action, e.hits, e.window) for e in sink.of_type(TrackLogic)]
    assert events == [
        (13, TrackLogicAction.TENTATIVE, 1, 3),
        (10, TrackLogicAction.CONFIRMED, 2, 3),
        (11, TrackLogicAction.DELETED, 1, 3),
        (12, TrackLogicAction.DELETED, 0, 2),
    ]


def test_history_keeps_62_frames_without_overflow():
    p = VectorParams(confirm_m=1, confirm_n=1, delete_misses=100)
    state = LogicState.born(1, p)
    for _ in range(200):
        state = advance(state, np.array([True]), p).state
    assert state.history[0] == (1 << 62) - 1 and state.hits(62)[0] == 62


@pytest.mark.parametrize(
    ("changes", "message"),
    [
        ({"p_detect": 1.0}, "p_detect"),
        ({"confirm_m": 4, "confirm_n": 3}, "confirm_m <= confirm_n"),
        ({"confirm_m": 0}, "confirm_m"),
        ({"delete_misses": 0}, "delete_misses"),
        ({"exact_cluster_max": 0}, "exact_cluster_max"),
    ],
)
def test_bad_vector_parameters_are_config_errors(changes, message):
    with pytest.raises(ConfigError, match=message):
        VectorParams(**changes)
