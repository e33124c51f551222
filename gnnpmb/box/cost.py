"""Association costs of the box trackers, each with what its numbers mean (``events.CostScale``).

A cost compares M detection boxes (M, 7) with the K predicted boxes of the tracks and gives an (M, K) matrix,
lower is better; a pair costing more than ``max_cost`` is never matched (``assign.matching``). The matrix is
exact wherever the cost may be at most ``limit`` (the largest threshold in play); past it a cost may be given
as a cheap lower bound (``assign.matching.BoundedCosts``), resolved exactly only if a solver picks it:

- ``OneMinusIou3d``: 1 - IoU_3D (AB3DMOT, Weng et al. 2020, sec. 3.4: matched iff IoU > IoU_min);
- ``OneMinusGiou3d``: 1 - GIoU_3D (SimpleTrack, Pang et al. 2021, sec. 4.1: matched iff GIoU >= GIoU_min);
- ``MahalanobisDistance``: sqrt(nu^T S^-1 nu) of the 7-D box residual, S = H P H^T + R the innovation
  covariance (Probabilistic 3D MOT, Chiu et al. 2020, eq. 7: matched iff below 11).
"""

from __future__ import annotations

from abc import ABC, abstractmethod
from dataclasses import dataclass

import numpy as np

from gnnpmb.assign.matching import BoundedCosts
from gnnpmb.box import kalman
from gnnpmb.box.overlap import giou_3d_bound_matrix, giou_3d_bound_pairs, giou_3d_pairs
from gnnpmb.data.boxes3d import UprightBoxes, all_pairs, iou_3d_pairs
from gnnpmb.events import CostScale
from gnnpmb.kalman import Innovation

EXACT_PAIRS = 256
"""Up to this many detection-track pairs the exact GIoU of every pair is computed at once (numpy's per-call
overhead, not the pairs, sets the time of such a matrix)."""


ROW_CANDIDATES = 6
"""Per detection, this many of its cheapest bounded pairs are made exact before the solve."""


class BoxCost(ABC):
    """An association cost with its threshold: ``matrix`` and what its numbers mean (``scale``, ``description``)."""

    @property
    @abstractmethod
    def scale(self) -> CostScale:
        """The quantity, unit, close-call margin, threshold (and similarity) of the costs; ``optimal`` is the
        solver's to say (``box.tracker``)."""

    @property
    @abstractmethod
    def description(self) -> str:
        """One line for the viewer's cost matrix: what an entry is and when a pair is matched."""

    @property
    def gate(self) -> bool:
        """True for a Mahalanobis gate (the tracker then reports ``Gated``)."""
        return False

    @property
    @abstractmethod
    def max_cost(self) -> float:
        """A pair costing more is never matched."""

    @abstractmethod
    def matrix(self, z_pred: np.ndarray, inn: Innovation | None, z: np.ndarray, limit: float) -> BoundedCosts:
        """(M, K) costs of M detection boxes ``z`` (M, 7) against the K predicted boxes ``z_pred`` (K, 7) (and,
        for a ``gate`` cost, their innovation quantities ``inn``); exact wherever <= ``limit``."""


def _upright(z: np.ndarray) -> UprightBoxes:
    """The boxes (N, >= 7) [x, y, z, yaw, l, w, h, ...] as ``overlap.UprightBoxes``."""
    return UprightBoxes.of(*kalman.box_fields(z))


@dataclass(frozen=True, slots=True)
class OneMinusIou3d(BoxCost):
    """1 - 3D IoU; matched iff IoU >= iou_min (cost <= 1 - iou_min)."""

    iou_min: float

    @property
    def max_cost(self) -> float:
        return 1.0 - self.iou_min

    @property
    def scale(self) -> CostScale:
        return CostScale("1 - IoU (3D)", "", 0.05, threshold=self.max_cost, similarity="3D IoU")

    @property
    def description(self) -> str:
        return (
            f"1 - 3D IoU of the detection and the track's predicted box (lower is better); a pair with 3D IoU below "
            f"{self.iou_min:g} is not matched; new-track column = {1.0 - self.iou_min:g}"
        )

    def matrix(self, z_pred: np.ndarray, inn: Innovation | None, z: np.ndarray, limit: float) -> BoundedCosts:
        """Exact everywhere (boxes apart have IoU 0 without clipping)."""
        m, k = len(z), len(z_pred)
        return BoundedCosts.of(1.0 - iou_3d_pairs(_upright(z), _upright(z_pred), *all_pairs(m, k)).reshape(m, k))


