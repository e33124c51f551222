"""How the Why prints what the checkers read back: the number pattern of an existence, weight or share, the
rounding that prints one, the Because paragraph and a list of frames."""

from __future__ import annotations

import re

NUMBER = r"\d+(?:\.\d+)?(?:e-?\d+)?"
"""An existence, weight or share as ``printed`` prints one."""
BECAUSE = re.compile(r"Because \(frame (\d+)[^)]*\): ([^\n]*)")
"""A Because paragraph: its frame and its text (to the end of the line)."""


def printed(r: float) -> str:
    """An existence as the text prints one: two decimals, one significant digit below 0.01."""
    return f"{r:.2f}" if r >= 0.01 or r == 0 else f"{r:.1g}"


def frames_of(text: str) -> list[int]:
    """``frame 7``, ``frames 7, 13``, ``frames 12–14, 20`` -> the frames."""
    out: list[int] = []
    for part in text.split(" ", 1)[1].split(","):
        lo, _, hi = part.strip().partition("–")
        if lo:
            out += range(int(lo), int(hi or lo) + 1)
    return out
