"""Sentences of the focus summary worked out from a failure report (``viz.focus_summary``)."""

from __future__ import annotations

from gnnpmb.eval.failures import ClassEvaluation, Failure, FailureKind, FailureReport
from viz.focus_summary import _counted_unshown, _first_false


def report(
    track_scores: dict[str, float], threshold: float | None = 0.037, failures: tuple[Failure, ...] = ()
) -> FailureReport:
    classes = (ClassEvaluation("bicycle", threshold, 0.5, 1.0, 0.0, 1.0, 1.0, 0.0),)
    tokens = tuple(f"t{i}" for i in range(25))
    return FailureReport("scene-x", "gnnpmb", tokens, classes, failures, track_scores=track_scores)


def test_a_track_too_unlikely_to_be_shown_is_said_to_count_when_its_average_reaches_the_threshold() -> None:
    (line,) = _counted_unshown(26, report({"26": 0.037}), "bicycle", 0.5)
    assert line == (
        "too low for track 26 to be shown here (existence below 0.5), yet the evaluation counted it: its score "
        "averaged over all its frames, 0.037, is exactly the bicycle threshold (the lowest score counted)"
    )
    (line,) = _counted_unshown(26, report({"26": 0.2}), "bicycle", 0.5)
    assert line.endswith("its score averaged over all its frames, 0.200, is above the bicycle threshold 0.037")
    assert _counted_unshown(26, report({"26": 0.01}), "bicycle", 0.5) == []  # not counted: nothing to explain
    assert _counted_unshown(26, report({}), "bicycle", 0.5) == []  # not evaluated
    assert _counted_unshown(26, report({"26": 0.2}, threshold=None), "bicycle", 0.5) == []


def test_an_identity_theft_names_the_frames_its_thief_was_a_false_track() -> None:
    def false_track(frame: int, track: str) -> Failure:
        return Failure(FailureKind.FALSE_TRACK, frame, f"t{frame}", "car", (), (track,), ())

    failures = (false_track(17, "315"), false_track(19, "315"), false_track(19, "321"), false_track(21, "315"))
    (line,) = _first_false(report({}, failures=failures), 315, 61, "7b025b" + "0" * 26, 20)
    assert line == (
        "track 315 had been a false track at frames 17, 19 (matched to no object: the evaluation still gave GT "
        "7b025b to track 61), so its taking the object is an identity theft"
    )
    assert _first_false(report({}, failures=failures), 315, 61, "7b025b" + "0" * 26, 17) == []  # none before frame 17


def test_a_tracker_without_existences_gets_no_existence_in_its_track_tables_and_summaries() -> None:
    import rerun as rr

    from viz.focus_summary import _diagnosis, _steps_markdown
    from viz.logger import TrackerLogger, TrackStep

    def logger(has_existence: bool, has_gates: bool = True) -> TrackerLogger:
        out = TrackerLogger(rr.RecordingStream("x"), "gnn", focus_tracks={25}, has_existence=has_existence)
        out.track_steps = {25: {5: TrackStep(1.0, (0.0, 0.0), ((8, 0.3),), 8, 1.0, True)}}
        out.has_gates = has_gates  # set by its first Gated event
        return out

    table = _steps_markdown(logger(False), [25], range(0, 10), 5, "car")
    assert table[2:5] == [
        "| frame | in gate (NIS) | given | shown |",
        "|---|---|---|---|",
        "| 5 | m8 (0.3) | m8 | yes |",
    ]
    assert _diagnosis(logger(False), [25], range(0, 10), 5) == [
        "**track 25**: last given a detection at frame 5 (m8); shown as a track."
    ]
    assert "r before update" in _steps_markdown(logger(True), [25], range(0, 10), 5, "car")[2]
    assert "existence after update 1.00 at frame 5" in _diagnosis(logger(True), [25], range(0, 10), 5)[0]
    greedy = _steps_markdown(logger(False, has_gates=False), [25], range(0, 10), 5, "car")  # no gates either
    assert greedy[2:5] == ["| frame | given | shown |", "|---|---|---|", "| 5 | m8 | yes |"]


def test_a_lost_track_output_away_from_its_object_is_traced_to_the_detections_that_led_it_off() -> None:
    from types import SimpleNamespace

    import numpy as np
    import rerun as rr

    from gnnpmb.focus import FocusTarget
    from viz.focus_summary import _lost_elsewhere
    from viz.logger import TrackerLogger, TrackStep

    class Gt(SimpleNamespace):  # one ground-truth box per frame (``types.Boxes`` has a length)
        def __len__(self) -> int:
            return len(self.instance_id)

    gt_id = "a8b080" + "0" * 26
    gt_x = {9: 10.0, 10: 10.0, 11: 10.0}  # the object stands still at x = 10 m
    det_x = {9: [10.5], 10: [14.0], 11: [15.4]}  # m0 on it at frame 9, then m0 of another object 4 m off
    scene = SimpleNamespace(
        keyframes={
            f: SimpleNamespace(gt=Gt(instance_id=np.array([gt_id]), translation_m=np.array([[x, 0, 0]])))
            for f, x in gt_x.items()
        }
    )
    by_frame = {
        f: SimpleNamespace(
            estimates=[SimpleNamespace(track_id=25, translation_m=(det_x[f][0], 0.0, 0.0))],
            detections=SimpleNamespace(boxes=SimpleNamespace(translation_m=np.array([[x, 0.0, 0.0] for x in xs]))),
        )
        for f, xs in det_x.items()
    }
    logger = TrackerLogger(rr.RecordingStream("x"), "gnn", focus_tracks={25}, has_existence=False)
    logger.track_steps = {25: {f: TrackStep(1.0, (0.0, 0.0), (), 0, 1.0, True) for f in det_x}}
    focus = FocusTarget("t", 11, (10.0, 0.0), "car", {"gnn": (25, 174)}, (gt_id,))
    (line,) = _lost_elsewhere(focus, scene, by_frame, logger, 25)
    assert line == (
        "at frame 11 track 25 was output 5.4 m from GT a8b080, on m0: beyond the evaluation's 2 m, so it no longer "
        "matched the object; it had been given detections 2 m or more from the object at frame 10 (m0)"
    )
    by_frame[11].estimates[0].translation_m = (11.0, 0.0, 0.0)  # within 2 m: still matched, nothing to say
    assert _lost_elsewhere(focus, scene, by_frame, logger, 25) == []
