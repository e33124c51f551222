"""How the Why prints what the checkers read back: the number pattern of an existence, weight or share, the
rounding that prints one, and the Because paragraph."""

from __future__ import annotations

import re

NUMBER = r"\d+(?:\.\d+)?(?:e-?\d+)?"
"""An existence, weight or share as ``printed`` prints one."""
BECAUSE = re.compile(r"Because \(frame (\d+)[^)]*\): ([^\n]*)")
"""A Because paragraph: its frame and its text (to the end of the line)."""


def printed(r: float) -> str:
    """An existence as the text prints one: two decimals, one significant digit below 0.01."""
    return f"{r:.2f}" if r >= 0.01 or r == 0 else f"{r:.1g}"
