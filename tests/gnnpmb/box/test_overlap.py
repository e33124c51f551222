"""IoU / GIoU of upright boxes: hand-computed cases, equivalence with shapely and scipy, the far-pair bound."""

import math

import numpy as np
import pytest
from scipy.spatial import ConvexHull
from shapely.geometry import Polygon

from gnnpmb.box.overlap import (
    convex_hull_area,
    giou_3d,
    giou_3d_bound_matrix,
    giou_3d_bound_pairs,
    giou_3d_pairs,
    giou_bev,
)
from gnnpmb.data.boxes3d import UprightBoxes, all_pairs, bev_corners, iou_3d, iou_3d_pairs, iou_bev

UNIT = np.array([[1.0, 1.0]])


def _bev(xy_a, xy_b, yaw_a=0.0, yaw_b=0.0, size_a=UNIT, size_b=UNIT):
    return (np.atleast_2d(xy_a), size_a, np.array([yaw_a]), np.atleast_2d(xy_b), size_b, np.array([yaw_b]))


@pytest.mark.parametrize(
    ("xy_b", "iou", "giou"),
    [
        ((0.0, 0.0), 1.0, 1.0),  # identical
        ((0.5, 0.0), 1 / 3, 1 / 3),  # half overlap: I 0.5, U 1.5, C 1.5
        ((1.0, 0.0), 0.0, 0.0),  # touching sides: U = C = 2
        ((2.0, 0.0), 0.0, -1 / 3),  # 1 m gap: U 2, C 3
        ((1.0, 1.0), 0.0, -1 / 3),  # touching corners: C = 2 x 2 minus two half-unit triangles = 3
    ],
)
def test_hand_computed_unit_squares(xy_b, iou, giou):
    args = _bev((0.0, 0.0), xy_b)
    assert iou_bev(*args)[0] == pytest.approx(iou, abs=1e-12)
    assert giou_bev(*args)[0] == pytest.approx(giou, abs=1e-12)


def test_square_and_its_45_degree_turn():
    """Same centre and size: I is the regular octagon 2(sqrt 2 - 1), C the octagon of the 8 corners (radius
    sqrt(2)/2): 2 sqrt(2) r^2 = sqrt 2."""
    args = _bev((0.0, 0.0), (0.0, 0.0), yaw_b=math.pi / 4)
    inter = 2.0 * (math.sqrt(2.0) - 1.0)
    union = 2.0 - inter
    hull = math.sqrt(2.0)
    assert iou_bev(*args)[0] == pytest.approx(inter / union, abs=1e-12)
    assert giou_bev(*args)[0] == pytest.approx(inter / union - (hull - union) / hull, abs=1e-12)


@pytest.mark.parametrize(
    ("z_b", "giou"),
    [
        (0.5, 1.0),  # identical unit cubes
        (1.0, 1 / 3),  # half the height overlaps: I 0.5, U 1.5, C 1 x 1.5
        (2.5, -1 / 3),  # stacked with a 1 m gap: I 0, U 2, C 1 x 3
    ],
)
def test_hand_computed_unit_cubes(z_b, giou):
    cube = np.array([[1.0, 1.0, 1.0]])
    value = giou_3d(np.array([[0.0, 0.0, 0.5]]), cube, np.zeros(1), np.array([[0.0, 0.0, z_b]]), cube, np.zeros(1))
    assert value[0] == pytest.approx(giou, abs=1e-12)


def _random_boxes(rng, n, spread=6.0):
    t = np.column_stack([rng.uniform(-spread, spread, (n, 2)), rng.uniform(0.0, 2.0, n)])
    size = rng.uniform(0.3, 6.0, (n, 3))
    return t, size, rng.uniform(-4.0, 4.0, n)


def _brute_giou_3d(ta, sa, ya, tb, sb, yb):
    """SimpleTrack's ``giou3d`` formula with shapely polygons and scipy's convex hull."""
    out = []
    for i in range(len(ya)):
        ca = bev_corners(ta[i : i + 1, :2], sa[i : i + 1, :2], ya[i : i + 1])[0]
        cb = bev_corners(tb[i : i + 1, :2], sb[i : i + 1, :2], yb[i : i + 1])[0]
        pa, pb = Polygon(ca), Polygon(cb)
        top_a, top_b = ta[i, 2] + sa[i, 2] / 2, tb[i, 2] + sb[i, 2] / 2
        bot_a, bot_b = ta[i, 2] - sa[i, 2] / 2, tb[i, 2] - sb[i, 2] / 2
        inter = pa.intersection(pb).area * max(0.0, min(top_a, top_b) - max(bot_a, bot_b))
        union = pa.area * sa[i, 2] + pb.area * sb[i, 2] - inter
        hull = ConvexHull(np.vstack([ca, cb])).volume * (max(top_a, top_b) - min(bot_a, bot_b))
        out.append(inter / union - (hull - union) / hull)
    return np.array(out)


