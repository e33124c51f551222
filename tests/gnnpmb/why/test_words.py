"""The wording of decisions: conflict headings, and a choice's costs taken apart (hand-computed)."""

from __future__ import annotations

import math
from types import SimpleNamespace

import numpy as np

from gnnpmb.events import Assignment, AxisKind, AxisLabel, CostMatrix, CostScale, CostTerms
from gnnpmb.explain import explain
from gnnpmb.why.counterfactual import would_take
from gnnpmb.why.words import choice_why, frames_text, track_why
from viz.decisions import _scale_notes, _tracks_phrase


def test_conflict_headings_count_tracks_and_candidates() -> None:
    assert _tracks_phrase((26,), {26}) == "track 26"
    assert _tracks_phrase((26, 123, 7), {26, 123}) == "tracks 26, 123 and 1 candidate"
    assert _tracks_phrase((7, 8), set()) == "2 candidate tracks"
    assert _tracks_phrase((7,), set()) == "1 candidate track"
    assert _tracks_phrase((7, 8), None) == "tracks 7, 8"


def one_detection(existence: float, d2: float) -> tuple[CostMatrix, Assignment, CostTerms]:
    """Detection m4 (score 0.5) in the gate of track 9 (P_D of its miss 0.8, |S| = 1); new-track cost 3.0."""
    terms = CostTerms(
        existence=np.array([existence]),
        miss_log_lik=np.log1p(-np.array([existence * 0.8])),
        score=np.array([0.5]),
        d2=np.array([[d2]]),
        log_det_S=np.array([0.0]),
        dim=2,
    )
    track_cost = terms.pair(0, 0).total_nats
    rows, cols = (AxisLabel(AxisKind.MEASUREMENT, 4),), (AxisLabel(AxisKind.TRACK, 9), AxisLabel(AxisKind.NEW_TRACK, 4))
    matrix = CostMatrix("car", np.array([[track_cost, 3.0]]), rows, cols, terms=terms)
    chosen = cols[1] if track_cost > 3.0 else cols[0]
    return matrix, Assignment("car", ((rows[0], chosen),), min(track_cost, 3.0), ()), terms


def test_a_detection_that_started_a_track_names_what_its_track_cost_was_made_of() -> None:
    matrix, assignment, terms = one_detection(existence=0.05, d2=1.0)
    (choice,) = explain(matrix, assignment).conflicts[0].choices
    t = terms.pair(0, 0)
    assert math.isclose(t.existence_nats, math.log(1 - 0.04) - math.log(0.05))  # 2.955
    assert math.isclose(t.spread_nats, math.log(2 * math.pi)) and math.isclose(t.spread_m, 1.0)
    assert choice_why(choice, "new track 40").endswith("(d² 1.0) + 0.69 for m4's score 0.50")  # unreplayed: says less
    why = choice_why(choice, "new track 40", would_take(matrix, assignment, 4, 9))
    assert why.startswith(f"m4 went to new track 40 (cost 3.00) rather than track 9 (cost {t.total_nats:.2f})")
    assert (
        # 2.955 shown as 2.96 (not 2.95) so that the parts add up to the 5.99 shown
        f"Track 9's {t.total_nats:.2f} = 2.96 for its predicted existence 0.05 + 1.84 for the "
        "uncertainty of its predicted position (±1.0 m) + 0.50 for the distance to m4 (d² 1.0) + 0.69 for m4's score "
        "0.50" in why
    )
    # The existence at which the track would have cost exactly the new track's 3.0: (1 - r 0.8) / r = exp(...).
    # Stated rounded up, on the side where re-solving gives the track the detection.
    needed = 1 / (math.exp(3.0 - t.spread_nats - t.distance_nats - t.score_nats) + 0.8)
    above = math.ceil(needed * 100) / 100
    assert why.endswith(f"With a predicted existence above {above:.2f} (instead of 0.05), track 9 would have taken m4")


def test_no_existence_helps_a_detection_far_outside_the_prediction() -> None:
    matrix, assignment, _ = one_detection(existence=0.5, d2=10.0)  # 7.71 against 3.0
    (choice,) = explain(matrix, assignment).conflicts[0].choices
    assert choice.chosen.kind is AxisKind.NEW_TRACK
    why = choice_why(choice, would=would_take(matrix, assignment, 4, 9))
    assert why.endswith("No predicted existence would have given m4 to track 9")
    assert why.startswith("m4 went to a new track (cost 3.00)")


