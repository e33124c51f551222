"""A rider annotated as a bicycle and a pedestrian on one spot (audit truth51, world7 scene-0916 centerpoint
ab3dmot miss:74): with no pedestrian box at frame 13 the Why said "a bicycle detection, m17, 0.5 m away: the
detector gave it the wrong class" of the bicycle's own box, which the evaluation matched to the bicycle. A box of
another class on an object of that class is now that object's, not a sight of this one."""

from __future__ import annotations

import numpy as np

from gnnpmb.eval.failures import FailureKind
from gnnpmb.why.reason import _Context
from gnnpmb.why.words import why_lines
from tests.gnnpmb.why.test_finding_words import finding
from tests.gnnpmb.why.test_reason_rules import Table, one_frame_context

PED = "4776dc" + "0" * 26
BIKE = "a402d8" + "0" * 26


def rider(bike_annotated: bool = True) -> _Context:
    """Frame 13: pedestrian GT 4776dc and bicycle GT a402d8 both at (0, 0) (the bicycle left out when not
    ``bike_annotated``); one detection, m0, a bicycle at (0.3, 0.4)."""
    ids, classes = [PED, BIKE], ["pedestrian", "bicycle"]
    n = 2 if bike_annotated else 1
    gt = Table(
        instance_id=np.array(ids[:n]),
        class_name=np.array(classes[:n]),
        translation_m=np.zeros((n, 3)),
    )
    boxes = Table(translation_m=np.array([[0.3, 0.4, 0.8]]), class_name=np.array(["bicycle"]), score=np.array([0.67]))
    return one_frame_context(13, gt, boxes, "pedestrian")


def test_a_box_of_another_class_on_an_object_of_that_class_is_that_objects_not_a_wrong_class_sight() -> None:
    ctx = rider()
    near = ctx.near(13, np.zeros(2), own=False)
    assert near is not None and near.meas == 0 and near.on_other is not None
    assert near.on_other[:2] == (BIKE, "bicycle") and abs(near.on_other[2] - 0.5) < 1e-9
    alone = rider(bike_annotated=False).near(13, np.zeros(2), own=False)  # no bicycle there: a wrong-class sight
    assert alone is not None and alone.of_it
    from gnnpmb.why.findings import Sighting

    s = Sighting(13, 40, None, near, None, None, ())
    miss = finding(FailureKind.MISS, class_name="pedestrian", gt_id=PED, frame=13, sightings=(s,))
    (line, *_) = why_lines(miss)
    assert "the detector gave it the wrong class" not in line
    assert "no detection of its own within 2 m (bicycle m0, 0.5 m away, lay 0.5 m from bicycle GT a402d8)" in line
