"""Where a time-series plot's legend goes so that it covers no data.

Rerun draws a plot's legend inside the plot, in one corner. With the few series of a focus recording the legend
takes a large share of a small plot, and in a fixed corner it hid the very lines it names (a starving track's
existence near 0 under a bottom-left legend). ``place_legend`` looks at the lines, as Rerun will scale them, and
picks a corner the legend's box leaves empty; when every corner holds data it puts the legend at the top and
stretches the y axis so the lines stay below it, except on a plot with a fixed range (a probability's), where it
takes the corner that covers the least.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
import rerun.blueprint as rrb

Corner = rrb.components.Corner2D

PLOT_HEIGHT_PX = 180.0
"""Height of a tracker's series plot in the focus layout at 1920x1080 (a legend's height is set in pixels by its
rows, so its share of the plot depends on the plot's size)."""
COMPARISON_PLOT_HEIGHT_PX = 140.0
"""The same for the disagreement counts below the views."""
LEGEND_ROW_PX = 21.0
LEGEND_PAD_PX = 10.0
"""Measured on a screenshot of the web viewer: a legend of 4 rows is 92 px high and 215 px wide."""
LEGEND_WIDTH = 0.3
"""Share of the plot's width the legend's box takes (its entries are short: "<track id> <class> existence")."""
MAX_LEGEND_HEIGHT = 0.75
"""The legend is assumed to take at most this share of the plot's height (Rerun scrolls a longer one)."""
PROBABILITY_RANGE = (-0.02, 1.02)
"""The y range of plots of probabilities (existence): [0, 1] with room for the lines at either end."""
LOW_EXISTENCE = 0.25
"""An existence plot whose tracks all stay below this is zoomed to them (``existence_range``)."""


def existence_range(values: Sequence[np.ndarray]) -> tuple[float, float]:
    """The y range of an existence plot of the tracks' (K,) value arrays: ``PROBABILITY_RANGE``, or, when every
    value is below ``LOW_EXISTENCE`` (tracks that never came close to being shown), [0, their peak] with the same
    relative room, so their rise and fall stay visible instead of flat lines on the floor of [0, 1]."""
    peak = max((float(np.max(v)) for v in values if len(v)), default=1.0)
    if peak >= LOW_EXISTENCE:
        return PROBABILITY_RANGE
    top = max(peak, 0.01)
    return (PROBABILITY_RANGE[0] * top, PROBABILITY_RANGE[1] * top)


Y_MARGIN = 0.05
"""Share of the data's y span added below and above it (Rerun's automatic bounds leave a similar margin)."""
SAMPLES = 200
"""Points per line at which the legend's box is tested (lines are straight between logged points)."""
CORNER_ORDER = (Corner.RightTop, Corner.LeftTop, Corner.RightBottom, Corner.LeftBottom)
"""Preference among corners that are equally empty."""
FOCUS_PAST_FRAMES = 1
"""A focus recording's track plots run this many frames past the failure frame, where they open
(``viz.blueprint``), so a line's point at that frame is not on the plot's edge."""
LAST_FRAME_WEIGHT = 20
"""When every corner of a fixed-range plot holds data, a sample within half a frame of the lines' last frame (a
focus plot's failure frame) counts this many times: the legend may hide the story's past, not its end (dev set
scene-0916 megvii phd id_switch:1: it covered track 8's weight falling below the threshold at frame 13)."""


@dataclass(frozen=True, slots=True)
class LegendPlacement:
    """A legend corner and, when the data had to make room for it, the y range to show (None: automatic)."""

    corner: Corner
    y_range: tuple[float, float] | None = None

    def view_args(self) -> dict[str, rrb.PlotLegend | rrb.ScalarAxis]:
        """Keyword arguments of ``rrb.TimeSeriesView``: the visible legend and, if set, the y axis."""
        args: dict[str, rrb.PlotLegend | rrb.ScalarAxis] = {"plot_legend": rrb.PlotLegend(self.corner, visible=True)}
        if self.y_range is not None:
            args["axis_y"] = rrb.ScalarAxis(range=self.y_range)
        return args


def legend_height(n_entries: int, plot_height_px: float = PLOT_HEIGHT_PX) -> float:
    """Share of the plot's height a legend of ``n_entries`` rows takes."""
    return min(MAX_LEGEND_HEIGHT, (LEGEND_PAD_PX + LEGEND_ROW_PX * n_entries) / plot_height_px)


