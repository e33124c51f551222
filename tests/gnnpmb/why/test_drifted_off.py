"""A false track whose predicted box ran off the object of its class it had been on (``_Context.drifted_off``)."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest

from gnnpmb.eval.evaluated import GtFrame, GtStatus
from gnnpmb.why.reason import _Context
from tests.gnnpmb.why.test_reason_rules import Table

BIKE, CAR = "9348e3" + "0" * 26, "a0c0a0" + "0" * 26


def coasting_past(bike_at_28: tuple[float, float] = (0.0, 0.0), track_x: tuple[float, ...] = (0.5, 1.0, 1.4)):
    """Frames 25-28 (dev set scene-0916 centerpoint, track 39): a bicycle GT with no sensor points stands at (0, 0)
    (at ``bike_at_28`` at frame 28), a car GT at (30, 0); track 39's box lies at x = ``track_x`` at frames 25-27
    and at (2.05, 0) at frame 28, the failure frame, where the evaluation has no box of the bicycle."""
    keyframes = {}
    frames = {}
    for i, f in enumerate(range(25, 29)):
        bike = bike_at_28 if f == 28 else (0.0, 0.0)
        keyframes[f] = SimpleNamespace(
            gt=Table(
                instance_id=np.array([BIKE, CAR]),
                class_name=np.array(["bicycle", "car"]),
                translation_m=np.array([[*bike, 0.0], [30.0, 0.0, 0.0]]),
            )
        )
        x = track_x[i] if f < 28 else 2.05
        frames[f] = SimpleNamespace(estimates=[SimpleNamespace(track_id=39, translation_m=np.array([x, 0.0, 0.0]))])
    g = GtFrame(28, GtStatus.NO_BOX, None, (0.0, 0.0), None, 0, 20.0, 40.0)
    ctx = _Context.__new__(_Context)
    ctx.scene = SimpleNamespace(keyframes=keyframes)
    ctx.frames, ctx.f, ctx.class_name = frames, 28, "bicycle"
    ctx.report = SimpleNamespace(gt_frame=lambda gt_id, frame: g if (gt_id, frame) == (BIKE, 28) else None)
    return ctx


def test_a_box_that_ran_off_the_object_it_was_on_names_that_object() -> None:
    # told as "no object of a tracked class lies within 2 m: the tracker output a box where no tracked object was"
    # though the track had followed the bicycle (no LiDAR or radar points) to frame 27 and lay 2.05 m from it
    drifted = coasting_past().drifted_off(39, np.array([2.05, 0.0]))
    assert drifted is not None
    gt_id, d, frame, g = drifted
    assert (gt_id, frame) == (BIKE, 27) and d == pytest.approx(2.05) and g.status is GtStatus.NO_BOX


def test_no_drift_is_told_when_the_object_is_far_or_the_track_never_was_on_one() -> None:
    assert coasting_past(bike_at_28=(-7.0, 0.0)).drifted_off(39, np.array([2.05, 0.0])) is None  # 9 m away now
    assert coasting_past(track_x=(5.0, 5.5, 6.0)).drifted_off(39, np.array([2.05, 0.0])) is None  # never within 2 m
