"""The independent checker (``tools.truth``) catches each class of false statement planted into a finding's text,
and passes the true sentence it replaces: one frame of hand-made raw events (a GNN-like and a PMB-like cost
matrix with their terms, the assignment, the predicted tracks) and hand-made devkit matches. The true
counterfactual and margin sentences are rendered by the explainer's own words (``gnnpmb.why.words``) from its own
decisions (``gnnpmb.explain``), so what is planted is exactly what the renderer would print if its rule were wrong.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from gnnpmb.events import (
    Assignment,
    AxisKind,
    CostMatrix,
    CostTerms,
    FrameStarted,
    Gated,
    Predicted,
    axis_labels,
)
from gnnpmb.explain import explain
from gnnpmb.why.counterfactual import would_take
from gnnpmb.why.words import choice_text, choice_why
from tools.truth import replay
from tools.truth.devkit import EvalFacts
from tools.truth.rawevents import RawEvents
from tools.truth.scene import SceneTruth
from tools.truth.sentences import Context, check_text

C = "car"
GT_A, GT_B = "a" * 32, "b" * 32


TAKEN = np.array([[6.0, 30.0], [2.0, 1.0], [50.0, 50.0]])
"""d2 (K, M): m0 is nearer track 7 than track 5, but track 7 is m1's (the rival the assignment gave away)."""
FREE = np.array([[6.0, 30.0], [2.5, 40.0], [50.0, 50.0]])
"""d2: m0 goes to track 7, track 5 is its free next best, m1 starts a track."""


def _matrix(existence: np.ndarray | None, d2: np.ndarray) -> CostMatrix:
    """Two detections (m0, m1), three tracks (5, 7, 9: 9 cannot take either, +inf), one new-track column each."""
    log_det = np.array([0.2, 0.1, 0.3])
    miss = None if existence is None else np.log1p(-existence * 0.9)
    terms = CostTerms(
        existence=existence,
        miss_log_lik=miss,
        score=None if existence is None else np.array([0.9, 0.8]),
        d2=d2,
        log_det_S=log_det,
        dim=2,
        offset_nats=-9.0 if existence is None else 0.0,
        track_ids=np.array([5, 7, 9]),
    )
    cost = np.full((2, 5), np.inf)
    for j in range(2):
        for k in range(2):
            cost[j, k] = terms.pair(j, k).total_nats
        cost[j, 3 + j] = 0.0 if existence is None else 10.0
    rows = axis_labels(AxisKind.MEASUREMENT, [0, 1])
    cols = axis_labels(AxisKind.TRACK, [5, 7, 9]) + axis_labels(AxisKind.NEW_TRACK, [0, 1])
    return CostMatrix(C, cost, rows, cols, terms=terms)


def _world(existence: np.ndarray | None, d2: np.ndarray = TAKEN):
    from gnnpmb.assign.hungarian import solve

    m = _matrix(existence, d2)
    cols, total = solve(np.asarray(m.cost))
    pairs = tuple((m.rows[j], m.cols[int(k)]) for j, k in enumerate(cols))
    a = Assignment(C, pairs, total, ())
    predicted = Predicted(C, np.array([5, 7, 9]), np.zeros((3, 4)), np.tile(np.eye(4), (3, 1, 1)), np.ones(3))
    raw = RawEvents.of([FrameStarted("t", 3, "token", 0, 0.5), predicted, m, a])
    return raw, m, a


def _eval() -> EvalFacts:
    ev = EvalFacts(thresholds={C: 0.5})
    ev.gt_to_track[(C, 3)] = {GT_A: "7", GT_B: None}  # GT B missed: matched to nothing
    ev.track_to_gt[(C, 3)] = {"7": GT_A, "5": None, "11": None}
    ev.counted[C] = {"7", "11"}
    return ev


CTX = Context(C, 3, GT_B, covered=(GT_A,), false_frames=(3,), taker=11)


def _found(text: str, ctx: Context = CTX, existence: np.ndarray | None = None, d2: np.ndarray = TAKEN):
    raw, _, _ = _world(existence, d2)
    return check_text(text, ctx, raw, _eval())


def _because(existence: np.ndarray | None, d2: np.ndarray = TAKEN) -> str:
    """The explainer's own Because sentence for m0's choice (frame 3); empty when it has none."""
    _, m, a = _world(existence, d2)
    d = explain(m, a)
    choice = next(ch for c in d.conflicts for ch in c.choices if ch.meas.ref == 0)
    would = would_take(m, a, 0, int(choice.alternative.ref))
    why = choice_why(choice, would=would)
    return f"Because (frame 3): {why}." if why else ""


PLANTED = {
    # class: (true sentence, planted false sentence)
    "matched: covered two": (
        "track 7 lay within 2 m of it and was counted, but the evaluation matched it to another object",
        "track 11 lay within 2 m of it and was counted, but the evaluation matched it to another object",
    ),
    "matched: identity theft": (
        None,
        "track 11 had been a false track at frame 3 (matched to no object: the evaluation still gave GT bbbbbb to "
        "track 7), so its taking the object is an identity theft",
    ),
    "matched: coalescence": (
        "at frame 3 track 7 was matched to GT aaaaaa and also lay within 2 m of GT bbbbbb",
        "at frame 3 track 5 was matched to GT aaaaaa and also lay within 2 m of GT bbbbbb",
    ),
    # dev set square (python -m tools.truth --square --all-scenes): 14 clauses of a coalescence matched at a box the
    # devkit interpolated for a track not output there were read by no checker
    "matched: coalescence at a box the evaluation interpolated for the track": (
        "at frame 3 track 7 was not output; the box the evaluation interpolated for it in its place was matched to "
        "GT aaaaaa and also lay within 2 m of GT bbbbbb",
        "at frame 3 track 7 was output, but the evaluation dropped its box; the box the evaluation interpolated for "
        "it in its place was matched to GT aaaaaa and also lay within 2 m of GT bbbbbb",
    ),
    "matched: not counted": (
        "track 5 was output on it, but its score averaged over its 3 frames, 0.40, is below the car threshold "
        "0.500: the evaluation did not count it",
        "track 7 was output on it, but its score averaged over its 3 frames, 0.40, is below the car threshold "
        "0.500: the evaluation did not count it",
    ),
    "matched: the class threshold, at a sentence's end": (
        "the evaluation counted the track: its score averaged over its 3 frames, 0.700, is at least the car threshold "
        "0.500.",
        "the evaluation counted the track: its score averaged over its 3 frames, 0.700, is at least the car threshold "
        "0.400.",
    ),
    "gone: column of infinite cost": (
        None,
        "at frame 3 m1 (score 0.80, 0.3 m from it; track 9 was gone) → track 7",
    ),
    "gone: outside the gate of a deleted track": (
        "Because (frame 3): m1 was outside the gate of track 9, which had the object.",
        "Because (frame 3): m1 was outside the gate of track 12, which had the object.",
    ),
    "misleading: viewer note in the terminal": (None, "its existence was too low to be shown here"),
}


@pytest.mark.parametrize("name", list(PLANTED))
def test_each_planted_statement_is_caught_and_its_true_form_passes(name: str) -> None:
    true, false = PLANTED[name]
    kind = name.split(":")[0]
    if true is not None:
        assert _found(true).found == [], true
    caught = _found(false).found
    assert [c.kind for c in caught][:1] == [kind], (false, caught)


def _break_even_d2() -> float:
    """The d2 of (m0, track 5) at which track 5 costs what track 7 does for m0 (FREE world), by hand."""
    m = _matrix(None, FREE)
    c5, c7 = m.cost[0, 0], m.cost[0, 1]
    return FREE[0, 0] - 2.0 * (c5 - c7)


def test_a_counterfactual_past_the_break_even_or_the_current_value_is_refuted() -> None:
    even = _break_even_d2()
    sentence = "Because (frame 3): Within d² {:.2f} (instead of 6.0), track 5 would have taken m0."
    holds = _found(sentence.format(even - 0.05), d2=FREE)
    assert holds.found == [] and holds.replays == 1
    for wrong in (even + 0.05, 6.5):  # just past the break-even (the issue's 14.3 for 14.25); above the current d2
        caught = _found(sentence.format(wrong), d2=FREE)
        assert [c.kind for c in caught.found] == ["counterfactual"] and caught.refuted == 1, wrong


def test_a_planted_existence_threshold_below_the_current_one_is_caught() -> None:
    existence = np.array([0.1, 0.5, 0.9])  # m0 goes to track 7; track 5 would take it above existence ~0.92
    sentence = "Because (frame 3): With a predicted existence above {} (instead of 0.10), track 5 would have taken m0."
    assert _found(sentence.format("0.95"), existence=existence, d2=FREE).found == []
    for wrong in ("0.90", "0.05"):  # short of the break-even; below the current existence
        found = _found(sentence.format(wrong), existence=existence, d2=FREE).found
        assert [c.kind for c in found] == ["counterfactual"], wrong


def test_a_rival_the_assignment_gave_to_another_detection_is_caught() -> None:
    fair = "Because (frame 3): m0 went to track 7 (cost -8.0) rather than track 5 (cost -5.0): the lower cost wins."
    assert _found(fair, d2=FREE).found == []  # track 5 is free: naming it is fair
    planted = "Because (frame 3): m0 went to track 5 (cost -5.0) rather than track 7 (cost -8.0): the lower cost wins."
    assert [c.kind for c in _found(planted).found] == ["counterfactual"]


def test_a_capped_or_wrong_margin_is_caught_and_the_solvers_margin_passes() -> None:
    _, m, a = _world(None)
    d = explain(m, a)
    choice = next(ch for c in d.conflicts for ch in c.choices if ch.meas.ref == 0)
    went = int(choice.chosen.ref)  # the cheaper track 7 took m1: said, as the explainer says it
    true = "then, " + choice_text(3, choice, went, False, alternative_took=1).replace("**", "")
    row, col = replay.row_of(m, 0), replay.chosen_col(m, a, 0)
    real = replay.margin(m, row, col)
    shown = float(true.rsplit("margin ", 1)[1])
    assert math.isclose(shown, min(real, 5.0), abs_tol=0.006)
    found = _found(true).found
    assert (found == []) == (real <= 5.0), (true, real)
    planted = true.rsplit("margin ", 1)[0] + f"margin {real + 1.0:.2f}"
    assert [c.kind for c in _found(planted).found] == ["misleading"]


def test_what_the_cheaper_next_best_took_instead_is_checked_against_the_assignment() -> None:
    _, m, a = _world(None)  # TAKEN: m0 goes to track 5 though track 7 is cheaper; track 7 took m1
    d = explain(m, a)
    choice = next(ch for c in d.conflicts for ch in c.choices if ch.meas.ref == 0)
    assert choice.alternative.ref == 7 and choice.alternative_cost < choice.chosen_cost
    true = "then, " + choice_text(3, choice, int(choice.chosen.ref), False, alternative_took=1).replace("**", "")
    assert "over track 7 (" in true and "), which took m1 (the lower total wins), margin" in true
    assert _found(true).found == []
    planted = true.replace("which took m1", "which took m0")
    assert [c.kind for c in _found(planted).found] == ["misleading"]
    # world4 scene-0061 centerpoint gnnpmb id_switch:3: the Why's deciding choice left "which took" out, so a cost
    # 10.50 was chosen over a cheaper 6.30 "by a margin 0.07" with nothing said of why
    bare = "then, " + choice_text(3, choice, int(choice.chosen.ref), False).replace("**", "")
    assert [c.kind for c in _found(bare).found] == ["misleading"]


@pytest.mark.parametrize("existence", [None, np.array([0.1, 0.5, 0.9])], ids=["gnn", "pmb"])
@pytest.mark.parametrize("d2", [TAKEN, FREE], ids=["rival taken", "rival free"])
def test_the_explainers_own_because_holds_when_replayed(d2: np.ndarray, existence: np.ndarray | None) -> None:
    text = _because(existence, d2)
    t = _found(text, existence=existence, d2=d2)
    assert t.found == [], (text, t.found)
    assert t.replays == 1, text  # the explainer said what the solver would do, and the replay agreed


def test_a_track_said_to_be_matched_instead_to_a_missed_object_is_caught() -> None:
    sentence = "car GT bbbbbb lies 0.4 m away and the evaluation matched it to another track (track 7): two tracks"
    assert [c.kind for c in _found(sentence).found] == ["matched"]  # GT B was missed at frame 3
    assert _found(sentence, Context(C, 3, GT_A)).found == []  # GT A was matched to track 7


def test_a_greedy_choice_over_a_column_another_detection_took_is_caught() -> None:
    from gnnpmb.events import CostScale

    rows = axis_labels(AxisKind.MEASUREMENT, [0, 1])
    cols = axis_labels(AxisKind.TRACK, [5, 7]) + axis_labels(AxisKind.NEW_TRACK, [0, 1])
    cost = np.array([[1.0, 4.0, 9.0, np.inf], [2.0, 3.0, np.inf, 9.0]])
    m = CostMatrix(C, cost, rows, cols, scale=CostScale("distance", "m", 0.3, optimal=False))
    a = Assignment(C, ((rows[0], cols[0]), (rows[1], cols[1])), 4.0, ())
    raw = RawEvents.of([FrameStarted("t", 3, "token", 0, 0.5), m, a])
    planted = "then, frame 3: m1 → track 7 (cost 3.00 m) over track 5 (2.00 m), margin 0.00 m"
    assert [c.kind for c in check_text(planted, CTX, raw, _eval()).found] == ["misleading"]
    fair = "then, frame 3: m1 → track 7 (cost 3.00 m) over new (9.00 m), margin 5.00 m or more"
    assert check_text(fair, CTX, raw, _eval()).found == []


def test_a_near_tie_is_stated_with_the_decimals_that_tell_the_two_values_apart() -> None:
    """m0 goes to track 7 at d² 2.52; track 5 (a spread 0.05 nats wider) breaks even at d² 2.42 and sits at 2.44:
    with one decimal both would print as 2.4."""
    d2 = FREE.copy()
    d2[1, 0], d2[0, 0] = 2.52, 2.44
    even = 2.42
    _, m, a = _world(None, d2)
    w = would_take(m, a, 0, 5)
    assert w is not None and w.digits >= 2 and w.needed < even
    text = _because(None, d2)
    assert f"Within d² {w.needed:.{w.digits}f} (instead of {d2[0, 0]:.{w.digits}f})" in text, text
    assert _found(text, d2=d2).found == []


def _scene():
    """Frames 0-3: GT A (car, 12 points) at the origin, GT B (car, 0 points) 30 m away; m0 (car, 0.90) 0.3 m from A
    at every frame, m1 (truck, 0.40) 1.0 m from B at frame 3."""
    from tools.truth.scene import Annotation, Detection, SceneTruth

    objects = [{GT_A: Annotation(C, (0.0, 0.0), 12), GT_B: Annotation(C, (30.0, 0.0), 0)} for _ in range(4)]
    detections = [[Detection(C, 0.9, (0.3, 0.0))] for _ in range(3)]
    detections.append([Detection(C, 0.9, (0.3, 0.0)), Detection("truck", 0.4, (31.0, 0.0))])
    return SceneTruth(detections, objects, [(-45.0, 0.0)] * 4)  # GT A 45 m from the ego pose


def _raw_with(*events):
    return RawEvents.of([FrameStarted("t", 3, "token", 0, 0.5), *events])


def _received(*meas: int):
    from gnnpmb.events import MeasurementsReceived

    return MeasurementsReceived(C, np.array(meas), np.zeros((len(meas), 3)), np.full(len(meas), 0.9))


PRESENCE_KEPT = "in the 2 recorded frames up to 3 (2–3), GT aaaaaa had a car detection the tracker kept within 2 m at "
PLANTED_FACTS = {
    # class: (true sentence, planted false sentence, raw events at frame 3); frame 2 has no event: m0 removed there
    "detector: score": (
        "at frame 3 detection m0 (score 0.90) lay 0.3 m from car GT aaaaaa and started no track",
        "at frame 3 detection m0 (score 0.80) lay 0.3 m from car GT aaaaaa and started no track",
        (),
    ),
    "detector: distance": (
        "at frame 3 m0 (score 0.90, 0.3 m from it) → track 7",
        "at frame 3 m0 (score 0.90, 1.3 m from it) → track 7",
        (),
    ),
    "detector: no detection though one was in reach": (
        "at frame 3 the detector gave no car detection within 2 m of car GT bbbbbb (0 LiDAR and radar points in its "
        "box), but a truck detection, m1 (score 0.40), 1.0 m away",
        "at frame 3 the detector gave no detection of a tracked class within 2 m of car GT aaaaaa (12 LiDAR and radar "
        "points in its box)",
        (),
    ),
    "detector: range side": (
        "the object lies 45.0 m from the ego vehicle, inside the evaluation's 50 m range",
        "the object lies 45.0 m from the ego vehicle, beyond the evaluation's 50 m range",
        (),
    ),
    "misleading: removed detections left out of 'had a detection within 2 m'": (
        PRESENCE_KEPT + "frame 3 only, and at frame 2 only one its preprocessing removed (score threshold or NMS)",
        "in the 2 recorded frames up to 3 (2–3), GT aaaaaa had a car detection within 2 m at frame 3 only",
        (_received(0),),
    ),
}