def test_a_gnn_cost_has_no_existence_but_a_constant_and_a_distance_to_win_at() -> None:
    """GNN: C = -log(P_D / ((1 - P_D) kappa)) - log N; track 9 (|S| = 1) at d² 4 loses m4 to track 5 at d² 1."""
    terms = CostTerms(
        existence=None,
        miss_log_lik=None,
        score=None,
        d2=np.array([[1.0], [4.0]]),
        log_det_S=np.zeros(2),
        dim=2,
        offset_nats=-5.0,
        offset_text="a detection against clutter (P_D 0.9)",
    )
    costs = [terms.pair(0, k).total_nats for k in (0, 1)]  # -5 + log 2 pi + d² / 2
    assert np.allclose(costs, [-5.0 + math.log(2 * math.pi) + 0.5, -5.0 + math.log(2 * math.pi) + 2.0])
    rows = (AxisLabel(AxisKind.MEASUREMENT, 4),)
    cols = (AxisLabel(AxisKind.TRACK, 5), AxisLabel(AxisKind.TRACK, 9), AxisLabel(AxisKind.NEW_TRACK, 4))
    matrix = CostMatrix("car", np.array([[*costs, 0.0]]), rows, cols, terms=terms)
    assignment = Assignment("car", ((rows[0], cols[0]),), costs[0], (9,))
    (choice,) = explain(matrix, assignment).conflicts[0].choices
    why = choice_why(choice, would=would_take(matrix, assignment, 4, 9))
    assert "Track 9's -1.16 = -5.00 for a detection against clutter (P_D 0.9) + 1.84 for the uncertainty" in why
    assert "existence" not in why and "score" not in why
    # The break-even is d² 1.0 (4 - 2 (2.0 - 0.5)), a tie there: the value stated is below it, where it takes m4.
    assert why.endswith("Within d² 0.9 (instead of 4.0), track 9 would have taken m4")


def test_the_track_that_had_the_object_gets_its_own_cost_when_it_was_not_the_next_best() -> None:
    """Tracks 5, 9, 11 (PMB terms) gate m4; 5 wins, 9 is next best; track 11's cost is read by its id."""
    r = np.array([0.9, 0.5, 0.05])
    terms = CostTerms(
        existence=r,
        miss_log_lik=np.log1p(-r * 0.8),
        score=np.array([0.5]),
        d2=np.array([[0.5], [1.0], [0.2]]),
        log_det_S=np.zeros(3),
        dim=2,
        track_ids=np.array([5, 9, 11]),
    )
    costs = [terms.pair(0, k).total_nats for k in range(3)]
    assert costs[0] < costs[1] < costs[2]
    rows = (AxisLabel(AxisKind.MEASUREMENT, 4),)
    cols = (*(AxisLabel(AxisKind.TRACK, t) for t in (5, 9, 11)), AxisLabel(AxisKind.NEW_TRACK, 4))
    matrix = CostMatrix("car", np.array([[*costs, 8.0]]), rows, cols, terms=terms)
    assignment = Assignment("car", ((rows[0], cols[0]),), costs[0], (9, 11))
    (choice,) = explain(matrix, assignment).conflicts[0].choices
    assert choice.alternative == cols[1] and terms.column_of(11) == 2 and terms.column_of(7) is None
    why = track_why(choice, 11, ", which had the object,", would_take(matrix, assignment, 4, 11))
    assert why.startswith(f"Track 11, which had the object, would have cost {costs[2]:.2f} = ")
    needed = math.ceil(terms.pair(0, 2).existence_for(costs[2] - costs[0]) * 100) / 100
    assert why.endswith(
        f"With a predicted existence above {needed:.2f} (instead of 0.05), track 11 would have taken m4"
    )
    assert track_why(choice, 7) is None


def test_the_parts_of_a_cost_are_rounded_so_that_they_add_up_to_the_cost_shown() -> None:
    from gnnpmb.why.words import hundredths_summing_to

    parts = [3.014, 3.784, 0.054, 0.234]  # rounded one by one: 3.01 + 3.78 + 0.05 + 0.23 = 7.07, not 7.09
    shown = hundredths_summing_to(parts, sum(parts))
    assert round(sum(shown), 2) == round(sum(parts), 2) == 7.09
    assert all(abs(a - b) < 0.01 for a, b in zip(shown, parts, strict=True))  # each moved by under a hundredth
    assert hundredths_summing_to([-1.005, 2.004], 0.999) == [-1.0, 2.0]


def test_frame_lists_join_consecutive_runs_of_three_or_more() -> None:
    assert frames_text([7]) == "frame 7"
    assert frames_text([13, 7]) == "frames 7, 13"
    assert frames_text([12, 13, 14, 16]) == "frames 12–14, 16"
    assert frames_text([9, 10, 15, 16]) == "frames 9, 10, 15, 16"


def test_the_decision_legend_says_a_new_column_holds_the_threshold() -> None:
    """ab3dmot's grid: its "new" column holds 0.90 = 1 - 3D IoU 0.10, the threshold, not a new track's cost (the
    focus text said "over new (3D IoU 0.10)" of the same entry)."""
    iou = CostScale("1 - 3D IoU", "3D IoU", 0.05, True, threshold=0.9, similarity="3D IoU")
    (note,) = _scale_notes([SimpleNamespace(scale=iou)])
    assert "**new** holds the threshold 0.9 = 1 − 3D IoU 0.1: the detection starts a track unless a track is" in note
    metres = CostScale("distance", "m", 0.5, False, threshold=2.0)
    (note,) = _scale_notes([SimpleNamespace(scale=metres)])
    assert "**new** holds the threshold 2 m: the detection starts a track unless a track is closer" in note
