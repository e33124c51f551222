"""Stage 4, the evaluation: each run's failures found with the devkit's own matching in the tracked keyframes
(``eval.failures``), or read back from an earlier run of the same tracks (``eval.failure_cache``)."""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import TYPE_CHECKING

from gnnpmb.classes import TRACKING_CLASSES
from gnnpmb.errors import DataError
from gnnpmb.stages.inputs import Inputs
from gnnpmb.stages.runs import Run

if TYPE_CHECKING:
    from gnnpmb.eval.failures import FailureReport


def find_reports(
    inputs: Inputs, runs: Sequence[Run], on_done: Callable[[], None] = lambda: None
) -> tuple[dict[str, FailureReport], list[str]]:
    """Each run's failure report, by name, and notices: a scene without ground truth, or one the devkit cannot
    evaluate, gives no reports. Only the tracked classes (``--classes``) are evaluated."""
    from gnnpmb.eval.failure_cache import scene_report
    from gnnpmb.eval.submission import run_results

    scene = inputs.scene
    missing = scene.no_ground_truth()
    if missing is not None:
        return {}, [missing]
    reports = {}
    classes = None if set(TRACKING_CLASSES) <= set(inputs.classes) else inputs.classes
    for run in runs:
        results = run_results(run.tracking)
        try:
            reports[run.name] = scene_report(
                inputs.location, scene.name, run.name, results, inputs.evaluated_keyframes, classes
            )
        except DataError as exc:
            return {}, [f"failure markers skipped: {exc}"]
        on_done()
    return reports, []
