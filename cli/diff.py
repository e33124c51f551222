"""``gnnpmb diff A B``: what changed from run A to run B on a scene or a split (``gnnpmb.diff``).

A and B are run spellings (``gnnpmb.runs``): ``gnnpmb``, ``gnnpmb:paper.toml``, ``mine=results.json``. The command
prints the failures fixed, introduced and kept per kind and class, each fixed or introduced one with its id and the
``gnnpmb-viz`` command that opens it beside the other run, and the per-class metric deltas; ``--json`` writes it
all for scripts.
"""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Annotated

import typer

from cli.options import DEFAULT_SOURCE, Source, source_options
from gnnpmb.errors import GnnpmbError, NotThisDatasetError
from gnnpmb.outputs import check_output_file

if TYPE_CHECKING:
    from rich.console import Console

    from gnnpmb.data.nuscenes import DatasetLocation
    from gnnpmb.diff import DiffEntry, DiffResult

DIFF_HELP = (
    "Compare two runs on the same detections: the failures B fixed, introduced and kept (matched by kind, frame "
    "and object or place, not by track ids), each with a --focus id, and the per-class metric deltas.\n\n"
    "A and B: a tracker (gnnpmb), a tracker with its own parameters (gnnpmb:paper.toml) or a results file "
    "(mine=results.json). Examples: gnnpmb diff gnnpmb:gnnpmb/params/paper.toml gnnpmb --split mini_val; "
    "gnnpmb diff mine=results.json gnnpmb --scene scene-0103."
)
RunArgument = Annotated[
    str, typer.Argument(metavar="RUN", help="TRACKER, TRACKER:PARAMS.toml or NAME=FILE.json.", show_default=False)
]


def _results_split_hint(location: DatasetLocation, runs: tuple[str, str], split: str) -> str:
    """Where a results run's file holds exactly another split's samples: which split (``split_hint``)."""
    from gnnpmb.eval.nuscenes_eval import split_hint
    from gnnpmb.eval.submission import read_submission
    from gnnpmb.runs import parse_run

    for spec in (parse_run(r) for r in runs):
        if spec.results is not None:
            hint = split_hint(location, read_submission(spec.results).get("results"), split)
            if hint:
                return hint
    return ""


def register(app: typer.Typer) -> None:
    """Add ``diff`` to the ``gnnpmb`` app."""
    app.command("diff", help=DIFF_HELP, short_help="What changed between two runs: failures and metrics.")(
        source_options(diff)
    )


def diff(
    a: RunArgument,
    b: RunArgument,
    scene: Annotated[str | None, typer.Option(metavar="SCENE", help="One scene (default: the whole split).")] = None,
    split: Annotated[
        str | None,
        typer.Option(metavar="NAME", help="Split (default: mini_val, val or test by --nuscenes-version)."),
    ] = None,
    source: Source = DEFAULT_SOURCE,
    json_out: Annotated[
        Path | None, typer.Option("--json", metavar="FILE.json", help="Also write the diff as JSON here.")
    ] = None,
) -> None:
    """``DIFF_HELP``."""
    from cli.options import stdout_console
    from gnnpmb.data.nuscenes import all_sample_tokens, resolve_dataroot, sample_tokens, split_scenes
    from gnnpmb.eval.nuscenes_eval import default_split
    from gnnpmb.runs import parse_run, run_inputs
    from gnnpmb.stages.diff import diff_runs
    from gnnpmb.stages.inputs import load_inputs
    from gnnpmb.stages.request import check_request

    inputs = (*source.input_files, *run_inputs([parse_run(a), parse_run(b)]))
    target = check_output_file(json_out, "--json", inputs=inputs) if json_out is not None else None
    if scene is not None and split is not None:
        raise GnnpmbError("pass either --scene SCENE or --split NAME, not both")
    if source.detections is not None and source.detector is not None:
        raise GnnpmbError("pass either --detections FILE.json or --detector PRESET, not both")
    location = resolve_dataroot(source.dataroot, source.version, tuple(x for x in (scene, split) if x))
    if scene is not None:
        scenes, where = [scene], scene
    else:
        split = split or default_split(location.version)
        scenes, where = split_scenes(split, location), f"split {split}"
        if not scenes:
            raise GnnpmbError(f"split {split} has no scenes in {location.dataroot / location.version}")
    try:
        result = diff_runs(
            a,
            b,
            scenes,
            where,
            scene_inputs=lambda name, runs: load_inputs(check_request(name, runs, **source.request_args())),
            split_tokens=sample_tokens(location, scenes),  # an unknown scene is one line here
            dataset_tokens=all_sample_tokens(location),
        )
    except NotThisDatasetError as exc:
        hint = _results_split_hint(location, (a, b), split) if scene is None and split is not None else ""
        raise NotThisDatasetError(f"{exc}{hint}") from None
    options = source.shell_words()
    for notice in result.notices:
        typer.echo(f"note: {notice}", err=True)
    if target is not None:
        from gnnpmb.eval.submission import write_json

        write_json(target, diff_json(result, options))
    print_diff(result, options, stdout_console())
    if json_out is not None:
        typer.echo(f"diff -> {json_out}")


def focus_command(result: DiffResult, entry: DiffEntry, options: str) -> str:
    """The ``gnnpmb-viz`` command that opens ``entry`` with A and B side by side."""
    runs = f"{result.a.option()} {result.b.option()}"
    return " ".join(x for x in ("gnnpmb-viz", entry.scene, runs, options, f"--focus {entry.diff_id}") if x)


