"""A box placed 3-6 m off its object for one frame (audit truth51, world7 scene-0916 megvii jpda miss:65: car GT
63bd3c's detection moved 5.1 m at frame 18). With nothing within 2 m the miss read "the detector missed it",
though the detector's car box m6 lay 5.1 m away, nearer that car than any other annotated object. The box is now
named beside the miss."""

from __future__ import annotations

import numpy as np

from gnnpmb.eval.failures import FailureKind
from gnnpmb.why.findings import Sighting
from gnnpmb.why.reason import _Context
from gnnpmb.why.words import why_lines
from tests.gnnpmb.why.test_finding_words import finding
from tests.gnnpmb.why.test_reason_rules import Table, one_frame_context

CAR = "63bd3c" + "0" * 26
OTHER = "b38260" + "0" * 26


def two_cars() -> _Context:
    """Frame 18: car GT 63bd3c at (0, 0), car GT b38260 at (10, 0); car detections m0 at (4, 3) (5.0 m from
    63bd3c, nearer it), m1 at (7, 0) (3 m from b38260, nearer that one) and m2 at (0, 7) (7 m off: too far)."""
    gt = Table(
        instance_id=np.array([CAR, OTHER]),
        class_name=np.array(["car", "car"]),
        translation_m=np.array([[0.0, 0.0, 0.8], [10.0, 0.0, 0.8]]),
    )
    boxes = Table(
        translation_m=np.array([[4.0, 3.0, 0.8], [7.0, 0.0, 0.8], [0.0, 7.0, 0.8]]),
        class_name=np.array(["car", "car", "car"]),
        score=np.array([0.55, 0.6, 0.7]),
    )
    return one_frame_context(18, gt, boxes, "car")


def test_a_miss_names_a_box_of_its_class_placed_off_it_nearer_it_than_any_other_object() -> None:
    ctx = two_cars()
    off = ctx.off_near(18, CAR)
    assert off is not None and off.meas == 0 and off.distance_m == 5.0
    ctx.scene.keyframes[18].gt.translation_m[1, :2] = (6.0, 3.0)  # b38260 now nearer m0 (2 m): none of 63bd3c's
    assert ctx.off_near(18, CAR) is None
    s = Sighting(18, 7, None, None, None, None, (), off=off)
    miss = finding(FailureKind.MISS, class_name="car", gt_id=CAR, frame=18, sightings=(s,))
    (line, *_) = why_lines(miss)
    assert (
        "at frame 18 the detector gave no detection of a tracked class within 2 m of car GT 63bd3c (7 LiDAR and "
        "radar points in its box); the nearest car detection, m0 (score 0.55), lay 5.0 m away, nearer it than any "
        "other annotated object: the detector missed it or placed its box that far off"
    ) in line
    assert ": the detector missed it;" not in line
