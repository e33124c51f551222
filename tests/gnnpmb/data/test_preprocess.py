import numpy as np
import pytest
import shapely

from gnnpmb.config import PreprocessParams
from gnnpmb.data.boxes3d import (
    UprightBoxes,
    bev_corners,
    convex_intersection_area,
    iou_3d,
    iou_3d_pairs,
    overlap_candidates,
    quat_wxyz_from_yaw,
    yaw_from_quat_wxyz,
)
from gnnpmb.data.preprocess import nms_3d, preprocess
from gnnpmb.types import Boxes


def make_boxes(rows, classes=None, scores=None) -> Boxes:
    """rows: (x, y, z, w, l, h, yaw) per box."""
    rows = np.asarray(rows, dtype=float).reshape(-1, 7)
    n = rows.shape[0]
    return Boxes(
        translation_m=rows[:, 0:3],
        size_wlh_m=rows[:, 3:6],
        quat_wxyz=quat_wxyz_from_yaw(rows[:, 6]),
        velocity_mps=np.zeros((n, 2)),
        score=np.asarray(scores if scores is not None else np.linspace(0.9, 0.5, n), dtype=float),
        class_name=np.asarray(classes if classes is not None else ["car"] * n, dtype=object),
        instance_id=np.full(n, "", dtype=object),
    )


def pairwise_iou_3d(translation_m: np.ndarray, size_wlh_m: np.ndarray, quat_wxyz: np.ndarray) -> np.ndarray:
    """(N, N) symmetric 3D IoU matrix of N boxes (diagonal 1 for boxes with a volume)."""
    boxes = UprightBoxes.of(translation_m, size_wlh_m, yaw_from_quat_wxyz(quat_wxyz))
    n = len(boxes)
    out = np.zeros((n, n))
    i, j = overlap_candidates(boxes.centre, boxes.size_wlh)
    out[i, j] = out[j, i] = iou_3d_pairs(boxes, boxes, i, j)
    out[np.arange(n), np.arange(n)] = (np.prod(boxes.size_wlh, axis=1) > 0).astype(float)
    return out


def iou_of(a, b) -> float:
    boxes = make_boxes([a, b])
    return float(pairwise_iou_3d(boxes.translation_m, boxes.size_wlh_m, boxes.quat_wxyz)[0, 1])


def test_yaw_quaternion_round_trip():
    yaw = np.array([0.0, 0.3, -2.0, np.pi / 2, 3.0])
    np.testing.assert_allclose(yaw_from_quat_wxyz(quat_wxyz_from_yaw(yaw)), yaw, atol=1e-12)
    # A scaled quaternion gives the same yaw.
    np.testing.assert_allclose(yaw_from_quat_wxyz(3.0 * quat_wxyz_from_yaw(yaw)), yaw, atol=1e-12)


def test_bev_corners_follow_heading():
    # A 2 m wide, 4 m long box heading along +y: its length runs along y.
    corners = bev_corners(np.array([[10.0, 5.0]]), np.array([[2.0, 4.0]]), np.array([np.pi / 2]))[0]
    np.testing.assert_allclose(corners, [[9.0, 7.0], [9.0, 3.0], [11.0, 3.0], [11.0, 7.0]], atol=1e-12)
    signed_area = 0.5 * np.sum(corners[:, 0] * np.roll(corners[:, 1], -1) - np.roll(corners[:, 0], -1) * corners[:, 1])
    assert signed_area == pytest.approx(8.0)  # counter-clockwise


def test_iou_identical_boxes_is_one():
    assert iou_of((1, 2, 0.5, 1.9, 4.5, 1.6, 0.7), (1, 2, 0.5, 1.9, 4.5, 1.6, 0.7)) == pytest.approx(1.0)


def test_iou_disjoint_boxes_is_zero():
    assert iou_of((0, 0, 0, 2, 2, 2, 0), (5, 0, 0, 2, 2, 2, 0)) == 0.0
    # Overlapping in the ground plane but stacked vertically.
    assert iou_of((0, 0, 0, 2, 2, 2, 0), (0, 0, 3, 2, 2, 2, 0)) == 0.0
    # Bounding circles overlap but the rotated rectangles do not.
    assert iou_of((0, 0, 0, 1, 4, 1, 0), (2.6, 2.6, 0, 1, 4, 1, np.pi / 2)) == 0.0


def test_iou_axis_aligned_half_overlap():
    # Shifted by half a length: intersection 1 x 2 x 2 = 4, union 8 + 8 - 4 = 12.
    assert iou_of((0, 0, 0, 2, 2, 2, 0), (1, 0, 0, 2, 2, 2, 0)) == pytest.approx(1 / 3)
    assert iou_of((0, 0, 0, 2, 2, 2, 0), (0, 0, 1, 2, 2, 2, 0)) == pytest.approx(1 / 3)
    # A box inside a bigger one: IoU is the volume ratio.
    assert iou_of((0, 0, 0, 4, 4, 4, 0), (0.5, -0.5, 0.5, 2, 2, 2, 0.3)) == pytest.approx(8 / 64)