@pytest.mark.parametrize("name", list(PLANTED_FACTS))
def test_each_planted_detector_statement_is_caught_against_the_files(name: str) -> None:
    true, false, events = PLANTED_FACTS[name]
    ctx = Context(C, 3, GT_A)
    raw = _raw_with(*events)
    assert check_text(true, ctx, raw, _eval(), scene=_scene()).found == [], true
    caught = check_text(false, ctx, raw, _eval(), scene=_scene()).found
    assert [c.kind for c in caught][:1] == [name.split(":")[0]], (false, caught)


def test_a_dropped_track_box_must_say_which_filter_dropped_it_at_the_box_own_distance() -> None:
    """Dev set scene-0757 pointpillars pmbm, frame 37: "its box lies beyond the evaluation's range for the class (or
    in a bike rack)", then "it lies 39.8 m from the ego vehicle, inside the evaluation's 40 m range" (the
    motorcycle's distance); the devkit put the track's box 40.13 m away. Car range 50 m here: box at 50.3 m."""
    ev = _eval()
    ev.pred_ego_m[(3, "12")] = 50.3
    ctx = Context(C, 3, GT_A, kind="miss")
    true = (
        "track 12 was output on it, but its box there lies 50.3 m from the ego vehicle, beyond the evaluation's 50 m "
        "range: the evaluation dropped that box"
    )
    assert check_text(true, ctx, None, ev).found == []
    hedged = (
        "track 12 was output on it, but its box lies beyond the evaluation's range for the class (or in a bike "
        "rack): the evaluation dropped that box"
    )
    assert [c.kind for c in check_text(hedged, ctx, None, ev).found] == ["misleading"]
    rack = "track 12 was output on it, but its box there lies in a bike rack: the evaluation dropped that box"
    assert [c.kind for c in check_text(rack, ctx, None, ev).found] == ["evaluation"]
    assert [c.kind for c in check_text(true.replace("50.3", "49.3"), ctx, None, ev).found] == ["evaluation"]
    ev.kept_frames["12"] = (3,)
    assert [c.kind for c in check_text(true, ctx, None, ev).found] == ["evaluation"]


def test_another_objects_detection_said_to_be_a_sight_of_this_one_is_caught() -> None:
    """A truck (GT cccccc) 0.1 m from m1 at frame 3: m1 is the truck's detection, not car GT B seen as a truck (dev set
    scene-1094 centerpoint ab3dmot, a car detection 0.1 m from a car called a bicycle's wrong class)."""
    from tools.truth.scene import Annotation

    scene = _scene()
    scene.objects[3]["c" * 32] = Annotation("truck", (31.1, 0.0), 40)
    ctx = Context(C, 3, GT_B)
    wrong_class = (
        "at frame 3 the detector gave no car detection within 2 m of car GT bbbbbb (0 LiDAR and radar points in its "
        "box), but a truck detection, m1 (score 0.40), 1.0 m away"
    )
    assert [c.kind for c in check_text(wrong_class, ctx, None, _eval(), scene=scene).found] == ["detector"]
    seen_as = "at frame 3 the detector saw it only as another class (truck m1 1.00 m away)"
    assert [c.kind for c in check_text(seen_as, ctx, None, _eval(), scene=scene).found] == ["detector"]
    true = (
        "at frame 3 the detector gave car GT bbbbbb (0 LiDAR and radar points in its box) no detection of its own "
        "within 2 m (truck m1, 1.0 m away, lay 0.1 m from truck GT cccccc): the detector missed it"
    )
    assert check_text(true, ctx, None, _eval(), scene=scene).found == []
    for planted in (true.replace("lay 0.1 m", "lay 0.6 m"), true.replace("truck GT cccccc", "truck GT aaaaaa")):
        assert [c.kind for c in check_text(planted, ctx, None, _eval(), scene=scene).found] == ["detector"], planted
    # without the truck, m1 is the car's own: "no detection of its own" is false
    assert [c.kind for c in check_text(true, ctx, None, _eval(), scene=_scene()).found] == ["detector"]


def test_another_run_said_not_to_have_a_switch_it_had_no_track_for_is_caught() -> None:
    other = _eval()  # GT B unmatched at frame 3 in the other run too; GT A matched to its track 7
    ctx = Context(C, 3, GT_B, kind="id_switch")
    planted = "pmbm on the same detections did not have this failure"
    assert [c.kind for c in check_text(planted, ctx, None, _eval(), others={"pmbm": other}).found] == ["misleading"]
    fair = "pmbm on the same detections had no counted track on the object here either"
    assert check_text(fair, ctx, None, _eval(), others={"pmbm": other}).found == []
    wrong = "pmbm on the same detections did not fail here: its track 7 was output on the object and counted"
    assert [c.kind for c in check_text(wrong, ctx, None, _eval(), others={"pmbm": other}).found] == ["other run"]


def test_a_failure_the_devkit_did_not_count_in_an_unscored_class_must_say_so() -> None:
    # independent audit truth46, dev set scene-0103 pointpillars jpda false_track:2 (bicycle): jpda reached no
    # bicycle score threshold at the lowest recall, so the devkit counted no false bicycle track of it
    ctx = Context(C, 3, GT_B, kind="false_track")
    unscored = _eval()
    unscored.thresholds[C] = None
    plain = "a clause no checker reads"
    said = f"{plain}; outside the evaluation's counts: jpda reached no score threshold at its lowest recall for {C}s"
    assert [c.kind for c in check_text(plain, ctx, None, unscored).found] == ["misleading"]
    assert check_text(said, ctx, None, unscored).found == []
    assert [c.kind for c in check_text(said, ctx, None, _eval()).found] == ["evaluation"]  # a scored class
    assert check_text(plain, Context(C, 3, GT_B, kind="miss"), None, unscored).found == []  # every miss counts


def test_a_bare_percentage_and_a_wrong_one_are_caught() -> None:
    from gnnpmb.events import UpdateWeights

    w = UpdateWeights(C, np.array([7]), np.array([1]), np.ones(1), np.array([0.03]), np.array([[0.99]]), np.zeros(1))
    raw = _raw_with(w)
    ctx = Context(C, 3, GT_A, lost=7)
    assert check_text("at frame 3 m1 (score 0.80, 0.3 m from it) → track 7 (99 % of m1)", ctx, raw, _eval()).found == []
    bare = check_text("at frame 3 m1 (score 0.80, 0.3 m from it) → track 7 (99 %)", ctx, raw, _eval()).found
    assert [c.kind for c in bare] == ["misleading"]
    assert check_text("at frame 3 it took 97 % of its weight from m1", ctx, raw, _eval()).found == []
    wrong = check_text("at frame 3 it took 99 % of its weight from m1", ctx, raw, _eval()).found
    assert [c.kind for c in wrong] == ["share"]  # 0.99 / (0.03 + 0.99) is 97 %


def test_an_interpolated_box_said_output_and_a_start_without_a_birth_are_caught() -> None:
    from gnnpmb.events import Born

    ev = _eval()
    ev.submitted[3] = {"5"}  # track 7's box at frame 3 is the evaluation's interpolation
    said = "at frame 3 track 7 (car) was output on detection m0 (car, score 0.90)"
    assert [c.kind for c in check_text(said, CTX, None, ev).found] == ["misleading"]
    ev.submitted[3] = {"5", "7"}
    assert check_text(said, CTX, None, ev).found == []
    born = Born(C, np.array([7]), np.array([1]), np.zeros((1, 4)), np.ones(1))
    started = "track 7 had been started at frame 3 by m1"
    assert check_text(started, CTX, _raw_with(born), _eval()).found == []
    handed = check_text(started, CTX, _raw_with(), _eval()).found  # a label handed over, no birth
    assert [c.kind for c in handed] == ["misleading"]


def test_another_runs_false_track_near_an_object_the_evaluation_had_no_box_of_is_a_failure_of_its_own() -> None:
    from tools.truth.scene import Annotation, SceneTruth

    ev, other = _eval(), _eval()
    other.pred_xy[(C, 3)] = {"5": (0.3, 0.0), "7": (9.0, 0.0)}  # its track 5: a false positive 0.3 m from GT A
    scene = SceneTruth([[]] * 4, [{GT_A: Annotation(C, (0.0, 0.0), 0)}] * 4)
    at = Context(C, 3, GT_A, kind="false_track", track=11)  # a false track beside GT A, whose box was dropped
    planted = "pmbm on the same detections did not have this failure"
    found = check_text(planted, at, None, ev, scene=scene, others={"pmbm": other}).found
    assert [c.kind for c in found] == ["other run"]  # what the explainer said before it compared false tracks by place
    fair = "pmbm on the same detections failed here too"
    assert check_text(fair, at, None, ev, scene=scene, others={"pmbm": other}).found == []
    other.pred_xy[(C, 3)] = {"7": (9.0, 0.0)}  # no false positive near GT A: now the other sentence is the lie
    assert [c.kind for c in check_text(fair, at, None, ev, scene=scene, others={"pmbm": other}).found] == ["other run"]
    assert check_text(planted, at, None, ev, scene=scene, others={"pmbm": other}).found == []


def test_another_runs_false_track_and_an_empty_place_are_checked_where_the_false_box_lies() -> None:
    ev, other = _eval(), _eval()
    ev.boxes[3] = [("11", C, (0.0, 0.0)), ("12", C, (10.0, 0.0))]
    other.pred_xy[(C, 3)] = {"5": (0.5, 0.0), "7": (0.0, 0.0)}  # its track 5 is a false positive beside the box
    at = Context(C, 3, None, kind="false_track", track=11)
    fair = "pmbm on the same detections had a false car track here too"
    assert check_text(fair, at, None, ev, others={"pmbm": other}).found == []
    planted = "pmbm on the same detections had no false car track here"
    assert [c.kind for c in check_text(planted, at, None, ev, others={"pmbm": other}).found] == ["other run"]
    walker = _eval()  # its only false positive there a pedestrian: another failure than a false car
    walker.track_to_gt[("pedestrian", 3)] = {"9": None}
    walker.pred_xy[("pedestrian", 3)] = {"9": (0.2, 0.0)}
    assert check_text(planted, at, None, ev, others={"pmbm": walker}).found == []
    assert [c.kind for c in check_text(fair, at, None, ev, others={"pmbm": walker}).found] == ["other run"]
    empty = "no object of a tracked class lies within 2 m of it"
    assert [c.kind for c in check_text(empty, at, None, ev, scene=_scene()).found] == ["detector"]  # GT A is there
    away = Context(C, 3, None, kind="false_track", track=12)
    assert check_text(empty, away, None, ev, scene=_scene()).found == []


# The kinds the retired tools/oracle.py checked: the lost track's story, places, costs, hypotheses, #1141.
def _frames(by_frame: dict[int, list]) -> RawEvents:
    events: list = []
    for x in sorted(by_frame):
        events += [FrameStarted("t", x, f"token{x}", x * 500_000, 0.5), *by_frame[x]]
    return RawEvents.of(events)


def _posterior(track: int, existence: float):
    from gnnpmb.events import Posterior

    return Posterior(C, np.array([track]), np.zeros((1, 4)), np.eye(4)[None], np.array([existence]))


def test_each_planted_statement_about_the_lost_track_is_caught() -> None:
    from gnnpmb.events import Marginals, Pruned, PruneReason, TrackLogic, TrackLogicAction

    marg = Marginals(
        C,
        np.array([[0.7, 0.2, 0.1]]),
        axis_labels(AxisKind.TRACK, [7]),
        axis_labels(AxisKind.MEASUREMENT, [0, 1]) + axis_labels(AxisKind.MISSED, [7]),
        "exact",
    )
    raw = _frames(
        {
            1: [_posterior(7, 0.9)],
            2: [_posterior(7, 0.95)],
            3: [
                _posterior(7, 0.4),
                marg,
                TrackLogic(C, 7, TrackLogicAction.DELETED, 1, 3),
                Pruned(C, 7, PruneReason.LOW_EXISTENCE, 0.4),
            ],
        }
    )
    ev = _eval()
    ev.submitted = {2: {"7"}, 3: {"5"}}
    ctx = Context(C, 3, GT_A, lost=7)
    pairs = [
        (
            "its existence went from 0.95 (frame 2) to 0.40 (frame 3)",
            "its existence went from 0.90 (frame 1) to 0.40 (frame 3)",
        ),  # frame 2 was higher: not the peak
        ("its existence was 0.40 (frame 3)", "its existence was 0.90 (frame 3)"),
        ("it was not output at frame 3", "it was not output at frames 2, 3"),
        ("its track logic deleted it at frame 3 (1 of 3 hits)", "its track logic deleted it at frame 3 (2 of 3 hits)"),
        (
            "it was pruned at frame 3 (existence below pruning threshold)",
            "it was pruned at frame 3 (over the component cap)",
        ),
        ("at frame 3 it used m0 (p 0.70), m1 (p 0.20)", "at frame 3 it used m1 (p 0.70), m0 (p 0.20)"),
    ]
    for true, false in pairs:
        assert check_text(true, ctx, raw, ev).found == [], true
        assert [c.kind for c in check_text(false, ctx, raw, ev).found] == ["tracker"], false


def test_a_planted_cost_in_a_breakdown_or_a_choice_is_caught() -> None:
    existence = np.array([0.1, 0.5, 0.9])
    text = _because(existence, FREE)
    assert "Track 5's " in text and _found(text, existence=existence, d2=FREE).found == [], text
    total = text.split("Track 5's ", 1)[1].split(" ", 1)[0]
    planted = text.replace(f"Track 5's {total}", f"Track 5's {float(total) + 1:.2f}")
    assert "cost" in [c.kind for c in _found(planted, existence=existence, d2=FREE).found], planted
    d2 = text.split("(d² ", 1)[1].split(")", 1)[0]
    planted = text.replace(f"(d² {d2})", f"(d² {float(d2) + 1:.1f})", 1)
    assert "cost" in [c.kind for c in _found(planted, existence=existence, d2=FREE).found], planted
    _, m, a = _world(None, FREE)
    choice = next(ch for c in explain(m, a).conflicts for ch in c.choices if ch.meas.ref == 0)
    true = "then, " + choice_text(3, choice, int(choice.chosen.ref), False).replace("**", "")
    assert not [c for c in _found(true, d2=FREE).found if c.kind == "cost"], true
    cost = true.split("(cost ", 1)[1].split(")", 1)[0]
    planted = true.replace(f"(cost {cost})", f"(cost {float(cost) - 1:.2f})")
    assert "cost" in [c.kind for c in _found(planted, d2=FREE).found], planted


def test_a_planted_hypothesis_switch_or_holding_frame_is_caught() -> None:
    from gnnpmb.events import GlobalHypotheses

    def hyp(weights: list[float], members):
        return GlobalHypotheses(
            C,
            np.log(weights),
            members,
            tuple((0,) * len(m) for m in members),
            tuple((0.9,) * len(m) for m in members),
            (0,) * len(weights),
        )

    raw = _frames(
        {
            1: [hyp([1.0], ((5,),))],
            2: [hyp([0.6, 0.4], ((5,), (5, 7)))],
            3: [Assignment(C, (), 0.0, (), hypothesis=1), hyp([1.0], ((5, 7),))],
        }
    )
    ctx = Context(C, 3, GT_A, lost=5)
    head = "at frame 3 the best hypothesis switched: it descends from prior hypothesis 1 (probability {} after frame "
    head += "2, against 0.60 for the best), not from a cost choice within the best (track 7: held by a kept "
    head += "hypothesis since frame {})"
    assert check_text(head.format("0.40", 2), ctx, raw, _eval()).found == []
    for p, since in (("0.30", 2), ("0.40", 3)):
        found = check_text(head.format(p, since), ctx, raw, _eval()).found
        assert [c.kind for c in found] == ["hypothesis"], (p, since)