def test_giou_3d_equals_shapely_and_scipy_on_random_boxes():
    rng = np.random.default_rng(0)
    a, b = _random_boxes(rng, 400), _random_boxes(rng, 400)
    np.testing.assert_allclose(giou_3d(*a, *b), _brute_giou_3d(*a, *b), atol=1e-9)


def test_giou_bev_equals_shapely_on_random_rectangles():
    rng = np.random.default_rng(1)
    (ta, sa, ya), (tb, sb, yb) = _random_boxes(rng, 300), _random_boxes(rng, 300)
    ours = giou_bev(ta[:, :2], sa[:, :2], ya, tb[:, :2], sb[:, :2], yb)
    ref = []
    for i in range(300):
        pa = Polygon(bev_corners(ta[i : i + 1, :2], sa[i : i + 1, :2], ya[i : i + 1])[0])
        pb = Polygon(bev_corners(tb[i : i + 1, :2], sb[i : i + 1, :2], yb[i : i + 1])[0])
        inter, union = pa.intersection(pb).area, pa.union(pb).area
        hull = pa.union(pb).convex_hull.area
        ref.append(inter / union - (hull - union) / hull)
    np.testing.assert_allclose(ours, ref, atol=1e-9)


def test_convex_hull_area_equals_scipy_including_degenerate_sets():
    rng = np.random.default_rng(2)
    pts = rng.normal(size=(500, 8, 2)) * rng.uniform(0.1, 50.0, (500, 1, 1)) + rng.uniform(-1e4, 1e4, (500, 1, 2))
    np.testing.assert_allclose(convex_hull_area(pts), [ConvexHull(p).volume for p in pts], rtol=1e-9)
    square = np.array([[0, 0], [1, 0], [1, 1], [0, 1]], dtype=float)
    degenerate = np.stack(
        [
            np.concatenate([square, square]),  # every corner twice
            np.array([[0, 0], [1, 0], [2, 0], [3, 0], [3, 1], [0, 1], [1, 1], [2, 1]], dtype=float),  # collinear
            np.zeros((8, 2)),  # one point
            np.repeat(np.arange(8.0)[:, None], 2, axis=1),  # a line
        ]
    )
    np.testing.assert_allclose(convex_hull_area(degenerate), [1.0, 3.0, 0.0, 0.0], atol=1e-12)


def test_pairs_and_all_pairs_agree_with_the_per_pair_functions():
    rng = np.random.default_rng(3)
    a, b = UprightBoxes.of(*_random_boxes(rng, 5)), UprightBoxes.of(*_random_boxes(rng, 7))
    ia, ib = all_pairs(5, 7)
    giou = giou_3d_pairs(a, b, ia, ib)
    np.testing.assert_allclose(
        giou, giou_3d(a.centre[ia], a.size_wlh[ia], a.yaw[ia], b.centre[ib], b.size_wlh[ib], b.yaw[ib])
    )
    iou = iou_3d_pairs(a, b, ia, ib)
    np.testing.assert_allclose(
        iou, iou_3d(a.centre[ia], a.size_wlh[ia], a.yaw[ia], b.centre[ib], b.size_wlh[ib], b.yaw[ib])
    )


def test_the_far_pair_bound_is_an_upper_bound_of_giou():
    rng = np.random.default_rng(4)
    a, b = UprightBoxes.of(*_random_boxes(rng, 3000, 30.0)), UprightBoxes.of(*_random_boxes(rng, 3000, 30.0))
    idx = np.arange(3000)
    exact, bound = giou_3d_pairs(a, b, idx, idx), giou_3d_bound_pairs(a, b, idx, idx)
    assert (exact <= bound + 1e-12).all()
    apart = bound < 1.0
    assert apart.mean() > 0.8 and np.median(bound[apart] - exact[apart]) < 0.05  # tight enough to skip most pairs


def test_the_crude_matrix_bound_is_an_upper_bound_too():
    rng = np.random.default_rng(5)
    a, b = UprightBoxes.of(*_random_boxes(rng, 60, 30.0)), UprightBoxes.of(*_random_boxes(rng, 70, 30.0))
    exact = giou_3d_pairs(a, b, *all_pairs(60, 70)).reshape(60, 70)
    crude = giou_3d_bound_matrix(a, b)
    tight = giou_3d_bound_pairs(a, b, *all_pairs(60, 70)).reshape(60, 70)
    assert (exact <= crude + 1e-12).all() and (exact <= tight + 1e-12).all()
    assert (tight <= crude + 1e-12).mean() > 0.95  # the corner bound is the tighter one, nearly always
