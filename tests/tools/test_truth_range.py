"""The oracle on the evaluation's class range (audit truth53, world9: a pedestrian and a bicycle crossing the 40 m
range, parked cars at 50 m): the old explainer's "(or in a bike rack)" of a car track's dropped box, and "it lies
50.0 m from the ego vehicle, inside the evaluation's 50 m range", passed the oracle unflagged."""

from __future__ import annotations

from tools.truth.devkit import EvalFacts
from tools.truth.scene import Annotation, Detection, SceneTruth
from tools.truth.sentences import Context, check_text

CAR = "a46079" + "0" * 26


def _kinds(text: str, class_name: str = "car", ego_m: float = 49.97, box_m: float = 50.02) -> list[str]:
    """Frame 3: the object ``ego_m`` from the ego (at the origin), track 15's box ``box_m`` from it."""
    scene = SceneTruth([[]] * 4, [{CAR: Annotation(class_name, (ego_m, 0.0), 60)}] * 4, [(0.0, 0.0)] * 4)
    ev = EvalFacts(thresholds={class_name: 0.3})
    ev.boxes[3] = [("15", class_name, (box_m, 0.0))]
    ev.pred_ego_m[(3, "15")] = box_m  # the devkit's distance of the box (``add_center_dist``)
    return [c.kind for c in check_text(text, Context(class_name, 3, CAR, kind="miss"), None, ev, scene=scene).found]


def test_a_bike_rack_offered_for_a_class_its_filter_never_drops_is_caught() -> None:
    # world9 scene-0103 centerpoint gnnpmb miss at frame 7, car GT a46079
    said = "track 15 was output on it, but its box lies beyond the evaluation's range for the class"
    assert _kinds(f"{said} (or in a bike rack): the evaluation dropped that box") == ["misleading"]
    assert _kinds(f"{said}: the evaluation dropped that box") == []
    assert _kinds(f"{said}: the evaluation dropped that box", box_m=49.5) == ["evaluation"]  # inside: not dropped
    rack = "track 15 was output on it, but its box there lies in a bike rack: the evaluation dropped that box"
    assert _kinds(rack, "bicycle", 39.0, 39.5) == []  # a bicycle's box may lie in a rack inside the range
    assert _kinds(rack, "bicycle", 39.0, 40.5) == ["evaluation"]  # beyond it: the range filter dropped it


def test_a_distance_printed_as_the_range_itself_is_caught() -> None:
    inside = "the object lies {} m from the ego vehicle, inside the evaluation's 50 m range"
    assert _kinds(inside.format("50.0")) == ["misleading"]
    assert _kinds(inside.format("49.97")) == []
    assert _kinds(inside.format("49.9")) == ["detector"]  # 49.97 to one decimal is 50.0, not 49.9


def test_a_dropped_box_on_the_object_told_as_the_track_running_off_it_is_caught() -> None:
    # world9 scene-0103 centerpoint gnnpmb false_track at frame 20: track 44's own box lay 0.2 m from pedestrian GT
    # b37203 and was dropped (beyond the 40 m range); the box the devkit interpolated in its place lay 5.6 m off
    ped = "b37203" + "0" * 26
    scene = SceneTruth([[]] * 4, [{ped: Annotation("pedestrian", (0.0, 0.0), 30)}] * 4, [(40.0, 0.0)] * 4)
    ev = EvalFacts(thresholds={"pedestrian": 0.3})
    ev.boxes[2] = [("44", "pedestrian", (0.1, 0.0))]
    ev.boxes[3] = [("44", "pedestrian", (0.2, 0.0))]
    ev.pred_xy[("pedestrian", 3)] = {"44": (5.6, 0.0)}
    ev.kept_frames["44"] = (2,)
    ctx = Context("pedestrian", 3, None, kind="false_track", track=44)
    nothing = "no object of a tracked class lies within 2 m of it"
    old = f"{nothing}: the track's box lies 5.6 m from pedestrian GT b37203, which it was last within 2 m of at frame 2"
    new = (
        f"{nothing}: the box the evaluation interpolated lies 5.6 m from pedestrian GT b37203, though the track's own "
        "box here, the one the evaluation dropped, lay within 2 m of it"
    )
    assert [c.kind for c in check_text(old, ctx, None, ev, scene=scene).found] == ["detector"]
    assert check_text(new, ctx, None, ev, scene=scene).found == []
    ev.kept_frames["44"] = (2, 3)  # kept there: the box the devkit scored is the track's own, and frame 2 is right
    ev.boxes[3] = [("44", "pedestrian", (5.6, 0.0))]
    assert check_text(old, ctx, None, ev, scene=scene).found == []


def test_a_dropped_lost_track_said_beyond_the_evaluations_2_m_is_caught() -> None:
    # world9 scene-1094 pointpillars gnnpmb id_switch:1 (track 91's box at frame 30 43.3 m from the ego)
    ped = "88761d" + "0" * 26
    scene = SceneTruth([[]] * 4, [{ped: Annotation("pedestrian", (39.7, 0.0), 12)}] * 4, [(0.0, 0.0)] * 4)
    ev = EvalFacts(thresholds={"pedestrian": 0.3})
    ev.boxes[3] = [("91", "pedestrian", (43.3, 0.0))]
    ev.submitted = {3: {"91"}}
    ev.kept_frames["91"] = (1, 2)
    ctx = Context("pedestrian", 3, ped, kind="id_switch")
    head = "at frame 3 track 91 was output 3.6 m from GT 88761d"
    old = f"{head}: beyond the evaluation's 2 m, so it no longer matched the object"
    new = (
        f"{head}, but its box lay 43.3 m from the ego vehicle, beyond the evaluation's 40 m range: the evaluation "
        "dropped it and had no box of the track to match to the object"
    )
    ev.pred_ego_m[(3, "91")] = 43.3
    assert [c.kind for c in check_text(old, ctx, None, ev, scene=scene).found] == ["evaluation"]
    assert check_text(new, ctx, None, ev, scene=scene).found == []
    ev.kept_frames["91"] = (1, 2, 3)  # kept: neither the drop nor its distance holds
    assert [c.kind for c in check_text(new, ctx, None, ev, scene=scene).found] == ["evaluation", "evaluation"]
    assert check_text(old, ctx, None, ev, scene=scene).found == []


