"""``gnnpmb failures``: one scene's failure reports (and, with --why, the findings), through the stages of
``gnnpmb.stages`` (request → inputs → runs → evaluation → findings), printed as tables or written as JSON.
Registered on the ``gnnpmb`` app by ``cli.batch``. No ``from __future__ import annotations`` here: typer must
evaluate the option annotations inside ``register``."""

from collections import defaultdict
from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Annotated

import typer

from cli.options import (
    DEFAULT_SOURCE,
    ResultsOption,
    RunsOption,
    SceneArgument,
    Source,
    source_options,
    stdout_console,
)
from gnnpmb.errors import GnnpmbError
from gnnpmb.outputs import check_output_file
from gnnpmb.stages.request import DEFAULT_TRACKER

if TYPE_CHECKING:
    from rich.console import Console

    from gnnpmb.eval.failures import FailureReport
    from gnnpmb.stages.inputs import Inputs
    from gnnpmb.why.findings import Finding


def register(app: typer.Typer) -> None:
    """Add the ``failures`` command to ``app``."""

    @app.command(short_help="List one scene's tracking failures per frame.")
    @source_options
    def failures(
        scene: SceneArgument,
        tracker: RunsOption = None,
        results: ResultsOption = None,
        source: Source = DEFAULT_SOURCE,
        json_out: Annotated[
            Path | None, typer.Option("--json", metavar="FILE.json", help="Also write the report as JSON here.")
        ] = None,
        why: Annotated[
            bool,
            typer.Option(
                "--why", help="Explain each failure: whose doing, why and because (with --json: the typed findings)."
            ),
        ] = False,
        each: Annotated[
            bool,
            typer.Option(
                "--each",
                help="With --why: every finding's sentences in full, one finding after another (by default a run of "
                "findings of one object or track that say the same but for per-frame values is printed once).",
            ),
        ] = False,
        frames: Annotated[
            str | None,
            typer.Option(
                metavar="START:END",
                help="Track and evaluate only keyframes START:END (END exclusive), as gnnpmb-viz --frames does; the "
                "ids are those gnnpmb-viz --frames START:END --focus takes.",
            ),
        ] = None,
        classes: Annotated[
            str | None,
            typer.Option(
                metavar="CLASS,...",
                help="Track and evaluate only these classes (default all), as gnnpmb-viz --classes does; the ids are "
                "those gnnpmb-viz --classes CLASS,... --focus takes.",
            ),
        ] = None,
    ) -> None:
        """Track one scene and list its failures per frame: ID switches, fragmentations, false tracks, misses,
        coalescence and cascading identity theft (scored with the devkit's own matching). With several runs (--tracker,
        --results) each is listed in turn; --why explains each failure beside the others."""
        from gnnpmb.runs import parse_runs, run_inputs

        if each and not why:
            raise GnnpmbError("--each prints the findings of --why in full: add --why")
        runs = parse_runs(tracker or [], results or [], default=DEFAULT_TRACKER)
        inputs = (*source.input_files, *run_inputs(runs))
        json_target = check_output_file(json_out, "--json", inputs=inputs) if json_out is not None else None
        reports, findings, loaded = failure_reports(
            scene,
            tracker or [],
            results or [],
            source,
            why=why,
            frames=frames,
            classes=classes,
        )
        foreign = {name: r.original_ids for name, r in loaded.foreign.items() if r.original_ids}
        if json_target is not None:
            from gnnpmb.eval.submission import write_json

            write_json(json_target, _report_json(reports, findings, foreign))
        console = stdout_console()
        for name, report in reports.items():
            print_report(report, console)
            if why:
                print_findings(findings[name], console, each=each)
        if json_out is not None:
            typer.echo(f"report -> {json_out}")


def failure_reports(
    scene: str,
    trackers: Sequence[str],
    results: Sequence[str],
    source: Source,
    *,
    why: bool,
    frames: str | None = None,
    classes: str | None = None,
) -> "tuple[dict[str, FailureReport], dict[str, list[Finding]], Inputs]":
    """Every run's failure report on ``scene`` in order, its findings (with ``why``; each explained with the
    other runs' evidence beside it) and the loaded inputs; notices go to stderr. Raises a one-line error when
    the scene cannot be evaluated (no ground truth, in no split). frames: ``--frames START:END``, the keyframes
    tracked and evaluated; classes: ``--classes a,b``, the classes tracked and evaluated."""
    import typer

    from gnnpmb.stages.evaluation import find_reports
    from gnnpmb.stages.findings import all_evidence, explain_all
    from gnnpmb.stages.inputs import load_inputs
    from gnnpmb.stages.request import check_request
    from gnnpmb.stages.runs import run_all

    request = check_request(
        scene,
        trackers,
        results=results,
        **source.request_args(),
        frames=frames,
        classes=classes,
    )
    inputs = load_inputs(request)
    for notice in inputs.notices:
        typer.echo(f"note: {notice}", err=True)
    runs = run_all(inputs, record=why)
    reports, notices = find_reports(inputs, runs)
    if not reports:
        raise GnnpmbError("; ".join(notices) or f"{scene} cannot be evaluated")
    findings = explain_all(inputs, all_evidence(inputs, runs, reports)) if why else {}
    return reports, findings, inputs


