"""Sentences of the focus summary worked out from a failure report (``viz.focus_summary``)."""

from __future__ import annotations

from gnnpmb.eval.failures import ClassEvaluation, FailureReport
from viz.focus_summary import _counted_unshown


def report(track_scores: dict[str, float], threshold: float | None = 0.037) -> FailureReport:
    classes = (ClassEvaluation("bicycle", threshold, 0.5, 1.0, 0.0, 1.0, 1.0, 0.0),)
    return FailureReport("scene-x", "gnnpmb", ("t0",), classes, (), track_scores=track_scores)


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
