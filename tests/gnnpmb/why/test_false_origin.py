"""A false bus beside a real bus's path (audit truth49's world5, scene-0553), re-read by audit truth50: where the
real bus's track took soft updates from the false bus's detections, and where a deciding choice is told, the story
said nothing of those detections (or of the thief's start) being of no object."""

from __future__ import annotations

import numpy as np

from gnnpmb.assign.hungarian import solve
from gnnpmb.eval.failures import FailureKind
from gnnpmb.events import Assignment, AxisKind, CostMatrix, CostTerms, axis_labels
from gnnpmb.explain import explain
from gnnpmb.why.facts import TrackStep, Use, UseMode
from gnnpmb.why.findings import Deciding, LostTrack, Origin
from gnnpmb.why.words import why_lines
from tests.gnnpmb.why.test_finding_words import finding


def test_soft_updates_from_detections_of_no_object_say_so() -> None:
    # world5 scene-0553 cphd id_switch:2: "at frame 15 it took 32 % of its weight from m24; ... at frame 18 it took
    # 8 % of its weight from m23", each the false bus's detection, unsaid
    steps = tuple(
        TrackStep(x, 0.01, (0.0, 0.0), (), Use(((m, share),), 0.5, UseMode.WEIGHTS), None, 0.01, None)
        for x, m, share in ((15, 24, 0.32), (16, 24, 0.33), (17, 29, 0.31), (18, 3, 0.08))
    )
    lost = LostTrack(34, 13, steps, None, None, None, used_of_no_object=((15, 24), (16, 24), (17, 29)))
    f = finding(FailureKind.ID_SWITCH, lost, mode=UseMode.WEIGHTS.value, deciding=(15, 16, 17, 18), frame=20)
    (line, *_) = why_lines(f)
    assert "at frame 15 it took 32 % of its weight from m24; at frame 16 it took 33 % of its weight from m24" in line
    assert (
        "of these, m24 (frames 15, 16) and m29 (frame 17) were detections of no object (none of a tracked class "
        "within 2 m)"
    ) in line
    assert "m3 (" not in line  # m3 lay on an object: nothing said
    one = LostTrack(34, 13, steps, None, None, None, used_of_no_object=((17, 29),))
    (line, *_) = why_lines(finding(FailureKind.ID_SWITCH, one, mode=UseMode.WEIGHTS.value, deciding=(17,), frame=20))
    assert "of these, m29 (frame 17) was a detection of no object (none of a tracked class within 2 m)" in line


def test_a_deciding_choice_still_says_the_thief_started_on_a_detection_of_no_object() -> None:
    # world5 scene-0553 gnn id_switch:1: "the deciding choice was earlier, frame 15: m24 → track 48 ...; m24 at
    # frame 15 was a detection of no object" and nothing of track 48 itself having started on the false bus (the
    # jpda and gnnpmb stories, without a deciding choice, said "track 47 had been started at frame 8 by m30, ...")
    d2, log_det = np.array([[4.4], [0.1]]), np.array([0.9, 0.4])  # track 48 right on m24, track 36 off it
    terms = CostTerms(None, None, None, d2, log_det, 2, -9.0, track_ids=np.array([36, 48]))
    cost = np.array([[terms.pair(0, 0).total_nats, terms.pair(0, 1).total_nats, 0.0]])
    rows = axis_labels(AxisKind.MEASUREMENT, [24])
    m = CostMatrix("bus", cost, rows, axis_labels(AxisKind.TRACK, [36, 48]) + axis_labels(AxisKind.NEW_TRACK, [24]))
    cols, total = solve(cost)
    a = Assignment("bus", ((rows[0], m.cols[int(cols[0])]),), total, ())
    choice = next(ch for c in explain(m, a).conflicts for ch in c.choices if ch.meas.ref == 24)
    assert choice.chosen.ref == 48
    d = Deciding(15, choice, 48, False, meas_of_no_object=True)
    taker = Origin(48, 8, 30, of_no_object=True)
    kw = dict(class_name="bus", track_ids=(36, 48), frame=20, lost=LostTrack(36, 12, (), None, None, None))
    (line, *_) = why_lines(finding(FailureKind.ID_SWITCH, decision=d, taker=taker, **kw))
    assert "m24 at frame 15 was a detection of no object (none of a tracked class within 2 m)" in line
    assert (
        "track 48 had been started at frame 8 by m30, a detection of no object (none of a tracked class within" in line
    )
    theft = finding(FailureKind.IDENTITY_THEFT, decision=d, taker=Origin(48, 8, 30, (9, 10), True, True), **kw)
    assert "had been started" not in why_lines(theft)[0]  # a theft says instead that track 48 was a false track
