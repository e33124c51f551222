"""An identity theft's "the evaluation still gave GT X to track V" at the thief's false frames (audit truth52,
world8 scene-0655 centerpoint cphd identity_theft:1): the victim must be the track the evaluation matched the object
to at every one of them, not only a track that was no false track there."""

from __future__ import annotations

from types import SimpleNamespace

from gnnpmb.why.reason import _Context


def test_a_thief_is_not_said_to_have_been_false_while_its_victim_held_the_object_before_the_victim_had_it() -> None:
    # world8 scene-0655 centerpoint cphd identity_theft:1: track 53 (started on the stroller's box) was false at
    # frames 16-18; the evaluation gave the adult 1defa4 to track 27 at frame 16 and to track 55 from frame 17, yet
    # the Why said "the evaluation still gave GT 1defa4 to track 55" at frames 16-18
    from gnnpmb.eval.evaluated import TrackEval

    ctx = _Context.__new__(_Context)
    gt = "1defa4" + "0" * 26
    ctx.report = SimpleNamespace(
        track_evals={"55": TrackEval((17, 18, 19), (17, 18, 19), (), 0.6, 0.6, ((17, gt), (18, gt)))}
    )
    ctx.missed_at = lambda gt_id, x: False
    ctx.evaluated_at = lambda gt_id, x: True
    ctx.false_at = lambda report, x, t: False
    assert ctx.victim_held(gt, "55", (17, 18))
    assert not ctx.victim_held(gt, "55", (16, 17, 18))  # track 27 held it at frame 16
    assert not ctx.victim_held(gt, None, (17,)) and not ctx.victim_held(gt, "55", ())
