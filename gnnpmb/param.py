"""One declaration per tracker parameter: its range, unit, the paper's value and meaning beside its default.

A section of the parameter file is a frozen dataclass (``gnnpmb.config``) whose fields are declared with
``param``: name, type and default are the field's; ``Param`` (its metadata) holds the rest. The TOML reader, the
range checks, the sweeps' ``--param`` (through the reader), ``params/paper.toml``, ``default_params.toml`` and
the table in ``docs/parameters.md`` (``gnnpmb.param_docs``) are all read from these declarations.

Limits where the model would overflow (issue 33 case 9): the 2-D innovation covariance's determinant
s00 s11 - s01^2 (``kalman.innovation``) overflows float64 once an entry exceeds sqrt(max) = 1.3e154, and a
covariance grows over a scene (P' = F P F^T + Q adds about n^3 dt^2 q over n predicts). A variance is therefore
kept at or below max^(1/4) = 1.2e77, leaving a factor 1e77 for that growth, and a standard deviation at or below
its square root, max^(1/8) = 3.4e38; a distance that is squared (a matching radius) and a factor of a product
(the clutter intensity times the velocity density or the CPHD's area) at or below sqrt(max) = 1.3e154.
"""

from __future__ import annotations

import dataclasses
import math
import sys
from collections.abc import Iterator
from dataclasses import dataclass
from typing import Any

from gnnpmb.errors import GnnpmbError


class ConfigError(GnnpmbError):
    """A parameter file that cannot be used; the message says what to fix."""


@dataclass(frozen=True, slots=True)
class Range:
    """Allowed values of one parameter: lo < v (or <= if ``lo_closed``) and v < hi (or <= if ``hi_closed``)."""

    lo: float
    hi: float
    lo_closed: bool
    hi_closed: bool

    def contains(self, value: float) -> bool:
        if not math.isfinite(value):
            return False
        above = value >= self.lo if self.lo_closed else value > self.lo
        below = value <= self.hi if self.hi_closed else value < self.hi
        return above and below

    def __str__(self) -> str:
        if self.hi == math.inf:
            return f">= {self.lo:g}" if self.lo_closed else f"> {self.lo:g}"
        return f"in {'[' if self.lo_closed else '('}{self.lo:g}, {self.hi:g}{']' if self.hi_closed else ')'}"


@dataclass(frozen=True, slots=True)
class Limit:
    """An upper bound the model needs on top of a parameter's meaning (``hi``, inclusive) and why."""

    hi: float
    why: str


_FLOAT_MAX = sys.float_info.max
VARIANCE_LIMIT = Limit(_FLOAT_MAX**0.25, "a larger variance overflows float64 as the covariance grows")
STD_LIMIT = Limit(_FLOAT_MAX**0.125, "its square is a variance; a larger one overflows float64")
SQUARED_LIMIT = Limit(_FLOAT_MAX**0.5, "its square overflows float64")
FACTOR_LIMIT = Limit(_FLOAT_MAX**0.5, "its product with another factor of the same quantity overflows float64")

PROB = Range(0.0, 1.0, True, True)
POSITIVE = Range(0.0, math.inf, False, False)
NON_NEGATIVE = Range(0.0, math.inf, True, False)
SWITCH = Range(0.0, 1.0, True, True)
GIOU = Range(-1.0, 1.0, True, True)


def at_least(n: int) -> Range:
    return Range(float(n), math.inf, True, False)


def unit_interval(lo_closed: bool, hi_closed: bool) -> Range:
    return Range(0.0, 1.0, lo_closed, hi_closed)


@dataclass(frozen=True, slots=True)
class Param:
    """What a parameter's field declares beside its name, type and default.

    doc: one line, what it means; range: the values that make sense; unit: SI unit ("" for a number);
    paper: the GNN-PMB paper's value where it differs from the default (``params/paper.toml``), else None;
    limit: the largest value the model's arithmetic takes, if below the range's top."""

    doc: str
    range: Range
    unit: str = ""
    paper: float | None = None
    limit: Limit | None = None

    def check(self, key: str, value: float, where: str) -> None:
        """Raise a ``ConfigError`` naming ``where`` (``[pmb]``, ``[classes.car]``), the key, the value and the
        allowed range if ``value`` is not allowed."""
        v = float(value)
        if self.limit is not None and v > self.limit.hi:
            allowed = Range(self.range.lo, self.limit.hi, self.range.lo_closed, True)
            raise ConfigError(f"{where} {key} must be {allowed} ({self.limit.why}), got {value!r}")
        if not self.range.contains(v):
            raise ConfigError(f"{where} {key} must be {self.range}, got {value!r}")

    @property
    def allowed(self) -> str:
        """The allowed range as text, the model's limit included."""
        if self.limit is None:
            return str(self.range)
        return str(Range(self.range.lo, self.limit.hi, self.range.lo_closed, True))


def param(
    default: Any,
    doc: str,
    range: Range,  # noqa: A002 - the declaration's own word
    unit: str = "",
    paper: float | None = None,
    limit: Limit | None = None,
) -> Any:
    """A dataclass field declaring one parameter (``default`` ``dataclasses.MISSING`` for a required one)."""
    return dataclasses.field(default=default, metadata={"param": Param(doc, range, unit, paper, limit)})


@dataclass(frozen=True, slots=True)
class Declared:
    """One declared parameter of a section: its field's name, type and default with its ``Param``."""

    name: str
    type: type
    default: Any
    spec: Param


def declared(kind: type) -> Iterator[Declared]:
    """Every parameter of section dataclass ``kind``, in declaration order."""
    for f in dataclasses.fields(kind):
        kind_of = int if f.type in ("int", int) else float
        yield Declared(f.name, kind_of, f.default, f.metadata["param"])


class Section:
    """Base of a parameter section: every field is checked against its declaration on construction."""

    __slots__ = ()
    SECTION = ""

    def __post_init__(self) -> None:
        check_section(self)


def check_section(params: Any) -> None:
    """Check every field of a section dataclass against its declaration."""
    where = f"[{params.SECTION}]"
    for d in declared(type(params)):
        d.spec.check(d.name, getattr(params, d.name), where)


def paper_values(kind: type) -> dict[str, Any]:
    """The paper's values of section ``kind`` where they differ from the defaults (name -> value)."""
    return {d.name: d.type(d.spec.paper) for d in declared(kind) if d.spec.paper is not None}
