"""Generalised IoU (GIoU) of upright 3D boxes, in the ground plane (BEV) and in 3D, vectorised.

A box is a centre (x, y, z), a size (w, l, h) and a yaw about the vertical axis (``gnnpmb.data.boxes3d``). For
two boxes A and B with intersection I, union U = |A| + |B| - I and smallest enclosing convex set C (Rezatofighi
et al., "Generalized Intersection over Union", CVPR 2019, Alg. 1):

    IoU = I / U,        GIoU = I / U - (|C| - U) / |C|        (GIoU in (-1, 1]; -> -1 as the boxes part)

BEV: areas, C the convex hull of the 8 corners. 3D (SimpleTrack, Pang et al. 2021, sec. 4.1, and its ``giou3d``):
I = I_bev h_overlap, U = V_A + V_B - I, |C| = |hull of the 8 BEV corners| x (top - bottom of the union's
vertical extent). I, U and the IoU itself are ``gnnpmb.data.boxes3d``'s, whose ``UprightBoxes``, index pairs
and arrays form the functions here share.
"""

from __future__ import annotations

import numpy as np

from gnnpmb.data.boxes3d import (
    UprightBoxes,
    apart,
    bev_intersection,
    inter_union_3d,
    of_arrays,
    vertical_spans,
)

_COLLINEAR_TOL = 1e-9
"""Relative tolerance of the hull: a turn (cross product) below this times the squared extent of the point set
counts as no turn, and two points closer than this times the extent as one point."""


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


def _bev_hull(a: UprightBoxes, b: UprightBoxes, ia: np.ndarray, ib: np.ndarray) -> np.ndarray:
    """(P,) areas of the convex hulls of the 8 BEV corners of P index pairs (m^2)."""
    return convex_hull_area(np.concatenate([a.corners[ia], b.corners[ib]], axis=1))


def _giou(inter: np.ndarray, union: np.ndarray, enclosing: np.ndarray) -> np.ndarray:
    """I / U - (|C| - U) / |C| (0 where U or |C| is 0: boxes without area)."""
    ok = (union > 0.0) & (enclosing > 0.0)
    u = np.where(ok, union, 1.0)
    c = np.where(ok, enclosing, 1.0)
    return np.where(ok, inter / u - (c - u) / c, 0.0)


def giou_3d_pairs(a: UprightBoxes, b: UprightBoxes, ia: np.ndarray, ib: np.ndarray) -> np.ndarray:
    """(P,) 3D GIoU of P index pairs (module docstring)."""
    inter, union, extent_h = inter_union_3d(a, b, ia, ib)
    return _giou(inter, union, _bev_hull(a, b, ia, ib) * extent_h)


def giou_bev_pairs(a: UprightBoxes, b: UprightBoxes, ia: np.ndarray, ib: np.ndarray) -> np.ndarray:
    """(P,) BEV GIoU of P index pairs: C is the convex hull of the 8 corners, heights ignored."""
    inter = bev_intersection(a, b, ia, ib)
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
    _, extent_h = vertical_spans(a, b, ia, ib)
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


giou_3d = of_arrays(giou_3d_pairs, "(P,) 3D GIoU of P box pairs given as arrays (module docstring).")


giou_bev = of_arrays(giou_bev_pairs, "(P,) GIoU of P pairs of rotated rectangles given as arrays.")


__all__ = [
    "convex_hull_area",
    "giou_3d",
    "giou_3d_bound_matrix",
    "giou_3d_bound_pairs",
    "giou_3d_pairs",
    "giou_bev",
    "giou_bev_pairs",
]
