"""``gnnpmb.assign.lsap``: scipy's own ``linear_sum_assignment`` without importing ``scipy.optimize``."""

from __future__ import annotations

import importlib.machinery
import subprocess
import sys

import pytest

from gnnpmb.assign import lsap

CHECK = """
import sys
from gnnpmb.assign.lsap import linear_sum_assignment
assert "scipy.optimize" not in sys.modules, "scipy.optimize was imported"
import scipy.optimize
assert scipy.optimize.linear_sum_assignment is linear_sum_assignment, "not scipy's own function"
rows, cols = linear_sum_assignment([[4.0, 1.0, 3.0], [2.0, 0.0, 5.0], [3.0, 2.0, 2.0]])
print(rows.tolist(), cols.tolist())
"""


def test_scipy_s_own_function_is_loaded_without_scipy_optimize() -> None:
    out = subprocess.run([sys.executable, "-c", CHECK], capture_output=True, text=True, timeout=60)
    assert out.returncode == 0, out.stderr
    assert out.stdout.split("\n")[0] == "[0, 1, 2] [1, 0, 2]"


def test_without_the_extension_file_the_public_import_is_used(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.delitem(sys.modules, lsap.MODULE, raising=False)
    monkeypatch.setattr(importlib.machinery, "EXTENSION_SUFFIXES", [])
    from scipy.optimize import linear_sum_assignment

    assert lsap._scipy_lsap() is linear_sum_assignment
