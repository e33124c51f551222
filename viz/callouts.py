"""Callouts: the labels of a focus recording's involved objects, stacked in a column beside them with a leader
line from each label to its object, so the labels of things that sit on one spot (the ground truth, the detection
on it, two tracks' predictions of it) never cover each other.

Rerun draws a label centred on its point in screen space, so labels of points closer than a label's size
overlap. The focus bird's-eye camera looks straight down from ``height_m`` with +y up and +x right on screen
(``blueprint.bev_view``); at the default layout on a 1920x1080 screen one screen pixel there is about
``M_PER_PX_PER_HEIGHT * height_m`` metres, which sizes the rows (``LINE_PX``) and the gap to the column.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
import rerun as rr

FOV_Y_DEG = 55.0
"""Vertical field of view of the bird's-eye view's eye (Rerun's default)."""
FOCUS_BEV_HEIGHT_PX = 683.0
"""Height of a focus recording's bird's-eye view of one run without a camera view, at 1920 x 1080 (measured in the
web viewer: dev set scene-0103 simpletrack fragmentation:9; two runs and a camera view below shorten it,
``viz.focus``)."""
M_PER_PX_PER_HEIGHT = 2.0 * math.tan(math.radians(FOV_Y_DEG / 2.0)) / FOCUS_BEV_HEIGHT_PX
"""Metres per screen pixel per metre of camera height in that view (a pinhole looking straight down: 18 m ->
0.027 m; it was a measured 0.0022, true of a shorter view, so a column could sit past a taller view's edge)."""
LINE_PX = 22.0
"""Rows of the column are this many pixels apart (a label is about 16 px tall)."""
CHAR_PX = 7.5
"""Width of one label character in pixels."""
GAP_PX = 40.0
"""Clear space between the rightmost object and the left end of the longest label."""
POINT_RADIUS_M = 0.08
LEADER_RADIUS_M = 0.05


@dataclass(frozen=True, slots=True)
class Callout:
    """One label: the BEV point it names (x, y, z in metres), its text and colour (RGB)."""

    anchor_m: tuple[float, float, float]
    text: str
    color: tuple[int, int, int]


def column_positions(
    anchors_xy_m: np.ndarray,
    chars: np.ndarray,
    height_m: float,
    view_x_m: tuple[float, float] | None = None,
    view_y_m: tuple[float, float] | None = None,
) -> np.ndarray:
    """(N, 2) label centres for N callouts at (N, 2) anchors with (N,) text lengths: one column right of the
    rightmost anchor (left of the leftmost one when the view's edge, ``view_x_m``: the x range the view shows,
    would cut less of it there), rows top-down in the order of the anchors' y (highest first, so leaders rarely cross),
    ``LINE_PX`` apart and centred on the anchors' mean y. When neither side holds the column whole (a narrow view:
    three runs side by side) and ``view_y_m`` (the y range the view shows) leaves room above the anchors, or else
    below them, the column goes there, moved sideways into the view; only when no place holds it does it go to
    the side that cuts less."""
    n = len(anchors_xy_m)
    if n == 0:
        return np.zeros((0, 2))
    m_per_px = M_PER_PX_PER_HEIGHT * height_m
    half_width_m = 0.5 * CHAR_PX * float(np.max(chars)) * m_per_px
    gap_m, line_m = GAP_PX * m_per_px, LINE_PX * m_per_px
    x = float(np.max(anchors_xy_m[:, 0])) + gap_m + half_width_m
    left = float(np.min(anchors_xy_m[:, 0])) - gap_m - half_width_m
    order = np.argsort(-anchors_xy_m[:, 1], kind="stable")
    rows_y = float(np.mean(anchors_xy_m[:, 1])) + line_m * (0.5 * (n - 1) - np.arange(n))
    if view_x_m is not None and x + half_width_m > view_x_m[1]:
        over_right, over_left = x + half_width_m - view_x_m[1], view_x_m[0] - (left - half_width_m)
        x = left if over_left < over_right else x
        stacked = _stacked(anchors_xy_m, n, half_width_m, gap_m, line_m, view_x_m, view_y_m)
        if min(over_left, over_right) > 0.0 and stacked is not None:
            x, rows_y = stacked
    out = np.empty((n, 2))
    out[order, 0] = x
    out[order, 1] = rows_y
    return out


def _stacked(
    anchors_xy_m: np.ndarray,
    n: int,
    half_width_m: float,
    gap_m: float,
    line_m: float,
    view_x_m: tuple[float, float],
    view_y_m: tuple[float, float] | None,
) -> tuple[float, np.ndarray] | None:
    """(x, rows' y, top-down) of a column above the anchors, else below them, that the view holds whole; None
    when neither does (or the view's y range is unknown, or a label is wider than the view)."""
    if view_y_m is None or 2.0 * half_width_m > view_x_m[1] - view_x_m[0]:
        return None
    x = float(np.clip(np.mean(anchors_xy_m[:, 0]), view_x_m[0] + half_width_m, view_x_m[1] - half_width_m))
    steps = line_m * np.arange(n)
    top = float(np.max(anchors_xy_m[:, 1])) + gap_m + line_m * (n - 0.5)  # the top row's centre, above
    if top + 0.5 * line_m <= view_y_m[1]:
        return x, top - steps
    first = float(np.min(anchors_xy_m[:, 1])) - gap_m - 0.5 * line_m  # the top row's centre, below
    if first - line_m * (n - 0.5) >= view_y_m[0]:
        return x, first - steps
    return None


def log_callouts(
    stream: rr.RecordingStream,
    path: str,
    callouts: Sequence[Callout],
    height_m: float,
    view_x_m: tuple[float, float] | None = None,
    view_y_m: tuple[float, float] | None = None,
) -> None:
    """The callouts as labelled points (``path``) and leader lines (``path/leaders``) at the current time; an
    empty list clears both. ``view_x_m`` / ``view_y_m``: the x / y range the bird's-eye view shows
    (``column_positions``)."""
    anchors = np.array([c.anchor_m for c in callouts], dtype=np.float64).reshape(-1, 3)
    chars = np.array([len(c.text) for c in callouts], dtype=np.int64)
    xy = column_positions(anchors[:, :2], chars, height_m, view_x_m, view_y_m)
    labels_at = np.concatenate([xy, anchors[:, 2:]], axis=1)
    colors = np.array([c.color for c in callouts], dtype=np.uint8).reshape(-1, 3)
    stream.log(
        path,
        rr.Points3D(
            labels_at,
            labels=[c.text for c in callouts],
            colors=colors,
            radii=POINT_RADIUS_M,
            show_labels=True,
        ),
    )
    stream.log(
        f"{path}/leaders",
        rr.LineStrips3D(np.stack([anchors, labels_at], axis=1), colors=colors, radii=LEADER_RADIUS_M),
    )
