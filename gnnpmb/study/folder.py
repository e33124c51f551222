"""A sweep's output folder knows its grid: a later sweep into the same folder adds its configurations to the one
table there instead of replacing it, or is refused when the two would not belong in one table.

``results.json`` records what the study is of (tracker, data, detections, base parameters: ``identity``) and
its rows, whose swept-key cells give each configuration (an empty cell is the base value). A new sweep of the
same study becomes the union of the configurations already in the table and its own (``merge_study``), with every
varied key as a column; configurations already scored come from the cache. A sweep of another tracker, other data
or other base parameters is refused with a line saying how to go on. The plots are then drawn for every key of
the table, and plots of keys the table no longer holds are deleted (``drop_stale_plots``), so they always match.
"""

from __future__ import annotations

import dataclasses
import hashlib
import json
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

from gnnpmb.outputs import Inputs, check_output_dir
from gnnpmb.study.cache import CACHE_FOLDER
from gnnpmb.study.grid import Assignment, StudyError, base_value, build_config, check_disjoint
from gnnpmb.study.plots import plot_file_name
from gnnpmb.study.sweep import SweepPlan

RESULTS_JSON = "results.json"
RESULTS_CSV = "results.csv"
IDENTITY_FIELDS: tuple[str, ...] = (
    "tracker",
    "dataroot",
    "version",
    "split",
    "scenes",
    "detections",
    "detector",
    "seed",
    "base_params_sha256",
)
"""What must agree for two sweeps to share one table (``meta`` fields of ``results.json``)."""


@dataclasses.dataclass(frozen=True, slots=True)
class Study:
    """The study already in a folder: its ``meta`` and its rows."""

    meta: dict[str, Any]
    rows: list[dict[str, Any]]

    @property
    def keys(self) -> tuple[str, ...]:
        return tuple(self.meta.get("keys", ()))

    def assignments(self) -> list[Assignment]:
        """Each row's configuration: its swept keys that are not at the base value."""
        return [tuple((k, row[k]) for k in self.keys if row.get(k) is not None) for row in self.rows]


def read_study(out: Path) -> Study | None:
    """The study in ``out`` (None without a ``results.json``); a StudyError if that file cannot be read."""
    path = Path(out) / RESULTS_JSON
    if not path.is_file():
        return None
    try:
        data = json.loads(path.read_text(encoding="utf-8"))
        meta, rows = dict(data["meta"]), [dict(r) for r in data["rows"]]
    except (OSError, ValueError, KeyError, TypeError) as exc:
        raise StudyError(
            f"{path} cannot be read ({type(exc).__name__}); delete it and {RESULTS_CSV} to start a new table "
            "there (the cache is kept), or give a new --out folder"
        ) from None
    return Study(meta, rows)


def check_study_dir(out: Path, keys: Sequence[str], inputs: Inputs) -> Path:
    """``check_output_dir`` for a sweep's folder: it, its cache and every file the sweep writes (the tables and
    the plots of ``keys`` and of the keys already there) must be writable and none of ``inputs``."""
    target = check_output_dir(out, "--out", inputs=inputs)
    study = read_study(target)
    every = dict.fromkeys([*(study.keys if study else ()), *keys])
    names = [RESULTS_CSV, RESULTS_JSON, *(plot_file_name(k) for k in every)]
    return check_output_dir(target, "--out", files=names, folders=[CACHE_FOLDER], inputs=inputs)


def identity(plan: SweepPlan, params: Path | None) -> dict[str, Any]:
    """What the sweep ``plan`` is a study of (``IDENTITY_FIELDS``, plus the ``--params`` path for the record)."""
    data = plan.data
    base = json.dumps(plan.base_toml, sort_keys=True, default=str).encode()
    return {
        "tracker": plan.tracker,
        "dataroot": str(data.location.dataroot),
        "version": data.location.version,
        "split": data.split,
        "scenes": list(data.scene_names),
        "detections": str(data.detections) if data.detections else None,
        "detector": None if data.detections else data.detector,
        "seed": data.seed,
        "params": str(params) if params else None,
        "base_params_sha256": hashlib.sha256(base).hexdigest(),
    }


def _differences(before: Mapping[str, Any], now: Mapping[str, Any]) -> list[str]:
    fields = [f for f in IDENTITY_FIELDS if f in before]
    if "base_params_sha256" not in before:  # written before the base parameters were recorded: their file
        fields.append("params")
    return [f for f in fields if before.get(f) != now.get(f)]


def _describe(field: str, value: Any) -> str:
    if field == "base_params_sha256":
        return "other base parameters (--params)"
    if isinstance(value, list):
        value = ",".join(map(str, value))
    return f"{field} {value}"


def merge_study(plan: SweepPlan, study: Study | None, out: Path, params: Path | None) -> tuple[SweepPlan, str | None]:
    """``plan`` grown by the configurations already in ``out``'s table, and a note saying so (None when there was
    nothing to add); a StudyError when the study there is of something else."""
    if study is None:
        return plan, None
    now = identity(plan, params)
    differ = _differences(study.meta, now)
    if differ:
        was = "; ".join(_describe(f, study.meta.get(f)) for f in differ)
        raise StudyError(
            f"--out {out} holds a study of another kind ({was}; this sweep: "
            f"{'; '.join(_describe(f, now.get(f)) for f in differ)}), which cannot share its table; give a new "
            f"--out folder, or delete {out / RESULTS_JSON} and {RESULTS_CSV} to start a new table there"
        )
    keys = tuple(dict.fromkeys([*study.keys, *plan.keys]))
    try:
        check_disjoint(keys)
    except StudyError as exc:
        raise StudyError(f"--out {out} already varies {', '.join(study.keys)}: {exc}") from None
    order = {k: i for i, k in enumerate(keys)}
    seen: dict[frozenset, Assignment] = {}
    for assignment in [*study.assignments(), *plan.assignments]:
        seen.setdefault(frozenset(assignment), tuple(sorted(assignment, key=lambda kv: order[kv[0]])))
    assignments = tuple(seen.values())
    if len(assignments) == len(plan.assignments) and keys == plan.keys:
        return plan, None
    base = build_config(plan.base_toml)
    merged = dataclasses.replace(
        plan,
        keys=keys,
        assignments=assignments,
        one_at_a_time=plan.one_at_a_time and bool(study.meta.get("one_at_a_time")),
        base_values={k: base_value(base, k) for k in keys},
    )
    added = len(assignments) - len(plan.assignments)
    note = (
        f"note: {out} already holds a table of {', '.join(study.keys)}; its {added} other configuration"
        f"{'s' if added != 1 else ''} stay in the table and plots ({len(assignments)} in all; a new --out folder "
        "keeps studies apart)"
    )
    return merged, note


def drop_stale_plots(out: Path, keys: Sequence[str]) -> None:
    """Delete the ``amota_vs_*.png`` plots in ``out`` of keys the table does not hold."""
    keep = {plot_file_name(k) for k in keys}
    for path in Path(out).glob("amota_vs_*.png"):
        if path.name not in keep:
            path.unlink(missing_ok=True)