def test_no_box_of_an_object_on_one_side_only_told_as_on_neither_is_caught() -> None:
    # audit truth54, dev set scene-0103 centerpoint gnnpmb false_track:12 (motorcycle GT 31c6f6 at frame 31, 40.15 m
    # from the ego): the devkit kept its boxes from frame 32 on, none before
    moto = "31c6f6" + "0" * 26
    scene = SceneTruth([[]] * 4, [{moto: Annotation("motorcycle", (40.15, 0.0), 20)}] * 4, [(0.0, 0.0)] * 4)
    ev = EvalFacts(thresholds={"motorcycle": 0.3})
    ev.kept_gt = {(3, moto)}
    ev.evaluated_gt = {(3, moto): (40.15, 0.0)}
    ctx = Context("motorcycle", 2, moto, kind="false_track", track=30)
    head = (
        "motorcycle GT 31c6f6 lies 0.2 m away, but the evaluation has no box for it here (it lies 40.15 m from the "
        "ego vehicle, beyond the evaluation's 40 m range, and "
    )

    def kinds(why: str) -> list[str]:
        return [c.kind for c in check_text(f"{head}{why}): a track on it is false", ctx, None, ev, scene=scene).found]

    assert kinds("it keeps no box of it both before and after this frame") == ["misleading"]
    assert kinds("the evaluation keeps none of its boxes before frame 3 to interpolate one from") == []
    assert kinds("the evaluation keeps none of its boxes after frame 1 to interpolate one from") == ["misleading"]
    assert kinds("the evaluation keeps none of its boxes at any frame") == ["misleading"]
    ev.kept_gt = {(1, moto), (3, moto)}  # kept on both sides: the devkit interpolated a box here
    ev.evaluated_gt[(2, moto)] = (40.1, 0.0)
    assert kinds("the evaluation keeps none of its boxes before frame 3 to interpolate one from") == ["evaluation"]


def test_a_detection_within_2_m_of_an_object_called_a_detection_of_no_tracked_object_is_caught() -> None:
    # audit truth54, dev set scene-0103 pointpillars jpda false_track:19 (frame 20): bicycle detection m14 lay 1.98 m
    # from bicycle GT 133f97, track 228's box on it 2.03 m
    bike = "133f97" + "0" * 26
    dets = [[Detection("bicycle", 0.31, (1.98, 0.0))]] * 4
    scene = SceneTruth(dets, [{bike: Annotation("bicycle", (0.0, 0.0), 15)}] * 4, [(0.0, 0.0)] * 4)
    ev = EvalFacts(thresholds={"bicycle": 0.3})
    ev.boxes[3] = [("228", "bicycle", (2.03, 0.0))]
    ev.submitted = {3: {"228"}}
    ctx = Context("bicycle", 3, None, kind="false_track", track=228)
    head = (
        "at frame 3 track 228 (bicycle) was output on detection m0 (bicycle, score 0.31); no object of a tracked class "
    )

    def kinds(tail: str) -> list[str]:
        return [c.kind for c in check_text(head + tail, ctx, None, ev, scene=scene).found]

    assert kinds("lies within 2 m: a detection of no tracked object") == ["detector"]
    said = "lies within 2 m of the box, but m0 lay 1.98 m from bicycle GT 133f97: the track's box lay 2.03 m from that "
    assert kinds(said + "object, beyond the evaluation's 2 m") == []
    assert kinds(said.replace("1.98", "1.90") + "object, beyond the evaluation's 2 m") == ["detector"]


def test_a_false_box_blamed_on_a_detection_of_nothing_that_lay_near_an_object_is_caught() -> None:
    # audit truth54, dev set scene-0103 pointpillars jpda false_track:23 (frame 28): truck detection m1 lay 0.25 m
    # from truck GT bcd4a2 and track 170's box 2.21 m, blamed on the detector ("a detection of no tracked object")
    from types import SimpleNamespace

    from gnnpmb.why.findings import Near, Rule
    from tools.truth.fields import Sources, check_blame

    truck = "bcd4a2" + "0" * 26
    scene = SceneTruth(
        [[Detection("truck", 0.75, (0.25, 0.0))]] * 4, [{truck: Annotation("truck", (0.0, 0.0), 80)}] * 4, [(0, 0)] * 4
    )
    ev = EvalFacts(thresholds={"truck": 0.5})
    ev.boxes[3] = [("170", "truck", (2.21, 0.0))]
    out = SimpleNamespace(track_id=170, on=Near(0, "truck", 0.75, 1.96, True))
    f = SimpleNamespace(class_name="truck", gt_id=None, lost=None, false_output=out, kind=SimpleNamespace(value="x"))
    src = Sources(scene, None, ev)
    assert check_blame(Rule.DETECTION_OF_NOTHING, (3,), f, src) != ""
    assert check_blame(Rule.OFF_OBJECT, (3,), f, src) == ""
    ev.boxes[3] = [("170", "truck", (1.5, 0.0))]  # the box within reach: not off the object
    assert check_blame(Rule.OFF_OBJECT, (3,), f, src) != ""
