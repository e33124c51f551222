"""A finding as JSON (``gnnpmb failures --why --json``): its fields as they are, for scripts.

Dataclasses become objects of their fields, enums their values, tuples lists and NumPy scalars numbers. A solver's
``PairChoice`` is written as what it says (the detection, the chosen and next-best columns, their costs and the
margin, and each cost's terms when the tracker gives them), not as the cost matrix it points into.
"""

from __future__ import annotations

import dataclasses
import enum
import math
from typing import Any

import numpy as np

from gnnpmb.events import AxisLabel
from gnnpmb.explain import PairChoice
from gnnpmb.why.findings import Finding


def finding_json(f: Finding) -> dict[str, Any]:
    """``f`` as JSON-ready data (``json.dumps`` takes it; non-finite numbers become null)."""
    return _value(f)


def _value(x: Any) -> Any:
    if isinstance(x, PairChoice):
        return _choice(x)
    if isinstance(x, AxisLabel):
        return {"kind": x.kind.value, "ref": int(x.ref)}
    if dataclasses.is_dataclass(x) and not isinstance(x, type):
        return {f.name: _value(getattr(x, f.name)) for f in dataclasses.fields(x)}
    if isinstance(x, enum.Enum):
        return x.value
    if isinstance(x, dict):
        return {str(k): _value(v) for k, v in x.items()}
    if isinstance(x, (tuple, list)):
        return [_value(v) for v in x]
    if isinstance(x, np.generic):
        return _value(x.item())
    if isinstance(x, float) and not math.isfinite(x):
        return None
    return x


def _choice(c: PairChoice) -> dict[str, Any]:
    return {
        "meas": int(c.meas.ref),
        "chosen": _value(c.chosen),
        "chosen_cost": _value(c.chosen_cost),
        "alternative": _value(c.alternative),
        "alternative_cost": _value(c.alternative_cost),
        "margin": _value(c.margin),
        "close_call": c.close_call,
        "scale": _value(c.scale),
        "chosen_terms": _value(c.chosen_terms),
        "alternative_terms": _value(c.alternative_terms),
    }
