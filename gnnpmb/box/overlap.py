"""Overlap of upright 3D boxes: IoU and generalised IoU (GIoU), in the ground plane (BEV) and in 3D, vectorised.

A box is a centre (x, y, z), a size (w, l, h) and a yaw about the vertical axis (``gnnpmb.data.boxes3d``). For
two boxes A and B with intersection I, union U = |A| + |B| - I and smallest enclosing convex set C (Rezatofighi
et al., "Generalized Intersection over Union", CVPR 2019, Alg. 1):

    IoU = I / U,        GIoU = I / U - (|C| - U) / |C|        (GIoU in (-1, 1]; -> -1 as the boxes part)

BEV: areas, C the convex hull of the 8 corners. 3D (IoU: the paper's NMS, sec. V-B; GIoU: SimpleTrack, Pang et
al. 2021, sec. 4.1, and its ``giou3d``): I = I_bev h_overlap, U = V_A + V_B - I, |C| = |hull of the 8 BEV
corners| x (top - bottom of the union's vertical extent).

``UprightBoxes`` holds N boxes with their corners computed once; the ``*_pairs`` functions take two such sets and
P index pairs (box ia[p] of a with box ib[p] of b) and return (P,): an (M, K) matrix is every pair
(``all_pairs``). ``iou_bev``, ``giou_bev``, ``iou_3d`` and ``giou_3d`` take the arrays of P pairs directly.
Pairs whose BEV bounding circles do not meet do not intersect: their intersection is 0 without clipping.
The rectangle intersection I_bev is computed for many pairs at once by convex-polygon clipping in numpy: the
intersection polygon's vertices are the corners of each rectangle inside the other plus the crossings of their
edges; sorted by angle around their mean they give the area by the shoelace formula.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from gnnpmb.data.boxes3d import bev_corners, yaw_from_quat_wxyz

_COLLINEAR_TOL = 1e-9
"""Relative tolerance of the hull: a turn (cross product) below this times the squared extent of the point set
counts as no turn, and two points closer than this times the extent as one point."""
_INSIDE_TOL = 1e-9
"""Slack of the point-in-polygon test (a cross product, m^2), so that shared corners count as inside."""
_PARALLEL_TOL = 1e-12
"""Edges whose direction cross product is below this are treated as parallel (no crossing point)."""


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


def convex_hull_area(points: np.ndarray) -> np.ndarray:
    """(P,) areas of the convex hulls of P point sets, (P, N, 2).

    Vectorised over the sets: the points are sorted by angle around their centroid c (inside the hull), farthest
    first on a tie, which makes a star-shaped polygon; a point equal to the one before it is dropped. Then every
    vertex whose turn (prev, v, next) is not to the left is removed at once, and again until none is: such a
    vertex lies in the triangle (c, prev, next), so it is no hull vertex, and removing several at once is safe.
    What remains is the hull; its area is the shoelace sum. Fewer than 3 distinct points, or all collinear, give
    0. Each pass costs O(N) per set; a few passes suffice for small N (8 corners of two boxes).
    """
    pts = np.asarray(points, dtype=float)
    n_sets, n = pts.shape[:2]
    if n_sets == 0 or n < 3:
        return np.zeros(n_sets)
    pts = pts - pts.mean(axis=1, keepdims=True)  # centroid at the origin: precision, and the angles' centre
    extent = np.maximum(np.abs(pts).max(axis=(1, 2)), 1e-300)[:, None]  # (P, 1)
    x, y = pts[..., 0], pts[..., 1]  # (P, N)
    norm1 = np.abs(x) + np.abs(y)
    ratio = np.divide(x, norm1, out=np.zeros_like(x), where=norm1 > 0.0)
    angle = np.where(y >= 0.0, 1.0 - ratio, 3.0 + ratio)  # pseudo-angle in [0, 4), monotone in the angle
    order = np.lexsort((-norm1, angle), axis=1)
    x, y = np.take_along_axis(x, order, axis=1), np.take_along_axis(y, order, axis=1)
    tol = _COLLINEAR_TOL * extent
    valid = np.ones(x.shape, dtype=bool)
    valid[:, 1:] = (np.abs(x[:, 1:] - x[:, :-1]) > tol) | (np.abs(y[:, 1:] - y[:, :-1]) > tol)
    rows = np.arange(n_sets)[:, None]
    tol_cross = tol * extent
    for _ in range(n):
        prev, nxt = _neighbours(valid)
        turn = (x - x[rows, prev]) * (y[rows, nxt] - y) - (y - y[rows, prev]) * (x[rows, nxt] - x)
        reflex = valid & (turn <= tol_cross)
        if not reflex.any():
            break
        valid &= ~reflex
    _, nxt = _neighbours(valid)
    twice = np.where(valid, x * y[rows, nxt] - x[rows, nxt] * y, 0.0).sum(axis=1)
    return np.maximum(0.5 * twice, 0.0)


def _neighbours(valid: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(P, N) each: the previous and the next valid slot of every slot, cyclically (a running max / min over
    the slots repeated twice)."""
    n = valid.shape[1]
    idx = np.arange(n)
    below = np.where(valid, idx, -n)
    prev = np.maximum.accumulate(np.concatenate([below - n, below], axis=1), axis=1)[:, n - 1 : 2 * n - 1] % n
    above = np.where(valid, idx, 2 * n)
    after = np.concatenate([above, above + n], axis=1)[:, ::-1]
    nxt = np.minimum.accumulate(after, axis=1)[:, ::-1][:, 1 : n + 1] % n
    return prev, nxt


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


