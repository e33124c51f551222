"""``gnnpmb sweep``: score every configuration of a parameter grid, reusing cached ones, in parallel on Ray.

Each configuration is one task (track the whole split, then one evaluation); finished rows are cached at once
(``gnnpmb.study.cache``), so an interrupted sweep resumes where it stopped.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

from gnnpmb.eval.result_cache import ResultCache
from gnnpmb.provenance import code_version
from gnnpmb.study.cache import config_key
from gnnpmb.study.data import StudyData, for_scoring, inputs_fingerprint
from gnnpmb.study.evaluate import ConfigJob, is_complete_row, score_config
from gnnpmb.study.grid import (
    Assignment,
    Scalar,
    SweptParam,
    base_value,
    build_config,
    check_assignments,
    config_toml,
    full_grid,
    one_at_a_time,
)
from gnnpmb.study.runner import Execution, run_tasks


@dataclass(frozen=True, slots=True)
class SweepPlan:
    """The configurations of a sweep and everything their results depend on.

    one_at_a_time: configurations are the base plus each key alone (else the full grid). base_values: each
    key's value in the base parameters (None where the loader has no single value for it).
    """

    tracker: str
    data: StudyData
    base_toml: dict[str, Any]
    keys: tuple[str, ...]
    assignments: tuple[Assignment, ...]
    one_at_a_time: bool
    base_values: dict[str, Scalar | None] = field(default_factory=dict)


@dataclass(frozen=True, slots=True)
class SweepOutcome:
    """Rows in configuration order (only finished ones), how many came from the cache, and whether Ctrl-C
    stopped the sweep early."""

    rows: list[dict[str, Any]]
    from_cache: int
    interrupted: bool


def plan_sweep(
    tracker: str,
    data: StudyData,
    base_toml: Mapping[str, Any],
    params: Sequence[SweptParam],
    one_at_a_time_mode: bool,
) -> SweepPlan:
    """Expand and check the grid: every configuration goes through the config loader before any work."""
    assignments = one_at_a_time(params) if one_at_a_time_mode else full_grid(params)
    check_assignments(base_toml, assignments)
    base = build_config(dict(base_toml))
    keys = tuple(p.key for p in params)
    return SweepPlan(
        tracker=tracker,
        data=data,
        base_toml=dict(base_toml),
        keys=keys,
        assignments=tuple(assignments),
        one_at_a_time=one_at_a_time_mode,
        base_values={k: base_value(base, k) for k in keys},
    )


def _row_head(plan: SweepPlan, index: int, key: str) -> dict[str, Any]:
    values = dict(plan.assignments[index])
    head: dict[str, Any] = {"config": index, "id": key[:12]}
    head.update({k: values.get(k) for k in plan.keys})
    return head


def run_sweep(
    plan: SweepPlan,
    cache: ResultCache,
    run: Execution,
    on_row: Callable[[dict[str, Any], bool], None] | None = None,
) -> SweepOutcome:
    """Score every configuration not in ``cache``; ``on_row(row, from_cache)`` is called as rows arrive.

    Must run inside ``runner.ray_session(run)`` when ``run.uses_ray``.
    """
    inputs = inputs_fingerprint(plan.data)
    code = code_version()
    keys = [config_key(plan.tracker, config_toml(plan.base_toml, a), inputs, code) for a in plan.assignments]
    rows: dict[int, dict[str, Any]] = {}
    for i, key in enumerate(keys):
        cached = cache.get(key)
        if cached is not None and is_complete_row(cached):  # an incomplete entry is scored again
            rows[i] = {**_row_head(plan, i, key), **cached}
            if on_row is not None:
                on_row(rows[i], True)
    from_cache = len(rows)
    data = for_scoring(plan.data, run.uses_ray) if len(rows) < len(keys) else plan.data
    jobs = [
        ConfigJob(i, a, build_config(config_toml(plan.base_toml, a)), plan.tracker, data)
        for i, a in enumerate(plan.assignments)
        if i not in rows
    ]
    interrupted = False
    try:
        for j, metrics in run_tasks(score_config, jobs, run):
            index = jobs[j].index
            cache.put(keys[index], metrics)
            rows[index] = {**_row_head(plan, index, keys[index]), **metrics}
            if on_row is not None:
                on_row(rows[index], False)
    except KeyboardInterrupt:
        interrupted = True
    return SweepOutcome(rows=[rows[i] for i in sorted(rows)], from_cache=from_cache, interrupted=interrupted)
