"""``gnnpmb sweep``: a parameter grid scored with the official evaluation, on Ray, and what ``gnnpmb tune``
(``cli.tune``) shares with it.

Registered on the ``gnnpmb`` app by ``cli.batch`` (``register``; this module imports nothing of ``cli.batch``);
the work is in ``gnnpmb.study``. No
``from __future__ import annotations`` here: typer must evaluate the option annotations inside ``register``.
"""

import tomllib
from pathlib import Path
from typing import Annotated, Any

import typer
from rich.progress import Progress
from rich.table import Table

from cli.errors import announce_stop
from cli.options import (
    DEFAULT_SOURCE,
    AddressOption,
    ProgressOption,
    Source,
    SplitOption,
    TrackerOption,
    VerboseOption,
    source_options,
    stdout_console,
)
from cli.progress import progress_bar
from gnnpmb.stages.request import DEFAULT_DETECTOR, DEFAULT_TRACKER

WorkersOption = Annotated[
    int | None,
    typer.Option(
        metavar="N",
        help="Parallel tasks (default: the CPU count; on a cluster, all its CPUs); 1 runs in this process without Ray.",
    ),
]


def base_params(params: Path | None) -> dict[str, Any]:
    """The ``--params`` file as a TOML dict (checked by the config loader first); empty without one."""
    from gnnpmb.config import load_config

    if params is None:
        return {}
    load_config(params)
    return tomllib.loads(params.read_text(encoding="utf-8"))


def train_split(version: str) -> str:
    """The split parameters are tuned on by default: mini_train for *mini versions, else train."""
    return "mini_train" if version.endswith("mini") else "train"


def study_progress(enabled: bool, total: int, what: str) -> Progress:
    bar = progress_bar(enabled, transient=True)
    bar.add_task(f"{what}, best AMOTA -", total=total)
    return bar


def best_label(what: str, best: float | None) -> str:
    return f"{what}, best AMOTA {'-' if best is None else f'{best:.3f}'}"


def metric_text(value: Any, digits: int = 3) -> str:
    if value is None:
        return "-"
    if isinstance(value, float) and not value.is_integer():
        return f"{value:.{digits}f}"
    return f"{value:g}" if isinstance(value, float) else str(value)


def _value(value: Any) -> str:
    """A swept value in the table (``base`` where the key kept its base value)."""
    if value is None:
        return "base"
    return f"{value:g}" if isinstance(value, float) else str(value)


def best_table(rows: list[dict[str, Any]], keys: tuple[str, ...], title: str) -> Table:
    """The best rows as a rich table: configuration, swept values, official metrics, wall time."""
    from gnnpmb.study.evaluate import OVERALL_METRICS

    table = Table(title=title)
    table.add_column("config", justify="right")
    for key in keys:
        table.add_column(key, justify="right")
    for metric in OVERALL_METRICS:
        table.add_column(metric.upper(), justify="right")
    table.add_column("wall s", justify="right")
    for row in rows:
        values = [_value(row[k]) for k in keys]
        table.add_row(
            str(row["config"]), *values, *(metric_text(row[m]) for m in OVERALL_METRICS), f"{row['wall_time_s']:.1f}"
        )
    return table


def register(app: typer.Typer) -> None:
    """Add ``sweep`` to the ``gnnpmb`` app."""

    @app.command()
    @source_options
    def sweep(
        out: Annotated[Path, typer.Option(metavar="DIR", help="Folder for results.csv/.json, plots and the cache.")],
        param: Annotated[
            list[str] | None,
            typer.Option(
                metavar="KEY=V1,V2",
                help=(
                    "A swept key and its values (repeatable): pmb.gate_chi2=20,40, car.q_x=0.1,0.2, *.r_x=0.05,0.1 "
                    "(keys, units, ranges: docs/parameters.md)."
                ),
            ),
        ] = None,
        tracker: TrackerOption = DEFAULT_TRACKER,
        source: Source = DEFAULT_SOURCE,
        split: SplitOption = None,
        one_at_a_time: Annotated[
            bool,
            typer.Option(help="Vary one key at a time around the base parameters (Table II style), not the grid."),
        ] = False,
        workers: WorkersOption = None,
        address: AddressOption = None,
        top: Annotated[int, typer.Option(metavar="N", help="Rows in the table of best configurations.")] = 10,
        progress: ProgressOption = True,
        verbose: VerboseOption = False,
    ) -> None:
        """Score every configuration of a parameter grid with the official evaluation (cached, resumable)."""
        from gnnpmb.data.simdet_presets import detector_choice
        from gnnpmb.eval.result_cache import ResultCache
        from gnnpmb.registry import check_tracker
        from gnnpmb.study.cache import CACHE_FOLDER
        from gnnpmb.study.folder import check_study_dir, drop_stale_plots, identity, merge_study, read_study
        from gnnpmb.study.grid import parse_param
        from gnnpmb.study.lock import hold_study_folder
        from gnnpmb.study.plots import plot_sweep
        from gnnpmb.study.results import best_amota, best_rows, write_results
        from gnnpmb.study.runner import execution, session
        from gnnpmb.study.sweep import plan_sweep, run_sweep

        check_tracker(tracker)
        preset = detector_choice(source.detections, source.detector, DEFAULT_DETECTOR)
        swept = [parse_param(p) for p in param or []]
        base = base_params(source.params)
        folder = check_study_dir(out, [p.key for p in swept], source.input_files)
        run = execution(workers, address, verbose)
        data = source.split_data(split, preset)
        plan = plan_sweep(tracker, data, base, swept, one_at_a_time)
        rows_seen: list[dict[str, Any]] = []
        with session(run):  # Ray is up (or one error line) before the folder is touched
            hold_study_folder(folder, lambda line: typer.echo(line, err=True))  # one sweep at a time per folder
            plan, note = merge_study(plan, read_study(folder), out, source.params)
            if note is not None:
                typer.echo(note, err=True)
            n = len(plan.assignments)
            with study_progress(progress, n, "configurations") as bar:  # the bar once Ray is up

                def on_row(row: dict[str, Any], from_cache: bool) -> None:
                    rows_seen.append(row)
                    task = bar.task_ids[0]
                    bar.update(task, advance=1, description=best_label("configurations", best_amota(rows_seen)))

                outcome = run_sweep(plan, ResultCache(folder / CACHE_FOLDER), run, on_row)
        meta = {
            **identity(plan, source.params),
            "keys": list(plan.keys),
            "one_at_a_time": plan.one_at_a_time,
            "base_values": plan.base_values,
            "configurations": n,
        }
        rows = outcome.rows
        if rows:
            write_results(folder, plan.keys, rows, meta)
            title = f"{tracker} on {data.split} ({len(data.scene_names)} scenes, {meta['detector'] or 'file'})"
            plot_sweep(folder, plan.keys, rows, plan.base_values, plan.one_at_a_time, title)
            drop_stale_plots(folder, plan.keys)
            console = stdout_console()
            console.print(best_table(best_rows(rows, top), plan.keys, f"best of {len(rows)} configurations"))
        ran = len(rows) - outcome.from_cache
        best = best_amota(rows)
        typer.echo(
            f"sweep: {len(rows)} of {n} configurations ({outcome.from_cache} from cache, {ran} run), "
            f"best AMOTA {'-' if best is None else f'{best:.3f}'} -> {out}"
        )
        if outcome.interrupted:
            left = f"{n - len(rows)} configurations left; run the same command again to resume"
            announce_stop(left)
            raise typer.Exit(130)