def _bev_intersection(a: UprightBoxes, b: UprightBoxes, ia: np.ndarray, ib: np.ndarray) -> np.ndarray:
    """(P,) BEV intersection areas of P index pairs (m^2), clipped only where the bounding circles meet."""
    inter = np.zeros(len(ia))
    near = np.flatnonzero(~apart(a, b, ia, ib))
    inter[near] = convex_intersection_area(a.corners[ia[near]], b.corners[ib[near]])
    return inter


def _bev_hull(a: UprightBoxes, b: UprightBoxes, ia: np.ndarray, ib: np.ndarray) -> np.ndarray:
    """(P,) areas of the convex hulls of the 8 BEV corners of P index pairs (m^2)."""
    return convex_hull_area(np.concatenate([a.corners[ia], b.corners[ib]], axis=1))


def _giou(inter: np.ndarray, union: np.ndarray, enclosing: np.ndarray) -> np.ndarray:
    """I / U - (|C| - U) / |C| (0 where U or |C| is 0: boxes without area)."""
    ok = (union > 0.0) & (enclosing > 0.0)
    u = np.where(ok, union, 1.0)
    c = np.where(ok, enclosing, 1.0)
    return np.where(ok, inter / u - (c - u) / c, 0.0)


def _vertical(a: UprightBoxes, b: UprightBoxes, ia: np.ndarray, ib: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(P,) each: the overlap and the extent (top - bottom) of the pairs' vertical intervals (m)."""
    za, zb = a.centre[ia, 2], b.centre[ib, 2]
    ha, hb = a.size_wlh[ia, 2], b.size_wlh[ib, 2]
    top_a, top_b, bottom_a, bottom_b = za + 0.5 * ha, zb + 0.5 * hb, za - 0.5 * ha, zb - 0.5 * hb
    overlap = np.maximum(np.minimum(top_a, top_b) - np.maximum(bottom_a, bottom_b), 0.0)
    return overlap, np.maximum(top_a, top_b) - np.minimum(bottom_a, bottom_b)


def _inter_union_3d(
    a: UprightBoxes, b: UprightBoxes, ia: np.ndarray, ib: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(P,) each: the intersection and union volumes (m^3) and the vertical extent (m) of P index pairs."""
    overlap_h, extent_h = _vertical(a, b, ia, ib)
    inter = _bev_intersection(a, b, ia, ib) * overlap_h
    union = a.area[ia] * a.size_wlh[ia, 2] + b.area[ib] * b.size_wlh[ib, 2] - inter
    return inter, union, extent_h


def _iou(inter: np.ndarray, union: np.ndarray) -> np.ndarray:
    """I / U (0 where U is 0: boxes without area or volume)."""
    return np.where(union > 0.0, inter / np.where(union > 0.0, union, 1.0), 0.0)


def iou_3d_pairs(a: UprightBoxes, b: UprightBoxes, ia: np.ndarray, ib: np.ndarray) -> np.ndarray:
    """(P,) 3D IoU of P index pairs (module docstring); 0 without clipping for pairs apart."""
    return _iou(*_inter_union_3d(a, b, ia, ib)[:2])


def giou_3d_pairs(a: UprightBoxes, b: UprightBoxes, ia: np.ndarray, ib: np.ndarray) -> np.ndarray:
    """(P,) 3D GIoU of P index pairs (module docstring)."""
    inter, union, extent_h = _inter_union_3d(a, b, ia, ib)
    return _giou(inter, union, _bev_hull(a, b, ia, ib) * extent_h)


def iou_bev_pairs(a: UprightBoxes, b: UprightBoxes, ia: np.ndarray, ib: np.ndarray) -> np.ndarray:
    """(P,) BEV IoU of P index pairs: the rotated rectangles' areas, heights ignored."""
    inter = _bev_intersection(a, b, ia, ib)
    return _iou(inter, a.area[ia] + b.area[ib] - inter)


def giou_bev_pairs(a: UprightBoxes, b: UprightBoxes, ia: np.ndarray, ib: np.ndarray) -> np.ndarray:
    """(P,) BEV GIoU of P index pairs: C is the convex hull of the 8 corners, heights ignored."""
    inter = _bev_intersection(a, b, ia, ib)
    return _giou(inter, a.area[ia] + b.area[ib] - inter, _bev_hull(a, b, ia, ib))


def giou_3d_bound_pairs(a: UprightBoxes, b: UprightBoxes, ia: np.ndarray, ib: np.ndarray) -> np.ndarray:
    """(P,) upper bounds of the 3D GIoU of P index pairs, cheap: 1 for pairs whose bounding circles meet; for
    the others (no intersection) GIoU = (V_A + V_B) / |C| - 1 with |C| >= A_q h_ext, A_q the larger of |A| + |B|
    and the shoelace area of the quadrilateral of the 4 corners extreme across the line between the centres
    (hull points, so at most the hull's area)."""
    e = b.centre[ib, :2] - a.centre[ia, :2]
    dist = np.hypot(e[:, 0], e[:, 1])
    normal = np.stack([-e[:, 1], e[:, 0]], axis=1) / np.where(dist > 0.0, dist, 1.0)[:, None]
    ca, cb = a.corners[ia], b.corners[ib]
    pa, pb = np.einsum("pvi,pi->pv", ca, normal), np.einsum("pvi,pi->pv", cb, normal)
    rows = np.arange(len(ia))
    quad = np.stack(
        [ca[rows, pa.argmin(1)], cb[rows, pb.argmin(1)], cb[rows, pb.argmax(1)], ca[rows, pa.argmax(1)]], axis=1
    )
    qx, qy = quad[..., 0] - quad[:, :1, 0], quad[..., 1] - quad[:, :1, 1]
    quad_area = 0.5 * np.sum(qx * np.roll(qy, -1, axis=1) - np.roll(qx, -1, axis=1) * qy, axis=1)
    area = np.maximum(quad_area, a.area[ia] + b.area[ib])
    _, extent_h = _vertical(a, b, ia, ib)
    volume = a.area[ia] * a.size_wlh[ia, 2] + b.area[ib] * b.size_wlh[ib, 2]
    bound = volume / np.where(area * extent_h > 0.0, area * extent_h, np.inf) - 1.0
    return np.where(apart(a, b, ia, ib), bound, 1.0)


def giou_3d_bound_matrix(a: UprightBoxes, b: UprightBoxes) -> np.ndarray:
    """(M, K) cruder upper bounds of the 3D GIoU of every pair, by broadcasting (no corners): 1 for pairs whose
    bounding circles meet; else |C| >= d (r_A + r_B) h_ext, the trapezoid between the boxes' inscribed circles
    (radii half their shorter sides) at centre distance d, or |A| + |B| if larger."""
    d = np.hypot(a.centre[:, None, 0] - b.centre[None, :, 0], a.centre[:, None, 1] - b.centre[None, :, 1])
    inner_a, inner_b = 0.5 * a.size_wlh[:, :2].min(axis=1), 0.5 * b.size_wlh[:, :2].min(axis=1)
    area = np.maximum(d * (inner_a[:, None] + inner_b[None, :]), a.area[:, None] + b.area[None, :])
    top = np.maximum(
        a.centre[:, None, 2] + 0.5 * a.size_wlh[:, None, 2], b.centre[None, :, 2] + 0.5 * b.size_wlh[None, :, 2]
    )
    bottom = np.minimum(
        a.centre[:, None, 2] - 0.5 * a.size_wlh[:, None, 2], b.centre[None, :, 2] - 0.5 * b.size_wlh[None, :, 2]
    )
    volume = (a.area * a.size_wlh[:, 2])[:, None] + (b.area * b.size_wlh[:, 2])[None, :]
    enclosing = area * (top - bottom)
    bound = volume / np.where(enclosing > 0.0, enclosing, np.inf) - 1.0
    return np.where(d > a.radius[:, None] + b.radius[None, :], bound, 1.0)


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


def pairwise_iou_3d(translation_m: np.ndarray, size_wlh_m: np.ndarray, quat_wxyz: np.ndarray) -> np.ndarray:
    """(N, N) symmetric 3D IoU matrix of N boxes (diagonal 1 for boxes with a volume)."""
    boxes = UprightBoxes.of(translation_m, size_wlh_m, yaw_from_quat_wxyz(quat_wxyz))
    n = len(boxes)
    out = np.zeros((n, n))
    i, j = overlap_candidates(boxes.centre, boxes.size_wlh)
    out[i, j] = out[j, i] = iou_3d_pairs(boxes, boxes, i, j)
    out[np.arange(n), np.arange(n)] = (np.prod(boxes.size_wlh, axis=1) > 0).astype(float)
    return out


def _of_arrays(pairs: Callable[[UprightBoxes, UprightBoxes, np.ndarray, np.ndarray], np.ndarray], doc: str):
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


iou_3d = _of_arrays(iou_3d_pairs, "(P,) 3D IoU of P box pairs given as arrays; 0 for zero-volume pairs.")
giou_3d = _of_arrays(giou_3d_pairs, "(P,) 3D GIoU of P box pairs given as arrays (module docstring).")
iou_bev = _of_arrays(iou_bev_pairs, "(P,) IoU of P pairs of rotated rectangles given as arrays.")
giou_bev = _of_arrays(giou_bev_pairs, "(P,) GIoU of P pairs of rotated rectangles given as arrays.")


__all__ = [
    "UprightBoxes",
    "all_pairs",
    "apart",
    "convex_hull_area",
    "convex_intersection_area",
    "giou_3d",
    "giou_3d_bound_matrix",
    "giou_3d_bound_pairs",
    "giou_3d_pairs",
    "giou_bev",
    "giou_bev_pairs",
    "iou_3d",
    "iou_3d_pairs",
    "iou_bev",
    "iou_bev_pairs",
    "overlap_candidates",
    "pairwise_iou_3d",
]
