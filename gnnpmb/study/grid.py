"""Parameter keys, values and grids of a parameter study, turned into tracker configs by the config loader.

A key is a dotted path into the parameter TOML (``gnnpmb/default_params.toml``):

* ``section.name`` — a shared parameter, e.g. ``models.gate_chi2`` -> ``[models] gate_chi2`` (a moved key's
  former section still names it: ``pmb.gate_chi2``, ``gnnpmb.config.MOVED_KEYS``);
* ``class.name`` — a per-class parameter, e.g. ``car.q_x`` -> ``[classes.car] q_x`` (``classes.car.q_x`` too);
* ``*.name`` — the per-class parameter of every tracking class at once.

Every configuration becomes a nested TOML dict (the ``--params`` file's content with the configuration's values
on top) that goes through ``gnnpmb.config.config_from_dict``, so the loader's names, types and ranges apply: an
unknown key or a bad value fails there, with the loader's message, before any tracking starts.
"""

from __future__ import annotations

import copy
import itertools
import math
import re
import tomllib
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

from gnnpmb.config import TrackerConfig, config_from_dict, current_section
from gnnpmb.errors import GnnpmbError
from gnnpmb.types import TRACKING_CLASSES

ALL_CLASSES = "*"
_KEY = re.compile(r"^(\*|[A-Za-z_][A-Za-z0-9_]*)(\.[A-Za-z_][A-Za-z0-9_]*){1,2}$")

Scalar = bool | int | float | str
Assignment = tuple[tuple[str, Scalar], ...]
"""One configuration: (key, value) pairs in the order the keys were given."""


class StudyError(GnnpmbError):
    """A bad parameter key, value, grid or search space; the message says what to fix."""


@dataclass(frozen=True, slots=True)
class SweptParam:
    """One ``--param KEY=V1,V2,...``: the key and its values in the given order."""

    key: str
    values: tuple[Scalar, ...]


def toml_paths(key: str) -> tuple[tuple[str, ...], ...]:
    """The TOML paths a key stands for: ``pmb.gate_chi2`` -> (("pmb", "gate_chi2"),),
    ``car.q_x`` -> (("classes", "car", "q_x"),), ``*.q_x`` -> one path per tracking class."""
    if not _KEY.match(key):
        raise StudyError(f"bad parameter key '{key}'; use section.name (pmb.gate_chi2), class.name (car.q_x) or *.name")
    parts = key.split(".")
    if parts[0] == "classes":
        if len(parts) != 3:
            raise StudyError(f"bad parameter key '{key}'; a per-class key is classes.CLASS.name or CLASS.name")
        parts = parts[1:]
    elif len(parts) != 2:
        raise StudyError(f"bad parameter key '{key}'; use section.name, class.name or *.name")
    head, name = parts
    if head == ALL_CLASSES:
        return tuple(("classes", c, name) for c in TRACKING_CLASSES)
    if head in TRACKING_CLASSES:
        return (("classes", head, name),)
    if key.startswith("classes."):
        raise StudyError(f"unknown class '{head}' in '{key}' (known: {', '.join(TRACKING_CLASSES)})")
    return ((head, name),)


def parse_value(text: str, key: str) -> Scalar:
    """A TOML scalar: ``0.1``, ``1e-3``, ``40``, ``true``, ``"name"``."""
    try:
        value = tomllib.loads(f"v = {text.strip()}")["v"]
    except tomllib.TOMLDecodeError:
        raise StudyError(f"{key}: '{text}' is not a number, true/false or a quoted string") from None
    if not isinstance(value, bool | int | float | str):
        raise StudyError(f"{key}: '{text}' is not a single value")
    if isinstance(value, float) and not math.isfinite(value):
        raise StudyError(f"{key}: value {text} is not finite")
    return value