def place_legend(
    lines: Sequence[tuple[np.ndarray, np.ndarray]],
    n_entries: int | None = None,
    plot_height_px: float = PLOT_HEIGHT_PX,
    y_range: tuple[float, float] | None = None,
    past_frames: int = 0,
    x_range: tuple[float, float] | None = None,
) -> LegendPlacement:
    """The corner for the legend of a plot of ``lines`` ((K,) x, (K,) y each; NaN values are gaps): the first
    of ``CORNER_ORDER`` whose legend box no line passes through. If there is none: with a fixed ``y_range``
    (e.g. a probability's [0, 1]) the corner that covers the fewest line samples (those at the last frame count
    ``LAST_FRAME_WEIGHT`` times); else the top right with a y range whose upper part is left free for it.
    ``n_entries``: legend rows (default: one per line); ``past_frames``: the plot's x axis runs this many frames
    past the lines' last x (``FOCUS_PAST_FRAMES``); ``x_range``: the x axis's own range when the view sets one (it
    then replaces the lines' range and ``past_frames``): a focus near the scene's start shows frames 0-9 for lines
    of frames 0-3, and a legend placed for 0-4 hid the two lines it named at the top of the plot (demo scene-9001
    cphd ``--focus identity_theft:1``, tracks 4 and 7)."""
    drawn = [(np.asarray(x, np.float64), np.asarray(y, np.float64)) for x, y in lines]
    drawn = [(x[np.isfinite(y)], y[np.isfinite(y)]) for x, y in drawn]
    drawn = [(x, y) for x, y in drawn if x.size]
    if not drawn:
        return LegendPlacement(CORNER_ORDER[0], y_range)
    height = legend_height(len(lines) if n_entries is None else n_entries, plot_height_px)
    x_lo = min(float(x.min()) for x, _ in drawn)
    last = max(float(x.max()) for x, _ in drawn)
    x_hi = last + past_frames
    if x_range is not None:
        x_lo, x_hi = x_range
    if y_range is None:
        y_lo = min(float(y.min()) for _, y in drawn)
        y_hi = max(float(y.max()) for _, y in drawn)
        span = y_hi - y_lo if y_hi > y_lo else max(abs(y_hi), 1.0)
        y_lo, y_hi = y_lo - Y_MARGIN * span, y_hi + Y_MARGIN * span
    else:
        y_lo, y_hi = y_range
    u, v = _normalised(drawn, (x_lo, x_hi), (y_lo, y_hi))
    weight = np.where(u >= (last - 0.5 - x_lo) / ((x_hi - x_lo) or 1.0), LAST_FRAME_WEIGHT, 1)
    covered = []
    for corner in CORNER_ORDER:
        left = corner in (Corner.LeftTop, Corner.LeftBottom)
        top = corner in (Corner.LeftTop, Corner.RightTop)
        in_x = u <= LEGEND_WIDTH if left else u >= 1.0 - LEGEND_WIDTH
        in_y = v >= 1.0 - height if top else v <= height
        covered.append(int(weight[in_x & in_y].sum()))
        if covered[-1] == 0:
            return LegendPlacement(corner, y_range)
    if y_range is not None:
        return LegendPlacement(CORNER_ORDER[int(np.argmin(covered))], y_range)
    # Every corner holds data: the data keeps the lower (1 - height) of the plot, the legend the band above it.
    top = y_lo + (y_hi - y_lo) / (1.0 - height)
    return LegendPlacement(Corner.RightTop, (y_lo, top))


def _normalised(
    lines: Sequence[tuple[np.ndarray, np.ndarray]], x_range: tuple[float, float], y_range: tuple[float, float]
) -> tuple[np.ndarray, np.ndarray]:
    """Every line sampled at ``SAMPLES`` points between its first and last x (one point for a single sample),
    mapped to [0, 1] x [0, 1] of the plot."""
    us, vs = [], []
    x_span = x_range[1] - x_range[0] or 1.0
    y_span = y_range[1] - y_range[0]
    for x, y in lines:
        order = np.argsort(x, kind="stable")
        x, y = x[order], y[order]
        at = np.linspace(x[0], x[-1], SAMPLES) if x.size > 1 else x
        us.append((at - x_range[0]) / x_span)
        vs.append((np.interp(at, x, y) - y_range[0]) / y_span)
    return np.concatenate(us), np.concatenate(vs)