def test_iou_square_rotated_45_degrees():
    # Side-2 square vs. itself rotated by 45 deg: a regular octagon of area 8 (sqrt 2 - 1); IoU = 1 / sqrt 2.
    assert iou_of((0, 0, 0, 2, 2, 1, 0), (0, 0, 0, 2, 2, 1, np.pi / 4)) == pytest.approx(1 / np.sqrt(2))
    # Touching at one corner only: zero area.
    assert iou_of((0, 0, 0, 2, 2, 1, 0), (1 + np.sqrt(2), 0, 0, 2, 2, 1, np.pi / 4)) == pytest.approx(0.0)


def _random_pairs(seed: int, n: int, dims: int, centre_m: float, size_m: tuple[float, float]) -> tuple[np.ndarray, ...]:
    """Two sets of ``n`` random boxes, centres (n, dims) within +-``centre_m``, sizes (n, dims) in ``size_m``, yaws
    (n,) in +-pi: (centres a, centres b, sizes a, sizes b, yaws a, yaws b)."""
    rng = np.random.default_rng(seed)
    centres = rng.uniform(-centre_m, centre_m, (n, dims)), rng.uniform(-centre_m, centre_m, (n, dims))
    sizes = rng.uniform(*size_m, (n, dims)), rng.uniform(*size_m, (n, dims))
    return *centres, *sizes, rng.uniform(-np.pi, np.pi, n), rng.uniform(-np.pi, np.pi, n)


def test_intersection_area_matches_shapely():
    xy_a, xy_b, s_a, s_b, y_a, y_b = _random_pairs(7, 3000, 2, 3.0, (0.3, 6.0))
    # Degenerate cases: identical boxes, and axis-aligned boxes sharing edge directions.
    xy_b[:200], s_b[:200], y_b[:200] = xy_a[:200], s_a[:200], y_a[:200]
    y_a[200:400] = y_b[200:400] = 0.0
    ca, cb = bev_corners(xy_a, s_a, y_a), bev_corners(xy_b, s_b, y_b)
    expected = shapely.area(shapely.intersection(shapely.polygons(ca), shapely.polygons(cb)))
    np.testing.assert_allclose(convex_intersection_area(ca, cb), expected, atol=1e-9)


def test_iou_3d_symmetric_and_bounded():
    t_a, t_b, s_a, s_b, y_a, y_b = _random_pairs(3, 500, 3, 2.0, (0.5, 4.0))
    ab = iou_3d(t_a, s_a, y_a, t_b, s_b, y_b)
    np.testing.assert_allclose(ab, iou_3d(t_b, s_b, y_b, t_a, s_a, y_a), atol=1e-12)
    assert np.all((ab >= 0) & (ab <= 1))
    assert np.any(ab > 0.2)


def test_overlap_candidates_contains_every_overlapping_pair():
    rng = np.random.default_rng(5)
    rows = np.column_stack(
        [
            rng.uniform(0, 20, (80, 2)),
            rng.uniform(0, 1, 80),
            rng.uniform(0.5, 3, (80, 3)),
            rng.uniform(-3, 3, 80),
        ]
    )
    boxes = make_boxes(rows)
    full = pairwise_iou_3d(boxes.translation_m, boxes.size_wlh_m, boxes.quat_wxyz)
    yaw = yaw_from_quat_wxyz(boxes.quat_wxyz)
    i, j = np.triu_indices(80, k=1)
    brute = iou_3d(
        boxes.translation_m[i],
        boxes.size_wlh_m[i],
        yaw[i],
        boxes.translation_m[j],
        boxes.size_wlh_m[j],
        yaw[j],
    )
    np.testing.assert_allclose(full[i, j], brute, atol=1e-12)
    ci, cj = overlap_candidates(boxes.translation_m, boxes.size_wlh_m)
    candidates = set(zip(ci.tolist(), cj.tolist(), strict=True))
    assert {(a, b) for a, b, v in zip(i, j, brute, strict=True) if v > 0} <= candidates
    assert 0 < len(candidates) < i.size


def test_nms_keeps_higher_score_of_overlapping_pair():
    boxes = make_boxes([(0, 0, 0, 2, 4, 1.5, 0), (0.3, 0, 0, 2, 4, 1.5, 0.1)], scores=[0.4, 0.8])
    np.testing.assert_array_equal(nms_3d(boxes, 0.1), [False, True])


def test_nms_is_per_class():
    boxes = make_boxes([(0, 0, 0, 2, 4, 1.5, 0), (0.3, 0, 0, 2, 4, 1.5, 0)], classes=["car", "truck"])
    np.testing.assert_array_equal(nms_3d(boxes, 0.1), [True, True])


def test_nms_tie_broken_by_index():
    boxes = make_boxes([(0, 0, 0, 2, 4, 1.5, 0), (0.2, 0, 0, 2, 4, 1.5, 0)], scores=[0.6, 0.6])
    np.testing.assert_array_equal(nms_3d(boxes, 0.1), [True, False])