def parse_param(text: str) -> SweptParam:
    """``KEY=V1,V2,...`` -> SweptParam (values kept in order, repeats refused)."""
    key, sep, values_text = text.partition("=")
    key = key.strip()
    if not sep or not key:
        raise StudyError(f"--param '{text}' must look like KEY=V1,V2,... (e.g. pmb.gate_chi2=20,40)")
    toml_paths(key)
    items = [v for v in values_text.split(",") if v.strip()]
    if not items:
        raise StudyError(f"--param {key} has no values; give at least one: {key}=V1,V2,...")
    values = tuple(parse_value(v, key) for v in items)
    if len(set(values)) != len(values):
        raise StudyError(f"--param {key} repeats a value: {values_text}")
    return SweptParam(key, values)


def check_disjoint(keys: Sequence[str]) -> None:
    """Refuse two keys that set the same TOML entry (``car.q_x`` and ``*.q_x``, or a key given twice)."""
    seen: dict[tuple[str, ...], str] = {}
    for key in keys:
        for path in toml_paths(key):
            if path in seen:
                raise StudyError(f"parameters {seen[path]} and {key} both set {'.'.join(path)}; give it once")
            seen[path] = key


def full_grid(params: Sequence[SweptParam]) -> list[Assignment]:
    """Every combination of the values (the first key varies slowest)."""
    if not params:
        raise StudyError("empty grid: give at least one --param KEY=V1,V2,...")
    check_disjoint([p.key for p in params])
    keys = [p.key for p in params]
    return [tuple(zip(keys, combo, strict=True)) for combo in itertools.product(*(p.values for p in params))]


def one_at_a_time(params: Sequence[SweptParam]) -> list[Assignment]:
    """The base configuration (no override), then each key alone at each of its values (like the paper's
    Table II ablation): 1 + sum of the value counts configurations."""
    if not params:
        raise StudyError("empty grid: give at least one --param KEY=V1,V2,...")
    check_disjoint([p.key for p in params])
    return [()] + [((p.key, v),) for p in params for v in p.values]


def overrides(assignment: Assignment) -> dict[str, Any]:
    """The nested TOML dict that sets the assignment's values."""
    out: dict[str, Any] = {}
    for key, value in assignment:
        for path in toml_paths(key):
            node = out
            for part in path[:-1]:
                node = node.setdefault(part, {})
            node[path[-1]] = value
    return out


def merge(base: Mapping[str, Any], top: Mapping[str, Any]) -> dict[str, Any]:
    """Deep merge of two TOML dicts; ``top`` wins."""
    out = copy.deepcopy(dict(base))
    for key, value in top.items():
        if isinstance(value, Mapping) and isinstance(out.get(key), Mapping):
            out[key] = merge(out[key], value)
        else:
            out[key] = copy.deepcopy(value)
    return out


def config_toml(base_toml: Mapping[str, Any], assignment: Assignment) -> dict[str, Any]:
    """The TOML dict of one configuration: the ``--params`` file's dict with the assignment on top."""
    return merge(base_toml, overrides(assignment))


def build_config(toml: Mapping[str, Any]) -> TrackerConfig:
    """Load a configuration's TOML dict through the project's config loader (its checks apply)."""
    return config_from_dict(dict(toml))


def check_assignments(base_toml: Mapping[str, Any], assignments: Sequence[Assignment]) -> None:
    """Load every configuration once so a bad key or value fails before any work, naming the configuration."""
    for assignment in assignments:
        try:
            build_config(config_toml(base_toml, assignment))
        except GnnpmbError as exc:
            where = ", ".join(f"{k}={v}" for k, v in assignment) or "the base parameters"
            raise StudyError(f"{where}: {exc}") from None


def base_value(config: TrackerConfig, key: str) -> Scalar | None:
    """The value ``key`` has in ``config`` (for ``*.name`` only if every class has the same), else None."""
    values = []
    data = config.as_dict()
    for path in toml_paths(key):
        if len(path) == 2:
            path = (current_section(*path), path[1])
        node: Any = data
        for part in path:
            if not isinstance(node, Mapping) or part not in node:
                return None
            node = node[part]
        values.append(node)
    return values[0] if values and all(v == values[0] for v in values) else None
