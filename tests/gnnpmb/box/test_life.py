"""Hits / misses life cycle: confirmation, deletion (or none: ImmortalTracker), output, its TrackLogic events."""

import numpy as np

from gnnpmb.box.life import LifeRule, LifeState, advance, emit_transitions, output_mask
from gnnpmb.events import ListSink, Pruned, TrackLogic, TrackLogicAction

AB3DMOT = LifeRule(min_hits=3, max_misses=2, output_max_misses=1)


def test_ab3dmot_confirms_at_the_third_hit_and_deletes_at_the_second_miss_in_a_row():
    state = LifeState.born(1, AB3DMOT)
    assert not state.confirmed[0]
    seen = []
    for hit in (True, True, False, True, False, False):
        update = advance(state, np.array([hit]), AB3DMOT)
        state = update.state
        seen.append((int(state.hits[0]), int(state.misses[0]), bool(state.confirmed[0]), bool(update.deleted[0])))
    assert seen == [
        (2, 0, False, False),
        (3, 0, True, False),
        (3, 1, True, False),
        (4, 0, True, False),
        (4, 1, True, False),
        (4, 2, True, True),
    ]


def test_output_needs_confirmation_except_in_the_first_min_hits_frames_and_at_most_one_miss():
    state = LifeState(np.array([1, 3, 3]), np.array([0, 1, 2]), np.array([False, True, True]))
    assert output_mask(state, AB3DMOT, frame=3).tolist() == [True, True, False]
    assert output_mask(state, AB3DMOT, frame=4).tolist() == [False, True, False]


def test_immortal_tracks_are_never_deleted():
    rule = LifeRule(min_hits=1, max_misses=None, output_max_misses=1)
    state = LifeState.born(1, rule)
    for _ in range(100):
        update = advance(state, np.array([False]), rule)
        assert not update.deleted[0]
        state = update.state
    assert state.misses[0] == 100 and not output_mask(state, rule, 101)[0]


def test_transitions_are_reported_as_track_logic_events():
    sink = ListSink()
    state = LifeState(np.array([2, 3]), np.array([0, 1]), np.array([False, True]))
    update = advance(state, np.array([True, False]), AB3DMOT)
    emit_transitions("car", np.array([7, 8]), update, np.array([9]), AB3DMOT, sink)
    logic = [(e.track_id, e.action) for e in sink.of_type(TrackLogic)]
    assert logic == [(9, TrackLogicAction.TENTATIVE), (7, TrackLogicAction.CONFIRMED), (8, TrackLogicAction.DELETED)]
    assert [e.track_id for e in sink.of_type(Pruned)] == [8]
