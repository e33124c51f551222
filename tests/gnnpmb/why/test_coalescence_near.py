"""A coalescence's second object among three (audit truth54, dev set scene-0061 centerpoint jpda coalescence:4,
pedestrians at frame 18): the old text said GT f21f93 was one "which no counted track covered", though counted
track 72 lay 0.9 m from it; the evaluation had matched track 72 to a third pedestrian, GT daa05e."""

from __future__ import annotations

from gnnpmb.eval.evaluated import GtFrame, GtStatus, TrackEval
from gnnpmb.eval.failures import FailureKind
from gnnpmb.why.findings import Blame, OnObject, Rule, Sighting
from gnnpmb.why.words import why_lines
from tests.gnnpmb.why.test_finding_words import finding

COVERED = "25b23b" + "1" * 26
THIRD = "daa05e" + "2" * 26


def _line(on: tuple[OnObject, ...]) -> str:
    g = GtFrame(13, GtStatus.SCORED, (0.0, 0.0), (0.0, 0.0), None, 6, 20.0, 40.0)
    seen = Sighting(13, 6, g, None, None, None, on)
    blame = (Blame(Rule.COVERED_TWO, (13,)),)
    f = finding(FailureKind.COALESCENCE, sightings=(seen,), blame=blame, covered=(COVERED,), track_ids=(75,))
    return why_lines(f)[0]


def test_a_counted_track_near_the_object_matched_to_a_third_one_is_named() -> None:
    ours = OnObject(75, 0.7, 0.48, 16, TrackEval((13,), (13,), (), 0.63, 0.63, ((13, COVERED),)), 0.47)
    other = OnObject(72, 0.88, 0.54, 13, TrackEval((13,), (13,), (), 0.76, 0.76, ((13, THIRD),)), 0.47)
    low = OnObject(80, 1.2, 0.2, 14, TrackEval((13,), (13,), (), 0.2, 0.2, ((13, THIRD),)), 0.47)  # not counted
    text = _line((ours, other, low))
    assert (
        "at frame 13 track 75 was matched to GT 25b23b and also lay within 2 m of GT bf3d85, which the evaluation "
        "matched to no track, though counted track 72 lay 0.9 m from it (matched to GT daa05e)"
    ) in text
    assert "no counted track covered" not in text and "track 80" not in text.split(";")[0]
    assert "which the evaluation matched to no track;" in _line((ours,))
