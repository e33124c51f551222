"""``gnnpmb failures``: the failure reports (and, with --why, the findings) of one scene's runs, for the printer."""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING

from gnnpmb.errors import GnnpmbError

if TYPE_CHECKING:
    from gnnpmb.eval.failures import FailureReport
    from gnnpmb.session import ViewRequest
    from gnnpmb.why.findings import Finding


def failure_reports(
    scene: str,
    trackers: Sequence[str],
    results: Sequence[str],
    *,
    dataroot: Path | None,
    version: str | None,
    detections: Path | None,
    detector: str | None,
    seed: int,
    params: Path | None,
    why: bool,
    frames: str | None = None,
) -> tuple[dict[str, FailureReport], dict[str, list[Finding]], ViewRequest]:
    """Every run's failure report on ``scene`` in order, its findings (with ``why``; each explained with the
    other runs' evidence beside it) and the checked request; notices go to stderr. Raises a one-line error when
    the scene cannot be evaluated (no ground truth, in no split). frames: ``--frames START:END``, the keyframes
    tracked and evaluated."""
    import typer

    from gnnpmb.session import explain_all, find_reports, gather_evidence, prepare, rerun_runs

    request = prepare(
        scene,
        trackers,
        results=results,
        dataroot=dataroot,
        version=version,
        detections_file=detections,
        detector=detector,
        seed=seed,
        params=params,
        frames=frames,
    )
    for notice in request.notices:
        typer.echo(f"note: {notice}", err=True)
    if why:
        evidence, notices = gather_evidence(request)
        reports = {name: ev.report for name, ev in evidence.items()}
        findings = explain_all(request, evidence)
    else:
        reports, notices = find_reports(request, rerun_runs(request))
        findings = {}
    if not reports:
        raise GnnpmbError("; ".join(notices) or f"{scene} cannot be evaluated")
    return reports, findings, request
