"""Greedy closest-pair tracker: the CenterPoint nuScenes tracking baseline.

Yin, Zhou & Krähenbühl, "Center-based 3D Object Detection and Tracking", CVPR 2021, sec. 4 ("Tracking"), and
their public ``PubTracker``: each detection j is projected back to the previous frame by its own velocity,
``c_j = p_j - v_j dt`` (p_j: BEV centre (2,), v_j: detector velocity (2,)), and compared with the centre t_k of
every live track of the same class:

    D[j, k] = || c_j - t_k ||_2     (metres; +inf when D[j, k] > d_class, the class's distance threshold)

Pairs are then taken greedily by increasing distance (closest pair first; ties by detection, then track index),
each detection and track at most once. A matched track takes the detection's box; an unmatched detection starts a
new track; a track missed ``max_age`` frames in a row is deleted, and while it coasts its centre moves by its
last velocity times dt. Every detection is output, with its own box and score, under its track's id; coasting
tracks are not output. The thresholds d_class are CenterPoint's per-class values (``config.ClassParams``:
``match_distance_m``) and ``max_age`` is ``[greedy] max_age`` (3 in CenterPoint's nuScenes script).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from gnnpmb.config import TrackerConfig
from gnnpmb.events import (
    Assignment,
    AxisKind,
    AxisLabel,
    Born,
    CostMatrix,
    EventSink,
    Panel,
    Predicted,
    Pruned,
    PruneReason,
)
from gnnpmb.skeleton import emit_posterior
from gnnpmb.soa import StructOfArrays
from gnnpmb.types import IdAllocator, Measurements, TrackEstimate

COST_DESCRIPTION = "distance (m) from the detection's centre minus velocity x dt; new-track column = threshold"


@dataclass(frozen=True, slots=True)
class GreedyTracks(StructOfArrays):
    """K live tracks: track_id (K,), center_xy (K, 2) m, velocity_mps (K, 2), misses (K,) consecutive misses."""

    track_id: np.ndarray
    center_xy: np.ndarray
    velocity_mps: np.ndarray
    misses: np.ndarray

    @staticmethod
    def empty() -> GreedyTracks:
        return GreedyTracks(
            track_id=np.zeros(0, dtype=np.int64),
            center_xy=np.zeros((0, 2)),
            velocity_mps=np.zeros((0, 2)),
            misses=np.zeros(0, dtype=np.int64),
        )


def distance_matrix(
    det_xy: np.ndarray, det_velocity_mps: np.ndarray, dt_s: float, track_xy: np.ndarray, max_distance_m: float
) -> np.ndarray:
    """(M, K) distances || (p_j - v_j dt) - t_k ||, +inf above ``max_distance_m`` (module docstring)."""
    back = det_xy - det_velocity_mps * dt_s
    dist = np.linalg.norm(back[:, None, :] - track_xy[None, :, :], axis=2)
    return np.where(dist <= max_distance_m, dist, np.inf)


def greedy_pairs(dist: np.ndarray) -> np.ndarray:
    """(P, 2) pairs [j, k] taken by increasing finite distance, each row and column at most once; ties are
    broken by row, then column index, so the result is deterministic."""
    rows, cols = np.nonzero(np.isfinite(dist))
    order = np.lexsort((cols, rows, dist[rows, cols]))
    used_r, used_c = set(), set()
    pairs = []
    for j, k in zip(rows[order].tolist(), cols[order].tolist(), strict=True):
        if j not in used_r and k not in used_c:
            used_r.add(j)
            used_c.add(k)
            pairs.append((j, k))
    return np.array(pairs, dtype=np.int64).reshape(-1, 2)


class GreedyTracker:
    """One class's greedy closest-pair tracker (module docstring)."""

    panels: tuple[Panel, ...] = ()

    def __init__(self, class_name: str, config: TrackerConfig, ids: IdAllocator):
        self.class_name = class_name
        self.max_distance_m = config.for_class(class_name).match_distance_m
        self.max_age = config.greedy.max_age
        self.ids = ids
        self.tracks = GreedyTracks.empty()

    def step(self, meas: Measurements, dt_s: float, sink: EventSink) -> list[TrackEstimate]:
        """Match this frame's detections to the live tracks; returns one estimate per detection."""
        prior = self.tracks
        boxes = meas.boxes
        m, k = len(meas), len(prior)
        dist = distance_matrix(meas.z, boxes.velocity_mps, dt_s, prior.center_xy, self.max_distance_m)
        pairs = greedy_pairs(dist)
        track_of_meas = np.full(m, -1, dtype=np.int64)
        track_of_meas[pairs[:, 0]] = pairs[:, 1]
        matched = np.zeros(k, dtype=bool)
        matched[pairs[:, 1]] = True
        new_j = np.flatnonzero(track_of_meas < 0)
        new_ids = np.array([self.ids.allocate() for _ in new_j], dtype=np.int64)
        ids_of_meas = np.empty(m, dtype=np.int64)
        ids_of_meas[pairs[:, 0]] = prior.track_id[pairs[:, 1]]
        ids_of_meas[new_j] = new_ids
        coasting = prior.subset(~matched)
        coasting = GreedyTracks(
            track_id=coasting.track_id,
            center_xy=coasting.center_xy + coasting.velocity_mps * dt_s,
            velocity_mps=coasting.velocity_mps,
            misses=coasting.misses + 1,
        )
        deleted = coasting.misses >= self.max_age
        self.tracks = GreedyTracks.concatenate(
            [
                GreedyTracks(ids_of_meas, meas.z.copy(), boxes.velocity_mps.copy(), np.zeros(m, dtype=np.int64)),
                coasting.subset(~deleted),
            ]
        )
        estimates = [
            TrackEstimate(
                track_id=int(ids_of_meas[j]),
                class_name=self.class_name,
                translation_m=tuple(float(v) for v in boxes.translation_m[j]),
                size_wlh_m=tuple(float(v) for v in boxes.size_wlh_m[j]),
                quat_wxyz=tuple(float(v) for v in boxes.quat_wxyz[j]),
                velocity_mps=tuple(float(v) for v in boxes.velocity_mps[j]),
                score=float(boxes.score[j]),
                existence=1.0,
                meas_index=int(meas.source_index[j]),
            )
            for j in range(m)
        ]
        if sink.enabled:
            self._emit(prior, meas, dist, track_of_meas, new_j, new_ids, coasting.track_id[deleted], estimates, sink)
        return estimates

    def _disc_cov(self, k: int) -> np.ndarray:
        """(k, 4, 4) diag(d^2, d^2, 1, 1): the greedy tracker has no covariance, so events carry the matching
        disc of radius d = the class threshold (one standard deviation drawn = the disc) and unit velocity."""
        d2 = self.max_distance_m**2
        return np.broadcast_to(np.diag([d2, d2, 1.0, 1.0]), (k, 4, 4)).copy()

    def _emit(
        self,
        prior: GreedyTracks,
        meas: Measurements,
        dist: np.ndarray,
        track_of_meas: np.ndarray,
        new_j: np.ndarray,
        new_ids: np.ndarray,
        deleted_ids: np.ndarray,
        estimates: list[TrackEstimate],
        sink: EventSink,
    ) -> None:
        m, k = dist.shape
        state = np.concatenate([prior.center_xy, prior.velocity_mps], axis=1)
        sink.emit(Predicted(self.class_name, prior.track_id, state, self._disc_cov(k), np.ones(k)))
        full = np.full((m, k + m), np.inf)
        full[:, :k] = dist
        full[np.arange(m), k + np.arange(m)] = self.max_distance_m
        rows = tuple(AxisLabel(AxisKind.MEASUREMENT, int(i)) for i in meas.source_index)
        track_cols = tuple(AxisLabel(AxisKind.TRACK, int(t)) for t in prior.track_id)
        new_cols = tuple(AxisLabel(AxisKind.NEW_TRACK, int(i)) for i in meas.source_index)
        sink.emit(CostMatrix(self.class_name, full, rows, track_cols + new_cols, description=COST_DESCRIPTION))
        pairs = tuple((rows[j], track_cols[t] if t >= 0 else new_cols[j]) for j, t in enumerate(track_of_meas.tolist()))
        total = float(sum(full[j, t] if t >= 0 else full[j, k + j] for j, t in enumerate(track_of_meas.tolist())))
        detected = set(track_of_meas[track_of_meas >= 0].tolist())
        missed = tuple(int(t) for i, t in enumerate(prior.track_id.tolist()) if i not in detected)
        sink.emit(Assignment(self.class_name, pairs, total, missed))
        if len(new_j):
            born_state = np.concatenate([meas.z[new_j], meas.boxes.velocity_mps[new_j]], axis=1)
            sink.emit(Born(self.class_name, new_ids, meas.source_index[new_j], born_state, np.ones(len(new_j))))
        for t in deleted_ids.tolist():
            sink.emit(Pruned(self.class_name, int(t), PruneReason.TRACK_LOGIC, 1.0))
        t = self.tracks
        state = np.concatenate([t.center_xy, t.velocity_mps], axis=1)
        emit_posterior(
            sink, self.class_name, t.track_id, state, self._disc_cov(len(t)), np.ones(len(t)), estimates, 1.0
        )