def test_nms_greedy_chain():
    # a overlaps b, b overlaps c, a and c apart: a suppresses b, so c survives.
    boxes = make_boxes([(0, 0, 0, 2, 2, 2, 0), (1, 0, 0, 2, 2, 2, 0), (2, 0, 0, 2, 2, 2, 0)], scores=[0.9, 0.8, 0.7])
    np.testing.assert_array_equal(nms_3d(boxes, 0.1), [True, False, True])
    # The IoU must exceed the threshold: at 1/3 overlap a threshold of 0.5 suppresses nothing.
    np.testing.assert_array_equal(nms_3d(boxes, 0.5), [True, True, True])


def brute_force_nms(boxes: Boxes, threshold: float) -> np.ndarray:
    iou = pairwise_iou_3d(boxes.translation_m, boxes.size_wlh_m, boxes.quat_wxyz)
    keep = np.zeros(len(boxes), dtype=bool)
    for k in sorted(range(len(boxes)), key=lambda k: (-boxes.score[k], k)):
        same = boxes.class_name == boxes.class_name[k]
        if not np.any(keep & same & (iou[k] > threshold)):
            keep[k] = True
    return keep


def test_nms_matches_brute_force_on_dense_scene():
    rng = np.random.default_rng(11)
    n = 250
    rows = np.column_stack(
        [
            rng.uniform(0, 30, (n, 2)),
            rng.normal(0, 0.2, n),
            rng.uniform(0.6, 3, (n, 2)),
            rng.uniform(1, 2, n),
            rng.uniform(-np.pi, np.pi, n),
        ]
    )
    classes = rng.choice(["car", "pedestrian", "truck"], size=n)
    boxes = make_boxes(rows, classes=classes, scores=rng.choice([0.2, 0.5, 0.7, 0.9], size=n))
    for threshold in (0.0, 0.1, 0.3):
        expected = brute_force_nms(boxes, threshold)
        np.testing.assert_array_equal(nms_3d(boxes, threshold), expected)
        assert 0 < expected.sum() < n


def test_preprocess_threshold_then_nms():
    boxes = make_boxes(
        [
            (0, 0, 0, 2, 4, 1.5, 0),  # 0: high score, kept
            (0.2, 0, 0, 2, 4, 1.5, 0),  # 1: overlaps 0, suppressed
            (20, 0, 0, 2, 4, 1.5, 0),  # 2: exactly at threshold, kept
            (20.2, 0, 0, 2, 4, 1.5, 0),  # 3: below threshold; does not suppress anything
            (40, 0, 0, 0.7, 0.7, 1.8, 0),  # 4: class not tracked
        ],
        classes=["car", "car", "car", "car", "barrier"],
        scores=[0.9, 0.5, 0.1, 0.09, 0.99],
    )
    out = preprocess(boxes, PreprocessParams(score_threshold=0.1, nms_iou_3d=0.1), classes=["car", "truck"])
    assert out.boxes is boxes
    np.testing.assert_array_equal(out.kept, [True, False, True, False, False])
    np.testing.assert_array_equal(out.below_threshold, [False, False, False, True, False])
    np.testing.assert_array_equal(out.suppressed_by_nms, [False, True, False, False, False])
    np.testing.assert_array_equal(out.measurements("car").source_index, [0, 2])


def test_preprocess_all_classes_and_empty():
    boxes = make_boxes([(0, 0, 0, 1, 1, 1, 0)], classes=["barrier"], scores=[0.5])
    assert preprocess(boxes, PreprocessParams()).kept.tolist() == [True]
    empty = preprocess(Boxes.empty(), PreprocessParams())
    assert empty.kept.shape == empty.below_threshold.shape == empty.suppressed_by_nms.shape == (0,)


def test_preprocess_is_deterministic():
    rng = np.random.default_rng(2)
    rows = np.column_stack([rng.uniform(0, 10, (60, 3)), rng.uniform(1, 3, (60, 3)), rng.uniform(-3, 3, 60)])
    boxes = make_boxes(rows, scores=rng.uniform(0, 1, 60))
    a = preprocess(boxes, PreprocessParams())
    b = preprocess(boxes, PreprocessParams())
    np.testing.assert_array_equal(a.kept, b.kept)
    assert a.below_threshold.any() and a.suppressed_by_nms.any() and a.kept.any()
    assert not np.any(a.kept & (a.below_threshold | a.suppressed_by_nms))


def test_impossible_boxes_are_never_kept_nor_flagged():
    boxes = make_boxes([(float(i) * 10, 0.0, 0.0, 4.0, 2.0, 1.5, 0.0) for i in range(5)])
    boxes.translation_m[1, 0] = np.nan
    boxes.size_wlh_m[2, 1] = -1.0
    boxes.quat_wxyz[3] = 0.0
    boxes.translation_m[4, 1] = 1e308
    out = preprocess(boxes, PreprocessParams())
    assert out.kept.tolist() == [True, False, False, False, False]
    assert not out.below_threshold.any() and not out.suppressed_by_nms.any()
