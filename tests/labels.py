"""Cost-matrix axis labels as hand-made events in tests spell them: ``meas(3)``, ``track(7)``, ``new(3)``."""

from __future__ import annotations

from gnnpmb.events import AxisKind, AxisLabel


def meas(i: int) -> AxisLabel:
    return AxisLabel(AxisKind.MEASUREMENT, i)


def track(t: int) -> AxisLabel:
    return AxisLabel(AxisKind.TRACK, t)


def new(i: int) -> AxisLabel:
    return AxisLabel(AxisKind.NEW_TRACK, i)


def missed() -> AxisLabel:
    return AxisLabel(AxisKind.MISSED, -1)