def test_a_planted_place_of_a_false_box_is_caught() -> None:
    ev = _eval()
    ev.boxes[3] = [("11", C, (0.5, 0.0)), ("12", "truck", (0.5, 0.0))]
    car, truck = (
        Context(C, 3, None, kind="false_track", track=11),
        Context("truck", 3, None, kind="false_track", track=12),
    )
    assert check_text("car GT aaaaaa lies 0.5 m away", car, None, ev, scene=_scene()).found == []
    for false in ("car GT aaaaaa lies 1.5 m away", "car GT bbbbbb lies 29.5 m away"):  # the nearest is GT A
        assert [c.kind for c in check_text(false, car, None, ev, scene=_scene()).found] == ["detector"], false
    fair = "no truck GT lies within 2 m, but GT car aaaaaa does (0.5 m): the detector gave it the wrong class"
    assert check_text(fair, truck, None, ev, scene=_scene()).found == []
    planted = "no car GT lies within 2 m, but GT car aaaaaa does (0.5 m): the detector gave it the wrong class"
    assert [c.kind for c in check_text(planted, car, None, ev, scene=_scene()).found] == ["detector"]


def _swapped_interpolation() -> tuple[SceneTruth, EvalFacts]:
    """GT A at x 0, 4, 10 m (frames 1-3) with no points at frame 2, where the devkit's interpolated box (weights
    swapped, nuscenes-devkit issue #1141) is at x 5.45 and the box weighted the right way at x 4.55: the scene and
    the evaluation's facts."""
    from tools.truth.scene import Annotation

    scene = SceneTruth([[]] * 4, [{GT_A: Annotation(C, (x, 0.0), 9)} for x in (0.0, 0.0, 4.0, 10.0)])
    ev = _eval()
    ev.kept_gt = {(0, GT_A), (1, GT_A), (3, GT_A)}
    ev.stamps = {0: 0, 1: 500_000, 2: 1_000_000, 3: 1_600_000}
    ev.evaluated_gt[(2, GT_A)] = (10.0 * 6 / 11, 0.0)
    return scene, ev


def test_a_planted_issue_1141_note_is_caught() -> None:
    """GT A annotated at x = 0, 4, 10 m at frames 1-3 (0.5, 1.0, 1.6 s); the devkit kept frames 1 and 3 and
    interpolated frame 2 with the ends swapped (x 5.45): weighted the right way, x 4.55, 0.5 m from the
    annotation."""
    scene, ev = _swapped_interpolation()
    ctx = Context(C, 2, GT_A)
    note = "from frames {} and 3, weighting the two ends the wrong way round (nuscenes-devkit issue #1141): weighted "
    note += "the right way the box would lie {} m from the annotation"
    assert check_text(note.format(1, "0.5"), ctx, None, ev, scene=scene).found == []
    for left, d in ((0, "0.5"), (1, "1.5")):
        found = check_text(note.format(left, d), ctx, None, ev, scene=scene).found
        assert [c.kind for c in found] == ["evaluation"], (left, d)


def test_a_placeholder_or_an_unknown_cause_is_caught() -> None:
    assert [c.kind for c in _found("at frame 3 m? → track 7").found] == ["misleading"]
    assert [c.kind for c in _found("Why (gnn, cause unknown): track 7 was not output").found] == ["misleading"]


def test_a_planted_placement_of_a_results_files_box_is_caught() -> None:
    """A results file (no events): track 11's box repeats m0's size, rotation and height at frame 3; track 12's
    lies 0.2 m from m0 with another size."""
    from tools.truth.scene import Annotation, Detection, SceneTruth

    box = (1.8, 4.5, 1.6, 1.0, 0.0, 0.0, 0.0, 0.9)
    scene = SceneTruth([[Detection(C, 0.9, (0.3, 0.0), box)]] * 4, [{GT_A: Annotation(C, (0.0, 0.0), 9)}] * 4)
    ev = _eval()
    ev.boxes[3] = [("11", C, (0.3, 0.0)), ("12", C, (0.5, 0.0))]
    ev.geometry = {(3, "11"): box, (3, "12"): (2.0, 4.5, 1.6, 1.0, 0.0, 0.0, 0.0, 0.9)}
    ev.submitted = {2: {"12"}, 3: {"11", "12"}}
    ctx = Context(C, 3, GT_A)
    on = "at frame 3 track 11 (car) was output on detection m0 (car, score 0.90; its box carries m0's size, heading "
    on += "and height)"
    near = "at frame 3 track 12 (car) was output on detection m0 (car, score 0.90; m0 is the nearest car detection, "
    near += "0.20 m from its box (none carries its size, heading and height))"
    for true, false in (
        (on, on.replace("track 11", "track 12")),
        (near, near.replace("0.20 m", "0.30 m")),
        (
            "at frame 3 m0 (score 0.90, 0.3 m from it) lay under track 11's box",
            "at frame 3 m0 (score 0.90, 0.3 m from it) lay under no output box",
        ),
        ("track 11 was first output at frame 3", "track 12 was first output at frame 3"),
    ):
        assert check_text(true, ctx, None, ev, scene=scene).found == [], true
        assert [c.kind for c in check_text(false, ctx, None, ev, scene=scene).found] == ["output"], false


def test_a_planted_gate_distance_or_averaged_score_is_caught() -> None:
    from gnnpmb.events import Gated

    d2 = np.array([[3.14, 50.0]])
    gated = Gated(C, np.array([7]), np.array([0, 1]), d2 < 16.0, np.zeros((1, 2)), np.eye(2)[None], 16.0, d2)
    raw = _raw_with(gated)
    ctx = Context(C, 3, GT_A, lost=7)
    gate = "at frame 3 m{} (score 0.90, 0.3 m from it, in track 7's gate at NIS {}) → track 5"
    assert check_text(gate.format(0, "3.1"), ctx, raw, _eval()).found == []
    for meas, nis in ((0, "4.1"), (1, "50.0")):  # another d²; a detection outside the gate
        assert [c.kind for c in check_text(gate.format(meas, nis), ctx, raw, _eval()).found] == ["tracker"]
    ev = _eval()
    ev.averaged, ev.submitted = {"5": (2, 0.4)}, {1: {"5"}, 2: {"5"}, 3: {"5"}}
    said = "track 5 was output on it, but its score averaged over {}, {}, is below the car threshold 0.500"
    kept = "the 2 of its 3 frames the evaluation kept (within the class range)"
    assert check_text(said.format(kept, "0.400"), CTX, None, ev).found == []
    for over, score in ((kept, "0.410"), ("its 3 frames", "0.400")):
        assert [c.kind for c in check_text(said.format(over, score), CTX, None, ev).found] == ["matched"]


def test_an_existence_said_held_over_frames_it_dipped_in_is_caught() -> None:
    """pmbm on dev-set scene-0916 megvii said 'its existence was 1.00 (frames 10–18)' of a track at 0.15 at frame 15;
    a deletion by maximum age and a merge recorded as ``Pruned`` events hold."""
    from gnnpmb.events import Pruned, PruneReason

    raw = _frames({1: [_posterior(7, 1.0)], 2: [_posterior(7, 0.15)], 3: [_posterior(7, 1.0)]})
    ctx = Context(C, 3, GT_A, lost=7)
    assert check_text("its existence was 1.00 (frame 3)", ctx, raw, _eval()).found == []
    assert [c.kind for c in check_text("its existence was 1.00 (frames 1–3)", ctx, raw, _eval()).found] == ["tracker"]
    ended = _raw_with(Pruned(C, 7, PruneReason.TRACK_LOGIC, 1.0), Pruned(C, 8, PruneReason.MERGED, 0.2))
    assert check_text("its track logic deleted it at frame 3", ctx, ended, _eval()).found == []
    merged = Context(C, 3, GT_A, lost=8)
    assert check_text("it was merged into another component at frame 3", merged, ended, _eval()).found == []
    assert check_text("it was merged into another component at frame 3", ctx, ended, _eval()).found != []


def test_a_planted_interpolation_or_unshown_existence_is_caught() -> None:
    ev = _eval()
    ev.kept_gt = {(1, GT_A), (4, GT_A)}
    ev.submitted = {1: {"11"}, 2: set(), 3: {"11"}}
    ev.pred_xy[(C, 2)] = {"11": (0.0, 0.0)}
    ev.track_to_gt[(C, 2)] = {"11": None}
    at2 = Context(C, 2, GT_A)
    assert check_text("the evaluation scored it at a box; from frames 1 and 4.", at2, None, ev).found == []
    assert [c.kind for c in check_text("a box; from frames 0 and 4.", at2, None, ev).found] == ["evaluation"]
    said = "at frame 2 track 11 (car) was not output: the evaluation interpolated it between its boxes at frames {} "
    said += "and 3, and that box matched no object"
    assert check_text(said.format(1), at2, None, ev).found == []
    assert [c.kind for c in check_text(said.format(0), at2, None, ev).found] == ["evaluation"]
    raw = _frames({1: [_posterior(11, 0.3)], 3: [_posterior(11, 0.6)]})
    stayed = "track 11's existence stayed below 0.5 (the views draw tracks from 0.5 up), yet the evaluation counted it"
    found = check_text(stayed, Context(C, 3, GT_A, lost=11), raw, ev).found
    assert [c.kind for c in found] == ["tracker"]  # 0.6 at frame 3, where it was output


def test_a_coalesced_object_said_to_have_no_detection_of_its_own_is_checked() -> None:
    said = "the detector gave GT {} no detection of its own within 2 m ({} LiDAR and radar points)"
    at2 = Context(C, 2, GT_A)
    assert check_text(said.format("bbbbbb", 0), at2, None, _eval(), scene=_scene()).found == []
    for gt, points in (("aaaaaa", 12), ("bbbbbb", 5)):  # m0 lies 0.3 m from GT A; GT B has no points
        assert [c.kind for c in check_text(said.format(gt, points), at2, None, _eval(), scene=_scene()).found] == [
            "detector"
        ]
    # A detection within 2 m that lies nearer the neighbour is the neighbour's, not the object's own (dev set
    # scene-0916 megvii gnn coalescence:2: 1.96 m from GT 55f69d, 0.13 m from GT c1ad9f)
    from tools.truth.scene import Annotation

    pair = _scene()
    pair.objects[2]["cccccc" + GT_A[6:]] = Annotation(C, (1.9, 0.0), 7)  # m0: 0.3 m from A, 1.6 m from C
    assert check_text(said.format("cccccc", 7), at2, None, _eval(), scene=pair).found == []
    pair.objects[2][GT_A] = Annotation(C, (-5.0, 0.0), 12)  # now m0 is C's own (1.6 m against 5.3 m)
    assert [c.kind for c in check_text(said.format("cccccc", 7), at2, None, _eval(), scene=pair).found] == ["detector"]


def test_a_last_output_on_the_object_the_devkit_did_not_match_there_is_caught() -> None:
    # independent audit, dev set (ab3dmot scene-0655 centerpoint id_switch:13; prob3dmot scene-0553 megvii
    # id_switch:9, identity_theft:1): "last output on it at frame F" where the devkit's last match was at F-1
    # (no box of the object at F, or track 7 matched to another object there)
    ev = _eval()
    ev.gt_to_track[(C, 1)] = {GT_A: "7"}
    ev.gt_to_track[(C, 2)] = {GT_B: "7"}  # track 7 output by GT A at frame 2, but matched to GT B there
    ev.submitted.update({1: {"7"}, 2: {"7"}})
    ctx = Context(C, 3, GT_A, kind="id_switch", lost=7)
    for said in ("track 7 was last output on it at frame 1", "the evaluation last matched track 7 to it at frame 1"):
        assert check_text(said, ctx, None, ev).found == [], said
    for said in (
        "track 7 was last output on it at frame 2",
        "the evaluation last matched track 7 to it at frame 2",
        "the evaluation last matched track 5 to it at frame 1",
    ):
        assert [c.kind for c in check_text(said, ctx, None, ev).found] == ["matched"], said


def test_a_last_match_at_a_box_the_devkit_interpolated_left_unsaid_is_misleading() -> None:
    # independent audit truth46, dev set scene-0757 pointpillars greedy fragmentation:5: "the evaluation last
    # matched track 16 to it at frame 12" where the submission has no box of track 16 at 12 (an interpolation)
    ev = _eval()
    ev.gt_to_track[(C, 1)] = {GT_A: "7"}
    ev.submitted.update({0: {"7"}, 2: {"7"}})  # no box of track 7 at frame 1: the devkit matched its interpolation
    ctx = Context(C, 3, GT_A, kind="fragmentation", lost=7)
    said = "the evaluation last matched track 7 to it at frame 1"
    assert [c.kind for c in check_text(said, ctx, None, ev).found] == ["misleading"]
    assert check_text(said + " (a box it interpolated for the track)", ctx, None, ev).found == []
    ev.submitted[1] = {"7"}
    assert check_text(said, ctx, None, ev).found == []


def test_no_track_carrying_an_object_a_track_was_on_and_a_reach_the_devkit_did_not_take_are_caught() -> None:
    # dev set scene-0757 megvii prob3dmot miss:133 (track 200 1.8 m from the annotation, 2.1 m from the devkit's box)
    from tools.truth.scene import Annotation, SceneTruth

    scene = SceneTruth([[]] * 4, [{}, {}, {}, {GT_A: Annotation(C, (0.0, 0.0), 0)}])
    ev = _eval()
    ev.boxes[3] = [("200", C, (0.0, -1.8))]
    ev.submitted[3] = {"200"}
    ev.evaluated_gt[(3, GT_A)] = (0.0, 0.3)  # interpolated (not kept): 2.1 m from track 200's box
    ctx = Context(C, 3, GT_A, kind="miss")
    said = "no detection within 2 m, and no track carried it through"
    assert [c.kind for c in check_text(said, ctx, None, ev, scene=scene).found] == ["output"]
    reach = (
        "at frame 3 track 200 was output 1.8 m from the annotated object, but the evaluation scored the object at a "
        "box it interpolated 0.3 m from the annotation, out of the track's reach"
    )
    assert check_text(reach, ctx, None, ev, scene=scene).found == []
    ev.evaluated_gt[(3, GT_A)] = (0.0, -0.3)  # 1.5 m from the track's box: within the devkit's reach
    assert [c.kind for c in check_text(reach, ctx, None, ev, scene=scene).found] == ["evaluation"]


def test_a_track_out_of_reach_that_the_devkit_matched_to_the_object_beside_it_is_misleading() -> None:
    # independent audit truth46, dev set scene-0655 centerpoint immortal miss:18: track 8 1.2 m from the annotation,
    # 3.0 m from the devkit's interpolated box, and 0.1 m from the pedestrian beside it, which the devkit matched it to
    from tools.truth.scene import Annotation, SceneTruth

    scene = SceneTruth([[]] * 4, [{}, {}, {}, {GT_A: Annotation(C, (0.0, 0.0), 0)}])
    ev = _eval()
    ev.boxes[3] = [("8", C, (1.2, 0.0))]
    ev.submitted[3] = {"8"}
    ev.evaluated_gt[(3, GT_A)] = (0.0, 3.0)
    ev.evaluated_gt[(3, GT_B)] = (1.2, 0.1)
    ev.track_to_gt[(C, 3)] = {"8": GT_B}
    ctx = Context(C, 3, GT_A, kind="miss")
    reach = (
        "at frame 3 track 8 was output 1.2 m from the annotated object, but the evaluation scored the object at a "
        "box it interpolated 3.0 m from the annotation, out of the track's reach"
    )
    assert [c.kind for c in check_text(reach, ctx, None, ev, scene=scene).found] == ["misleading"]
    ev.evaluated_gt[(3, GT_B)] = (3.0, 0.0)  # the object it was matched to lies farther than this one: the reach held
    assert check_text(reach, ctx, None, ev, scene=scene).found == []


def _matched_away_world():
    """Track 7 matched to GT A at frame 1, to GT B at frames 2 and 3 (GT A missed at 2), track 11 to GT A at 3; the
    files: GT A at the origin at frame 3, track 7's box 0.5 m from it, track 11's 0.7 m."""
    from tools.truth.scene import Annotation, SceneTruth

    ev = EvalFacts(thresholds={C: 0.5})
    ev.gt_to_track.update({(C, 1): {GT_A: "7"}, (C, 2): {GT_A: None, GT_B: "7"}, (C, 3): {GT_A: "11", GT_B: "7"}})
    ev.track_to_gt.update({(C, 1): {"7": GT_A}, (C, 2): {"7": GT_B}, (C, 3): {"7": GT_B, "11": GT_A}})
    ev.submitted.update({1: {"7"}, 2: {"7"}, 3: {"7", "11"}})
    ev.boxes[3] = [("7", C, (0.5, 0.0)), ("11", C, (0.0, 0.7))]
    scene = SceneTruth([[]] * 4, [{}, {}, {}, {GT_A: Annotation(C, (0.0, 0.0), 0)}])
    return ev, scene, Context(C, 3, GT_A, kind="id_switch", lost=7, taker=11)


