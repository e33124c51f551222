"""Stories of two objects close together (world4: two parked cars 1.7-2.2 m apart, paths crossing), from hand-made
findings and a two-detection cost matrix: what the Why says of the solver's deciding choice and of another run's
track on the neighbouring object."""

from __future__ import annotations

import numpy as np

from gnnpmb.assign.hungarian import solve
from gnnpmb.eval.evaluated import TrackEval
from gnnpmb.eval.failures import FailureKind
from gnnpmb.events import Assignment, AxisKind, CostMatrix, CostTerms, axis_labels
from gnnpmb.explain import explain
from gnnpmb.why.findings import Deciding, Finding, LostTrack, OnObject, OtherRun
from gnnpmb.why.words import why_lines
from tests.gnnpmb.why.test_finding_words import finding as id_switch

GT = "1419ed" + "0" * 26
PAIR = "188906" + "1" * 26


def finding(**kw) -> Finding:
    """A car's id switch at frame 13, track 18 to 19 (``test_finding_words.finding``'s other fields)."""
    base = dict(class_name="car", gt_id=GT, track_ids=(18, 19), lost=LostTrack(18, 12, (), None, None, None))
    return id_switch(FailureKind.ID_SWITCH, **(base | kw))


def test_the_deciding_choice_over_a_cheaper_track_says_what_that_track_took() -> None:
    # world4 scene-0061 centerpoint gnnpmb id_switch:3: "m18 → new track 74 (cost 10.50) over track 50 (6.30 ...),
    # margin 0.07" -- a cheaper next best passed over with nothing said: track 50 took m17 in the same assignment
    d2 = np.array([[6.0, 30.0], [2.0, 1.0]])  # m0 is nearer track 7 than track 5, but track 7 is m1's
    terms = CostTerms(None, None, None, d2, np.array([0.2, 0.1]), 2, -9.0, track_ids=np.array([5, 7]))
    cost = np.full((2, 4), np.inf)
    for j in range(2):
        for k in range(2):
            cost[j, k] = terms.pair(j, k).total_nats
        cost[j, 2 + j] = 0.0
    rows = axis_labels(AxisKind.MEASUREMENT, [0, 1])
    m = CostMatrix(
        "car", cost, rows, axis_labels(AxisKind.TRACK, [5, 7]) + axis_labels(AxisKind.NEW_TRACK, [0, 1]), terms=terms
    )
    cols, total = solve(cost)
    a = Assignment("car", tuple((rows[j], m.cols[int(k)]) for j, k in enumerate(cols)), total, ())
    choice = next(ch for c in explain(m, a).conflicts for ch in c.choices if ch.meas.ref == 0)
    assert choice.alternative.ref == 7 and choice.alternative_cost < choice.chosen_cost
    deciding = Deciding(13, choice, int(choice.chosen.ref), False, alternative_took=1)
    (line, *_) = why_lines(finding(decision=deciding))
    assert "then, frame 13: m0 → **track 5** (cost " in line
    assert "over track 7 (" in line and "), which took m1 (the lower total wins), margin " in line


def test_another_runs_track_on_the_neighbouring_car_is_not_said_to_be_on_this_one() -> None:
    # world4 scene-1100 megvii cphd id_switch:12: jpda's track 55, 1.1 m from car 6203bb and 0.6 m from the parked
    # car beside it (01ffcf, 1.7 m away), which the evaluation matched it to, was said "output on the object"
    there = TrackEval((13,), (13,), (), 0.9, 0.9, ((13, PAIR),))
    beside = OnObject(55, 1.1, 0.8, -1, there, 0.3, matched_m=0.6)
    (line, *_) = why_lines(finding(others=(OtherRun("jpda", False, (beside,), missed=True),)))
    assert (
        "jpda on the same detections did not match the object here: its track 55 was output on the car beside it "
        "and counted: the evaluation matched track 55 to car GT 188906, 0.6 m from the track (1.1 m from this one)"
    ) in line
    assert "output on the object" not in line
    nearer_this = OnObject(55, 0.5, 0.8, -1, there, 0.3, matched_m=1.2)  # matched away, but nearer this car
    (line, *_) = why_lines(finding(others=(OtherRun("jpda", False, (nearer_this,), missed=True),)))
    assert (
        "jpda on the same detections did not match the object here: its track 55 was output on the object and "
        "counted, but the evaluation matched track 55 to car GT 188906"
    ) in line
    # two tracks, one on this car and one on the car beside it (world4 scene-0061 pointpillars gnn fragmentation:14):
    # only the one on this car is named "on the object"
    here = OnObject(30, 0.3, 0.8, -1, there, 0.3, matched_m=1.9)
    (line, *_) = why_lines(finding(others=(OtherRun("jpda", False, (here, beside), missed=True),)))
    assert (
        "jpda on the same detections did not match the object here: its track 30 was output on the object and "
        "counted, but the evaluation matched track 30 to car GT 188906."
    ) in line
    assert "track 55" not in line


def test_a_close_call_over_a_cheaper_track_says_what_that_track_took() -> None:
    # world4 scene-0061 centerpoint gnnpmb, the focus story: "close call: m18 → new track 74 (cost 10.50) over track
    # 50 (6.30), margin 0.07" -- track 50 was cheaper for m18 and lost it because it took m17
    from gnnpmb.events import Extracted
    from gnnpmb.why.story import StoryKind, Storyteller
    from tests.gnnpmb.why.test_facts import estimate, facts_of, frame, label, predicted, received

    rows = (label(AxisKind.MEASUREMENT, 0), label(AxisKind.MEASUREMENT, 1))
    cols = tuple(label(AxisKind.TRACK, t) for t in (1, 2)) + tuple(label(AxisKind.NEW_TRACK, j) for j in (0, 1))
    cost = np.array([[4.0, 3.5, 4.5, np.inf], [np.inf, 0.5, np.inf, 10.0]])  # m0 → 1 (4.0) + m1 → 2 (0.5): 4.5
    shown = Extracted("car", (estimate(1, 0), estimate(2, 1)), 0.0)
    events = [frame(0), received([0, 1]), predicted([1, 2], [1.0, 1.0]), shown, frame(1), received([0, 1])]
    events += [predicted([1, 2], [1.0, 1.0]), CostMatrix("car", cost, rows, cols)]
    events += [Assignment("car", ((rows[0], cols[0]), (rows[1], cols[1])), 4.5, ()), shown]
    teller = Storyteller(facts_of(events))
    teller.frame_lines(0)
    (call,) = [line for line in teller.frame_lines(1) if line.kind is StoryKind.CLOSE_CALL]
    assert call.text == (
        "close call: m0 → track 1 (cost 4.00) over track 2 (3.50), which took m1 (the lower total wins), margin 0.50"
    )
