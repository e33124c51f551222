"""``gnnpmb tune``: a per-class parameter search (Optuna TPE on Ray Tune) scored with the official evaluation;
the best values are written as a ``--params`` TOML with their provenance. Registered on the ``gnnpmb`` app by
``cli.batch``; the work is in ``gnnpmb.study.tune``. No ``from __future__ import annotations`` here: typer must
evaluate the option annotations inside ``register``.
"""

from pathlib import Path
from typing import TYPE_CHECKING, Annotated, Any

import typer
from rich.console import Console
from rich.table import Table

from cli.errors import announce_stop
from cli.options import (
    DEFAULT_SOURCE,
    AddressOption,
    ProgressOption,
    Source,
    TrackerOption,
    VerboseOption,
    source_options,
    stdout_console,
)
from cli.study import (
    WorkersOption,
    base_params,
    best_label,
    metric_text,
    study_progress,
    train_split,
)
from gnnpmb.errors import GnnpmbError
from gnnpmb.stages.request import DEFAULT_DETECTOR, DEFAULT_TRACKER, parse_classes

if TYPE_CHECKING:
    from gnnpmb.study.data import StudyData
    from gnnpmb.study.runner import Execution
    from gnnpmb.study.tune import SearchDim, TuneResult


def register(app: typer.Typer) -> None:
    """Add ``tune`` to the ``gnnpmb`` app."""

    @app.command()
    @source_options
    def tune(
        out: Annotated[Path, typer.Option(metavar="FILE.toml", help="Where to write the best parameters.")],
        tracker: TrackerOption = DEFAULT_TRACKER,
        trials: Annotated[int, typer.Option(metavar="N", help="Number of trials.")] = 20,
        classes: Annotated[
            str | None,
            typer.Option(metavar="a,b", help="Classes whose per-class parameters are searched (default: all 7)."),
        ] = None,
        space: Annotated[
            list[str] | None,
            typer.Option(
                metavar="KEY=LOW:HIGH[:log]",
                help="Searched key and range (repeatable); replaces the default per-class space.",
            ),
        ] = None,
        source: Source = DEFAULT_SOURCE,
        split: Annotated[
            str | None,
            typer.Option(metavar="NAME", help="Split to tune on (default: mini_train for *mini versions, else train)."),
        ] = None,
        workers: WorkersOption = None,
        address: AddressOption = None,
        progress: ProgressOption = True,
        verbose: VerboseOption = False,
    ) -> None:
        """Search per-class parameters (Optuna TPE on Ray Tune) and write the best as a --params TOML; --seed
        seeds the sampler too."""
        from gnnpmb.data.nuscenes import resolve_dataroot
        from gnnpmb.data.simdet_presets import detector_choice
        from gnnpmb.outputs import check_output_file
        from gnnpmb.registry import check_tracker
        from gnnpmb.study.data import resolve_study_data
        from gnnpmb.study.grid import config_toml
        from gnnpmb.study.runner import execution, session
        from gnnpmb.study.tune import check_space, default_space, parse_space, run_tune, write_params

        check_tracker(tracker)
        target = check_output_file(out, "--out", inputs=source.input_files)
        preset = detector_choice(source.detections, source.detector, DEFAULT_DETECTOR)
        base = base_params(source.params)
        class_names = parse_classes(classes)
        dims = [parse_space(s) for s in space] if space else default_space(class_names, base)
        check_space(dims, base)
        if trials < 1:
            raise GnnpmbError(f"--trials must be at least 1, got {trials}")
        run = execution(workers, address, verbose)
        # the demo generates its train scenes only when asked for them; tuning defaults to a train split
        location = resolve_dataroot(source.dataroot, source.version, (split or "mini_train",))
        data = resolve_study_data(
            location, split or train_split(location.version), source.detections, preset, source.seed
        )
        seen: list[float] = []
        with session(run), study_progress(progress, trials, "trials") as bar:  # the bar once Ray is up

            def on_trial(trial: Any) -> None:
                if trial.row.get("amota") is not None:
                    seen.append(trial.row["amota"])
                bar.update(bar.task_ids[0], advance=1, description=best_label("trials", max(seen, default=None)))

            result = run_tune(tracker, data, base, dims, trials, source.seed, run, on_trial)
        final = result.final_row
        header = _provenance(tracker, data, dims, trials, source.seed, run, result, source.params)
        write_params(target, config_toml(base, result.best), header)
        _print_tune(stdout_console(), result, class_names, dims)
        typer.echo(
            f"tune: {len(result.trials)} trials on {data.split}, combined AMOTA {metric_text(final['amota'])} -> {out}"
        )
        if result.interrupted:
            announce_stop("wrote the best of the finished trials")
            raise typer.Exit(130)


def _provenance(
    tracker: str,
    data: "StudyData",
    dims: "list[SearchDim]",
    trials: int,
    seed: int,
    run: "Execution",
    result: "TuneResult",
    params: Path | None,
) -> list[str]:
    """Comment header of a tuned parameter file: search space, trials, data, versions, scores."""
    from gnnpmb.provenance import code_version, package_versions
    from gnnpmb.study.evaluate import class_column
    from gnnpmb.types import TRACKING_CLASSES

    versions = package_versions(("gnnpmb-viz", "nuscenes-devkit", "ray", "optuna", "numpy"))
    detections = f"file {data.detections}" if data.detections else f"simulated preset {data.detector}, seed {seed}"
    where = "in process" if not run.uses_ray else f"Ray Tune, {run.workers or 'all cluster CPUs'} concurrent"
    per_class = ", ".join(f"{c} {metric_text(result.final_row[class_column(c)])}" for c in TRACKING_CLASSES)
    return [
        f"gnnpmb tune: per-class parameters for tracker {tracker}; pass this file with --params",
        "search space: " + "; ".join(d.describe() for d in dims),
        f"trials: {len(result.trials)} of {trials} (Optuna TPE sampler, seed {seed}, {where})",
        "choice: per class, the values of the trial with that class's highest AMOTA",
        f"data: {data.location.dataroot} {data.location.version}, split {data.split} "
        f"({', '.join(data.scene_names)}); detections: {detections}",
        f"base parameters: {params or 'paper defaults'}",
        f"combined on {data.split}: AMOTA {metric_text(result.final_row['amota'])}; per class: {per_class}",
        "versions: " + ", ".join(f"{k} {v}" for k, v in versions.items()) + f"; code {code_version()[:12]}",
        "score it on held-out data: gnnpmb track --params THIS.toml ... then gnnpmb eval",
    ]


def _print_tune(console: Console, result: "TuneResult", class_names: tuple[str, ...], dims: "list[SearchDim]") -> None:
    """Per class: the best AMOTA seen in a trial, the combined evaluation's AMOTA, and the chosen values."""
    from gnnpmb.study.evaluate import class_column
    from gnnpmb.study.tune import class_of

    chosen = dict(result.best)
    table = Table(title="best per class")
    for name in ("class", "best trial AMOTA", "combined AMOTA", "values"):
        table.add_column(name, justify="left" if name in ("class", "values") else "right")
    for c in class_names:
        column = class_column(c)
        scores = [t.row[column] for t in result.trials if t.row.get(column) is not None]
        values = ", ".join(f"{d.key.split('.', 1)[1]}={chosen[d.key]:.4g}" for d in dims if class_of(d.key) == c)
        table.add_row(c, metric_text(max(scores, default=None)), metric_text(result.final_row[column]), values or "-")
    console.print(table)