def test_the_lost_tracks_matches_to_another_object_left_out_or_misstated_are_caught() -> None:
    # independent audit r38, dev set scene-0655 pointpillars pmbm id_switch:3: "the evaluation last matched track
    # 160 to it at frame 20" where the devkit matched track 160 to another pedestrian from frame 22 to the failure
    ev, scene, ctx = _matched_away_world()
    true = "the evaluation last matched track 7 to it at frame 1, then matched track 7 to car GT bbbbbb at frames 2, 3"
    assert check_text(true, ctx, None, ev, scene=scene).found == []
    planted = {
        "the evaluation last matched track 7 to it at frame 1, its existence was 1.00": "misleading",  # left out
        "the evaluation last matched track 7 to it at frame 1, then matched track 7 to car GT bbbbbb at frame 2": (
            "matched"
        ),
        "the evaluation last matched track 7 to it at frame 1, then matched track 7 to car GT cccccc at frames 2, 3": (
            "matched"
        ),
        # and "last output on it" of a track whose box lay 0.5 m from the annotation at frame 3
        "track 7 was last output on it at frame 1, then the evaluation matched track 7 to car GT bbbbbb at frames 2, 3 "
        "and to car GT cccccc at frame 3": ("output", "matched"),
    }
    for said, kind in planted.items():
        kinds = list(kind) if isinstance(kind, tuple) else [kind]
        assert [c.kind for c in check_text(said, ctx, None, ev, scene=scene).found] == kinds, said
    ev.track_to_gt[(C, 2)] = {"7": None}  # matched to nothing at 2: no other object to name there
    ev.track_to_gt[(C, 3)] = {"7": None, "11": GT_A}
    assert [c.kind for c in check_text(true, ctx, None, ev, scene=scene).found] == ["matched"]
    assert check_text("the evaluation last matched track 7 to it at frame 1,", ctx, None, ev, scene=scene).found == []


def test_two_tracks_on_one_object_said_of_a_track_matched_to_another_object_is_caught() -> None:
    # the same audit finding: "track 160 was still output on the object, but so was track 718: two tracks on one
    # object, and the evaluation matched the other" where the devkit matched track 160 to GT 2e96cc at that frame
    ev, scene, ctx = _matched_away_world()
    two = (
        "at frame 3 track 7 was still output on the object, but so was track {}: two tracks on one object, and the "
        "evaluation matched the other"
    )
    assert [c.kind for c in check_text(two.format(11), ctx, None, ev, scene=scene).found] == ["misleading"]
    both = (
        "at frame 3 track 7 was still output {} m from it, but the evaluation matched track 7 to car GT {} and track "
        "{} to GT aaaaaa"
    )
    assert check_text(both.format("0.5", "bbbbbb", 11), ctx, None, ev, scene=scene).found == []
    for said, kind in (
        (both.format("0.5", "cccccc", 11), "matched"),
        (both.format("0.5", "bbbbbb", 12), "matched"),
        (both.format("1.5", "bbbbbb", 11), "output"),
    ):
        assert [c.kind for c in check_text(said, ctx, None, ev, scene=scene).found] == [kind], said
    ev.track_to_gt[(C, 3)] = {"7": None, "11": GT_A}  # track 7 matched to nothing at 3: a spare second track
    ev.gt_to_track[(C, 3)] = {GT_A: "11", GT_B: None}
    assert check_text(two.format(11), ctx, None, ev, scene=scene).found == []
    assert [c.kind for c in check_text(two.format(12), ctx, None, ev, scene=scene).found] == ["matched"]
    assert [c.kind for c in check_text(both.format("0.5", "bbbbbb", 11), ctx, None, ev, scene=scene).found] == [
        "matched"
    ]


def test_another_runs_track_on_the_object_said_to_keep_it_where_its_evaluation_matched_it_elsewhere_is_caught() -> None:
    ev, scene, _ = _matched_away_world()  # the other run: GT A missed at frame 2, track 7 (on it) matched to GT B
    ev.boxes[2] = [("7", C, (0.0, 0.5))]
    ev.counted[C] = {"7", "11"}
    scene.objects[2][GT_A] = scene.objects[3][GT_A]
    ctx = Context(C, 2, GT_A, kind="id_switch")
    kept = "pmbm on the same detections did not fail here: its track 7 was output on the object and counted"
    assert [c.kind for c in check_text(kept, ctx, None, _eval(), scene=scene, others={"pmbm": ev}).found] == [
        "misleading"
    ]
    told = (
        "pmbm on the same detections did not match the object here: its track 7 was output on the object and "
        "counted, but the evaluation matched track 7 to car GT {}"
    )
    assert check_text(told.format("bbbbbb"), ctx, None, _eval(), scene=scene, others={"pmbm": ev}).found == []
    planted = told.format("cccccc")
    assert [c.kind for c in check_text(planted, ctx, None, _eval(), scene=scene, others={"pmbm": ev}).found] == [
        "other run"
    ]
    to_it = "pmbm on the same detections did not fail here: the evaluation matched the object to its track 7"
    assert [c.kind for c in check_text(to_it, ctx, None, _eval(), scene=scene, others={"pmbm": ev}).found] == [
        "other run"
    ]
    ctx3 = Context(C, 3, GT_A, kind="id_switch")
    to_11 = to_it.replace("track 7", "track 11")
    assert check_text(to_11, ctx3, None, _eval(), scene=scene, others={"pmbm": ev}).found == []


def test_another_runs_track_on_the_object_beside_it_said_to_be_on_this_one_is_caught() -> None:
    # world4 scene-1100 megvii cphd id_switch:12: jpda's track, 1.1 m from one of two parked cars 1.7 m apart and
    # 0.6 m from the other (matched there), was said "output on the object": it was the neighbour's
    from tools.truth.scene import Annotation

    ev, scene, _ = _matched_away_world()  # at frame 2 GT A is missed and track 7 matched to GT B
    ev.boxes[2] = [("7", C, (1.1, 0.0))]
    ev.counted[C] = {"7"}
    scene.objects[2].update({GT_A: Annotation(C, (0.0, 0.0), 0), GT_B: Annotation(C, (1.7, 0.0), 0)})
    ctx = Context(C, 2, GT_A, kind="id_switch")

    def found(text: str) -> list[str]:
        return [c.kind for c in check_text(text, ctx, None, _eval(), scene=scene, others={"pmbm": ev}).found]

    on_it = (
        "pmbm on the same detections did not match the object here: its track 7 was output on the object and "
        "counted, but the evaluation matched track 7 to car GT bbbbbb"
    )
    assert found(on_it) == ["misleading"]
    beside = (
        "pmbm on the same detections did not match the object here: its track 7 was output on the car beside it and "
        "counted: the evaluation matched track 7 to car GT bbbbbb, {} m from the track (1.1 m from this one)"
    )
    assert found(beside.format("0.6")) == []
    assert found(beside.format("0.2")) == ["other run"]
    ev.boxes[2] = [("7", C, (0.5, 0.0))]  # nearer this car: "on the object" holds, "beside it" does not
    assert found(on_it) == []
    assert found(beside.format("1.2").replace("1.1 m from this", "0.5 m from this")) == ["other run"]


def test_a_because_sentence_no_pattern_reads_is_left_out_of_coverage() -> None:
    """The pattern that cuts a Because paragraph out matches all of it; neither it nor a module's import of it may
    count its sentences as read (every clause of a Because paragraph was counted read that way)."""
    from tools.truth.sentences import coverage

    clauses, unchecked = coverage("  Because (frame 3): the moon was full. Track 5 sang a song.")
    assert clauses == 2 and sum(unchecked.values()) == 2, unchecked


def test_no_detection_said_with_no_class_beside_a_box_of_an_untracked_class_is_caught() -> None:
    """Dev set scene-0553 centerpoint gnnpmb miss:2: a barrier box (0.53) lay within 2 m of the pedestrian, which
    the explainer, given only the tracked classes' boxes, said had "no detection within 2 m"."""
    from tools.truth.scene import Detection

    scene = _scene()
    scene.untracked = [[], [], [Detection("barrier", 0.53, (30.5, 0.0))], []]
    ctx = Context(C, 2, GT_B, kind="miss")
    said = (
        "at frame 2 the detector gave no detection{} within 2 m of car GT bbbbbb (0 LiDAR and radar points in its box)",
        "at frame 2 car GT bbbbbb had no LiDAR or radar points (no detector could see it) and no detection{} "
        "within 2 m",
        "at frame 2 the detector gave no detection of {} class within 2 m, though it had 0 LiDAR and radar points",
    )
    for sentence in said:
        untracked, tracked = ("any", "a tracked") if "of {}" in sentence else ("", " of a tracked class")
        false, true = sentence.format(untracked), sentence.format(tracked)
        read = check_text(true, ctx, None, _eval(), scene=scene)
        assert read.found == [] and read.checked["detector"] == 1 and not read.unchecked, true
        assert [c.kind for c in check_text(false, ctx, None, _eval(), scene=scene).found] == ["detector"], false


def test_one_track_for_two_objects_said_of_a_track_out_of_reach_of_the_scored_box_is_caught() -> None:
    """Dev set scene-0061 megvii gnnpmb miss at frame 9: track 72, matched to another object, lay 0.3 m from the
    annotation but 2.9 m from the box the devkit interpolated for the object: it could not have had the object."""
    said = "track 7 lay within 2 m of it and was counted, but the evaluation matched it to another object"
    ev = _eval()
    ev.pred_xy[(C, 3)] = {"7": (0.0, 0.0)}
    ev.evaluated_gt[(3, GT_B)] = (1.0, 0.0)
    assert check_text(said, CTX, None, ev).found == []
    ev.evaluated_gt[(3, GT_B)] = (2.9, 0.0)
    assert [c.kind for c in check_text(said, CTX, None, ev).found] == ["misleading"]
    ev.evaluated_gt[(3, GT_B)] = (1.0, 0.0)
    both = "tracks 7, 11 lay within 2 m of it and were counted, but the evaluation matched each to another object"
    ev.pred_xy[(C, 3)]["11"] = (0.5, 0.0)
    caught = check_text(both, CTX, None, ev).found  # track 11 was matched to no object: each named track is read
    assert [(c.kind, c.truth) for c in caught] == [("matched", "the devkit matched track 11 at frame 3 to None")]
    ev.track_to_gt[(C, 3)]["11"] = GT_A
    found = check_text(both, CTX, None, ev)
    assert found.found == [] and found.checked["matched"] == 2


def test_one_track_for_two_objects_holds_of_a_track_the_devkit_matched_to_the_object_beside_it() -> None:
    # independent audit truth46, dev set scene-0655 centerpoint immortal miss:18: track 8 1.2 m from GT B's
    # annotation, 4.2 m from the box the devkit interpolated for it, and 0.1 m from GT A, which the devkit matched
    # it to: the neighbour's track (with B's box where it belongs the devkit still matches it to A)
    from tools.truth.scene import Annotation, SceneTruth

    said = "track 7 lay within 2 m of it and was counted, but the evaluation matched it to another object"
    ev = _eval()
    ev.pred_xy[(C, 3)] = {"7": (1.2, 0.0)}
    ev.evaluated_gt[(3, GT_B)] = (0.0, 4.0)
    ev.evaluated_gt[(3, GT_A)] = (1.3, 0.0)
    scene = SceneTruth([[]] * 4, [{}, {}, {}, {GT_B: Annotation(C, (0.0, 0.0), 0)}])
    assert check_text(said, CTX, None, ev, scene=scene).found == []
    ev.evaluated_gt[(3, GT_A)] = (2.5, 1.0)  # GT A scored farther from the track than B's annotation: misleading
    assert [c.kind for c in check_text(said, CTX, None, ev, scene=scene).found] == ["misleading"]


def test_another_run_whose_coalescence_matched_the_object_is_not_said_to_fail_on_it() -> None:
    """Dev set scene-1077 pointpillars: gnn's coalescence missed pedestrian a2d371; jpda's coalescence there matched
    a2d371 (its track also covered a neighbour, which it missed): "jpda ... failed here too" was false."""
    ev, other = _eval(), EvalFacts(thresholds={C: 0.5})
    other.evaluated_gt.update({(3, GT_A): (0.0, 0.0), (3, GT_B): (1.0, 0.0)})
    other.pred_xy[(C, 3)] = {"7": (0.9, 0.0)}
    other.gt_to_track[(C, 3)] = {GT_B: "7", GT_A: None}  # its track 7 on GT B (the finding's object), GT A missed
    ctx = Context(C, 3, GT_B, covered=(GT_A,), kind="coalescence")
    said = "pmbm on the same detections failed here too"
    assert [c.kind for c in check_text(said, ctx, None, ev, others={"pmbm": other}).found] == ["other run"]
    other.gt_to_track[(C, 3)] = {GT_A: "7", GT_B: None}  # now it matched GT A and missed the finding's object
    assert check_text(said, ctx, None, ev, others={"pmbm": other}).found == []


def test_a_track_the_objects_detection_started_left_unsaid_off_the_object_is_caught() -> None:
    # independent audit r42, dev set scene-0553 megvii ab3dmot coalescence at frame 12: "its detection m4 (score
    # 0.74, 0.1 m away) started new track 148", a tentative track never output, read as covering the object
    from tools.truth.scene import Annotation, SceneTruth

    scene = SceneTruth([[]] * 4, [{}, {}, {}, {GT_A: Annotation(C, (0.0, 0.0), 0)}])
    ev = _eval()
    ev.boxes[3] = [("150", C, (0.0, 0.5))]
    ctx = Context(C, 3, GT_A, kind="coalescence")

    def misleading(text: str) -> list[str]:  # the scene has no detections: the detector's checks object apart
        return [c.truth for c in check_text(text, ctx, None, ev, scene=scene).found if c.kind == "misleading"]

    for said in (
        "its detection m4 (score 0.74, 0.1 m away) started new track 148",
        "at frame 3 detection m4 (score 0.74) lay 0.1 m from car GT aaaaaa and went to track 148",
    ):
        assert misleading(said) == ["track 148 has no box within 2 m of the object at frame 3, unsaid"], said
        assert misleading(f"{said}; track 148 was not output on it") == []
    on_it = "its detection m4 (score 0.74, 0.1 m away) went to track 150"
    assert misleading(on_it) == []


def test_a_results_files_detection_said_under_no_box_beside_one_on_another_detection_is_caught() -> None:
    # independent audit r42, dev set scene-1094 pointpillars (cbmot's output as a results file): "detection m14
    # (score 0.29) lay 0.7 m from pedestrian GT 9a6fb4 and lay under no output box", 0.02 m from track 358's box
    from tools.truth.scene import Annotation, Detection, SceneTruth

    box = (1.8, 4.5, 1.6, 1.0, 0.0, 0.0, 0.0, 0.9)
    other = (1.7, 4.2, 1.5, 1.0, 0.0, 0.0, 0.0, 0.5)
    dets = [Detection(C, 0.9, (0.3, 0.0), box), Detection(C, 0.5, (0.32, 0.0), other)]
    scene = SceneTruth([dets] * 4, [{GT_A: Annotation(C, (0.0, 0.0), 9)}] * 4)
    ev = _eval()
    ev.boxes[3] = [("11", C, (0.3, 0.0))]
    ev.geometry = {(3, "11"): box}
    ev.submitted = {3: {"11"}}
    ctx = Context(C, 3, GT_A, kind="miss")
    miss = "at frame 3 detection m1 (score 0.50) lay 0.3 m from car GT aaaaaa and lay under "
    coalesced = "its detection m1 (score 0.50, 0.3 m away) lay under "
    for head in (miss, coalesced, "at frame 3 m1 (score 0.50, 0.3 m from it) lay under "):
        true, false = head + "track 11's box, which sat on another detection", head + "no output box"
        assert check_text(true, ctx, None, ev, scene=scene).found == [], true
        assert [c.kind for c in check_text(false, ctx, None, ev, scene=scene).found] == ["output"], false
    ev.boxes[3] = [("11", C, (0.3, 0.6))]  # 0.6 m away: no box beside it
    assert check_text(miss + "no output box", ctx, None, ev, scene=scene).found == []


