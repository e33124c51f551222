"""The evaluation's class range in words (audit truth53, world9: a pedestrian and a bicycle crossing the 40 m range,
parked cars at 50 m). world9 scene-0103 centerpoint gnnpmb miss at frame 7 said of car GT a46079 "track 15 was
output on it, but its box lies beyond the evaluation's range for the class (or in a bike rack): ...; it lies 50.0 m
from the ego vehicle, inside the evaluation's 50 m range": the devkit's bike-rack filter never drops a car's box, and
"50.0 m, inside the 50 m range" beside a box "beyond" it tells neither side."""

from __future__ import annotations

from gnnpmb.eval.evaluated import DroppedBox, GtFrame, GtStatus, TrackEval
from gnnpmb.eval.failures import FailureKind
from gnnpmb.why.findings import Blame, OnObject, Rule, Sighting
from gnnpmb.why.words import why_lines
from tests.gnnpmb.why.test_finding_words import GT, finding


def dropped_miss(class_name: str, ego_m: float, reach_m: float, box_m: float | None = None) -> str:
    """A miss at frame 13 of an object ``ego_m`` from the ego vehicle, with track 15's box on it, ``box_m`` from the
    ego vehicle (default 0.05 m beyond the range), dropped by the evaluation's filters (output at frame 13, not kept
    there)."""
    g = GtFrame(13, GtStatus.SCORED, (0.0, 0.0), (0.0, 0.0), None, 40, ego_m, reach_m)
    box_m = reach_m + 0.05 if box_m is None else box_m
    ev = TrackEval((12, 13), (12,), (), 0.6, 0.6, (), (DroppedBox(13, box_m, reach_m),))
    s = Sighting(13, 40, g, None, None, None, (OnObject(15, 0.1, 0.6, -1, ev, 0.3),))
    f = finding(
        FailureKind.MISS, class_name=class_name, gt_id=GT, sightings=(s,), blame=(Blame(Rule.TRACK_DROPPED, (13,)),)
    )
    return why_lines(f)[0]


def test_a_dropped_box_is_told_by_the_filter_that_dropped_it() -> None:
    car = dropped_miss("car", 49.97, 50.0)
    assert (
        "track 15 was output on it, but its box there lies 50.05 m from the ego vehicle, beyond the evaluation's 50 m "
        "range: the evaluation dropped that box" in car
    )
    assert "bike rack" not in car
    bike = dropped_miss("bicycle", 39.0, 40.0, box_m=39.5)  # inside the range: the bike-rack filter dropped it
    assert "track 15 was output on it, but its box there lies in a bike rack: the evaluation dropped that box" in bike


def test_a_distance_at_the_range_is_printed_with_the_decimals_that_tell_its_side() -> None:
    assert "the object lies 49.97 m from the ego vehicle, inside the evaluation's 50 m range" in dropped_miss(
        "car", 49.97, 50
    )
    assert "the object lies 40.04 m from the ego vehicle, beyond the evaluation's 40 m range" in dropped_miss(
        "pedestrian", 40.04, 40
    )
    assert "the object lies 47.3 m from the ego vehicle" in dropped_miss("car", 47.31, 50)  # one decimal where it tells
    from gnnpmb.why.words import ego_distance_text

    assert ego_distance_text(39.9997, 40.0) == "39.9997"  # world9 scene-0103 pedestrian b37203 at frame 20
    assert ego_distance_text(39.99999, 40.0) == "40.0000"  # at most four: the side is in the words beside it


def test_a_lost_track_whose_box_the_evaluation_dropped_is_not_said_to_be_beyond_its_2_m() -> None:
    # world9 scene-1094 pointpillars gnnpmb id_switch:1: "at frame 30 track 91 was output 3.7 m from GT 88761d:
    # beyond the evaluation's 2 m, so it no longer matched the object", though its box lay 43.3 m from the ego,
    # beyond the pedestrian range: the devkit dropped it and had no box of the track there at all
    from gnnpmb.why.findings import LostTrack, OffObject

    def said(kept: tuple[int, ...], interpolated: tuple[int, ...] = ()) -> str:
        dropped = () if 11 in kept else (DroppedBox(11, 43.3, 40.0),)
        ev = TrackEval((9, 10, 11, 12), kept, interpolated, 0.6, 0.6, (), dropped)
        lost = LostTrack(91, 9, (), OffObject(3.7, -1, ()), ev, 0.3)
        return why_lines(finding(FailureKind.ID_SWITCH, lost, class_name="pedestrian", frame=11))[0]

    dropped = (
        "at frame 11 track 91 was output 3.7 m from GT bf3d85, but its box lay 43.3 m from the ego vehicle, beyond "
        "the evaluation's 40 m range: the evaluation dropped it and had no box of the track to match to the object"
    )
    assert dropped in said((9, 10))
    beyond = "at frame 11 track 91 was output 3.7 m from GT bf3d85: beyond the evaluation's 2 m, so it no longer"
    assert beyond in said((9, 10, 11))  # kept: the 2 m decided
    assert beyond in said((9, 10, 12), (11,))  # interpolated between frames 10 and 12: a box of it was there


def test_a_box_interpolated_over_frames_beyond_the_range_is_not_noted_as_one_without_points() -> None:
    # world9 scene-1094 pointpillars gnnpmb: "pedestrian GT 88761d (GT box interpolated by the evaluation: no
    # points)" at frames 20-29, where it had 12 LiDAR points and lay 41-43 m from the ego, beyond the 40 m range
    from gnnpmb.eval.evaluated import Dropped
    from gnnpmb.eval.failures import Failure, FailureBox, _unannotated

    box = FailureBox("missed gt", GT, (41.0, 0.0, 1.0), (0.6, 0.7, 1.8), (1.0, 0.0, 0.0, 0.0), interpolated=True)
    miss = Failure(FailureKind.MISS, 13, "token", "pedestrian", (GT,), (), (box,))

    def note(dropped: Dropped) -> str:
        g = GtFrame(13, GtStatus.INTERPOLATED, (41.0, 0.0), (40.0, 0.0), dropped, 12, 41.0, 40.0)
        marked = _unannotated(miss, {GT: {13: g}})
        assert Failure.from_json(marked.to_json()) == marked
        return marked.describe()

    assert note(Dropped.BEYOND_RANGE).endswith("(GT box interpolated by the evaluation: beyond the class range)")
    assert note(Dropped.NO_POINTS).endswith("(GT box interpolated by the evaluation: no points)")
    assert _unannotated(miss, {GT: {}}).describe().endswith("(GT box interpolated by the evaluation: not annotated)")
