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

from viz.colors import readable_text
from viz.label_size import BELOW_ANCHOR_PX, CLEARANCE_PX, HEIGHT_PX, width_px

FOV_Y_DEG = 55.0
"""Vertical field of view of the bird's-eye view's eye (Rerun's default)."""
FOCUS_BEV_HEIGHT_PX = 683.0
"""Height of a focus recording's bird's-eye view of one run without a camera view, at 1920 x 1080 (measured in the
web viewer: dev set scene-0103 simpletrack fragmentation:9); ``focus_bev_height_px`` for the other layouts."""
COMPARED_CAMERA_HEIGHTS_PX = {
    (False, False): FOCUS_BEV_HEIGHT_PX,
    (True, False): 791.0,
    (False, True): 404.0,
    (True, True): 465.0,
}
"""(runs compared, a camera view below) -> the bird's-eye view's height in pixels at 1920 x 1080, laid out from the
focus blueprint as ``tools.labels.layout_px`` does (689 px there for ``FOCUS_BEV_HEIGHT_PX``). The shares they
were estimated from (0.55 with a camera, 0.8 compared) made a three-run view with a camera 300 px tall, not 318:
the views were thought 6 % wider in metres than they are and their callouts ran past the edge (demo scene-0103,
pointpillars, cphd beside ab3dmot and pmbm, ``--focus id_switch:1``). Runs compared keep their perspective views
in tabs behind these (``viz.blueprint``), so their bird's-eye views are the scene's whole height."""
FOCUS_ROW_SHARES = (7, 3)
"""One run's focus layout: the bird's-eye view above the perspective view, in these shares of the scene's height
(``viz.blueprint``); runs compared keep the perspective view in a tab behind the bird's-eye view, as tall."""
VIEW_TITLE_PX = 24.0
"""A view's title bar, above its content (``tools.labels.TITLE_PX``)."""
FOCUS_VIEW_WIDTH_PX = 1920 * 3 / 5
"""Width the runs' bird's-eye views share in a focus recording at 1920 x 1080 (the scene column, ``viz.blueprint``)."""
M_PER_PX_PER_HEIGHT = 2.0 * math.tan(math.radians(FOV_Y_DEG / 2.0)) / FOCUS_BEV_HEIGHT_PX
"""Metres per screen pixel per metre of camera height in that view (a pinhole looking straight down: 18 m ->
0.027 m; it was a measured 0.0022, true of a shorter view, so a column could sit past a taller view's edge)."""
LINE_PX = HEIGHT_PX + CLEARANCE_PX
"""Rows of the column are this many pixels apart: a label's height and air (``viz.label_size``)."""
GAP_PX = 40.0
"""Clear space between the rightmost object and the labels' aligned left ends (and between the objects and a
column stacked above or below them)."""
STACK_GAP_PX = 8.0
"""Beside the objects, between the rightmost one and the aligned left ends of a column stacked above them."""
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
    clear_xy_m: np.ndarray | None = None,
) -> np.ndarray:
    """(N, 2) label centres for N callouts at (N, 2) anchors with (N,) text lengths: one column right of the
    rightmost anchor, its labels' left ends aligned ``GAP_PX`` from it (left of the leftmost anchor, right ends
    aligned, when the view's edge, ``view_x_m``: the x range the view shows, would cut less there), rows top-down
    in the order of the anchors' y (highest first, so leaders rarely cross), ``LINE_PX`` apart and centred on the
    anchors' mean y. A leader ends at its label's near end (``leader_ends``), so with aligned ends no leader runs
    through a label. When neither side holds the column whole (a narrow view: three runs side by side) and
    ``view_y_m`` (the y range the view shows) leaves room above the anchors, or else below them, the column goes
    there, just right (else left) of the anchors, inside the view; only when no place holds it does it go to the
    side that cuts less, pushed inside the view when the view is wider than the column. Near the view's top or
    bottom edge (``view_y_m``) the rows move as a block to stay inside it. ``clear_xy_m`` (M, 2):
    more points the column keeps clear of as of the anchors (the corners of the boxes the labels name: a long
    truck's box reaches metres past its centre)."""
    n = len(anchors_xy_m)
    if n == 0:
        return np.zeros((0, 2))
    extent_xy_m = anchors_xy_m if clear_xy_m is None else np.concatenate([anchors_xy_m, clear_xy_m.reshape(-1, 2)])
    m_per_px = M_PER_PX_PER_HEIGHT * height_m
    halves_m = half_widths_m(chars, m_per_px)
    width_m = 2.0 * float(np.max(halves_m))
    gap_m, line_m = GAP_PX * m_per_px, LINE_PX * m_per_px
    order = np.argsort(-anchors_xy_m[:, 1], kind="stable")
    rows_y = float(np.mean(anchors_xy_m[:, 1])) + line_m * (0.5 * (n - 1) - np.arange(n))
    edge, side = float(np.max(extent_xy_m[:, 0])) + gap_m, 1.0  # the column's near edge; +1: it runs right
    if view_x_m is not None and edge + width_m > view_x_m[1]:
        left_edge = float(np.min(extent_xy_m[:, 0])) - gap_m
        over_right, over_left = edge + width_m - view_x_m[1], view_x_m[0] - (left_edge - width_m)
        if over_left < over_right:
            edge, side = left_edge, -1.0
        stacked = _stacked(extent_xy_m, n, width_m, gap_m, line_m, STACK_GAP_PX * m_per_px, view_x_m, view_y_m)
        if min(over_left, over_right) > 0.0 and stacked is not None:
            edge, side, rows_y = stacked
        elif min(over_left, over_right) > 0.0 and width_m <= view_x_m[1] - view_x_m[0]:
            # no place holds it: pushed back inside the view, over the objects (a label over a box can be read,
            # one past the view's edge cannot)
            edge = view_x_m[1] - width_m if side > 0 else view_x_m[0] + width_m
    if view_x_m is not None and width_m <= view_x_m[1] - view_x_m[0]:
        # objects beside the view (frames before the failure, the object still on its way): the column starts at the
        # view's edge and its leaders run out to them (demo scene-0103 pointpillars gnnpmb+pmbm fragmentation:1,
        # frames 8-9: the object 17 m left of the centre, its labels half past the view's left edge)
        edge = max(edge, view_x_m[0]) if side > 0 else min(edge, view_x_m[1])
    if view_y_m is not None:  # near the view's top or bottom edge (frames before the failure): rows kept inside
        rows_y = _inside(rows_y, view_y_m, (BELOW_ANCHOR_PX + HEIGHT_PX) * m_per_px)
    out = np.empty((n, 2))
    out[:, 0] = edge + side * halves_m
    out[order, 1] = rows_y
    return out