def test_an_unshown_phd_labels_existence_is_caught_as_misleading_and_its_weight_passes() -> None:
    # independent audit r42, dev set scene-0061 centerpoint cphd fragmentation:3: "track 38's existence stayed below
    # 0.5" of a CPHD label (its heaviest component's weight, 0.30, was what the line called "its weight")
    from gnnpmb.events import IntensityWeights

    ev = _eval()
    ev.submitted = {1: {"38"}, 2: set()}
    raw = _frames({1: [IntensityWeights(C, np.array([38, 38]), np.array([0.30, 0.25]))]})
    ctx = Context(C, 2, GT_A, lost=38)
    said = "track 38's {} stayed below 0.5 (the views draw tracks from 0.5 up), yet the evaluation counted it"
    assert check_text(said.format("weight"), ctx, raw, ev).found == []
    assert [c.kind for c in check_text(said.format("existence"), ctx, raw, ev).found] == ["misleading"]
    posterior = _frames({1: [_posterior(38, 0.3)]})
    assert [c.kind for c in check_text(said.format("weight"), ctx, posterior, ev).found] == ["misleading"]


def test_a_focus_documents_story_line_with_a_wrong_value_or_symbol_is_caught() -> None:
    # independent audit r42, dev set scene-0061 centerpoint cphd id_switch:1: "frame 2: track 18 no longer shown
    # (r=0.02 fell below 0.50)" of a CPHD label whose heaviest component weighed 0.22
    from gnnpmb.events import IntensityWeights
    from tools.truth.lost import check_story
    from tools.truth.sentences import Tally

    phd = _frames({2: [IntensityWeights(C, np.array([18, 18, 18]), np.array([0.22, 0.211, 0.024]))]})
    bernoulli = _frames({2: [_posterior(18, 0.22)]})

    def found(section: str, raw) -> list[str]:
        out = Tally()
        check_story(section, C, raw, out, lambda kind, sentence, why: out.found.append(kind))
        return out.found

    gone = "- frame 2: track 18 no longer shown ({}={} fell below 0.50)\n"
    hidden = "- frame 2: track 18 (not shown, {0} < 0.5): started by m7, {0}={1}\n"
    for line in (gone, hidden):
        assert found(line.format("w", "0.22"), phd) == []
        assert found(line.format("w", "0.02"), phd) == ["tracker"]
        assert found(line.format("r", "0.22"), phd) == ["misleading"]
        assert found(line.format("r", "0.22"), bernoulli) == []
        assert found(line.format("w", "0.22"), bernoulli) == ["misleading"]


def test_a_story_line_calling_a_track_the_submission_output_not_shown_or_not_output_is_caught() -> None:
    # viewer review, demo scene-0103 pointpillars pmbm fragmentation:5: "frame 17: track 72 no longer shown (r=0.41
    # fell below 0.50)" of a track output there (the viewer's 0.5, not the submission's 0.01); dev scene-0916 megvii
    # pmbm coalescence:1: "track 434 (not shown, r < 0.5)" of the track the evaluation matched to GT 4afe77
    from tools.truth.lost import check_story
    from tools.truth.sentences import Tally

    raw = _frames({17: [_posterior(72, 0.41)]})

    def found(section: str, submitted: dict) -> list[str]:
        out = Tally()
        check_story(section, C, raw, out, lambda kind, sentence, why: out.found.append(kind), submitted)
        return out.found

    output, not_output = {17: {"72"}}, {17: set()}
    lines = {
        "old": "- frame 17: track 72 no longer shown (r=0.41 fell below 0.50)\n",
        "hidden": "- frame 17: track 72 (not shown, r < 0.5): started by m7, r=0.41\n",
        "below": "- frame 17: track 72 fell below the display threshold (r=0.41 < 0.50), still output\n",
        "faint": "- frame 17: track 72 (output; r below the display threshold 0.5): started by m7, r=0.41\n",
        "gone": "- frame 17: track 72 no longer output (r=0.41 fell below 0.50)\n",
        "none": "- frame 17: track 72 (not output): started by m7, r=0.41\n",
    }
    assert found(lines["old"], output) == ["misleading"]
    assert found(lines["hidden"], output) == ["misleading"]
    assert found(lines["old"], not_output) == []
    for key in ("below", "faint"):
        assert found(lines[key], output) == []
        assert found(lines[key], not_output) == ["output"]
    for key in ("gone", "none"):
        assert found(lines[key], not_output) == []
        assert found(lines[key], output) == ["output"]
    for again in ("output again", "back above the display threshold"):  # a track back after a gap
        line = f"- frame 17: track 72 {again} (r=0.41, from m7)\n"
        assert found(line, output) == []
        assert found(line, not_output) == ["output"]
        assert found(line.replace("0.41", "0.61"), output) == ["tracker"]


def test_last_output_on_it_of_a_track_the_submission_still_had_on_the_annotation_later_is_caught() -> None:
    # viewer review, demo scene-0103 pointpillars pmbm fragmentation:1: "track 26 was last output on it at frame 14"
    # of a track the submission had 0.0 m from the annotation at frame 15 (the evaluation scored an interpolated box)
    from tools.truth.scene import Annotation, SceneTruth

    scene = SceneTruth([[]] * 16, [{}] * 14 + [{GT_A: Annotation(C, (0.0, 0.0), 9)}] * 2)
    ctx = Context(C, 15, GT_A, kind="fragmentation", lost=26)
    said = "track 26 was last output on it at frame 14"
    ev = _eval()
    ev.submitted = {14: {"26"}, 15: {"26"}}
    ev.boxes = {14: [("26", C, (0.1, 0.0))], 15: [("26", C, (0.0, 0.0))]}
    assert "output" in [c.kind for c in check_text(said, ctx, None, ev, scene=scene).found]
    ev.boxes[15] = [("26", C, (4.0, 0.0))]
    assert "output" not in [c.kind for c in check_text(said, ctx, None, ev, scene=scene).found]


def test_another_run_said_not_to_fail_where_its_devkit_switched_the_objects_track_is_caught() -> None:
    # independent audit r42, dev set scene-0553 megvii prob3dmot fragmentation at frame 23 (ab3dmot's evaluation had a
    # SWITCH of the object to track 241 there)
    from tools.truth.scene import Annotation, SceneTruth

    other = _eval()  # GT A matched to the other run's track 7 at frame 3, by a SWITCH
    other.switches[(C, 3)] = {GT_A}
    other.boxes[3] = [("7", C, (0.0, 0.3))]
    scene = SceneTruth([[]] * 4, [{}, {}, {}, {GT_A: Annotation(C, (0.0, 0.0), 9)}])
    ctx = Context(C, 3, GT_A, kind="fragmentation")

    def kinds(text: str, ev: EvalFacts = other) -> list[str]:
        return [c.kind for c in check_text(text, ctx, None, _eval(), scene=scene, others={"pmbm": ev}).found]

    head = "pmbm on the same detections "
    assert kinds(head + "did not fail here: its track 7 was output on the object and counted") == ["other run"]
    assert kinds(head + "did not have this failure") == ["other run"]
    true = head + "switched the object's track here instead: the evaluation matched the object to its track 7"
    assert kinds(true) == []
    assert kinds(true.replace("track 7", "track 8")) == ["other run"]
    assert kinds(true, _eval()) == ["other run"]  # no SWITCH in its events


def test_a_focus_documents_track_table_with_a_wrong_word_or_value_is_caught() -> None:
    # independent audit r42, dev set scene-0757 centerpoint phd: "r before update" / "r after" 1.10 of a PHD label
    from gnnpmb.events import IntensityWeights, Predicted
    from tools.truth.lost import check_track_tables
    from tools.truth.sentences import Tally

    predicted = Predicted(
        C, np.array([39, 39]), np.zeros((2, 4)), np.tile(np.eye(4), (2, 1, 1)), np.array([0.03, 0.94])
    )
    gated = Gated(
        C,
        np.array([39, 39]),
        np.array([17, 4]),
        np.array([[True, False], [False, True]]),
        np.zeros((2, 2)),
        np.tile(np.eye(2), (2, 1, 1)),
        40.0,
        np.array([[0.2, 50.0], [60.0, 3.1]]),
    )
    intensity = IntensityWeights(C, np.array([39, 39]), np.array([1.10, 0.02]))
    phd = _frames({16: [predicted, gated, intensity]})

    def found(word: str, before: str, after: str, gate: str = "m17 (0.2)") -> list[str]:
        table = "Track 39, frame by frame:\n\n"
        table += f"| frame | {word} before update | in gate (NIS) | used | {word} after | output |\n"
        table += f"|---|---|---|---|---|---|\n| 16 | {before} | {gate} | m17 (91 % of its weight) | {after} | yes |\n"
        out = Tally()
        check_track_tables(table, C, phd, out, lambda kind, sentence, why: out.found.append(kind))
        return out.found

    assert found("weight", "0.94", "1.10") == []
    assert found("r", "0.94", "1.10") == ["misleading"]
    assert found("weight", "0.03", "1.10") == ["tracker"]
    assert found("weight", "0.94", "0.02") == ["tracker"]
    # the gate column against the Gated rows of the label (a row per component)
    assert found("weight", "0.94", "1.10", "m4 (3.1)") == []
    assert found("weight", "0.94", "1.10", "m17 (0.4)") == ["tracker"]
    assert found("weight", "0.94", "1.10", "m17 (0.2), m4 (3.1)") == ["tracker"]  # no one row gates both
    assert found("weight", "0.94", "1.10", "nothing") == ["tracker"]


def test_a_far_detection_the_lost_track_used_is_checked_and_its_soft_share_must_be_said() -> None:
    # independent audit r42, dev set scene-1100 centerpoint cphd fragmentation:1: "it had used detections 2 m or more
    # from the object at frame 5 (m5)", 24 % of its weight (72 % from m11, 0.9 m from the object)
    from gnnpmb.events import UpdateWeights
    from tools.truth.scene import Annotation, Detection, SceneTruth

    box = (1.8, 4.5, 1.6, 1.0, 0.0, 0.0, 0.0, 0.9)
    dets = [Detection(C, 0.8, (4.1, 0.0), box), Detection(C, 0.5, (0.9, 0.0), box)]
    scene = SceneTruth([dets] * 6, [{GT_A: Annotation(C, (0.0, 0.0), 9)}] * 6)
    weights = UpdateWeights(
        C, np.array([9]), np.array([0, 1]), np.array([1.0]), np.array([0.04]), np.array([[0.24, 0.72]]), np.zeros(2)
    )
    raw = _frames({5: [weights]})
    ctx = Context(C, 5, GT_A, kind="fragmentation", lost=9)

    def kinds(text: str) -> list[str]:
        return [x.kind for x in check_text(text, ctx, raw, _eval(), scene=scene).found if x.kind != "detector"]

    head = "it had used detections 2 m or more from the object at frame 5 "
    assert kinds(head + "(m0, 24 % of its weight)") == []
    assert kinds(head + "(m0)") == ["misleading"]
    assert kinds(head + "(m0, 72 % of its weight)") == ["misleading"]
    assert kinds(head + "(m1, 72 % of its weight)") == ["tracker"]  # 0.9 m from the object


def test_another_run_said_not_to_have_the_failure_where_its_evaluation_matched_the_object_is_caught() -> None:
    # independent audit r42, dev set scene-1094 pointpillars cbmot fragmentation:2 (greedy's evaluation matched the
    # object to a box it interpolated for its track 50)
    other = _eval()  # GT A matched to its track 7 at frame 3
    ctx = Context(C, 3, GT_A, kind="fragmentation")
    vague = "pmbm on the same detections did not have this failure"
    assert [c.kind for c in check_text(vague, ctx, None, _eval(), others={"pmbm": other}).found] == ["misleading"]
    named = "pmbm on the same detections did not fail here: the evaluation matched the object to its track 7"
    assert check_text(named, ctx, None, _eval(), others={"pmbm": other}).found == []


def test_a_new_track_column_said_as_a_cost_where_it_holds_the_threshold_or_a_wrong_threshold_is_caught() -> None:
    # viewer review, demo scene-0103 pointpillars ab3dmot: "m0 → track 210 (3D IoU 0.10) over new (3D IoU 0.10),
    # margin 0.00": AB3DMOT's new-track column holds its IoU threshold (cost 1 - 0.1), no new track's IoU
    from gnnpmb.events import CostScale
    from tools.truth.costs import check_thresholds
    from tools.truth.sentences import Tally

    iou = CostScale("1 - IoU (3D)", "", 0.05, threshold=0.9, similarity="3D IoU")
    rows = axis_labels(AxisKind.MEASUREMENT, [0])
    cols = axis_labels(AxisKind.TRACK, [210]) + axis_labels(AxisKind.NEW_TRACK, [0])
    mat = CostMatrix(C, np.array([[0.8999, 0.9]]), rows, cols, scale=iou)
    raw = _frames({12: [mat, Assignment(C, ((rows[0], cols[0]),), 0.8999, ())]})

    def found(line: str, events: RawEvents = raw) -> list[str]:
        out = Tally()
        check_thresholds(line, C, events, out, lambda kind, sentence, why: out.found.append(kind))
        return out.found

    took = "- frame 12: m0 → **track 210** (3D IoU 0.10) over {}, margin 0.00 of 3D IoU"
    assert found(took.format("new (3D IoU 0.10)")) == ["misleading"]
    assert found(took.format("a new track (the 3D IoU threshold 0.10)")) == []
    assert found(took.format("a new track (the 3D IoU threshold 0.30)")) == ["cost"]
    assert found("- frame 12: close call: m0 → track 210 (3D IoU 0.10) over new (3D IoU 0.10), margin 0.00") == [
        "misleading"
    ]
    assert found("- frame 12: m0 → **new track 9** (the 3D IoU threshold 0.20) over track 210 (3D IoU 0.10)") == [
        "cost"
    ]
    nats = CostMatrix(C, np.array([[6.0, 6.5]]), rows, cols)  # no threshold: a new track's cost is a cost
    plain = _frames({12: [nats, Assignment(C, ((rows[0], cols[0]),), 6.0, ())]})
    assert found("- frame 12: m0 → **track 210** (cost 6.00) over new (6.50), margin 0.50", plain) == []
    assert found(took.format("a new track (the 3D IoU threshold 0.10)"), plain) == ["cost"]


def test_a_focus_naming_another_runs_track_its_views_do_not_highlight_is_caught() -> None:
    # viewer review: the run without the failure of a diff focus highlighted no track though the text named its
    # track (dev scene-0916 megvii phd -> cphd diff:fixed:20, phd's false_track:5: cphd's track 27 named, none
    # involved)
    from tools.truth.otherruns import check_involved
    from tools.truth.sentences import Tally

    doc = (
        "**Why** (phd): ...; cphd on the same detections did not fail here: its tracks 27, 31 were output on the "
        "object and counted; gnnpmb on the same detections did not fail here: the evaluation matched the object to "
        "its track 50.\n"
    )

    def found(track_ids: dict) -> list[str]:
        out = Tally()
        check_involved(doc, track_ids, out, lambda kind, sentence, why: out.found.append(kind))
        return out.found

    assert found({"phd": (12,), "cphd": (27, 31), "gnnpmb": (50, 51)}) == []
    assert found({"phd": (12,), "cphd": (), "gnnpmb": (50,)}) == ["misleading"]
    assert found({"phd": (12,), "cphd": (27, 31), "gnnpmb": (51,)}) == ["misleading"]


