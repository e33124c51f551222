"""``gnnpmb diff A B``: two runs through the same stages, scene by scene (inputs → runs → evaluation), their
failures matched (``gnnpmb.diff.scene_diff``) and their metrics scored by the devkit: on one scene, the figures
of the accumulation that found each run's failures (``FailureReport.scores``, each run evaluated once); on
several, each run's scenes scored together (the official metrics of a split pick each class's threshold over
all its scenes, the failure reports per scene)."""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import TYPE_CHECKING

from gnnpmb.diff import DiffEntry, DiffResult, metric_deltas, scene_diff
from gnnpmb.errors import GnnpmbError
from gnnpmb.stages.evaluation import find_reports
from gnnpmb.stages.inputs import Inputs, simulated_note
from gnnpmb.stages.runs import run_all

if TYPE_CHECKING:
    from gnnpmb.eval.failures import FailureReport


def diff_runs(
    a: str,
    b: str,
    scenes: Sequence[str],
    where: str,
    *,
    scene_inputs: Callable[[str, list[str]], Inputs],
    split_tokens: Sequence[str],
    dataset_tokens: set[str],
) -> DiffResult:
    """Diff run spellings ``a`` and ``b`` (``runs.parse_run``) over ``scenes`` (``gnnpmb.diff``).
    scene_inputs(scene, runs) -> the loaded inputs of both runs on that scene (the caller's data options);
    split_tokens: every sample of ``scenes`` (a results file must cover them); dataset_tokens: every sample of the
    dataset."""
    from gnnpmb.data.eval_subset import eval_location
    from gnnpmb.data.nuscenes import open_nuscenes
    from gnnpmb.eval.scene_scores import scene_scores
    from gnnpmb.eval.submission import run_results
    from gnnpmb.foreign import check_coverage, read_results
    from gnnpmb.runs import check_runs, parse_run

    specs = check_runs([parse_run(a, "A"), parse_run(b, "B")])
    if len(specs) < 2:
        raise GnnpmbError(f"A and B are the same run ({specs[0].text()}); compare two different runs")
    notices = []
    for spec in specs:
        if spec.results is not None:
            notice = check_coverage(read_results(spec.results), spec.results.name, where, split_tokens, dataset_tokens)
            notices += [notice] if notice else []
    entries: list[DiffEntry] = []
    results: dict[str, dict] = {s.name: {} for s in specs}
    location = None
    scene_reports: list[dict[str, FailureReport]] = []
    for scene in scenes:
        inputs = scene_inputs(scene, [s.text() for s in specs])
        location = inputs.location
        runs = run_all(inputs, record=False)
        reports, problems = find_reports(inputs, runs)
        if len(reports) < 2:
            raise GnnpmbError(f"{scene} cannot be evaluated: {'; '.join(problems)}")
        entries += scene_diff(scene, reports[specs[0].name], reports[specs[1].name])
        scene_reports.append(reports)
        for run in runs:
            results[run.name].update(run_results(run.tracking))
    simulated = simulated_note(inputs.location, inputs.source.preset, inputs.source.seed or 0) if scenes else None
    notices += [simulated] if simulated else []
    one_scene = [scene_reports[0][s.name] for s in specs] if len(scenes) == 1 else []
    shared = [r.scores for r in one_scene if r.scores is not None and r.frames is None]
    if len(shared) == len(specs):
        scores = [s.as_floats() for s in shared]
    else:
        nusc = open_nuscenes(eval_location(location, list(scenes)))  # a version folder of these scenes only
        scores = [scene_scores(nusc, scenes, results[s.name]) for s in specs]
    return DiffResult(
        specs[0], specs[1], where, tuple(scenes), tuple(entries), tuple(metric_deltas(*scores)), tuple(notices)
    )
