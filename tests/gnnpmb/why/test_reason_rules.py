"""Whose doing a failure was (``why.reason``), from hand-made evaluation records: the evaluation's interpolated
box."""

from __future__ import annotations

from types import SimpleNamespace

from gnnpmb.eval.evaluated import GtFrame, GtStatus
from gnnpmb.eval.failures import FailureKind
from gnnpmb.why.findings import Rule
from gnnpmb.why.reason import _Context

GT = "4ab7b6" + "0" * 26


def context(kind: FailureKind, offset_m: float) -> _Context:
    """A finding's context at frame 18 whose object the evaluation scored at a box interpolated ``offset_m`` from
    the annotation, with no track output there."""
    g = GtFrame(18, GtStatus.INTERPOLATED, (0.0, 0.0), (offset_m, 0.0), None, 0, 20.0, 40.0, (14, 20))
    ctx = _Context.__new__(_Context)
    ctx.report = SimpleNamespace(gt_frame=lambda gt_id, frame: g if (gt_id, frame) == (GT, 18) else None)
    ctx.failure = SimpleNamespace(kind=kind, gt_ids=(GT,))
    ctx.f, ctx.frames = 18, {}
    return ctx


def rules(blame) -> list[Rule]:
    return [b.rule for b in blame]


def test_a_miss_is_the_evaluations_doing_only_where_its_box_would_put_a_track_on_the_object_out_of_reach() -> None:
    # demo scene-0103 gnnpmb miss:11: a box interpolated 1.3 m from the annotation, the track on the object not
    # counted (its average below the threshold) was "the evaluation's and the tracker's doing": a counted track on
    # the annotation would still have been matched, so the interpolation did not make the miss
    assert rules(context(FailureKind.MISS, 1.3).miss(())["blame"]) == []
    # miss:7 of the same run: 2.6 m, beyond the evaluation's 2 m: a track on the object would have been out of reach
    assert rules(context(FailureKind.MISS, 2.6).miss(())["blame"]) == [Rule.INTERPOLATED]


def test_a_lost_track_keeps_the_half_metre_rule() -> None:
    # an ID switch or a fragmentation: a box 0.5 m or more off can decide which of two tracks the evaluation matched
    assert rules(context(FailureKind.ID_SWITCH, 1.3).evaluation_blame()) == [Rule.INTERPOLATED]
    assert rules(context(FailureKind.ID_SWITCH, 0.4).evaluation_blame()) == []