def test_a_focus_documents_choice_line_with_a_wrong_value_or_margin_on_any_scale_is_caught() -> None:
    # the key decisions and close calls of a focus document were read by no check (their 3D IoU and nats values,
    # "over new (V)", and a close call's margin): each value against the deciding matrix, the margin re-solved
    from gnnpmb.events import CostScale
    from tools.truth.sentences import Tally, check_choice_lines

    iou = CostScale("1 - IoU (3D)", "", 0.05, threshold=0.9, similarity="3D IoU")
    rows = axis_labels(AxisKind.MEASUREMENT, [0, 1])
    cols = axis_labels(AxisKind.TRACK, [210]) + axis_labels(AxisKind.NEW_TRACK, [0, 1])
    cost = np.array([[0.7, 0.9, np.inf], [np.inf, np.inf, 0.9]])
    pairs = ((rows[0], cols[0]), (rows[1], cols[2]))
    raw = _frames({12: [CostMatrix(C, cost, rows, cols, scale=iou), Assignment(C, pairs, 1.6, ())]})
    nats = np.array([[10.39, 10.71, np.inf], [np.inf, np.inf, 9.0]])
    plain = _frames({18: [CostMatrix(C, nats, rows, cols), Assignment(C, pairs, 19.39, ())]})

    def found(line: str, events: RawEvents = raw) -> list[str]:
        out = Tally()
        check_choice_lines(line, C, events, out, lambda kind, sentence, why: out.found.append(kind))
        return out.found

    true = (
        "- frame 12: m0 → **track 210** (3D IoU 0.30) over a new track (the 3D IoU threshold 0.10), margin 0.20 of "
        "3D IoU"
    )
    assert found(true) == []
    assert found(true.replace("(3D IoU 0.30)", "(3D IoU 0.70)")) == ["cost"]
    assert found(true.replace("margin 0.20", "margin 0.05")) == ["misleading"]
    close = "- frame 18: close call: m0 → track 210 (cost 10.39) over new (10.71), margin 0.32"
    assert found(close, plain) == []
    assert found(close.replace("(10.71)", "(10.17)"), plain) == ["cost"]
    assert found(close.replace("margin 0.32", "margin 0.50"), plain) == ["misleading"]


def test_a_phd_copy_said_with_a_weight_of_its_own_or_a_wrong_source_is_caught() -> None:
    # dev set scene-0916 megvii phd: "frame 29: track 44 confirmed (w=1.00, from m3)" of the extraction's second
    # copy of label 40's component (weight 1.62): no component is labelled 44
    from gnnpmb.events import IntensityWeights
    from tools.truth.lost import check_story
    from tools.truth.sentences import Tally

    raw = _frames({29: [IntensityWeights(C, np.array([40, 41]), np.array([1.62, 0.9]))]})

    def found(section: str) -> list[str]:
        out = Tally()
        check_story(section, C, raw, out, lambda kind, sentence, why: out.found.append(kind))
        return out.found

    assert found("- frame 29: track 44 confirmed (w=1.00, from m3)\n") == ["tracker"]
    copy = "- frame 29: track 44 confirmed (a copy of track {}'s component, w={}, which the extraction outputs"
    assert found(copy.format(40, "1.62")) == []
    assert found(copy.format(41, "0.90")) == ["tracker"]  # too light to be copied
    assert found(copy.format(40, "1.00")) == ["tracker"]


def test_the_test_an_infinite_cost_is_said_to_stand_for_is_checked_against_the_gate_and_the_threshold() -> None:
    # "track T could not take it: its column's cost for it was infinite (outside its gate / beyond its K
    # threshold)": the kind said was read by no check
    from gnnpmb.events import CostScale

    rows = axis_labels(AxisKind.MEASUREMENT, [3])
    cols = axis_labels(AxisKind.TRACK, [7]) + axis_labels(AxisKind.NEW_TRACK, [3])
    gated = Gated(
        C, np.array([7]), np.array([3]), np.array([[False]]), np.zeros((1, 2)), np.eye(2)[None], 9.2, np.array([[30.0]])
    )
    metres = CostScale("distance", "m", 0.5, threshold=2.0)
    say = (
        "at frame 4 m3 (score 0.50, 0.4 m from it; track 7 could not take it: its column's cost for it was infinite "
        "({}))"
    )
    ctx = Context(C, 4, GT_A, kind="fragmentation", lost=7)

    def kinds(events: list, test: str) -> list[str]:
        raw = _frames({4: events})
        return [k.kind for k in check_text(say.format(test), ctx, raw, _eval()).found if k.kind == "gone"]

    gate_only = [gated, CostMatrix(C, np.array([[np.inf, 1.0]]), rows, cols)]
    assert kinds(gate_only, "outside its gate") == []
    assert kinds(gate_only, "beyond its distance threshold") == ["gone"]
    inside = Gated(
        C, np.array([7]), np.array([3]), np.array([[True]]), np.zeros((1, 2)), np.eye(2)[None], 9.2, np.array([[1.0]])
    )
    threshold = [inside, CostMatrix(C, np.array([[np.inf, 2.0]]), rows, cols, scale=metres)]
    assert kinds(threshold, "beyond its distance threshold") == []
    assert kinds(threshold, "outside its gate") == ["gone"]
    # prob3dmot's threshold is its gate's own test (Mahalanobis distance 11, gate d² 121): both words hold (dev set
    # scene-1094 megvii prob3dmot id_switch:4 was flagged)
    mahalanobis = CostScale("Mahalanobis distance", "", 0.5, threshold=11.0)
    same = Gated(
        C,
        np.array([7]),
        np.array([3]),
        np.array([[False]]),
        np.zeros((1, 2)),
        np.eye(2)[None],
        121.0,
        np.array([[384.0]]),
    )
    both = [same, CostMatrix(C, np.array([[np.inf, 11.0]]), rows, cols, scale=mahalanobis)]
    assert kinds(both, "beyond its Mahalanobis distance threshold") == []
    assert kinds(both, "outside its gate") == []
    assert kinds(
        gate_only + [CostMatrix(C, np.array([[np.inf, 11.0]]), rows, cols, 1, scale=mahalanobis)],
        "beyond its Mahalanobis distance threshold",
    ) == ["gone"]


def test_a_parting_line_where_the_runs_only_number_their_tracks_differently_is_caught() -> None:
    # dev set scene-0655 megvii gnnpmb beside pmbm: "Where the trackers part" listed "gnnpmb: m9 → **track 104** ·
    # pmbm: m9 → **track 231**" though both tracks were started by m11 at frame 14 (61 of 63 lines)
    from gnnpmb.events import Born
    from tools.truth.otherruns import check_parting
    from tools.truth.sentences import Tally

    def run(births: dict[int, tuple[int, int]]) -> RawEvents:
        events = []
        for frame in sorted({f for f, _ in births.values()}):
            events.append(FrameStarted("t", frame, "s", 0, 0.5))
            born = [(t, m) for t, (f, m) in births.items() if f == frame]
            ids, meas = zip(*born, strict=True)
            events.append(Born(C, np.array(ids), np.array(meas), np.zeros((len(ids), 4)), np.ones(len(ids))))
        return RawEvents.of(events)

    def found(line: str, raws: dict) -> list[str]:
        doc = f"**Where the trackers part** at frame 15 (...):\n\n- {line}\n\n**Involved** (car): ...\n"
        out = Tally()
        check_parting(doc, 15, C, raws, out, lambda kind, sentence, why: out.found.append(kind))
        return out.found

    same = {"gnnpmb": run({104: (14, 11)}), "pmbm": run({231: (14, 11)})}
    other = {"gnnpmb": run({104: (14, 11)}), "pmbm": run({231: (12, 10)})}
    tracks = "gnnpmb: m9 → **track 104** (2.34; next new 10.4) · pmbm: m9 → **track 231** (2.34; next new 10.4)"
    assert found(tracks, same) == ["misleading"]
    assert found(tracks, other) == []
    assert found("gnnpmb: m11 → **new track 104** · pmbm: m11 → **new track 231**", same) == ["misleading"]
    assert found("gnnpmb: m11 → **new track 104** · pmbm: m11 → **track 231**", other) == []
    shares = "gnnpmb: m9 → **track 104 (98 % of m9)** · pmbm: m9 → **track 231 (p 0.70)**"  # a soft update's share
    assert found(shares, same) == ["misleading"]
    assert found(shares, other) == []


def test_a_false_tracks_issue_1141_citation_is_checked_against_the_box_weighted_the_right_way() -> None:
    # dev set scene-1094 megvii prob3dmot false_track:6 cited issue #1141 though the box weighted the right way lay
    # 2.6 m from the track, out of its reach too. Scene as in the planted #1141 note: GT A at x 0, 4, 10 m (frames
    # 1-3), the devkit's box at frame 2 at x 5.45, weighted the right way x 4.55
    scene, ev = _swapped_interpolation()
    head = "car GT aaaaaa lies {} m away, but the evaluation has it interpolated 1.5 m from the annotation, out of the "
    head += "track's reach"
    see = " (see nuscenes-devkit issue #1141)"
    still = ", and weighted the right way (nuscenes-devkit issue #1141) it "

    def found(track_x: float, tail: str) -> list[str]:
        ev.pred_xy[(C, 2)] = {"30": (track_x, 0.0)}
        text = head.format(f"{abs(track_x - 4.0):.1f}") + tail
        return [c.kind for c in check_text(text, Context(C, 2, GT_A, track=30), None, ev, scene=scene).found]

    assert found(3.0, see) == []  # 1.5 m from the box weighted the right way: the swap put it out of reach
    assert found(2.0, see) == ["misleading"]  # 2.5 m from it: out of reach either way
    assert found(2.0, still + "would still lie 2.5 m from the track") == []
    assert found(2.0, still + "would still lie 2.0 m from the track") == ["misleading"]
    assert found(3.0, "") == ["misleading"]  # the swap decided, unsaid


def test_a_track_said_beyond_the_evaluations_reach_while_within_reach_of_its_interpolated_box_is_caught() -> None:
    # dev set scene-1077 centerpoint topmb id_switch:1: track 455 2.3 m from the annotation, 1.8 m from the box the
    # devkit interpolated, was said "beyond the evaluation's 2 m, so it no longer matched the object"
    from tools.truth.scene import Annotation, SceneTruth

    scene = SceneTruth([[]] * 4, [{GT_A: Annotation(C, (0.0, 0.0), 0)}] * 4)
    ev = _eval()
    ev.boxes[3] = [("455", C, (2.3, 0.0))]
    ev.submitted = {3: {"455"}}
    ev.evaluated_gt[(3, GT_A)] = (0.5, 0.0)
    beyond = "at frame 3 track 455 was output 2.3 m from GT aaaaaa, on m7: beyond the evaluation's 2 m, so it no "
    beyond += "longer matched the object"
    within = "at frame 3 track 455 was output 2.3 m from GT aaaaaa, on m7, 1.8 m from the box the evaluation "
    within += "interpolated for it"
    ctx = Context(C, 3, GT_A)
    assert [c.kind for c in check_text(beyond, ctx, None, ev, scene=scene).found] == ["evaluation"]
    assert check_text(within, ctx, None, ev, scene=scene).found == []
    ev.evaluated_gt[(3, GT_A)] = (-0.5, 0.0)  # 2.8 m from the track: out of reach of both
    assert check_text(beyond, ctx, None, ev, scene=scene).found == []
    assert [c.kind for c in check_text(within, ctx, None, ev, scene=scene).found] == ["evaluation"]


def test_a_track_out_of_reach_of_an_interpolated_box_says_whether_the_right_way_would_reach_it() -> None:
    # dev set scene-1094 megvii prob3dmot miss:61: "out of the track's reach" beside the #1141 note, though the box
    # weighted the right way lay 2.6 m from the track. GT A at x 0, 4, 10 m (frames 1-3), the devkit's box at frame
    # 2 at x 5.45, weighted the right way x 4.55
    from tools.truth.place import check_out_of_reach
    from tools.truth.sentences import Tally

    scene, ev = _swapped_interpolation()
    out = "at frame 2 track 30 was output {} m from the annotated object, but the evaluation scored the object at a "
    out += "box it interpolated 1.5 m from the annotation, out of the track's reach"
    still = ", and weighted the right way it would still lie {} m from the track"

    def found(track_x: float, text: str) -> list[str]:
        ev.boxes[2] = [("30", C, (track_x, 0.0))]
        tally = Tally()
        check_out_of_reach(text, C, 2, GT_A, scene, ev, tally, lambda kind, s, why: tally.found.append(kind))
        return tally.found

    assert found(3.0, out.format("1.0")) == []  # 1.5 m from the box weighted the right way: the swap decided
    assert found(3.0, out.format("1.0") + still.format("1.5")) == ["misleading"]
    assert found(2.4, out.format("1.6") + still.format("2.1")) == []
    assert found(2.4, out.format("1.6")) == ["misleading"]  # out of reach either way, unsaid


def test_another_run_said_to_count_no_track_of_a_class_it_scored_is_caught() -> None:
    """An unscored class: no threshold of the other run reached the devkit's lowest recall (``thresholds[c]`` None)."""
    said = (
        "pmbm on the same detections reached no score threshold at the evaluation's lowest recall for cars: the "
        "evaluation counted none of its car tracks"
    )
    unscored = EvalFacts(thresholds={C: None})
    assert check_text(said, CTX, None, _eval(), others={"pmbm": unscored}).found == []
    caught = check_text(said, CTX, None, _eval(), others={"pmbm": _eval()}).found  # its cars scored at 0.5
    assert [c.kind for c in caught] == ["other run"]


def _undercut_world():
    """A box tracker's frame (SimpleTrack's GIoU, threshold cost 1.5): the solve over every pair gave m0 track 5
    (1.49) and m1 track 7 (1.6, then dropped), so the reported matrix leaves track 7 free and cheaper for m0 (1.41)."""
    from gnnpmb.box.cost import OneMinusGiou3d

    rows = axis_labels(AxisKind.MEASUREMENT, [0, 1])
    cols = axis_labels(AxisKind.TRACK, [5, 7]) + axis_labels(AxisKind.NEW_TRACK, [0, 1])
    cost = np.array([[1.49, 1.41, 1.5, np.inf], [np.inf, np.inf, np.inf, 1.5]])
    m = CostMatrix(C, cost, rows, cols, scale=OneMinusGiou3d(-0.5).scale)
    a = Assignment(C, ((rows[0], cols[0]), (rows[1], cols[3])), 2.99, (7,))
    return RawEvents.of([FrameStarted("t", 3, "token", 0, 0.5), m, a]), m, a


def test_an_undercut_choice_said_with_a_margin_is_caught_and_said_as_undercut_passes() -> None:
    raw, m, a = _undercut_world()
    (conflict,) = explain(m, a).conflicts
    (choice,) = conflict.choices
    said = "then, " + choice_text(3, choice, 5, False).replace("**", "")
    assert "not track 7 (GIoU -0.41): the solver matched every pair" in said
    assert check_text(said, CTX, raw, _eval()).found == []
    old = "then, frame 3: m0 → track 5 (GIoU -0.49) over track 7 (GIoU -0.41), margin 0.00 of GIoU"
    assert [c.kind for c in check_text(old, CTX, raw, _eval()).found] == ["misleading"]
    wrong = said.replace("not track 7 (GIoU -0.41)", "not track 5 (GIoU -0.49)").replace("gave track 7", "gave track 5")
    assert [c.kind for c in check_text(wrong, CTX, raw, _eval()).found] == ["misleading"]


def test_a_cphd_track_said_to_fall_below_a_threshold_is_caught_and_the_map_cardinality_form_is_checked() -> None:
    # viewer review, dev set scene-0916 pointpillars cphd id_switch:1: "track 15 no longer output (w=0.14 fell below
    # 1.20)" a frame after it was output at w=0.72 (a CPHD outputs the MAP cardinality's heaviest components)
    from gnnpmb.events import Cardinality, Extracted, IntensityWeights, TrackEstimate
    from tools.truth.lost import check_story
    from tools.truth.sentences import Tally

    def est(t: int) -> TrackEstimate:
        return TrackEstimate(t, C, (0.0, 0.0, 0.0), (1.0, 1.0, 1.0), (1.0, 0, 0, 0), (0.0, 0.0), 0.5, 1.0, 0)

    weights = IntensityWeights(C, np.array([15, 7]), np.array([0.14, 1.2]))
    cphd = _frames({5: [weights, Cardinality(C, np.array([0.2, 0.7, 0.1])), Extracted(C, (est(7),), 1.2)]})
    phd = _frames({5: [weights, Extracted(C, (est(7),), 0.5)]})

    def found(section: str, raw) -> list[str]:
        out = Tally()
        check_story(section, C, raw, out, lambda kind, sentence, why: out.found.append(kind))
        return out.found

    fell = "- frame 5: track 15 no longer output (w=0.14 fell below {})\n"
    assert found(fell.format("1.20"), cphd) == ["misleading"]
    assert found(fell.format("0.50"), phd) == []
    kept = "- frame 5: track 15 no longer output (w=0.14; the MAP cardinality {} kept the {} heaviest components, the "
    kept += "lightest at w={})\n"
    assert found(kept.format(1, 1, "1.20"), cphd) == []
    assert found(kept.format(2, 2, "1.20"), cphd) == ["tracker"]
    assert found(kept.format(1, 1, "0.14"), cphd) == ["tracker"]


