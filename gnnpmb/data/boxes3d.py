"""Geometry of 3D boxes in the nuScenes convention, vectorised over many boxes.

A box is a centre (x, y, z), a size (w, l, h) and a rotation quaternion (w, x, y, z) (``gnnpmb.types.Boxes``).
The box's length runs along its heading (the local x axis), its width along the local y axis, like the
devkit's ``Box.corners``. Detectors and annotations rotate boxes about the vertical axis only, so the geometry
here uses the yaw angle and ignores pitch and roll.

IoU of upright boxes, for many pairs at once: I / U with I the intersection and U = |A| + |B| - I, in the ground
plane (BEV: rectangle areas) or in 3D (the paper's NMS, sec. V-B: I = I_bev h_overlap, U = V_A + V_B - I).
``UprightBoxes`` holds N boxes with their corners computed once; the ``*_pairs`` functions take two such sets and
P index pairs (box ia[p] of a with box ib[p] of b) and return (P,): an (M, K) matrix is every pair
(``all_pairs``). ``iou_bev`` and ``iou_3d`` take the arrays of P pairs directly. Pairs whose BEV bounding circles
do not meet do not intersect: their intersection is 0 without clipping. The rectangle intersection I_bev is
computed by convex-polygon clipping in numpy: the intersection polygon's vertices are the corners of each
rectangle inside the other plus the crossings of their edges; sorted by angle around their mean they give the
area by the shoelace formula. The generalised IoU (GIoU) is ``gnnpmb.box.overlap``.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    from gnnpmb.types import Boxes

_INSIDE_TOL = 1e-9
"""Slack of the point-in-polygon test (a cross product, m^2), so that shared corners count as inside."""
_PARALLEL_TOL = 1e-12
"""Edges whose direction cross product is below this are treated as parallel (no crossing point)."""


def yaw_from_quat_wxyz(quat_wxyz: np.ndarray) -> np.ndarray:
    """Heading angle (rad, counter-clockwise from the global x axis) of (..., 4) quaternions (w, x, y, z).

    yaw = atan2(2 (w z + x y), 1 - 2 (y^2 + z^2)); a scaled (unnormalised) quaternion gives the same angle.
    """
    q = np.asarray(quat_wxyz, dtype=float)
    w, x, y, z = q[..., 0], q[..., 1], q[..., 2], q[..., 3]
    norm2 = w * w + x * x + y * y + z * z
    return np.arctan2(2.0 * (w * z + x * y), norm2 - 2.0 * (y * y + z * z))


def in_footprint(boxes: Boxes, k: int, xy_m: np.ndarray) -> np.ndarray:
    """Which of the points ``xy_m`` (N, 2) lie inside box ``k``'s ground-plane footprint (its w x l rectangle turned
    by its yaw), (N,) bool."""
    yaw = float(yaw_from_quat_wxyz(boxes.quat_wxyz[k]))
    d = np.asarray(xy_m, dtype=float).reshape(-1, 2) - boxes.translation_m[k, :2]
    along = d[:, 0] * np.cos(yaw) + d[:, 1] * np.sin(yaw)
    across = -d[:, 0] * np.sin(yaw) + d[:, 1] * np.cos(yaw)
    return (np.abs(along) <= 0.5 * boxes.size_wlh_m[k, 1]) & (np.abs(across) <= 0.5 * boxes.size_wlh_m[k, 0])


def containing_box(boxes: Boxes, xy_m: np.ndarray) -> tuple[int, float] | None:
    """The box whose footprint contains the point ``xy_m`` (2,) (the nearest centre of those) and the point's
    distance to its centre (m); None: inside none."""
    xy = np.asarray(xy_m, dtype=float)[:2]
    hits = [k for k in range(len(boxes)) if in_footprint(boxes, k, xy)[0]]
    if not hits:
        return None
    dist_m = {k: float(np.hypot(*(boxes.translation_m[k, :2] - xy))) for k in hits}
    k = min(hits, key=dist_m.__getitem__)
    return k, dist_m[k]


def quat_wxyz_from_yaw(yaw_rad: np.ndarray) -> np.ndarray:
    """(..., 4) unit quaternions (w, x, y, z) of rotations by ``yaw_rad`` about the vertical axis."""
    half = 0.5 * np.asarray(yaw_rad, dtype=float)
    zeros = np.zeros_like(half)
    return np.stack([np.cos(half), zeros, zeros, np.sin(half)], axis=-1)


def bev_corners(xy: np.ndarray, size_wl_m: np.ndarray, yaw_rad: np.ndarray) -> np.ndarray:
    """(N, 4, 2) ground-plane corners, counter-clockwise, of N boxes: centres (N, 2), sizes (w, l) (N, 2)."""
    xy = np.asarray(xy, dtype=float)
    size = np.asarray(size_wl_m, dtype=float)
    yaw = np.asarray(yaw_rad, dtype=float)
    half_w = 0.5 * size[:, 0]
    half_l = 0.5 * size[:, 1]
    # Local corners (along heading, across heading), counter-clockwise: front-left, rear-left, rear-right, ...
    along = np.stack([half_l, -half_l, -half_l, half_l], axis=1)
    across = np.stack([half_w, half_w, -half_w, -half_w], axis=1)
    c, s = np.cos(yaw)[:, None], np.sin(yaw)[:, None]
    x = xy[:, 0:1] + c * along - s * across
    y = xy[:, 1:2] + s * along + c * across
    return np.stack([x, y], axis=-1)


def _inside_convex(
    px: np.ndarray, py: np.ndarray, vx: np.ndarray, vy: np.ndarray, ex: np.ndarray, ey: np.ndarray
) -> np.ndarray:
    """(P, K) bool: whether points (px, py), (P, K) each, lie in (or on) convex CCW polygons with vertices
    (vx, vy) and edge vectors (ex, ey), (P, V) each: edge x (point - vertex) >= 0 for every edge."""
    cross = ex[:, None, :] * (py[:, :, None] - vy[:, None, :]) - ey[:, None, :] * (px[:, :, None] - vx[:, None, :])
    return np.all(cross >= -_INSIDE_TOL, axis=2)


def convex_intersection_area(poly_a: np.ndarray, poly_b: np.ndarray) -> np.ndarray:
    """(P,) intersection areas of P pairs of counter-clockwise convex polygons, (P, Va, 2) and (P, Vb, 2)."""
    poly_a = np.asarray(poly_a, dtype=float)
    poly_b = np.asarray(poly_b, dtype=float)
    n_pairs = poly_a.shape[0]
    if n_pairs == 0:
        return np.zeros(0)
    # Work relative to the first vertex of A (precision far from the origin) and with x, y as separate arrays.
    origin = poly_a[:, :1, :]
    ax, ay = np.moveaxis(poly_a - origin, -1, 0)  # (P, Va) each
    bx, by = np.moveaxis(poly_b - origin, -1, 0)  # (P, Vb) each
    rx, ry = np.roll(ax, -1, axis=1) - ax, np.roll(ay, -1, axis=1) - ay
    sx, sy = np.roll(bx, -1, axis=1) - bx, np.roll(by, -1, axis=1) - by
    a_in_b = _inside_convex(ax, ay, bx, by, sx, sy)
    b_in_a = _inside_convex(bx, by, ax, ay, rx, ry)

    # Edge i of A (p + t r) meets edge j of B (q + u s) at t = (q-p) x s / (r x s), u = (q-p) x r / (r x s).
    rx3, ry3, sx3, sy3 = rx[:, :, None], ry[:, :, None], sx[:, None, :], sy[:, None, :]
    qpx = bx[:, None, :] - ax[:, :, None]  # (P, Va, Vb)
    qpy = by[:, None, :] - ay[:, :, None]
    denom = rx3 * sy3 - ry3 * sx3
    ok = np.abs(denom) > _PARALLEL_TOL
    inv = np.divide(1.0, denom, out=np.zeros_like(denom), where=ok)
    t = (qpx * sy3 - qpy * sx3) * inv
    u = (qpx * ry3 - qpy * rx3) * inv
    crossing_ok = ok & (t >= 0.0) & (t <= 1.0) & (u >= 0.0) & (u <= 1.0)
    cx = ax[:, :, None] + t * rx3
    cy = ay[:, :, None] + t * ry3

    x = np.concatenate([ax, bx, cx.reshape(n_pairs, -1)], axis=1)  # (P, K) candidate vertices
    y = np.concatenate([ay, by, cy.reshape(n_pairs, -1)], axis=1)
    valid = np.concatenate([a_in_b, b_in_a, crossing_ok.reshape(n_pairs, -1)], axis=1)
    count = valid.sum(axis=1)
    n_valid = np.maximum(count, 1)
    x = x - np.where(valid, x, 0.0).sum(axis=1, keepdims=True) / n_valid[:, None]
    y = y - np.where(valid, y, 0.0).sum(axis=1, keepdims=True) / n_valid[:, None]
    # Pseudo-angle in [0, 4), monotone in the true angle around the centre; unused candidates sort last.
    norm1 = np.abs(x) + np.abs(y)
    ratio = np.divide(x, norm1, out=np.zeros_like(x), where=norm1 > 0.0)
    angle = np.where(valid, np.where(y >= 0.0, 1.0 - ratio, 3.0 + ratio), np.inf)
    order = np.argsort(angle, axis=1)
    x = np.take_along_axis(x, order, axis=1)
    y = np.take_along_axis(y, order, axis=1)
    valid = np.take_along_axis(valid, order, axis=1)
    # Unused slots repeat the first vertex: repeated points add nothing to the shoelace sum.
    x = np.where(valid, x, x[:, :1])
    y = np.where(valid, y, y[:, :1])
    twice_area = np.sum(x[:, :-1] * y[:, 1:] - x[:, 1:] * y[:, :-1], axis=1) + (x[:, -1] * y[:, 0] - x[:, 0] * y[:, -1])
    return np.where(count >= 3, np.maximum(0.5 * twice_area, 0.0), 0.0)


@dataclass(frozen=True, slots=True)
class UprightBoxes:
    """N upright boxes: centre (N, 3), size_wlh (N, 3) (w, l, h), yaw (N,) rad; corners (N, 4, 2) their BEV
    corners (counter-clockwise), radius (N,) the BEV circumradius (m)."""

    centre: np.ndarray
    size_wlh: np.ndarray
    yaw: np.ndarray
    corners: np.ndarray
    radius: np.ndarray

    @staticmethod
    def of(translation_m: np.ndarray, size_wlh_m: np.ndarray, yaw_rad: np.ndarray) -> UprightBoxes:
        t = np.asarray(translation_m, dtype=float)
        size = np.asarray(size_wlh_m, dtype=float)
        yaw = np.asarray(yaw_rad, dtype=float)
        if t.shape[1] == 2:  # BEV rectangles: a zero height at z = 0
            t, size = np.column_stack([t, np.zeros(len(t))]), np.column_stack([size, np.zeros(len(t))])
        return UprightBoxes(t, size, yaw, bev_corners(t[:, :2], size[:, :2], yaw), 0.5 * np.hypot(*size[:, :2].T))

    def __len__(self) -> int:
        return len(self.yaw)

    @property
    def area(self) -> np.ndarray:
        return self.size_wlh[:, 0] * self.size_wlh[:, 1]


def all_pairs(m: int, k: int) -> tuple[np.ndarray, np.ndarray]:
    """Index pairs (ia, ib), each (M K,), of every box of an M-set with every box of a K-set, row-major."""
    return np.repeat(np.arange(m), k), np.tile(np.arange(k), m)


def apart(a: UprightBoxes, b: UprightBoxes, ia: np.ndarray, ib: np.ndarray) -> np.ndarray:
    """(P,) bool: the pairs whose BEV bounding circles do not meet (so the boxes do not intersect)."""
    d2 = np.sum((a.centre[ia, :2] - b.centre[ib, :2]) ** 2, axis=1)
    return d2 > (a.radius[ia] + b.radius[ib]) ** 2


def bev_intersection(a: UprightBoxes, b: UprightBoxes, ia: np.ndarray, ib: np.ndarray) -> np.ndarray:
    """(P,) BEV intersection areas of P index pairs (m^2), clipped only where the bounding circles meet."""
    inter = np.zeros(len(ia))
    near = np.flatnonzero(~apart(a, b, ia, ib))
    inter[near] = convex_intersection_area(a.corners[ia[near]], b.corners[ib[near]])
    return inter


def vertical_spans(a: UprightBoxes, b: UprightBoxes, ia: np.ndarray, ib: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(P,) each: the overlap and the extent (top - bottom) of the pairs' vertical intervals (m)."""
    za, zb = a.centre[ia, 2], b.centre[ib, 2]
    ha, hb = a.size_wlh[ia, 2], b.size_wlh[ib, 2]
    top_a, top_b, bottom_a, bottom_b = za + 0.5 * ha, zb + 0.5 * hb, za - 0.5 * ha, zb - 0.5 * hb
    overlap = np.maximum(np.minimum(top_a, top_b) - np.maximum(bottom_a, bottom_b), 0.0)
    return overlap, np.maximum(top_a, top_b) - np.minimum(bottom_a, bottom_b)


