"""Life cycle of the box trackers by hits and misses (AB3DMOT's ``min_hits`` / ``max_age``, SimpleTrack's
``mot_3d/life/hit_manager.py``, ImmortalTracker's tracks that never die).

Every track counts its hits (frames a detection updated it, its birth included) and its misses (frames in a row
since the last hit: AB3DMOT's time_since_update). Per frame:

- a track is *confirmed* once it has ``min_hits`` hits (at birth when min_hits <= 1);
- a track missed ``max_misses`` frames in a row is deleted (never, for ImmortalTracker: max_misses None);
- a track is output while it has been missed at most ``output_max_misses`` frames in a row and it is confirmed,
  or the tracker is in its first ``min_hits`` frames (AB3DMOT's ``frame_count <= min_hits``, so a sequence's
  first objects are output at once). A track missed this frame is output at its prediction.

Vectorised over the K tracks of a class; ``emit_transitions`` reports the changes as ``TrackLogic`` events.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from gnnpmb.events import EventSink, Pruned, PruneReason, TrackLogic, TrackLogicAction
from gnnpmb.soa import StructOfArrays
from gnnpmb.vector.track_logic import LogicUpdate


@dataclass(frozen=True, slots=True)
class LifeRule:
    """min_hits; max_misses (None: never deleted); output_max_misses (module docstring)."""

    min_hits: int
    max_misses: int | None
    output_max_misses: int


@dataclass(frozen=True, slots=True)
class LifeState(StructOfArrays):
    """K tracks: hits (K,) int64, misses (K,) int64 consecutive missed frames, confirmed (K,) bool."""

    hits: np.ndarray
    misses: np.ndarray
    confirmed: np.ndarray

    @staticmethod
    def empty() -> LifeState:
        return LifeState.born(0, LifeRule(0, None, 0))

    @staticmethod
    def born(n: int, rule: LifeRule) -> LifeState:
        """n tracks started this frame by a detection: one hit."""
        return LifeState(np.ones(n, dtype=np.int64), np.zeros(n, dtype=np.int64), np.full(n, rule.min_hits <= 1))


def advance(state: LifeState, hit: np.ndarray, rule: LifeRule) -> LogicUpdate[LifeState]:
    """The K tracks' life after a frame in which tracks ``hit`` (K,) bool were updated (or kept alive)."""
    hits = state.hits + hit
    misses = np.where(hit, 0, state.misses + 1)
    confirmed_now = ~state.confirmed & (hits >= rule.min_hits)
    deleted = np.zeros(len(hit), dtype=bool) if rule.max_misses is None else misses >= rule.max_misses
    return LogicUpdate(LifeState(hits, misses, state.confirmed | confirmed_now), confirmed_now, deleted)


def output_mask(state: LifeState, rule: LifeRule, frame: int) -> np.ndarray:
    """(K,) bool: the tracks output at the tracker's ``frame``-th frame (1 for the first; module docstring)."""
    return (state.misses <= rule.output_max_misses) & (state.confirmed | (frame <= rule.min_hits))


def emit_transitions(
    class_name: str,
    track_ids: np.ndarray,
    update: LogicUpdate[LifeState],
    born_ids: np.ndarray,
    rule: LifeRule,
    sink: EventSink,
) -> None:
    """``TrackLogic`` of one frame: TENTATIVE (or CONFIRMED when min_hits <= 1) for the tracks born, CONFIRMED
    and DELETED (with ``Pruned``) for the K tracks that existed before. hits / window: the track's hits and
    min_hits for a confirmation; 0 hits in its max_misses missed frames for a deletion."""
    action = TrackLogicAction.CONFIRMED if rule.min_hits <= 1 else TrackLogicAction.TENTATIVE
    for t in born_ids.tolist():
        sink.emit(TrackLogic(class_name, int(t), action, 1, max(rule.min_hits, 1)))
    hits = update.state.hits
    for i in np.flatnonzero(update.confirmed_now).tolist():
        sink.emit(TrackLogic(class_name, int(track_ids[i]), TrackLogicAction.CONFIRMED, int(hits[i]), rule.min_hits))
    window = rule.max_misses or 0
    for i in np.flatnonzero(update.deleted).tolist():
        sink.emit(TrackLogic(class_name, int(track_ids[i]), TrackLogicAction.DELETED, 0, window))
        sink.emit(Pruned(class_name, int(track_ids[i]), PruneReason.TRACK_LOGIC, 1.0))