def test_a_sum_of_points_that_hides_radar_returns_is_caught() -> None:
    """World3 (/tmp/truth47: the dev set with radar-only boxes, as real nuScenes has): "(3 LiDAR and radar points in
    its box): the detector missed it" of a box with no LiDAR return and 3 radar ones read as a LiDAR detector's
    oversight. The sum of a box with radar returns is misleading, the two counts apart hold, a wrong split is
    caught, and a sum over LiDAR-only boxes still holds (both the miss and the span of a lost track's frames)."""
    from tools.truth.scene import Annotation

    scene = _scene()
    scene.objects[1][GT_B] = Annotation(C, (30.0, 0.0), 2, radar=2)  # 0 LiDAR and 2 radar points
    scene.objects[2][GT_B] = Annotation(C, (30.0, 0.0), 2, radar=1)  # 1 LiDAR and 1 radar point
    ctx = Context(C, 2, GT_B, kind="miss")
    miss = "at frame 1 the detector gave no detection of a tracked class within 2 m of car GT bbbbbb ({} in its box)"
    cases = {
        "2 LiDAR and radar points": ["misleading"],
        "0 LiDAR and 2 radar points": [],
        "1 LiDAR and 1 radar points": ["detector"],
    }
    for said, kinds in cases.items():
        assert [c.kind for c in check_text(miss.format(said), ctx, None, _eval(), scene=scene).found] == kinds, said
    span = "at frames 1–2 the detector gave no detection of a tracked class within 2 m, though it had {}"
    for said, kinds in {
        "2 LiDAR and radar points": ["misleading"],
        "0–1 LiDAR and 1–2 radar points": [],
        "0 LiDAR and 2 radar points": ["detector"],
    }.items():
        assert [c.kind for c in check_text(span.format(said), ctx, None, _eval(), scene=scene).found] == kinds, said
    plain = "at frame 0 the detector gave no detection of a tracked class within 2 m of car GT bbbbbb (0 LiDAR and "
    assert [c.kind for c in check_text(plain + "radar points in its box)", ctx, None, _eval(), scene=scene).found] == []


def test_a_lost_track_said_far_from_an_object_with_no_annotation_there_is_caught() -> None:
    """World3 (/tmp/truth47: the dev set with annotation gaps) scene-0757 centerpoint pmbm fragmentation:4: "track
    266 was last output on it at frame 26 (output farther than 2 m from it at frames 27–31)" of a pedestrian with no
    annotation at 27-31 (the devkit matched track 266 to its interpolated box at 30-31), and "in the 4 recorded
    frames up to 32 (24–32)" over those same unannotated frames. Here GT B is unannotated at frame 2."""
    scene = _scene()
    del scene.objects[2][GT_B]
    ev = _eval()
    ev.boxes = {x: [("9", C, (34.0, 0.0))] for x in range(4)}  # 4 m from GT B's annotation
    ev.submitted = {x: {"9"} for x in range(4)}
    ctx = Context(C, 3, GT_B, kind="fragmentation")

    def kinds(text: str) -> list[str]:  # the devkit's own last match is not set up here: its check left aside
        return [c.kind for c in check_text(text, ctx, None, ev, scene=scene).found if c.kind != "matched"]

    last = "the evaluation last matched track 9 to it at frame 0"
    assert kinds(last + " (output farther than 2 m from it at frames 1, 2)") == ["output"]
    assert kinds(last + " (output farther than 2 m from it at frame 1)") == []
    gap = " (it was not annotated at frame {}: the evaluation scored boxes it interpolated)"
    assert kinds(last + " (output farther than 2 m from it at frame 1)" + gap.format(2)) == []
    assert kinds(last + gap.format(1)) == ["output"]
    seen = "in the 3 recorded frames up to 3 ({}), GT bbbbbb had a car detection within 2 m at no frame"
    assert "misleading" in kinds(seen.format("0–3"))
    assert kinds(seen.format("0–1, 3")) == []


def test_another_runs_track_said_matched_elsewhere_with_the_scored_box_out_of_its_reach_unsaid_is_caught() -> None:
    """Dev set scene-0061 megvii immortal coalescence:3 beside pmbm, world3's pedestrian queue: the other run's track
    near the annotation, matched to a neighbour, while the devkit scored the object at a box it interpolated out of
    the track's 2 m. Left unsaid: misleading; said: holds; said of a box within reach: misleading too."""
    ev, scene, _ = _matched_away_world()  # the other run: GT A missed at frame 2, track 7 (on it) matched to GT B
    ev.boxes[2] = [("7", C, (0.0, 0.5))]
    ev.counted[C] = {"7", "11"}
    scene.objects[2][GT_A] = scene.objects[3][GT_A]
    ctx = Context(C, 2, GT_A, kind="id_switch")
    told = (
        "pmbm on the same detections did not match the object here: its track 7 was output on the object and "
        "counted, but the evaluation matched track 7 to car GT bbbbbb"
    )
    note = " (the box it scored for this object, interpolated 2.6 m from the annotation, lay 2.7 m from track 7)"

    def kinds(text: str, box: tuple[float, float]) -> list[str]:
        ev.evaluated_gt[(2, GT_A)] = box
        return [c.kind for c in check_text(text, ctx, None, _eval(), scene=scene, others={"pmbm": ev}).found]

    far = (scene.objects[2][GT_A].xy_m[0] + 2.6, scene.objects[2][GT_A].xy_m[1])
    near = (scene.objects[2][GT_A].xy_m[0] + 0.6, scene.objects[2][GT_A].xy_m[1])
    assert kinds(told, far) == ["misleading"]
    assert kinds(told + note, far) == []
    assert kinds(told + note, near) == ["misleading"]
    assert kinds(told, near) == []


def test_a_failure_said_to_be_at_a_frame_without_annotation_is_checked_against_the_tables() -> None:
    """World3's annotation gaps: "at frame F C GT H had no annotation, though it had some before and after: the
    evaluation scored a box it interpolated between them there" holds where the object has no annotation at F, one
    on each side, and the devkit scored a box of it at F; planted at an annotated frame, it is caught."""
    scene = _scene()
    del scene.objects[2][GT_B]
    ev = _eval()
    ev.evaluated_gt[(2, GT_B)] = (30.0, 0.5)
    said = (
        "at frame {} car GT bbbbbb had no annotation, though it had some before and after: the evaluation scored a "
        "box it interpolated between them there"
    )
    assert check_text(said.format(2), Context(C, 2, GT_B, kind="miss"), None, ev, scene=scene).found == []
    caught = check_text(said.format(1), Context(C, 1, GT_B, kind="miss"), None, ev, scene=scene).found
    assert [c.kind for c in caught] == ["evaluation"]


def test_another_runs_track_on_an_object_with_no_annotation_is_judged_at_the_devkits_box() -> None:
    """World3 scene-0061 nohead ab3dmot fragmentation:5 beside pmbm: at frame 12 car 732475 had no annotation and
    pmbm's track 7 lay on the box the devkit interpolated for it (and was matched there): "its track 7 was output
    on the object and counted" holds against that box; a track 3 m from it is caught."""
    ev, scene, _ = _matched_away_world()  # GT A annotated at frame 3 only: none at frame 2
    ev.evaluated_gt[(2, GT_A)] = (5.0, 0.0)
    ev.counted[C] = {"7", "11"}
    ev.gt_to_track[(C, 2)] = {GT_A: "7"}
    ev.track_to_gt[(C, 2)] = {"7": GT_A}
    ctx = Context(C, 2, GT_A, kind="miss")
    said = "pmbm on the same detections did not fail here: its track 7 was output on the object and counted"
    for xy, kinds in (((5.3, 0.0), []), ((8.0, 0.0), ["other run"])):
        ev.boxes[2] = [("7", C, xy)]
        found = check_text(said, ctx, None, _eval(), scene=scene, others={"pmbm": ev}).found
        assert [c.kind for c in found if c.kind == "other run"] == kinds, (xy, found)


def test_a_soft_updates_minor_detection_called_the_one_it_used_is_caught() -> None:
    """World3 scene-1100 megvii jpda false_track:1: JPDA weighted m0 p 0.37 for track 7 (missed p 0.34, another
    detection p 0.29): "the one its update used" is misleading there, and holds at p 0.9."""
    from gnnpmb.events import AxisKind, AxisLabel, Marginals

    said = "at frame 3 track 7 (car) was output 2.2 m from detection m0 (car, score 0.90), the one its update used"
    cols = (AxisLabel(AxisKind.MISSED, -1), AxisLabel(AxisKind.MEASUREMENT, 0), AxisLabel(AxisKind.MEASUREMENT, 5))
    for p, kinds in ((0.37, ["misleading"]), (0.9, [])):
        probs = np.array([[0.63 - p * 0.5, p, 0.37 - p * 0.5]])
        marg = Marginals(C, probs, (AxisLabel(AxisKind.TRACK, 7),), cols, "exact")
        found = check_text(said, Context(C, 3, None, kind="false_track"), _raw_with(marg), _eval(), scene=_scene())
        assert [c.kind for c in found.found if "soft update" in c.truth] == kinds, (p, found.found)


def test_a_deciding_choice_led_by_the_wrong_word_and_a_detection_of_no_object_said_or_unsaid_wrongly_are_caught() -> (
    None
):
    # audit truth49, world5 scene-0553 (a false bus took the real bus's ID): "at frame 20 m25 → track 48; then,
    # frame 15: m24 → track 48 ..." (frame 15 told as after frame 20), and neither the thief's start m30 nor m24 said
    # to be a detection of no object
    from gnnpmb.events import Born
    from tools.truth.scene import Annotation, Detection, SceneTruth

    objects = [{GT_A: Annotation(C, (0.0, 0.0), 9)}] * 4
    scene = SceneTruth([[Detection(C, 0.9, (0.3, 0.0)), Detection(C, 0.7, (5.0, 0.0))]] * 4, objects)
    choice = "frame 2: m1 → track 11 (cost 1.00) over track 7 (2.00), margin 1.00"
    at = Context(C, 3, GT_A)

    def kinds(text: str, raw=None) -> list[str]:
        return [c.kind for c in check_text(text, at, raw or _raw_with(), _eval(), scene=scene).found]

    no_object = "m1 at frame 2 was a detection of no object (none of a tracked class within 2 m)"
    assert kinds(f"the deciding choice was earlier, {choice}; {no_object}") == []
    assert kinds(f"then, {choice}; {no_object}") == ["misleading"]  # frame 2 before the failure's frame 3
    assert kinds(f"the deciding choice was earlier, {choice}") == ["misleading"]  # m1 lies 5 m from GT A: unsaid
    assert kinds("then, frame 3: m0 → track 7 (cost 1.00) over track 5 (2.00), margin 1.00") == []
    planted = "the deciding choice was earlier, frame 2: m0 → track 7 (cost 1.00) over track 5 (2.00), margin 1.00"
    assert kinds(f"{planted}; m0 at frame 2 was a detection of no object") == ["detector"]  # m0: 0.3 m from GT A
    born = _raw_with(Born(C, np.array([11]), np.array([1]), np.zeros((1, 4)), np.ones(1)))
    started = "track 11 had been started at frame 3 by m1"
    assert kinds(f"{started}, a detection of no object (none of a tracked class within 2 m)", born) == []
    assert kinds(started, born) == ["misleading"]


def test_a_box_inside_a_long_objects_box_said_to_be_of_no_object_is_caught() -> None:
    # audit truth50, world6 scene-0916 / scene-0796: a 16 m truck with trailer detected as a cab box 4.75 m ahead of
    # its centre and a trailer box 3.25 m behind it; "a detection of no object", "where no tracked object was" and
    # "the detector missed it" said of boxes inside the truck's own box
    from gnnpmb.events import Born
    from tools.truth.scene import Annotation, Detection, SceneTruth

    truck = "c" * 32
    objects = [{truck: Annotation("truck", (0.0, 0.0), 200, 0, (2.6, 16.0, 0.0))} for _ in range(4)]
    scene = SceneTruth([[Detection("truck", 0.7, (4.75, 0.0)), Detection("truck", 0.6, (-3.25, 0.0))]] * 4, objects)
    born = _raw_with(Born("truck", np.array([11]), np.array([1]), np.zeros((1, 4)), np.ones(1)))
    at = Context("truck", 3, truck)

    def kinds(text: str, ctx: Context = at, ev: EvalFacts | None = None) -> list[str]:
        return [c.kind for c in check_text(text, ctx, born, ev or _eval(), scene=scene).found]

    started = "track 11 had been started at frame 3 by m1"
    assert kinds(f"{started}, a detection of no object (none of a tracked class within 2 m)") == ["misleading"]
    part = "a detection of part of truck GT cccccc (inside its box, 3.2 m from its centre, beyond the evaluation's 2 m)"
    assert kinds(f"{started}, {part}") == []
    assert kinds(f"{started}, {part.replace('cccccc', 'aaaaaa')}") == ["detector"]  # not inside GT A's box
    missed = (
        "at frame 3 the detector gave no detection of a tracked class within 2 m of truck GT cccccc (200 LiDAR and "
        "radar points in its box)"
    )
    assert kinds(f"{missed}: the detector missed it") == ["misleading"]
    assert (
        kinds(f"{missed}, but truck m1 (score 0.60) lay inside its box, 3.2 m from its centre: the detector saw part")
        == []
    )
    gap = (
        "at frame 3 the detector gave no detection of a tracked class within 2 m, though it had 200 LiDAR and radar "
        "points"
    )
    assert kinds(gap) == ["misleading"]
    assert (
        kinds(
            f"{gap}, but a detection lay inside its box, farther from its centre (truck m1 3.2 m): the detector saw "
            "part of it"
        )
        == []
    )
    # a false track's box on the trailer
    ev = _eval()
    ev.boxes[3] = [("12", "truck", (-3.0, 0.0))]
    false = Context("truck", 3, None, kind="false_track", track=12)
    nothing = "no object of a tracked class lies within 2 m: the tracker output a box where no tracked object was"
    assert kinds(nothing, false, ev) == ["misleading"]
    on_part = (
        "no object of a tracked class lies within 2 m, but the box lies on part of truck GT cccccc (inside its box"
    )
    assert kinds(on_part, false, ev) == []


def test_two_tracks_on_one_object_the_detector_gave_two_boxes_of_must_say_so() -> None:
    # audit truth50, world6 scene-0655 (a detector without NMS): "two tracks on one object", the tracker's doing,
    # where the detector gave the pedestrian two boxes 0.5 m apart
    from tools.truth.scene import Annotation, Detection, SceneTruth

    objects = [{GT_A: Annotation(C, (0.0, 0.0), 9), GT_B: Annotation(C, (30.0, 0.0), 9)}] * 4
    scene = SceneTruth([[Detection(C, 0.9, (0.3, 0.0)), Detection(C, 0.5, (-0.3, 0.2))]] * 4, objects)
    ev = _eval()
    ev.boxes[3] = [("11", C, (-0.3, 0.2))]
    false = Context(C, 3, None, kind="false_track", track=11)
    two = "car GT aaaaaa lies 0.4 m away and the evaluation matched it to another track: two tracks on one object"

    def kinds(text: str, sc: SceneTruth = scene) -> list[str]:
        return [c.kind for c in check_text(text, false, None, ev, scene=sc).found]

    assert kinds(two) == ["misleading"]
    assert kinds(f"{two}; the detector gave it two car detections within 2 m (m0, m1)") == []
    assert kinds(f"{two}; the detector gave it two car detections within 2 m (m0, m2)") == ["detector"]
    one = SceneTruth([[Detection(C, 0.9, (0.3, 0.0)), Detection(C, 0.5, (29.0, 0.0))]] * 4, objects)
    assert kinds(two, one) == []  # one box of it: the tracker's doing


