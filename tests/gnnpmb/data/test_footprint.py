"""Points inside an annotated box's ground-plane footprint (``boxes3d.in_footprint``, ``containing_box``), and the
focus on a false track on part of a long object names that object (``focus._gt_under_false_track``), as its Why
does (audit truth50, world6: a 16 m truck seen as a cab box and a trailer box)."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np

from gnnpmb.data.boxes3d import containing_box, in_footprint
from gnnpmb.eval.failures import Failure, FailureBox, FailureKind
from gnnpmb.focus import _gt_under_false_track
from gnnpmb.types import Boxes


def _truck_and_car() -> Boxes:
    """A 16 m x 2.5 m truck at the origin heading along +y (yaw 90 degrees), and a 4.5 m x 2 m car at (10, 0)
    heading along +x."""
    half = np.sqrt(0.5)
    return Boxes(
        translation_m=np.array([[0.0, 0.0, 1.0], [10.0, 0.0, 1.0]]),
        size_wlh_m=np.array([[2.5, 16.0, 3.5], [2.0, 4.5, 1.6]]),
        quat_wxyz=np.array([[half, 0.0, 0.0, half], [1.0, 0.0, 0.0, 0.0]]),
        velocity_mps=np.zeros((2, 2)),
        score=np.ones(2),
        class_name=np.array(["truck", "car"]),
        instance_id=np.array(["truck1", "car1"]),
    )


def test_footprint_follows_the_heading_by_hand() -> None:
    """Turned by 90 degrees the truck spans |y| <= 8 and |x| <= 1.25: (0, 7.9) and (1.2, -5) are in, (7.9, 0) (along
    x, where it would be unturned) and (1.3, 0) are out."""
    boxes = _truck_and_car()
    points = np.array([[0.0, 7.9], [1.2, -5.0], [7.9, 0.0], [1.3, 0.0]])
    assert in_footprint(boxes, 0, points).tolist() == [True, True, False, False]
    k, dist_m = containing_box(boxes, np.array([0.5, -4.75]))
    assert k == 0 and dist_m == np.hypot(0.5, 4.75)
    assert containing_box(boxes, np.array([10.0, 1.5])) is None  # beside the car, in no box


def test_a_false_track_on_a_trailer_opens_on_the_truck() -> None:
    """A false track 4.75 m behind the truck's centre (no centre within 2 m) is on part of the truck: the focus
    names it; one 3 m beside the car, inside no box, names no object."""
    scene = SimpleNamespace(keyframes=[SimpleNamespace(gt=_truck_and_car())])

    def false_track(x: float, y: float) -> Failure:
        box = FailureBox("false track", "72", (x, y, 1.0), (2.5, 9.0, 3.5), (1.0, 0.0, 0.0, 0.0))
        return Failure(FailureKind.FALSE_TRACK, 0, "s0", "truck", (), ("72",), (box,))

    assert _gt_under_false_track(false_track(0.3, -4.75), scene) == ("truck1",)
    assert _gt_under_false_track(false_track(10.0, 3.0), scene) == ()


def test_a_false_track_opens_on_the_object_of_its_class_its_why_names() -> None:
    """World7 scene-0796 pointpillars gnn false_track:16: a car box 1.87 m from car GT d97fc4 and 1.79 m from a
    bicycle. The Why names the car (its nearest of the class) and another run's track on it; the focus opened on
    the bicycle, so that track was not highlighted."""
    gt = Boxes(
        translation_m=np.array([[0.0, 0.0, 1.0], [1.87, 0.0, 1.0], [-1.79, 0.0, 1.0]]),
        size_wlh_m=np.tile([1.0, 1.0, 1.0], (3, 1)),
        quat_wxyz=np.tile([1.0, 0.0, 0.0, 0.0], (3, 1)),
        velocity_mps=np.zeros((3, 2)),
        score=np.ones(3),
        class_name=np.array(["truck", "car", "bicycle"]),
        instance_id=np.array(["far", "d97fc4", "0f89de"]),
    )
    gt.translation_m[0, 0] = 30.0
    scene = SimpleNamespace(keyframes=[SimpleNamespace(gt=gt)])
    box = FailureBox("false track", "237", (0.0, 0.0, 1.0), (2.0, 4.5, 1.6), (1.0, 0.0, 0.0, 0.0))
    car = Failure(FailureKind.FALSE_TRACK, 0, "s0", "car", (), ("237",), (box,))
    assert _gt_under_false_track(car, scene) == ("d97fc4",)
    truck = Failure(FailureKind.FALSE_TRACK, 0, "s0", "truck", (), ("237",), (box,))
    assert _gt_under_false_track(truck, scene) == ("0f89de",)  # none of its class within 2 m: the nearest of any
