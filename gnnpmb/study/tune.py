"""``gnnpmb tune``: search per-class parameters with an Optuna TPE sampler, on Ray Tune (or in this process for
one worker), and write the best as a ``--params`` TOML.

Each trial sets the searched keys of every class, tracks the split and runs one evaluation; the sampler
maximises the overall AMOTA (the mean of the per-class AMOTAs). The trackers run each class on its own
detections with its own parameters and the devkit scores each class on its own, so a class's AMOTA depends only
on that class's parameters (and the shared ones). The result therefore takes, for each class, the values of the
trial where *that class's* AMOTA was highest; if the space holds a shared key (not per class) the classes are
coupled and the best overall trial is taken whole. One last evaluation of the combined parameters reports the
per-class scores they actually reach.

With one worker the Optuna study runs sequentially in this process (deterministic for a seed); with several,
Ray Tune's ``OptunaSearch`` runs ``workers`` trials at once, so which points are sampled depends on the order
trials finish in.
"""

from __future__ import annotations

import math
import os
import re
import shutil
import tempfile
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from gnnpmb.config import config_from_dict, dump_toml, load_config
from gnnpmb.errors import GnnpmbError
from gnnpmb.study.data import StudyData, for_scoring
from gnnpmb.study.evaluate import ConfigJob, class_column, score_config
from gnnpmb.study.grid import (
    Assignment,
    StudyError,
    build_config,
    config_toml,
    merge,
    parse_value,
    toml_paths,
)
from gnnpmb.study.results import write_text
from gnnpmb.study.runner import Execution, import_ray
from gnnpmb.types import TRACKING_CLASSES

DEFAULT_CLASS_SPACE: dict[str, tuple[float, float, bool]] = {
    "score_threshold": (0.0, 0.5, False),
    "nms_iou_3d": (0.01, 0.5, False),
    "birth_weight": (1e-3, 1.0, True),
    "birth_pos_std_m": (1.0, 30.0, True),
    "extraction_threshold": (0.005, 0.95, True),
    "q_x": (0.005, 2.0, True),
    "q_y": (0.005, 2.0, True),
    "r_x": (0.01, 1.0, True),
    "r_y": (0.01, 1.0, True),
}
"""Per-class parameters searched by default, name -> (low, high, log scale). Only the names the config loader
accepts in a ``[classes.<class>]`` section are used."""

_BOUNDS = re.compile(r"^([^:]+):([^:]+)(:log)?$")


@dataclass(frozen=True, slots=True)
class SearchDim:
    """One searched key: uniform on [low, high], or log-uniform when ``log``."""

    key: str
    low: float
    high: float
    log: bool

    def describe(self) -> str:
        return f"{self.key} in [{self.low:g}, {self.high:g}]{' log' if self.log else ''}"


@dataclass(frozen=True, slots=True)
class Trial:
    """One finished trial: its values and its scores (a results row)."""

    assignment: Assignment
    row: dict[str, Any]


@dataclass(frozen=True, slots=True)
class TuneResult:
    """The trials, the chosen values, the final evaluation's scores, and whether Ctrl-C cut the search short."""

    trials: list[Trial]
    best: Assignment
    final_row: dict[str, Any]
    interrupted: bool


def parse_space(text: str) -> SearchDim:
    """``KEY=LOW:HIGH`` or ``KEY=LOW:HIGH:log`` -> SearchDim."""
    key, sep, bounds = text.partition("=")
    key = key.strip()
    match = _BOUNDS.match(bounds.strip())
    if not sep or not key or match is None:
        raise StudyError(f"--space '{text}' must look like KEY=LOW:HIGH or KEY=LOW:HIGH:log")
    toml_paths(key)
    low, high = (parse_value(match.group(i), key) for i in (1, 2))
    if any(isinstance(v, bool) or not isinstance(v, int | float) for v in (low, high)):
        raise StudyError(f"--space {key}: bounds must be numbers, got {bounds}")
    if not low < high:
        raise StudyError(f"--space {key}: need LOW < HIGH, got {bounds}")
    log = match.group(3) is not None
    if log and low <= 0:
        raise StudyError(f"--space {key}: a log scale needs LOW > 0, got {bounds}")
    return SearchDim(key, float(low), float(high), log)


def _accepted_per_class(base_toml: Mapping[str, Any], name: str, value: float) -> bool:
    try:
        config_from_dict(merge(base_toml, {"classes": {TRACKING_CLASSES[0]: {name: value}}}))
    except GnnpmbError:
        return False
    return True


