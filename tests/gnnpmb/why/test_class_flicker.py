"""A car detected as a truck at every other frame (audit truth51, world7 scene-0103 centerpoint gnnpmb
false_track:13): the truck track the wrong-class boxes started stays on the car through the frames the car is
seen as a car. Its predicted box there was said to have "coasted onto" the car, the tracker's doing alone; it had
been on the car all along, fed by the detector's truck boxes of it."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np

from gnnpmb.eval.failures import FailureKind
from gnnpmb.why.findings import Blame, FalseOutput, Rule
from gnnpmb.why.reason import _Context
from gnnpmb.why.words import why_lines
from tests.gnnpmb.why.test_finding_words import finding
from tests.gnnpmb.why.test_reason_rules import Table

CAR = "0f0413" + "0" * 26
PED = "9a6fb4" + "0" * 26


def flicker() -> _Context:
    """Car GT 0f0413 drives along x at 5 m/s, pedestrian GT 9a6fb4 stands 1.5 m beside its frame-14 place. Frame
    14: truck track 70 on m0, a truck box on the pedestrian's side of the car (nearer the pedestrian); frame 15:
    truck track 77 on m0, a truck box 0.4 m from the car; frame 16: both predicted (the car seen as a car, m0)."""
    gts, frames = {}, {}
    for x in (14, 15, 16):
        car = np.array([5.0 * (x - 14), 0.0])
        gts[x] = SimpleNamespace(
            gt=Table(
                instance_id=np.array([CAR, PED]),
                class_name=np.array(["car", "pedestrian"]),
                translation_m=np.array([[*car, 0.8], [0.0, 1.5, 0.9]]),
            )
        )
        det = {14: [0.0, 1.2, 0.9], 15: [5.4, 0.0, 0.8], 16: [10.1, 0.0, 0.8]}[x]
        boxes = Table(
            translation_m=np.array([det]), class_name=np.array(["car" if x == 16 else "truck"]), score=np.array([0.9])
        )
        ests = [SimpleNamespace(track_id=77, meas_index=0 if x == 15 else -1)]
        ests.append(SimpleNamespace(track_id=70, meas_index=0 if x == 14 else -1))
        frames[x] = SimpleNamespace(detections=SimpleNamespace(boxes=boxes), estimates=ests)
    ctx = _Context.__new__(_Context)
    ctx.scene = SimpleNamespace(keyframes=gts)
    ctx.frames = frames
    ctx.class_name = "truck"
    ctx.f = 16
    return ctx


def test_a_track_fed_by_an_objects_wrong_class_boxes_coasted_on_with_it_not_onto_it() -> None:
    ctx = flicker()
    assert ctx.coasted_from(77, CAR) == (15, 0)  # its last box sat on m0 at frame 15, 0.4 m from the car
    assert ctx.coasted_from(70, CAR) is None  # its last box's detection lay nearer the pedestrian: onto the car
    out = FalseOutput(77, None, (10.4, 0.0), None, None, (CAR, "car", 0.4), None, None, None, coasted_from=(15, 0))
    f = finding(
        FailureKind.FALSE_TRACK,
        class_name="truck",
        gt_id=None,
        track_ids=(77,),
        frame=16,
        false_output=out,
        blame=(Blame(Rule.OTHER_CLASS, (15,)), Blame(Rule.COASTED, (16,))),
    )
    (line, *_) = why_lines(f)
    assert (
        "no truck GT lies within 2 m, but GT car 0f0413 does (0.4 m): the track coasted on with it from m0 at frame "
        "15, a truck detection of it: the detector gave it the wrong class"
    ) in line
    assert "coasted onto it" not in line
    assert line.startswith("**Why** (gnnpmb, the detector's and the tracker's doing)")