def _inside(rows_y: np.ndarray, view_y_m: tuple[float, float], hang_m: float) -> np.ndarray:
    """Rows' y (their labels' anchors; each label hangs ``hang_m`` below its anchor) shifted as a block so that
    every label lies inside ``view_y_m``, when the view is tall enough for them."""
    low, high = float(np.min(rows_y)) - hang_m, float(np.max(rows_y))
    if high - low > view_y_m[1] - view_y_m[0]:
        return rows_y
    if low < view_y_m[0]:
        return rows_y + (view_y_m[0] - low)
    if high > view_y_m[1]:
        return rows_y - (high - view_y_m[1])
    return rows_y


def _stacked(
    extent_xy_m: np.ndarray,
    n: int,
    width_m: float,
    gap_m: float,
    line_m: float,
    near_m: float,
    view_x_m: tuple[float, float],
    view_y_m: tuple[float, float] | None,
) -> tuple[float, float, np.ndarray] | None:
    """(near edge, +1 / -1: the column runs right / left from it, rows' y top-down) of a column of ``n`` labels
    above the objects (``extent_xy_m`` (M, 2): the anchors and the points to keep clear of), else below them, that
    the view holds whole, its near edge ``near_m`` right of the rightmost point (else left of the leftmost one;
    else at the view's right edge, where a leader may cross a label); None when neither above nor below holds it
    (or the view's y range is unknown, or a label is wider than the view)."""
    if view_y_m is None or width_m > view_x_m[1] - view_x_m[0]:
        return None
    steps = line_m * np.arange(n)
    top = float(np.max(extent_xy_m[:, 1])) + gap_m + line_m * (n - 0.5)  # the top row's centre, above
    first = float(np.min(extent_xy_m[:, 1])) - gap_m - 0.5 * line_m  # the top row's centre, below
    if top + 0.5 * line_m <= view_y_m[1]:
        rows = top - steps
    elif first - line_m * (n - 0.5) >= view_y_m[0]:
        rows = first - steps
    else:
        return None
    right = float(np.max(extent_xy_m[:, 0])) + near_m
    if right + width_m <= view_x_m[1]:
        return right, 1.0, rows
    left = float(np.min(extent_xy_m[:, 0])) - near_m
    if left - width_m >= view_x_m[0]:
        return left, -1.0, rows
    return view_x_m[1] - width_m, 1.0, rows


def focus_height_m(eye_height_m: float, compared: bool, camera: bool) -> float:
    """The height ``column_positions`` takes for a focus bird's-eye view whose eye is ``eye_height_m`` above the
    ground: the one at which ``FOCUS_BEV_HEIGHT_PX`` tall would show as many metres per pixel as the layout's view
    (``COMPARED_CAMERA_HEIGHTS_PX``) does from ``eye_height_m``."""
    return eye_height_m * FOCUS_BEV_HEIGHT_PX / COMPARED_CAMERA_HEIGHTS_PX[compared, camera]


