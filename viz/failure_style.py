"""How each failure kind looks wherever it is drawn or listed: its colour, its words and its TextLog level."""

from __future__ import annotations

from gnnpmb.eval.failures import FailureKind

KIND_COLORS: dict[FailureKind, tuple[int, int, int]] = {
    FailureKind.ID_SWITCH: (255, 0, 255),
    FailureKind.FRAGMENTATION: (255, 160, 0),
    FailureKind.FALSE_TRACK: (255, 0, 0),
    FailureKind.MISS: (150, 150, 150),
    FailureKind.COALESCENCE: (0, 255, 140),
    FailureKind.IDENTITY_THEFT: (255, 255, 0),
}
"""One colour per failure kind, outside the hues tracks may take (``viz.colors.TRACK_HUE_BANDS``); "miss", the
most frequent kind, is a mid grey that shows on the dark and the light theme alike."""

KIND_LABELS: dict[FailureKind, str] = {
    FailureKind.ID_SWITCH: "ID switch",
    FailureKind.FRAGMENTATION: "fragmentation",
    FailureKind.FALSE_TRACK: "false track",
    FailureKind.MISS: "miss",
    FailureKind.COALESCENCE: "coalescence",
    FailureKind.IDENTITY_THEFT: "identity theft",
}

KIND_LEVELS: dict[FailureKind, str] = {
    FailureKind.ID_SWITCH: "WARN",
    FailureKind.FRAGMENTATION: "WARN",
    FailureKind.FALSE_TRACK: "INFO",
    FailureKind.MISS: "INFO",
    FailureKind.COALESCENCE: "WARN",
    FailureKind.IDENTITY_THEFT: "ERROR",
}
"""TextLog levels: the paper's failure patterns stand out, plain misses and false tracks stay quiet."""