def default_space(classes: Sequence[str], base_toml: Mapping[str, Any]) -> list[SearchDim]:
    """``DEFAULT_CLASS_SPACE`` for each class, keeping the names the config loader accepts per class."""
    names = [
        name
        for name, (low, high, log) in DEFAULT_CLASS_SPACE.items()
        if _accepted_per_class(base_toml, name, math.sqrt(low * high) if log else 0.5 * (low + high))
    ]
    return [SearchDim(f"{c}.{n}", *DEFAULT_CLASS_SPACE[n]) for c in classes for n in names]


def check_space(dims: Sequence[SearchDim], base_toml: Mapping[str, Any]) -> None:
    """Every key once, and both bounds of every key accepted by the config loader (before any work)."""
    from gnnpmb.study.grid import check_disjoint

    if not dims:
        raise StudyError("empty search space: give --space KEY=LOW:HIGH or --classes with per-class keys")
    check_disjoint([d.key for d in dims])
    for dim in dims:
        for bound in (dim.low, dim.high):
            try:
                build_config(config_toml(base_toml, ((dim.key, bound),)))
            except GnnpmbError as exc:
                raise StudyError(f"--space {dim.key}={bound:g}: {exc}") from None


def class_of(key: str) -> str | None:
    """The class a key belongs to (``car.q_x`` -> car), None for a shared key."""
    paths = toml_paths(key)
    return paths[0][1] if len(paths) == 1 and paths[0][0] == "classes" else None


def _score(row: Mapping[str, Any], column: str) -> float:
    value = row.get(column)
    return -math.inf if value is None else float(value)


def choose_best(dims: Sequence[SearchDim], trials: Sequence[Trial]) -> Assignment:
    """Per class, the values of the trial with that class's highest AMOTA (earliest on ties); the best overall
    trial whole when any key is shared."""
    if not trials:
        raise StudyError("no trial finished; nothing to write")
    best_overall = max(trials, key=lambda t: _score(t.row, "amota"))
    if any(class_of(d.key) is None for d in dims):
        return best_overall.assignment
    chosen: dict[str, Any] = {}
    for class_name in sorted({class_of(d.key) for d in dims}):
        column = class_column(class_name)
        best = max(trials, key=lambda t, column=column: _score(t.row, column))
        if _score(best.row, column) == -math.inf:
            best = best_overall
        chosen.update({k: v for k, v in best.assignment if class_of(k) == class_name})
    return tuple((d.key, chosen[d.key]) for d in dims)


def _job(index: int, assignment: Assignment, base_toml: Mapping[str, Any], tracker: str, data: StudyData) -> ConfigJob:
    return ConfigJob(index, assignment, build_config(config_toml(base_toml, assignment)), tracker, data)


def _distributions(dims: Sequence[SearchDim]) -> dict[str, Any]:
    import optuna

    return {f"p{i}": optuna.distributions.FloatDistribution(d.low, d.high, log=d.log) for i, d in enumerate(dims)}


def _assignment(dims: Sequence[SearchDim], params: Mapping[str, Any]) -> Assignment:
    return tuple((d.key, float(params[f"p{i}"])) for i, d in enumerate(dims))


def _sampler(seed: int) -> Any:
    import optuna

    return optuna.samplers.TPESampler(seed=seed)


def _search_in_process(
    dims: Sequence[SearchDim],
    trials: int,
    seed: int,
    evaluate: Callable[[int, Assignment], dict[str, Any]],
    on_trial: Callable[[Trial], None],
) -> tuple[list[Trial], bool]:
    import optuna

    optuna.logging.set_verbosity(optuna.logging.WARNING)
    study = optuna.create_study(direction="maximize", sampler=_sampler(seed))
    distributions = _distributions(dims)
    done: list[Trial] = []
    try:
        for i in range(trials):
            trial = study.ask(distributions)
            assignment = _assignment(dims, trial.params)
            row = evaluate(i, assignment)
            study.tell(trial, row["amota"] if row["amota"] is not None else 0.0)
            done.append(Trial(assignment, row))
            on_trial(done[-1])
    except KeyboardInterrupt:
        return done, True
    return done, False


@dataclass(frozen=True, slots=True)
class _TrialContext:
    dims: tuple[SearchDim, ...]
    base_toml: dict[str, Any]
    tracker: str
    data: StudyData


def _ray_trainable(config: dict[str, Any], context: _TrialContext) -> None:
    """A Ray Tune function trainable: one configuration, one report."""
    from ray import tune

    assignment = _assignment(context.dims, config)
    row = score_config(_job(0, assignment, context.base_toml, context.tracker, context.data))
    metrics = {k: (math.nan if v is None else v) for k, v in row.items()}
    tune.report({"score": row["amota"] if row["amota"] is not None else 0.0, **metrics})