def diff_json(result: DiffResult, options: str) -> dict:
    """The diff for scripts: the runs, where, every change (with its command), counts and metric deltas."""
    from gnnpmb.diff import Change, counts_table

    def number(x: float) -> float | None:
        return None if x != x else float(x)

    return {
        "a": result.a.text(),
        "b": result.b.text(),
        "where": result.where,
        "scenes": list(result.scenes),
        "totals": {c.value: len(result.of(c)) for c in Change},
        "counts": [
            {"kind": k, "class_name": c, "fixed": f, "introduced": i, "kept": kept}
            for k, c, f, i, kept in counts_table(result.entries)
        ],
        "changes": [{**e.to_json(), "command": focus_command(result, e, options)} for e in result.entries],
        "metrics": [
            {
                "class_name": m.class_name,
                "metric": m.metric,
                "a": number(m.a),
                "b": number(m.b),
                "delta": number(m.delta),
            }
            for m in result.metrics
        ],
        "notices": list(result.notices),
    }


def print_diff(result: DiffResult, options: str, console: Console) -> None:
    """The counts per kind and class, the fixed and introduced failures with their ids (one object's failures over
    consecutive frames on one row), the metrics per class and a summary line."""
    from rich.table import Table

    from gnnpmb.diff import Change, counts_table, grouped
    from gnnpmb.why.words import frames_text

    a, b = result.a.name, result.b.name
    counts = Table(title=f"failures from A = {a} to B = {b} on {result.where}, per kind and class")
    for name in ("kind", "class", "fixed by B", "introduced by B", "kept"):
        counts.add_column(name, justify="left" if name in ("kind", "class") else "right")
    for row in counts_table(result.entries):
        counts.add_row(*map(str, row))
    console.print(counts)
    shown = [e for e in result.entries if e.change is not Change.KEPT]
    changes = Table(title="fixed and introduced failures, association errors first (open one: the command below)")
    for name in ("scene", "id", "frames", "kind", "what", f"in A ({a})", f"in B ({b})"):
        changes.add_column(name)
    for group in grouped(shown):
        first, last = group[0], group[-1]
        ids = first.diff_id if len(group) == 1 else f"{first.diff_id}-{last.diff_id.rsplit(':', 1)[1]}"
        runs = [_span([e.before for e in group]), _span([e.after for e in group])]
        instead = list(dict.fromkeys(i for e in group for i in e.instead))
        if instead:  # the run without the failure had another one about the same object there
            runs[1 if first.change is Change.FIXED else 0] += f" ({_span(instead)} there instead)"
        what = first.what if len(group) == 1 else f"{first.what.split(' (', 1)[0]} ({len(group)} frames)"
        changes.add_row(
            first.scene, ids, frames_text(e.frame for e in group).split(" ", 1)[1], first.kind.value, what, *runs
        )
    console.print(changes)
    metrics = Table(title="metrics per class, A -> B (devkit; the counts at each run's best-MOTA threshold)")
    metrics.add_column("class")
    for name in _TABLE_METRICS:
        metrics.add_column(name.upper(), justify="right")
    by = {(m.class_name, m.metric): m for m in result.metrics}
    for cls in dict.fromkeys(m.class_name for m in result.metrics):
        metrics.add_row(cls, *(_cell(by[(cls, name)]) for name in _TABLE_METRICS), end_section=cls == "overall")
    console.print(metrics)
    for scene in result.scenes:
        first = next((e for e in shown if e.scene == scene and e.change is Change.INTRODUCED), None)
        first = first or next((e for e in shown if e.scene == scene), None)
        if first is not None:
            console.print(
                f"open {first.diff_id} on {scene}: {focus_command(result, first, options)}",
                highlight=False,
                soft_wrap=True,
            )
    amota = by[("overall", "amota")]
    console.print(
        f"{b} against {a} on {result.where}: {len(result.of(Change.FIXED))} failures fixed, "
        f"{len(result.of(Change.INTRODUCED))} introduced, {len(result.of(Change.KEPT))} kept; AMOTA "
        f"{amota.a:.3f} -> {amota.b:.3f} ({amota.delta:+.3f})",
        highlight=False,
        soft_wrap=True,
    )


_TABLE_METRICS = ("amota", "mota", "ids", "frag", "fp", "fn")
"""The metrics of the printed table (every ``gnnpmb.diff.DIFF_METRICS`` is in --json)."""


def _span(ids: list[str | None]) -> str:
    """``miss:3`` or ``miss:3 … miss:40`` for the run's own ids of a group (not consecutive: the run numbers its
    failures by frame; "-": it does not have them)."""
    if ids[0] is None:
        return "-"
    return ids[0] if len(ids) == 1 else f"{ids[0]} … {ids[-1]}"


def _cell(m) -> str:
    """``0.749 → 0.957 (+0.208)``; ``8 → 0 (-8)``; a trailing ``!`` where B is worse."""
    from gnnpmb.eval.nuscenes_eval import COUNT_METRICS, format_metric

    if m.delta != m.delta:
        return f"{format_metric(m.metric, m.a)} → {format_metric(m.metric, m.b)}"
    delta = f"{m.delta:+.0f}" if m.metric in COUNT_METRICS else f"{m.delta:+.3f}"
    worse = " !" if m.better is False else ""
    return f"{format_metric(m.metric, m.a)} → {format_metric(m.metric, m.b)} ({delta}){worse}"
