"""A false track on an object the evaluation had no box of, beyond the class range (audit truth54, dev set
scene-0103 centerpoint gnnpmb false_track:12, motorcycle GT 31c6f6 at frame 31, 40.15 m from the ego): the old
text said the evaluation "keeps no box of it both before and after this frame", read as none on either side,
though it kept the object's boxes from frame 32 on; what is true is that it kept none before, so it had nothing to
interpolate from."""

from __future__ import annotations

from types import SimpleNamespace

import pytest

from gnnpmb.eval.evaluated import Dropped, GtFrame, GtStatus
from gnnpmb.eval.failures import FailureKind
from gnnpmb.why.findings import Blame, FalseOutput, Rule
from gnnpmb.why.reason import _Context
from gnnpmb.why.words import why_lines
from tests.gnnpmb.why.test_finding_words import GT, finding

BEYOND = GtFrame(13, GtStatus.BEYOND_RANGE, (0.0, 0.0), None, Dropped.BEYOND_RANGE, 20, 40.15, 40.0)


def _text(kept: tuple[int | None, int | None]) -> str:
    out = FalseOutput(30, None, (0.2, 0.0), None, (GT, 0.2, BEYOND), None, None, None, None, kept_around=kept)
    blame = (Blame(Rule.NO_EVAL_BOX, (13,)),)
    return why_lines(finding(FailureKind.FALSE_TRACK, class_name="motorcycle", blame=blame, false_output=out))[0]


@pytest.mark.parametrize(
    ("kept", "said"),
    [
        ((None, 14), "the evaluation keeps none of its boxes before frame 14 to interpolate one from"),
        ((8, None), "the evaluation keeps none of its boxes after frame 8 to interpolate one from"),
        ((None, None), "the evaluation keeps none of its boxes at any frame"),
    ],
)
def test_the_side_the_evaluation_kept_no_box_on_is_named(kept, said) -> None:
    text = _text(kept)
    assert f"beyond the evaluation's 40 m range, and {said}): a track on it is false" in text
    assert "both before and after" not in text


def test_the_frames_the_evaluation_kept_the_object_at_around_the_failure() -> None:
    def g(x: int, dropped: Dropped | None) -> GtFrame:
        return GtFrame(x, GtStatus.SCORED, (0.0, 0.0), (0.0, 0.0), dropped, 20, 39.0, 40.0)

    frames = {x: g(x, Dropped.BEYOND_RANGE if x <= 13 else None) for x in range(10, 18)}
    ctx = _Context.__new__(_Context)
    ctx.f, ctx.report = 13, SimpleNamespace(gt_frames={GT: frames})
    assert ctx.kept_around(GT) == (None, 14)
    frames[11] = g(11, None)
    assert ctx.kept_around(GT) == (11, 14)
    assert ctx.kept_around("another") == (None, None)