def _reporter(listener: Callable[[Any, Mapping[str, Any]], None]) -> Any:
    """A Ray Tune callback passing each trial's result to ``listener`` in the driver. Tune pickles its
    callbacks into the experiment state; the listener (progress bar, locks) is left out of that copy."""
    from ray import tune

    class Reporter(tune.Callback):
        def __init__(self, listener: Callable[[Any, Mapping[str, Any]], None]) -> None:
            self.listener: Callable[[Any, Mapping[str, Any]], None] | None = listener

        def __getstate__(self) -> dict[str, Any]:
            return {}

        def __setstate__(self, state: dict[str, Any]) -> None:
            self.listener = None

        def on_trial_result(self, iteration: int, trials: list, trial: Any, result: dict, **info: Any) -> None:
            if self.listener is not None:
                self.listener(trial, result)

    return Reporter(listener)


def _search_on_ray(
    dims: Sequence[SearchDim],
    trials: int,
    seed: int,
    context: _TrialContext,
    run: Execution,
    on_trial: Callable[[Trial], None],
) -> tuple[list[Trial], bool]:
    import optuna

    import_ray()
    os.environ.setdefault("RAY_AIR_NEW_OUTPUT", "0")
    os.environ.setdefault("TUNE_DISABLE_AUTO_CALLBACK_LOGGERS", "1")
    from ray import tune
    from ray.tune.search.optuna import OptunaSearch

    optuna.logging.set_verbosity(optuna.logging.WARNING)
    done: list[Trial] = []

    def to_row(metrics: Mapping[str, Any]) -> dict[str, Any]:
        return {
            k: (None if isinstance(v, float) and math.isnan(v) else v)
            for k, v in metrics.items()
            if k == "amota"
            or k.startswith("amota_")
            or k in ("amotp", "mota", "ids", "frag", "tp", "fp", "fn")
            or k.endswith("_time_s")
        }

    def listen(trial: Any, result: Mapping[str, Any]) -> None:
        done.append(Trial(_assignment(dims, trial.config), to_row(result)))
        on_trial(done[-1])

    storage = Path(tempfile.mkdtemp(prefix="gnnpmb-tune-"))
    try:
        tuner = tune.Tuner(
            tune.with_parameters(_ray_trainable, context=context),
            tune_config=tune.TuneConfig(
                search_alg=OptunaSearch(space=_distributions(dims), metric="score", mode="max", sampler=_sampler(seed)),
                num_samples=trials,
                max_concurrent_trials=run.workers,
            ),
            run_config=tune.RunConfig(
                storage_path=str(storage), name="gnnpmb-tune", verbose=0, callbacks=[_reporter(listen)]
            ),
        )
        try:
            grid = tuner.fit()
        except KeyboardInterrupt:
            return done, True
        interrupted = len(done) < trials
        errors = [r.error for r in grid if r.error is not None]
        if errors and not done:
            raise StudyError(f"every trial failed; first error: {str(errors[0]).splitlines()[-1]}")
    finally:
        shutil.rmtree(storage, ignore_errors=True)
    return done, interrupted


def run_tune(
    tracker: str,
    data: StudyData,
    base_toml: Mapping[str, Any],
    dims: Sequence[SearchDim],
    trials: int,
    seed: int,
    run: Execution,
    on_trial: Callable[[Trial], None],
) -> TuneResult:
    """Search, choose the per-class best, and score the chosen values once more.

    Must run inside ``runner.ray_session(run)`` when ``run.uses_ray``.
    """
    if trials < 1:
        raise StudyError(f"--trials must be at least 1, got {trials}")
    data = for_scoring(data, run.uses_ray)
    base = dict(base_toml)
    if run.uses_ray:
        context = _TrialContext(tuple(dims), base, tracker, data)
        done, interrupted = _search_on_ray(dims, trials, seed, context, run, on_trial)
    else:

        def evaluate(index: int, assignment: Assignment) -> dict[str, Any]:
            return score_config(_job(index, assignment, base, tracker, data))

        done, interrupted = _search_in_process(dims, trials, seed, evaluate, on_trial)
    best = choose_best(dims, done)
    final_row = score_config(_job(len(done), best, base, tracker, data))
    return TuneResult(trials=done, best=best, final_row=final_row, interrupted=interrupted)


def write_params(path: Path, toml: Mapping[str, Any], header: Sequence[str]) -> None:
    """Write the parameters atomically, after checking the text loads back through ``load_config``."""
    text = dump_toml(toml, header)
    path = Path(path)
    check = Path(tempfile.mkdtemp(prefix="gnnpmb-params-")) / "params.toml"
    try:
        check.write_text(text, encoding="utf-8")
        load_config(check)
    finally:
        shutil.rmtree(check.parent, ignore_errors=True)
    write_text(path, text)
