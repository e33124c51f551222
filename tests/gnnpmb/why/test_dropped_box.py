"""A false track at a frame where the evaluation dropped the track's own box (beyond the class range) and
interpolated one in its place (audit truth53, world9 scene-0103 centerpoint gnnpmb false_track at frame 20: the
track's box on pedestrian GT b37203, 40.0 m from the ego, was dropped; the box the devkit interpolated between frames
11 and 21 lay 5.6 m off, told as "the track's box lies 5.6 m from pedestrian GT b37203, which it was last within 2 m
of at frame 19", though the track's own box at frame 20 lay 0.2 m from it)."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np

from gnnpmb.eval.evaluated import GtFrame, GtStatus
from gnnpmb.eval.failures import FailureKind
from gnnpmb.why.findings import Blame, FalseOutput, Rule
from gnnpmb.why.words import why_lines
from tests.gnnpmb.why.test_drifted_off import BIKE, coasting_past
from tests.gnnpmb.why.test_finding_words import GT, finding


def test_the_tracks_own_dropped_box_on_the_object_counts_as_on_it_at_the_failure_frame() -> None:
    ctx = coasting_past()
    ctx.frames[28] = SimpleNamespace(estimates=[SimpleNamespace(track_id=39, translation_m=np.array([0.2, 0.0, 0.0]))])
    interpolated = np.array([4.0, 0.0])
    assert ctx.drifted_off(39, interpolated)[:3:2] == (BIKE, 27)  # its box output there: only earlier frames count
    gt_id, d, frame, _ = ctx.drifted_off(39, interpolated, dropped=True)
    assert (gt_id, frame) == (BIKE, 28) and abs(d - 4.0) < 1e-9


def test_a_box_interpolated_in_place_of_a_dropped_one_on_the_object_is_not_told_as_the_track_running_off() -> None:
    g = GtFrame(13, GtStatus.SCORED, (0.0, 0.0), (0.0, 0.0), None, 30, 39.98, 40.0)
    out = FalseOutput(44, None, (5.6, 0.0), (11, 21), None, None, None, None, None, drifted_from=(GT, 5.6, 13, g))
    blame = (Blame(Rule.TRACK_INTERPOLATED, (13,)), Blame(Rule.TRACK_DROPPED, (13,)))
    text = why_lines(finding(FailureKind.FALSE_TRACK, class_name="pedestrian", blame=blame, false_output=out))[0]
    assert (
        "no object of a tracked class lies within 2 m of it: the box the evaluation interpolated lies 5.6 m from "
        "pedestrian GT bf3d85, though the track's own box here, the one the evaluation dropped, lay within 2 m of it"
    ) in text
    assert "which it was last within" not in text
