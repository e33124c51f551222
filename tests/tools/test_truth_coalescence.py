"""The oracle on a coalescence's second object (audit truth54, dev set scene-0061 centerpoint jpda coalescence:4,
three pedestrians at frame 18): "which no counted track covered" of GT f21f93, with counted track 72 0.9 m from
it that the devkit matched to a third pedestrian, passed the oracle unread."""

from __future__ import annotations

from tools.truth.devkit import EvalFacts
from tools.truth.scene import Annotation, SceneTruth
from tools.truth.sentences import Context, check_text

C = "pedestrian"
A, B, THIRD = "25b23b" + "1" * 26, "f21f93" + "2" * 26, "daa05e" + "3" * 26


def _kinds(text: str) -> list[str]:
    objects = {A: Annotation(C, (0.0, 0.0), 6), B: Annotation(C, (1.0, 0.0), 6), THIRD: Annotation(C, (1.6, 0.6), 6)}
    scene = SceneTruth([[]] * 4, [objects] * 4, [(0.0, 0.0)] * 4)
    ev = EvalFacts(thresholds={C: 0.47})
    ev.boxes[3] = [("75", C, (0.3, 0.0)), ("72", C, (1.5, 0.7)), ("80", C, (1.2, 0.0))]
    ev.gt_to_track[(C, 3)] = {A: "75", B: None, THIRD: "72"}
    ev.track_to_gt[(C, 3)] = {"75": A, "72": THIRD, "80": None}
    ev.counted[C] = {"75", "72"}  # track 80's averaged score is below the threshold
    ctx = Context(C, 3, B, covered=(A,), kind="coalescence")
    return [c.kind for c in check_text(text, ctx, None, ev, scene=scene).found]


def test_a_counted_track_near_the_second_object_left_unsaid_is_caught() -> None:
    head = "at frame 3 track 75 was matched to GT 25b23b and also lay within 2 m of GT f21f93, which "
    assert _kinds(f"{head}no counted track covered") == ["misleading"]
    assert _kinds(f"{head}the evaluation matched to no track") == ["misleading"]
    named = f"{head}the evaluation matched to no track, though counted track 72 lay 0.9 m from it (matched to GT "
    named += "daa05e)"
    assert _kinds(named) == []
    assert _kinds(named.replace("GT daa05e", "GT 25b23b")) == ["matched"]
    assert _kinds(named.replace("track 72 lay", "track 80 lay")) == ["matched", "misleading"]