def _report_json(reports: dict, findings: dict, track_names: dict) -> dict:
    """The first run's report (and findings), the other runs' under ``other_runs``; a results file's renumbered
    ids under ``track_names`` (``track_names``: run -> track id -> the file's id)."""
    from gnnpmb.why.serialize import finding_json

    def one(name: str) -> dict:
        data = reports[name].to_json()
        if name in findings:
            data["findings"] = [finding_json(f) for f in findings[name]]
        if name in track_names:
            data["track_names"] = {str(t): i for t, i in track_names[name].items()}
        return data

    first, *rest = reports
    data = one(first)
    if rest:
        data["other_runs"] = [one(name) for name in rest]
    return data


def print_findings(findings: list, console: "Console", *, each: bool = False) -> None:
    """Each failure's finding: its id and whose doing, then its Why and Because lines (``why.words``); findings
    of one subject at consecutive frames that say the same but for per-frame values are printed once
    (``why.runs``), and a comparison the subject's previous finding gave word for word is not repeated. each:
    every finding in full, on its own."""
    from gnnpmb.why.runs import Run, group, run_lines, said

    everything = [said(f) for f in findings]
    runs = [Run((s,), (None,) * len(s.comparisons)) for s in everything] if each else group(everything)
    for run in runs:
        head, *lines = run_lines(run)
        console.print(head, highlight=False, soft_wrap=True)
        for line in lines:
            console.print(f"  {line}", highlight=False, soft_wrap=True)
    if len(runs) < len(findings) or any(a is not None for r in runs for a in r.as_for):
        console.print(
            "(findings alike but for the <values> given per frame are printed once; 'T: as for ID': run T fared as "
            "finding ID says; every finding is in --json, and each id opens with gnnpmb-viz SCENE --focus ID)",
            highlight=False,
            soft_wrap=True,
        )


def print_report(report: "FailureReport", console: "Console") -> None:
    """The failure report as two tables: per class at its best-MOTA threshold, then failures per frame."""
    from rich.table import Table

    from gnnpmb.eval.failures import FailureKind
    from gnnpmb.eval.nuscenes_eval import format_metric

    classes = Table(title=f"{report.tracker} on {report.scene_name}: devkit counts at the best-MOTA threshold")
    for name in ("class", "threshold", "MOTA", "TP", "FP", "FN", "IDS", "FRAG"):
        classes.add_column(name, justify="left" if name == "class" else "right")
    for c in report.classes:
        threshold = "all" if c.threshold is None else f"{c.threshold:.3f}"
        counts = (format_metric(m, getattr(c, m)) for m in ("tp", "fp", "fn", "ids", "frag"))
        classes.add_row(c.class_name, threshold, format_metric("mota", c.mota), *counts)
    console.print(classes)
    for c in report.classes:
        if c.threshold is None and any(f.class_name == c.class_name for f in report.failures):
            console.print(
                f"{c.class_name}: no score threshold reached the evaluation's lowest recall, so it counts every "
                f"{c.class_name} box missed and no false track, ID switch or fragmentation ('-'); the "
                f"{c.class_name} failures below are what matching every box finds, outside those counts",
                highlight=False,
                soft_wrap=True,
            )

    grouped: dict[tuple[int, FailureKind], list[tuple[str, str]]] = defaultdict(list)
    for failure_id, f in zip(report.ids(), report.failures, strict=True):
        grouped[(f.frame_index, f.kind)].append((failure_id, f.describe()))
    rows = Table(title="failures per frame (open one: gnnpmb-viz SCENE --tracker T --focus ID)")
    rows.add_column("frame", justify="right")
    rows.add_column("id")
    rows.add_column("what (GT ids shortened to 6 characters)")
    for (frame, _kind), entries in grouped.items():
        rows.add_row(str(frame), _id_span([i for i, _ in entries]), "; ".join(text for _, text in entries))
    console.print(rows)
    totals = f"{report.scene_name}, {report.tracker}{report.scope_text()}: {report.totals_text()}"
    console.print(totals, highlight=False, soft_wrap=True)


def _id_span(ids: list[str]) -> str:
    """``miss:3`` or ``miss:3-7`` for the ids of one kind in one frame (numbered consecutively)."""
    return ids[0] if len(ids) == 1 else f"{ids[0]}-{ids[-1].split(':')[1]}"