def inter_union_3d(
    a: UprightBoxes, b: UprightBoxes, ia: np.ndarray, ib: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(P,) each: the intersection and union volumes (m^3) and the vertical extent (m) of P index pairs."""
    overlap_h, extent_h = vertical_spans(a, b, ia, ib)
    inter = bev_intersection(a, b, ia, ib) * overlap_h
    union = a.area[ia] * a.size_wlh[ia, 2] + b.area[ib] * b.size_wlh[ib, 2] - inter
    return inter, union, extent_h


def _iou(inter: np.ndarray, union: np.ndarray) -> np.ndarray:
    """I / U (0 where U is 0: boxes without area or volume)."""
    return np.where(union > 0.0, inter / np.where(union > 0.0, union, 1.0), 0.0)


def iou_3d_pairs(a: UprightBoxes, b: UprightBoxes, ia: np.ndarray, ib: np.ndarray) -> np.ndarray:
    """(P,) 3D IoU of P index pairs (module docstring); 0 without clipping for pairs apart."""
    return _iou(*inter_union_3d(a, b, ia, ib)[:2])


def iou_bev_pairs(a: UprightBoxes, b: UprightBoxes, ia: np.ndarray, ib: np.ndarray) -> np.ndarray:
    """(P,) BEV IoU of P index pairs: the rotated rectangles' areas, heights ignored."""
    inter = bev_intersection(a, b, ia, ib)
    return _iou(inter, a.area[ia] + b.area[ib] - inter)


def overlap_candidates(
    translation_m: np.ndarray, size_wlh_m: np.ndarray, group: np.ndarray | None = None
) -> tuple[np.ndarray, np.ndarray]:
    """Index pairs (i, j), i < j, of boxes that may overlap: bounding circles and vertical extents intersect.

    A cheap filter before ``iou_3d_pairs``: every pair with a positive 3D IoU is returned (and usually few others).
    group: optional (N,) labels; only boxes with equal labels are paired (e.g. the class, for per-class NMS).
    Returns two (P,) integer arrays.
    """
    t = np.asarray(translation_m, dtype=float)
    size = np.asarray(size_wlh_m, dtype=float)
    radius = 0.5 * np.hypot(size[:, 0], size[:, 1])
    d2 = (t[:, None, 0] - t[None, :, 0]) ** 2 + (t[:, None, 1] - t[None, :, 1]) ** 2  # (N, N)
    near = d2 <= (radius[:, None] + radius[None, :]) ** 2
    near &= np.abs(t[:, None, 2] - t[None, :, 2]) <= 0.5 * (size[:, None, 2] + size[None, :, 2])
    if group is not None:
        codes = np.unique(np.asarray(group), return_inverse=True)[1].reshape(-1)
        near &= codes[:, None] == codes[None, :]
    i, j = np.nonzero(near)
    upper = i < j
    return i[upper], j[upper]


def of_arrays(pairs: Callable[[UprightBoxes, UprightBoxes, np.ndarray, np.ndarray], np.ndarray], doc: str):
    """``pairs`` taking P pairs as arrays: centres (P, 3) or (P, 2), sizes (w, l, h) or (w, l), yaws (P,) rad;
    row p of the a arrays with row p of the b arrays."""

    def of_arrays(
        translation_a: np.ndarray,
        size_a: np.ndarray,
        yaw_a: np.ndarray,
        translation_b: np.ndarray,
        size_b: np.ndarray,
        yaw_b: np.ndarray,
    ) -> np.ndarray:
        idx = np.arange(len(np.asarray(yaw_a)))
        return pairs(
            UprightBoxes.of(translation_a, size_a, yaw_a), UprightBoxes.of(translation_b, size_b, yaw_b), idx, idx
        )

    of_arrays.__doc__ = doc
    return of_arrays


iou_3d = of_arrays(iou_3d_pairs, "(P,) 3D IoU of P box pairs given as arrays; 0 for zero-volume pairs.")


iou_bev = of_arrays(iou_bev_pairs, "(P,) IoU of P pairs of rotated rectangles given as arrays.")
