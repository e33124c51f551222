"""Detection preprocessing before tracking (paper sec. V-B): score threshold, then per-class 3D-IoU NMS.

1. Boxes with ``score < score_threshold`` are dropped (``below_threshold``).
2. Among the remaining boxes of each class, greedy non-maximum suppression: visit boxes from the highest
   score down (equal scores: lower input index first, so the result is deterministic); keep a box unless a box
   kept before it overlaps it with 3D IoU ``> nms_iou_3d`` (``suppressed_by_nms``). Boxes of different classes
   never suppress each other.

Both thresholds may differ per class (``TrackerConfig.preprocess_by_class``).

Boxes that cannot be real (a NaN or infinite field, a centre beyond ``MAX_ABS_COORD_M``, a size not in
(0, ``MAX_SIZE_M``], a speed beyond ``MAX_SPEED_MPS``, a zero quaternion, a score outside [0, 1]) are never
kept either: a detection file with such a box is refused when read (``gnnpmb.data.detections``), and this keeps
the trackers safe from boxes built in code. Boxes whose class is not among the tracked ``classes`` are simply
not kept: neither ``below_threshold`` nor ``suppressed_by_nms`` is set for them, so the viewer can tell "not
tracked" apart from "filtered out".
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence

import numpy as np

from gnnpmb.config import PreprocessParams
from gnnpmb.data.boxes3d import UprightBoxes, iou_3d_pairs, overlap_candidates, yaw_from_quat_wxyz
from gnnpmb.data.detections import MAX_ABS_COORD_M, MAX_SIZE_M, MAX_SPEED_MPS, MIN_QUAT_NORM
from gnnpmb.types import Boxes, FrameDetections


def nms_3d(boxes: Boxes, iou_threshold: float | np.ndarray) -> np.ndarray:
    """(N,) bool mask of the boxes greedy per-class NMS keeps, suppressing at 3D IoU > ``iou_threshold`` (a
    number, or (N,) per box: boxes of one class share it)."""
    n = len(boxes)
    keep = np.ones(n, dtype=bool)
    if n < 2:
        return keep
    t, size = boxes.translation_m, boxes.size_wlh_m
    i, j = overlap_candidates(t, size, group=boxes.class_name)
    if i.size == 0:
        return keep
    upright = UprightBoxes.of(t, size, yaw_from_quat_wxyz(boxes.quat_wxyz))
    iou = iou_3d_pairs(upright, upright, i, j)
    over = iou > np.broadcast_to(np.asarray(iou_threshold, dtype=float), (n,))[i]
    i, j = i[over], j[over]
    if i.size == 0:
        return keep
    # Rank by score descending, then by index; each overlapping pair is directed from better to worse rank.
    order = np.lexsort((np.arange(n), -boxes.score))
    rank = np.empty(n, dtype=np.int64)
    rank[order] = np.arange(n)
    better = np.where(rank[i] < rank[j], i, j)
    worse = np.where(rank[i] < rank[j], j, i)
    by_better = np.argsort(rank[better], kind="stable")
    better, worse = better[by_better], worse[by_better]
    # A box's own suppression is final before its pairs are visited: pairs are in order of the better rank.
    suppressed = np.zeros(n, dtype=bool)
    for b, w in zip(better.tolist(), worse.tolist(), strict=True):
        if not suppressed[b]:
            suppressed[w] = True
    return ~suppressed


def usable(boxes: Boxes) -> np.ndarray:
    """(N,) bool: the boxes whose every field is finite and physically possible (module docstring)."""
    with np.errstate(invalid="ignore", over="ignore"):
        return (
            np.isfinite(boxes.translation_m).all(axis=1)
            & (np.abs(boxes.translation_m) <= MAX_ABS_COORD_M).all(axis=1)
            & ((boxes.size_wlh_m > 0.0) & (boxes.size_wlh_m <= MAX_SIZE_M)).all(axis=1)
            & (np.linalg.norm(np.nan_to_num(boxes.quat_wxyz), axis=1) >= MIN_QUAT_NORM)
            & np.isfinite(boxes.quat_wxyz).all(axis=1)
            & (np.abs(boxes.velocity_mps) <= MAX_SPEED_MPS).all(axis=1)
            & (boxes.score >= 0.0)
            & (boxes.score <= 1.0)
        )


def _per_box(boxes: Boxes, params: PreprocessParams | Mapping[str, PreprocessParams], key: str) -> np.ndarray:
    """(N,) the value of ``key`` for each box's class."""
    if isinstance(params, PreprocessParams):
        return np.full(len(boxes), getattr(params, key), dtype=float)
    default = getattr(PreprocessParams(), key)
    values = {name: getattr(p, key) for name, p in params.items()}
    return np.array([values.get(str(c), default) for c in boxes.class_name], dtype=float)


def preprocess(
    boxes: Boxes,
    params: PreprocessParams | Mapping[str, PreprocessParams],
    classes: Sequence[str] | None = None,
) -> FrameDetections:
    """Apply the score threshold and per-class 3D NMS to one frame's N detections.

    params: one set for every class, or class name -> parameters.
    classes: the tracked classes; ``None`` tracks every class present. Boxes of other classes are not kept and
    have neither flag set. Returns the input boxes unchanged with ``kept``, ``below_threshold`` and
    ``suppressed_by_nms`` (N,) masks.
    """
    n = len(boxes)
    if classes is None:
        tracked = np.ones(n, dtype=bool)
    else:
        tracked = np.isin(boxes.class_name.astype(str), np.asarray(list(classes), dtype=str))
    tracked &= usable(boxes)
    below = tracked & (boxes.score < _per_box(boxes, params, "score_threshold"))
    candidates = np.flatnonzero(tracked & ~below)
    suppressed = np.zeros(n, dtype=bool)
    iou_threshold = _per_box(boxes, params, "nms_iou_3d")[candidates]
    suppressed[candidates] = ~nms_3d(boxes.subset(candidates), iou_threshold)
    kept = tracked & ~below & ~suppressed
    return FrameDetections(boxes=boxes, kept=kept, below_threshold=below, suppressed_by_nms=suppressed)