@dataclass(frozen=True, slots=True)
class OneMinusGiou3d(BoxCost):
    """1 - 3D GIoU; matched iff GIoU >= giou_min (cost <= 1 - giou_min)."""

    giou_min: float

    @property
    def max_cost(self) -> float:
        return 1.0 - self.giou_min

    @property
    def scale(self) -> CostScale:
        return CostScale("1 - GIoU (3D)", "", 0.05, threshold=self.max_cost, similarity="GIoU")

    @property
    def description(self) -> str:
        return (
            f"1 - GIoU (3D) of the detection and the track's predicted box (lower is better, GIoU = 1 - cost); a pair "
            f"with GIoU below {self.giou_min:g} is not matched; new-track column = {1.0 - self.giou_min:g}"
        )

    def matrix(self, z_pred: np.ndarray, inn: Innovation | None, z: np.ndarray, limit: float) -> BoundedCosts:
        """Only bounds when the cheap bound rules out every pair (``overlap.giou_3d_bound_matrix``); else exact
        for every pair of a small matrix (up to ``EXACT_PAIRS``: one vectorised call costs about the same); else
        exact where the cheap bounds (``overlap.giou_3d_bound_matrix``, then ``giou_3d_bound_pairs``
        where the first allows it) allow a cost <= ``limit``, for
        each detection's ``ROW_CANDIDATES`` cheapest bounds and, when there are no more tracks than detections,
        each track's cheapest (what a solver takes first, so the certified solve seldom needs a second round),
        the bound elsewhere."""
        m, k = len(z), len(z_pred)
        dets, preds = _upright(z), _upright(z_pred)
        bound = 1.0 - giou_3d_bound_matrix(dets, preds)

        def resolve(j: np.ndarray, t: np.ndarray) -> np.ndarray:
            return 1.0 - giou_3d_pairs(dets, preds, j, t)

        if (bound > limit).all():  # no pair can be matched: no solver needs an exact cost
            return BoundedCosts(bound, np.zeros((m, k), dtype=bool), resolve)
        if m * k <= EXACT_PAIRS:
            return BoundedCosts.of(1.0 - giou_3d_pairs(dets, preds, *all_pairs(m, k)).reshape(m, k))
        close = np.nonzero(bound <= limit)  # the crude bound allows a match: try the tighter one
        bound[close] = 1.0 - giou_3d_bound_pairs(dets, preds, *close)
        costs = BoundedCosts(bound, np.zeros((m, k), dtype=bool), resolve)
        first = bound <= limit
        n = min(k, ROW_CANDIDATES)
        first[np.arange(m)[:, None], np.argpartition(bound, n - 1, axis=1)[:, :n]] = True
        if k <= m:  # every track takes a detection: each track's cheapest too
            first[bound.argmin(axis=0), np.arange(k)] = True
        costs.refine(*np.nonzero(first))
        return costs


@dataclass(frozen=True, slots=True)
class MahalanobisDistance(BoxCost):
    """sqrt(nu^T S^-1 nu) of the heading-aligned 7-D box residual; matched iff below max_distance."""

    max_distance: float

    @property
    def gate(self) -> bool:
        return True

    @property
    def max_cost(self) -> float:
        return self.max_distance

    @property
    def scale(self) -> CostScale:
        return CostScale("Mahalanobis distance of the 7-D box residual", "sigma", 0.5, threshold=self.max_distance)

    @property
    def description(self) -> str:
        return (
            "Mahalanobis distance sqrt(nu^T S^-1 nu) of the box residual (x, y, z, yaw, l, w, h) to the track's "
            f"prediction (lower is better); a pair at {self.max_distance:g} or more is not matched; new-track "
            f"column = {self.max_distance:g}"
        )

    def matrix(self, z_pred: np.ndarray, inn: Innovation | None, z: np.ndarray, limit: float) -> BoundedCosts:
        if inn is None:
            raise ValueError("the Mahalanobis distance needs the innovation covariances")
        return BoundedCosts.of(np.sqrt(kalman.mahalanobis2(inn, z)).T)
