"""A long object seen as two boxes (audit truth50, world6: a 16 m truck with trailer detected as a cab box 4.75 m
ahead of its centre and a trailer box 3.25 m behind it). Neither box lies within 2 m of the truck's centre, so the
Why said "a detection of no object", "the tracker output a box where no tracked object was" and "the detector
missed it" of boxes that lay inside the truck's own box. They are now said to be on part of it."""

from __future__ import annotations

import numpy as np
import pytest

from gnnpmb.eval.failures import FailureKind
from gnnpmb.why.findings import Blame, FalseOutput, Origin, Rule, Sighting
from gnnpmb.why.reason import _Context, part_of
from gnnpmb.why.words import why_lines
from tests.gnnpmb.why.test_finding_words import finding
from tests.gnnpmb.why.test_reason_rules import Table, one_frame_context

TRUCK = "ecf44b" + "0" * 26
CAR = "26e63e" + "0" * 26
YAW = 0.5  # the truck heads 0.5 rad from the x axis: the footprint test turns with it
AHEAD = np.array([np.cos(YAW), np.sin(YAW)])


def truck_split() -> _Context:
    """Frame 14: truck GT ecf44b at (0, 0) (2.6 m wide, 16 m long, heading 0.5 rad), car GT 26e63e 10 m to its side;
    detections: m0 the cab 4.75 m ahead, m1 the trailer 3.25 m behind, m2 3 m to the truck's side (outside it)."""
    gt = Table(
        instance_id=np.array([TRUCK, CAR]),
        class_name=np.array(["truck", "car"]),
        translation_m=np.array([[0.0, 0.0, 1.9], [-10 * AHEAD[1], 10 * AHEAD[0], 0.8]]),
        size_wlh_m=np.array([[2.6, 16.0, 3.8], [1.9, 4.6, 1.6]]),
        quat_wxyz=np.array([[np.cos(YAW / 2), 0, 0, np.sin(YAW / 2)], [np.cos(YAW / 2), 0, 0, np.sin(YAW / 2)]]),
    )
    side = 3.0 * np.array([-AHEAD[1], AHEAD[0]])
    xy = np.array([4.75 * AHEAD, -3.25 * AHEAD, side])
    boxes = Table(
        translation_m=np.c_[xy, np.full(3, 1.9)],
        class_name=np.array(["truck", "truck", "truck"]),
        score=np.array([0.7, 0.6, 0.5]),
    )
    return one_frame_context(14, gt, boxes, "truck")


def test_a_detection_inside_a_long_objects_box_is_part_of_it_not_of_no_object() -> None:
    ctx = truck_split()
    assert ctx.of_no_object(14, 0) and ctx.of_no_object(14, 1)  # no centre within 2 m: the evaluation's view
    cab, trailer = ctx.meas_part_of(14, 0), ctx.meas_part_of(14, 1)
    assert cab[:2] == (TRUCK, "truck") and cab[2] == pytest.approx(4.75)
    assert trailer[:2] == (TRUCK, "truck") and trailer[2] == pytest.approx(3.25)
    assert ctx.meas_part_of(14, 2) is None  # 3 m to the side of a 2.6 m wide truck: outside it
    near = ctx.in_box(14, TRUCK)  # the nearest detection inside the truck's box
    assert near is not None and near.meas == 1 and near.distance_m == pytest.approx(3.25)
    assert ctx.in_box(14, CAR) is None
    assert part_of(ctx.scene.keyframes[14].gt, np.array([0.0, 7.9])) is None  # beside it once turned by 0.5 rad


def _false_truck(out: FalseOutput, blame: tuple[Blame, ...]) -> object:
    """False truck track 72 at frame 14 with output ``out`` and ``blame``."""
    return finding(
        FailureKind.FALSE_TRACK,
        class_name="truck",
        gt_id=None,
        track_ids=(72,),
        frame=14,
        false_output=out,
        blame=blame,
    )


def test_the_why_says_a_split_objects_boxes_were_on_part_of_it() -> None:
    ctx = truck_split()
    part = ctx.meas_part_of(14, 1)
    # the thief's start: "started at frame 14 by m1, a detection of no object (none of a tracked class within 2 m)"
    theft = finding(
        FailureKind.ID_SWITCH, class_name="truck", frame=22, taker=Origin(199, 14, 1, of_no_object=True, part_of=part)
    )
    (line, *_) = why_lines(theft)
    assert (
        "track 199 had been started at frame 14 by m1, a detection of part of truck GT ecf44b (inside its box, "
        "3.2 m from its centre, beyond the evaluation's 2 m)"
    ) in line
    assert "of no object" not in line
    # a false track coasting on the trailer: not "a box where no tracked object was"
    out = FalseOutput(72, None, (-3.0, -1.6), None, None, None, None, None, None, part_of=part)
    coast = _false_truck(out, (Blame(Rule.COASTED, (14,)),))
    (line, *_) = why_lines(coast)
    assert "no object of a tracked class lies within 2 m, but the box lies on part of truck GT ecf44b" in line
    assert "where no tracked object was" not in line
    # a miss at a frame where only the trailer box was given: the detector saw part of it, it did not miss it
    s = Sighting(14, 200, None, None, None, None, (), in_box=ctx.in_box(14, TRUCK))
    miss = finding(FailureKind.MISS, class_name="truck", gt_id=TRUCK, frame=14, sightings=(s,))
    (line, *_) = why_lines(miss)
    assert (
        "at frame 14 the detector gave no detection of a tracked class within 2 m of truck GT ecf44b (200 LiDAR and "
        "radar points in its box), but truck m1 (score 0.60) lay inside its box, 3.2 m from its centre: the detector "
        "saw part of it"
    ) in line
    assert "the detector missed it" not in line


def test_a_second_track_on_an_object_the_detector_gave_two_boxes_of_is_not_the_trackers_doing_alone() -> None:
    # audit truth50, world6 scene-0655 centerpoint gnn false_track:15 (a detector without NMS: a second pedestrian
    # box 0.3-0.8 m from the first): "two tracks on one object", the tracker's doing, with the detector's two boxes
    # of it unsaid
    from gnnpmb.why.findings import Party

    ctx = truck_split()
    ctx.gt_xy = lambda gt_id, frame: np.zeros(2) if gt_id == TRUCK else None
    boxes = ctx.frames[14].detections.boxes
    boxes.translation_m = np.array([[0.2, 0.0, 1.9], [-0.4, 0.3, 1.9], [1.5, 0.0, 1.9]])
    ctx.frames[14].detections.kept = np.array([True, True, False])  # m2 dropped by preprocessing: not seen
    assert ctx.own_detections(14, TRUCK) == (0, 1)
    out = FalseOutput(72, None, (-0.4, 0.3), None, (TRUCK, 0.5, None), None, 41, None, None, twins=(0, 1))
    blame = (Blame(Rule.TWO_DETECTIONS, (14,)), Blame(Rule.TWO_TRACKS, (14,)))
    f = _false_truck(out, blame)
    (line, *_) = why_lines(f)
    assert (
        "truck GT ecf44b lies 0.5 m away and the evaluation matched it to another track (track 41): two tracks on one "
        "object; the detector gave it two truck detections within 2 m (m0, m1)"
    ) in line
    assert Rule.TWO_DETECTIONS.party is Party.DETECTOR and line.startswith("**Why** (gnnpmb, the detector's and")