def focus_views_px(runs: int, camera: bool) -> tuple[tuple[float, float], tuple[float, float]]:
    """(width, height) in pixels at 1920 x 1080 of a focus recording's bird's-eye view and of its perspective view,
    for ``runs`` side by side with a ``camera`` view below or not: one run's perspective view shares the scene's
    height with the bird's-eye view (``FOCUS_ROW_SHARES``; 159 px with a camera, as ``tools.labels.layout_px``
    lays the demo's out), runs compared show it in a tab as big as the bird's-eye view."""
    width = FOCUS_VIEW_WIDTH_PX / max(runs, 1)
    bev = COMPARED_CAMERA_HEIGHTS_PX[runs > 1, camera]
    if runs > 1:
        return (width, bev), (width, bev)
    top, below = FOCUS_ROW_SHARES
    scene = (bev + VIEW_TITLE_PX) * (top + below) / top
    return (width, bev), (width, scene * below / (top + below) - VIEW_TITLE_PX)


def half_widths_m(chars: np.ndarray, m_per_px: float) -> np.ndarray:
    """(N,) half widths in metres of labels of ``chars`` (N,) characters, with their background."""
    return 0.5 * width_px(np.asarray(chars, dtype=np.float64)) * m_per_px


def leader_ends(anchors_xy_m: np.ndarray, labels_xy_m: np.ndarray, chars: np.ndarray, height_m: float) -> np.ndarray:
    """(N, 2) where each leader meets its label: the end of the label's background nearer its anchor (N, 2), whose
    centre is ``labels_xy_m`` (N, 2) and width ``chars`` (N,) characters; the centre for a label right above or
    below its anchor."""
    halves_m = half_widths_m(chars, M_PER_PX_PER_HEIGHT * height_m)
    side = np.sign(labels_xy_m[:, 0] - anchors_xy_m[:, 0])
    return np.stack([labels_xy_m[:, 0] - side * halves_m, labels_xy_m[:, 1]], axis=1)


def log_callouts(
    stream: rr.RecordingStream,
    path: str,
    callouts: Sequence[Callout],
    height_m: float,
    view_x_m: tuple[float, float] | None = None,
    view_y_m: tuple[float, float] | None = None,
    clear_xy_m: np.ndarray | None = None,
    label_z_m: float | None = None,
) -> None:
    """The callouts as labelled points (``path``; the text in its colour darkened to be read on the label's pale
    background, ``colors.readable_text``: a truck's light cyan was not) and leader lines (``path/leaders``, in the
    colour itself) at the current time; an empty list clears both. ``view_x_m`` / ``view_y_m``: the x / y range
    the bird's-eye view shows; ``clear_xy_m`` (M, 2): the corners of the boxes the column keeps clear of
    (``column_positions``). The labels lie in one plane, ``label_z_m`` high (the height the column is sized for;
    None: the highest anchor's), and each leader runs from its anchor up or down to it: a label at its own anchor's
    height stood nearer the eye or further from it than its neighbours, so rows of one column showed unevenly
    spaced and two touched (demo scene-0103 pointpillars, gnnpmb beside pmbm, ``--focus miss:2``: "m1 0.75 → track
    76" over "evaluation range for car: 50 m", the detection's box 0.9 m above the circle)."""
    anchors = np.array([c.anchor_m for c in callouts], dtype=np.float64).reshape(-1, 3)
    chars = np.array([len(c.text) for c in callouts], dtype=np.int64)
    xy = column_positions(anchors[:, :2], chars, height_m, view_x_m, view_y_m, clear_xy_m)
    z = np.full((len(anchors), 1), label_z_m if label_z_m is not None else np.max(anchors[:, 2], initial=0.0))
    labels_at = np.concatenate([xy, z], axis=1)
    ends = np.concatenate([leader_ends(anchors[:, :2], xy, chars, height_m), z], axis=1)
    colors = np.array([c.color for c in callouts], dtype=np.uint8).reshape(-1, 3)
    text_colors = np.array([readable_text(c.color) for c in callouts], dtype=np.uint8).reshape(-1, 3)
    stream.log(
        path,
        rr.Points3D(
            labels_at,
            labels=[c.text for c in callouts],
            colors=text_colors,
            radii=POINT_RADIUS_M,
            show_labels=True,
        ),
    )
    stream.log(
        f"{path}/leaders",
        rr.LineStrips3D(np.stack([anchors, ends], axis=1), colors=colors, radii=LEADER_RADIUS_M),
    )