def test_a_soft_update_or_a_thiefs_start_from_a_detection_of_no_object_left_unsaid_is_caught() -> None:
    # audit truth50 on world5 scene-0553 (a false bus beside a bus): cphd's "at frame 15 it took 32 % of its weight
    # from m24" and gnn's deciding choice "frame 15: m24 → track 48", track 48 started by the false bus, unsaid
    from gnnpmb.events import Born
    from tools.truth.scene import Annotation, Detection, SceneTruth

    objects = [{GT_A: Annotation(C, (0.0, 0.0), 9)}] * 4
    scene = SceneTruth([[Detection(C, 0.9, (0.3, 0.0)), Detection(C, 0.7, (5.0, 0.0))]] * 4, objects)
    at = Context(C, 3, GT_A)

    def kinds(text: str, raw=None) -> list[str]:
        return [c.kind for c in check_text(text, at, raw or _raw_with(), _eval(), scene=scene).found]

    soft = "at frame 2 it took 32 % of its weight from m1"
    assert "misleading" in kinds(soft)
    said = f"{soft}; m1 (frame 2) was a detection of no object (none of a tracked class within 2 m)"
    assert "misleading" not in kinds(said) and "detector" not in kinds(said)
    assert "detector" in kinds(f"{soft}; m0 (frame 2) was a detection of no object")  # m0: 0.3 m from GT A
    assert "misleading" not in kinds("at frame 2 it took 90 % of its weight from m0")  # the object's own
    born = _raw_with(Born(C, np.array([11]), np.array([1]), np.zeros((1, 4)), np.ones(1)))
    born.by[(1, C)] = born.by.pop((3, C))  # track 11 born at frame 1 from m1
    choice = "the deciding choice was earlier, frame 2: m0 → track 11 (cost 1.00) over track 7 (2.00), margin 1.00"
    assert "misleading" in kinds(choice, born)
    started = f"{choice}; track 11 had been started at frame 1 by m1, a detection of no object (none within 2 m)"
    assert "misleading" not in kinds(started, born)


def test_a_miss_beside_a_box_of_its_class_placed_off_it_said_to_be_missed_is_caught() -> None:
    # audit truth51, world7 scene-0916 megvii jpda miss:65: car GT 63bd3c's box moved 5.1 m for one frame; "the
    # detector missed it" said of a car whose own box lay 5.1 m away, nearer it than any other annotated object
    from tools.truth.scene import Annotation, Detection

    car, other = "c" * 32, "d" * 32
    objects = [{car: Annotation("car", (0.0, 0.0), 7), other: Annotation("car", (10.0, 0.0), 50)}] * 4
    dets = [Detection("car", 0.55, (4.0, 3.0)), Detection("car", 0.6, (7.0, 0.0))]
    scene = SceneTruth([dets] * 4, objects)

    def kinds(text: str) -> list[str]:
        return [c.kind for c in check_text(text, Context("car", 3, car), None, _eval(), scene=scene).found]

    missed = (
        "at frame 3 the detector gave no detection of a tracked class within 2 m of car GT cccccc (7 LiDAR and radar "
        "points in its box)"
    )
    assert kinds(f"{missed}: the detector missed it") == ["misleading"]
    off = (
        "; the nearest car detection, m0 (score 0.55), lay 5.0 m away, nearer it than any other annotated object: the "
        "detector missed it or placed its box that far off"
    )
    assert kinds(f"{missed}{off}") == []
    from tools.truth.sentences import coverage

    assert not coverage(f"Why (gnnpmb, the detector's doing): {missed}{off}")[1]  # the clause is read
    assert kinds(f"{missed}{off.replace('m0 (score 0.55)', 'm1 (score 0.60)')}") == ["detector"]  # m1 is dddddd's
    assert kinds(f"{missed}{off.replace('5.0 m', '4.0 m')}") == ["detector"]


def test_a_wrong_class_track_said_to_have_coasted_onto_the_object_it_was_fed_by_is_caught() -> None:
    # audit truth51, world7 scene-0103 centerpoint gnnpmb false_track:13: a car detected as a truck at every other
    # frame; the truck track's predicted box at frame 16 "coasted onto" the car whose truck box m0 it sat on at 15
    from tools.truth.scene import Annotation, Detection

    car = "0f0413" + "0" * 26
    box = (1.9, 4.6, 1.6, 1.0, 0.0, 0.0, 0.0, 0.8)
    objects = [{car: Annotation("car", (5.0 * x, 0.0), 60)} for x in range(4)]
    dets = [[Detection("truck" if x == 2 else "car", 0.9, (5.0 * x + 0.4, 0.0), box)] for x in range(4)]
    scene = SceneTruth(dets, objects)
    ev = _eval()
    ev.boxes = {2: [("77", "truck", (10.4, 0.0))], 3: [("77", "truck", (15.3, 0.0))]}
    ev.geometry = {(2, "77"): box, (3, "77"): (2.0, 5.0, 1.6, 1.0, 0.0, 0.0, 0.0, 0.8)}
    ev.submitted = {2: {"77"}, 3: {"77"}}

    def kinds(text: str) -> list[str]:
        found = check_text(text, Context("truck", 3, None), None, ev, scene=scene).found
        return [c.kind for c in found if "coasted" in c.sentence]

    head = (
        "at frame 3 track 77 (truck) was output on no detection this frame (a predicted box); no truck GT lies within "
        "2 m, but GT car 0f0413 does (0.3 m): the track coasted "
    )
    assert kinds(f"{head}onto it") == ["misleading"]
    fed = "on with it from m0 at frame 2, a truck detection of it: the detector gave it the wrong class"
    assert kinds(f"{head}{fed}") == []
    assert kinds(f"{head}{fed.replace('frame 2', 'frame 1')}") == ["detector"]
    ev.boxes[1] = [("77", "truck", (5.4, 0.0))]  # a predicted box at 2 is passed over: its box at 1 sat on m0
    ev.geometry[(1, "77")], ev.geometry[(2, "77")] = box, (2.0, 5.0, 1.6, 1.0, 0.0, 0.0, 0.0, 0.8)
    scene.detections[1] = [Detection("truck", 0.9, (5.4, 0.0), box)]
    assert kinds(f"{head}onto it") == ["misleading"]
    assert kinds(f"{head}{fed.replace('frame 2', 'frame 1')}") == []
    # a box filter's box at 2 repeats no detection's (ab3dmot filters the size): its pair with m0 there says it
    pair = ((axis_labels(AxisKind.MEASUREMENT, [0])[0], axis_labels(AxisKind.TRACK, [77])[0]),)
    raw = RawEvents.of([FrameStarted("t", 2, "token", 0, 0.5), Assignment("truck", pair, 0.0, ())])
    found = check_text(f"{head}{fed}", Context("truck", 3, None), raw, ev, scene=scene).found
    assert [c.kind for c in found if "coasted" in c.sentence] == []


def test_a_riders_bicycle_box_said_to_be_the_pedestrian_seen_as_the_wrong_class_is_caught() -> None:
    # audit truth51, world7 scene-0916 centerpoint ab3dmot miss:74: a rider annotated as a bicycle and a pedestrian
    # on one spot; the bicycle's own box was said to be the pedestrian seen as the wrong class
    from tools.truth.scene import Annotation, Detection

    ped, bike = "4776dc" + "0" * 26, "a402d8" + "0" * 26
    objects = [{ped: Annotation("pedestrian", (0.0, 0.0), 40), bike: Annotation("bicycle", (0.0, 0.0), 30)}] * 4
    scene = SceneTruth([[Detection("bicycle", 0.67, (0.3, 0.4))]] * 4, objects)

    def kinds(text: str) -> list[str]:
        return [c.kind for c in check_text(text, Context("pedestrian", 3, ped), None, _eval(), scene=scene).found]

    no_ped = (
        "at frame 3 the detector gave no pedestrian detection within 2 m of pedestrian GT 4776dc (40 LiDAR and radar "
        "points in its box)"
    )
    assert kinds(
        f"{no_ped}, but a bicycle detection, m0 (score 0.67), 0.5 m away: the detector gave it the wrong class"
    ) == ["detector"]
    own = (
        "at frame 3 the detector gave pedestrian GT 4776dc (40 LiDAR and radar points in its box) no detection of its "
        "own within 2 m (bicycle m0, 0.5 m away, lay 0.5 m from bicycle GT a402d8)"
    )
    assert kinds(own) == []
    assert kinds("at frame 3 the detector saw it only as another class (bicycle m0 0.50 m away)") == ["detector"]


def test_a_false_box_that_ran_off_its_object_must_say_so_and_say_it_right() -> None:
    """Dev set scene-0916 centerpoint gnnpmb false_track:14: track 11 on a car with no sensor points at frames 1-2
    (0.5 m from it), 2.1 m from it at frame 3 (the failure), where the evaluation has no box of it. "A box where no
    tracked object was" leaves that unsaid; the drift told with the wrong distance, object or frame is false."""
    from tools.truth.scene import Annotation

    ev = _eval()
    for x, at in ((1, 0.5), (2, 0.5), (3, 2.1)):
        ev.boxes[x] = [("11", C, (at, 0.0))]
    scene = SceneTruth([[]] * 4, [{GT_A: Annotation(C, (0.0, 0.0), 0)}] * 4)
    at = Context(C, 3, None, kind="false_track", track=11)
    head = "no object of a tracked class lies within 2 m"
    unsaid = f"{head}: the tracker output a box where no tracked object was"
    assert [c.kind for c in check_text(unsaid, at, None, ev, scene=scene).found] == ["misleading"]
    said = f"{head}: the track's predicted box lies 2.1 m from car GT aaaaaa, which it was last within 2 m of at "
    said += "frame 2"
    no_box = "; the evaluation has no box for that one here (it had no LiDAR or radar points, so its box was dropped)"
    assert check_text(said + no_box, at, None, ev, scene=scene).found == []
    for false in (said.replace("2.1 m", "3.1 m"), said.replace("frame 2", "frame 1")):
        assert [c.kind for c in check_text(false, at, None, ev, scene=scene).found] == ["detector"], false
    # a box the evaluation interpolated for the track between its own boxes: the same, after "... within 2 m of it"
    interpolated = f"{head} of it"
    assert [c.kind for c in check_text(interpolated, at, None, ev, scene=scene).found] == ["misleading"]
    told = f"{interpolated}: the track's box lies 2.1 m from car GT aaaaaa, which it was last within 2 m of at frame 2"
    assert check_text(told, at, None, ev, scene=scene).found == []
    # a box on a detection of nothing, or on part of another object, is told by those words, not by a drift
    assert check_text(f"{head}: a detection of no tracked object", at, None, ev, scene=scene).found == []
    ev.evaluated_gt[(3, GT_A)] = (0.0, 0.0)  # the devkit scored a box of it after all
    assert [c.kind for c in check_text(said + no_box, at, None, ev, scene=scene).found] == ["evaluation"]


def test_a_drift_said_from_further_back_than_the_window_is_checked_against_that_frame() -> None:
    """Dev set scene-1077 pointpillars immortal false_track:33 at frame 35: "last within 2 m of it at frame 26" (track
    90's box 1.84 m from car a1a72a there, not output at 29-34) was read over 8 frames back only and called false."""
    from tools.truth.scene import Annotation

    ev = _eval()
    ev.boxes[2] = [("90", C, (1.8, 0.0))]
    ev.boxes[12] = [("90", C, (5.1, 0.0))]
    scene = SceneTruth([[]] * 13, [{GT_A: Annotation(C, (0.0, 0.0), 0)}] * 13)
    at = Context(C, 12, None, kind="false_track", track=90)
    said = "no object of a tracked class lies within 2 m: the track's predicted box lies 5.1 m from car GT aaaaaa, "
    assert check_text(said + "which it was last within 2 m of at frame 2", at, None, ev, scene=scene).found == []
    wrong = check_text(said + "which it was last within 2 m of at frame 3", at, None, ev, scene=scene).found
    assert [c.kind for c in wrong] == ["detector"]


def test_a_box_on_an_untracked_category_or_an_untracked_detection_name_left_unsaid_is_caught() -> None:
    # audit truth52, world8 scene-0103 centerpoint gnnpmb false_track:7: a car track on an annotated ambulance was
    # "a detection of no tracked object"; scene-0916: car 812dba seen only as a construction_vehicle was "missed"
    from tools.truth.scene import Annotation, Detection

    car, amb = "812dba" + "0" * 26, "7b72e3" + "0" * 26
    objects = [{car: Annotation("car", (0.0, 0.0), 120)}] * 4
    others = [{amb: Annotation("vehicle.emergency.ambulance", (20.0, 0.0), 80, 0, (2.2, 6.0, 0.0))}] * 4
    dets = [[Detection("car", 0.61, (20.2, 0.0))]] * 4
    untracked = [[Detection("construction_vehicle", 0.45, (0.3, 0.0))]] * 4
    scene = SceneTruth(dets, objects, None, untracked, others)
    ev = _eval()
    ev.boxes[3] = [("42", "car", (20.2, 0.0))]
    false = Context("car", 3, None, kind="false_track", track=42)

    def kinds(text: str, ctx: Context | None = None) -> list[str]:
        return [c.kind for c in check_text(text, ctx or Context("car", 3, car), None, ev, scene=scene).found]

    nothing = "no object of a tracked class lies within 2 m: a detection of no tracked object"
    assert kinds(nothing, false) == ["misleading"]
    named = (
        "no object of a tracked class lies within 2 m, but the detection lies on vehicle.emergency.ambulance 7b72e3 "
        "(0.2 m away), a category the evaluation does not track"
    )
    assert kinds(named, false) == []
    assert kinds(named.replace("7b72e3", "7b72e4"), false) == ["detector"]
    missed = (
        "at frame 3 the detector gave no detection of a tracked class within 2 m of car GT 812dba (120 LiDAR and radar "
        "points in its box)"
    )
    assert kinds(f"{missed}: the detector missed it") == ["misleading"]
    said = ", but a construction_vehicle box (score 0.45) 0.3 m away: the detector gave it a class no tracker takes"
    assert kinds(f"{missed}{said}") == []
    assert kinds(f"{missed}{said.replace('0.45', '0.55')}") == ["detector"]
    # the box lies on an annotated barrier (dev set scene-0103: a barrier box beside a construction worker)
    scene.others = [{**others[0], "e499f1" + "0" * 26: Annotation("movable_object.barrier", (0.4, 0.0), 9)}] * 4
    assert kinds(f"{missed}: the detector missed it") == []
    assert kinds(f"{missed}{said}") == ["detector"]


def test_a_strollers_pedestrian_box_counted_as_its_pushers_second_is_caught() -> None:
    # audit truth52, world8 scene-0103 megvii gnn false_track:16: "the detector gave it two pedestrian detections
    # within 2 m (m17, m18)" of an adult, where m18 lay on the (untracked) stroller it pushed
    from tools.truth.scene import Annotation, Detection

    mum, stroller = "57377a" + "0" * 26, "5b2c3d" + "0" * 26
    objects = [{mum: Annotation("pedestrian", (0.0, 0.0), 40)}] * 4
    others = [{stroller: Annotation("human.pedestrian.stroller", (0.8, 0.0), 25)}] * 4
    dets = [[Detection("pedestrian", 0.64, (0.1, 0.0)), Detection("pedestrian", 0.6, (0.75, 0.1))]] * 4
    scene = SceneTruth(dets, objects, None, None, others)
    ev = _eval()
    ev.boxes[3] = [("121", "pedestrian", (0.75, 0.1))]
    false = Context("pedestrian", 3, None, kind="false_track", track=121)
    two = (
        "pedestrian GT 57377a lies 0.8 m away and the evaluation matched it to another track: two tracks on one object"
    )
    found = check_text(
        f"{two}; the detector gave it two pedestrian detections within 2 m (m0, m1)", false, None, ev, scene=scene
    ).found
    assert [c.kind for c in found] == ["detector"]
    assert check_text(two, false, None, ev, scene=scene).found == []


def test_a_thiefs_start_on_an_untracked_object_is_told_as_that_objects_box() -> None:
    # audit truth52, world8: a track started by a car box on an ambulance is "a detection of
    # vehicle.emergency.ambulance 7b72e3 (...)", not "a detection of no object"
    from gnnpmb.events import Born
    from tools.truth.scene import Annotation, Detection

    car, amb = "26e63e" + "0" * 26, "7b72e3" + "0" * 26
    objects = [{car: Annotation("car", (0.0, 0.0), 60)}] * 4
    others = [{amb: Annotation("vehicle.emergency.ambulance", (20.0, 0.0), 80, 0, (2.2, 6.0, 0.0))}] * 4
    scene = SceneTruth([[Detection("car", 0.61, (20.2, 0.0))]] * 4, objects, None, None, others)
    ctx = Context("car", 3, car, kind="id_switch")

    def kinds(text: str) -> list[str]:
        raw = _raw_with(Born("car", np.array([42]), np.array([0]), np.zeros((1, 4)), np.ones(1)))
        return [c.kind for c in check_text(text, ctx, raw, _eval(), scene=scene).found]

    start = "track 42 had been started at frame 3 by m0"
    named = ", a detection of vehicle.emergency.ambulance 7b72e3 (0.2 m away), a category the evaluation does not track"
    assert kinds(f"{start}{named}") == []
    assert kinds(f"{start}, a detection of no object (none of a tracked class within 2 m)") == ["misleading"]
    assert kinds(f"{start}{named.replace('7b72e3', '7b72e4')}") == ["detector"]
