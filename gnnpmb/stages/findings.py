"""Stage 5, the findings: what the evaluation's failures mean, from the runs' facts (``gnnpmb.why``); the focus,
a selection of one failure (``gnnpmb.focus``); where a full recording opens; and where runs disagree
(``gnnpmb.compare``)."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import TYPE_CHECKING

from gnnpmb.errors import GnnpmbError
from gnnpmb.stages.inputs import Inputs
from gnnpmb.stages.runs import Run

if TYPE_CHECKING:
    from gnnpmb.compare import Comparison
    from gnnpmb.eval.failures import FailureReport
    from gnnpmb.focus import FocusTarget
    from gnnpmb.why.findings import Finding
    from gnnpmb.why.reason import Evidence


def evidence_of(inputs: Inputs, report: FailureReport, run: Run) -> Evidence:
    """The ``why.reason.Evidence`` of one recorded run: with a results file, how each box was placed on a
    detection."""
    from gnnpmb.why.reason import Evidence

    if run.facts is None:
        raise ValueError(f"run {run.name} was not recorded: its failures cannot be explained")
    foreign = inputs.foreign.get(run.name)
    path = Path(inputs.source.path) if inputs.source.kind == "file" and inputs.source.path else None
    return Evidence(report, run.facts, run.tracking, foreign.boxes_on if foreign is not None else {}, path)


def all_evidence(inputs: Inputs, runs: Sequence[Run], reports: Mapping[str, FailureReport]) -> dict[str, Evidence]:
    """The evidence of every run that has a failure report, by name."""
    return {run.name: evidence_of(inputs, reports[run.name], run) for run in runs if run.name in reports}


def explain_all(inputs: Inputs, evidence: Mapping[str, Evidence]) -> dict[str, list[Finding]]:
    """Per run, the finding of each of its failures (in ``FailureReport.ids`` order), the other runs' evidence
    beside it."""
    from gnnpmb.why.findings import FRAMES_BEFORE
    from gnnpmb.why.reason import explain_failure

    out = {}
    start = inputs.frame_range.start
    for tracker, ev in evidence.items():
        others = [o for t, o in evidence.items() if t != tracker]
        out[tracker] = [
            explain_failure(fid, ev, inputs.scene, others, first_frame=max(start, f.frame_index - FRAMES_BEFORE))
            for fid, f in zip(ev.report.ids(), ev.report.failures, strict=True)
        ]
    return out


def explain_focus(
    inputs: Inputs, focus: FocusTarget, evidence: Mapping[str, Evidence], first_frame: int
) -> Finding | None:
    """The finding of the focus failure (None when the focus is not a failure of a run with evidence)."""
    from gnnpmb.why.reason import explain_failure

    if focus.failure_id is None or focus.failure_tracker not in evidence:
        return None
    owner = evidence[focus.failure_tracker]
    others = [ev for t, ev in evidence.items() if t != focus.failure_tracker]
    return explain_failure(focus.failure_id, owner, inputs.scene, others, first_frame=first_frame)


def _estimates(runs: Sequence[Run]) -> dict:
    return {run.name: [f.estimates for f in run.tracking.frames] for run in runs}


def where_to_open(
    inputs: Inputs, runs: Sequence[Run], reports: Mapping[str, FailureReport], notices: Sequence[str]
) -> FocusTarget | None:
    """Where a recording opens: the focus ``inputs.focus`` names in these runs (raises a one-line GnnpmbError when
    it names nothing), else the first failure worth a look of the first run (``FailureReport.first_worth_opening``)
    as a focus target; None without a focus when there is no failure or no ground truth."""
    from gnnpmb.focus import opening_focus, resolve_focus

    estimates = _estimates(runs)
    if inputs.focus is not None:
        if not reports and not inputs.focus.startswith("track:"):
            raise GnnpmbError(f"--focus {inputs.focus} needs ground truth: {'; '.join(notices)}")
        return resolve_focus(inputs.focus, inputs.scene, reports, estimates, inputs.frame_range)
    return opening_focus(inputs.scene, reports, estimates, inputs.frame_range)


def compare_runs(runs: Sequence[Run]) -> Comparison:
    """Per-frame disagreements between runs over the same keyframes (``gnnpmb.compare``), between the tracks the
    viewer draws (existence at least ``why.words.SHOW_MIN_EXISTENCE``)."""
    from gnnpmb.compare import compare_trackers
    from gnnpmb.why.words import SHOW_MIN_EXISTENCE

    frames = runs[0].tracking.frames
    return compare_trackers(
        [f.keyframe.gt for f in frames],
        {run.name: [tuple(f.estimates) for f in run.tracking.frames] for run in runs},
        frame_indices=[f.keyframe.index for f in frames],
        show_min_existence=SHOW_MIN_EXISTENCE,
    )
