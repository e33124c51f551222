"""scipy's ``linear_sum_assignment`` without the rest of ``scipy.optimize``.

``from scipy.optimize import linear_sum_assignment`` first runs ``scipy.optimize``'s ``__init__``, which imports
the whole toolbox (``scipy.linalg``, ``scipy.sparse``, linprog, the array-API layer with ``numpy.f2py`` and
``numpy.testing``): 0.35 s of CPU, measured, in a ``gnnpmb-viz`` run that needs one function of it. That function
is scipy's compiled extension module ``scipy.optimize._lsap``, which ``scipy.optimize`` re-exports unchanged. It
is loaded here from its file on its own and registered under its own name, so a later ``import scipy.optimize``
reuses this very module; where this scipy keeps no such file, the public import is used. Either way the function
is scipy's own (``tests/gnnpmb/assign/test_lsap.py``).
"""

from __future__ import annotations

import importlib.machinery
import importlib.util
import sys
from collections.abc import Callable
from pathlib import Path
from typing import Any

import scipy

MODULE = "scipy.optimize._lsap"
"""The extension module holding ``linear_sum_assignment``."""


def _scipy_lsap() -> Callable[..., Any]:
    """scipy's ``linear_sum_assignment``, loading only its extension module where it can."""
    module = sys.modules.get(MODULE)
    if module is None:
        folder = Path(scipy.__file__).parent / "optimize"
        found = [p for s in importlib.machinery.EXTENSION_SUFFIXES if (p := folder / f"_lsap{s}").is_file()]
        if not found:
            from scipy.optimize import linear_sum_assignment

            return linear_sum_assignment
        loader = importlib.machinery.ExtensionFileLoader(MODULE, str(found[0]))
        module = importlib.util.module_from_spec(importlib.machinery.ModuleSpec(MODULE, loader, origin=str(found[0])))
        loader.exec_module(module)
        sys.modules[MODULE] = module
    return module.linear_sum_assignment


linear_sum_assignment = _scipy_lsap()
"""``scipy.optimize.linear_sum_assignment``: (R, C) cost -> (row indices, column indices) of a minimum-cost
assignment; ValueError when the matrix holds NaN or -inf, or +inf leaves no full assignment."""
