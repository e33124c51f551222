"""M/N track confirmation and deletion for the vector-type trackers (GNN, JPDA).

Blackman & Popoli, "Design and Analysis of Modern Tracking Systems", 1999 (M-of-N track confirmation logic):
every track records per frame a *hit* (it was associated with a detection) or a *miss*.

- A new track is tentative; its birth frame counts as a hit (it was started by a detection).
- A tentative track is confirmed as soon as it has M hits within its first N frames (age <= N), and deleted as
  soon as it can no longer reach M hits in them: hits + (N - age) < M. So no track stays tentative longer than
  N frames (a sliding window would let a track with one hit every N frames stay tentative forever).
- A confirmed track is deleted after ``delete_misses`` consecutive misses.

The last 62 frames of hits are kept as bits of an int64 (bit 0 = latest frame) and counted with
``np.bitwise_count``. Everything is vectorised over the K tracks of a class.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Generic, TypeVar

import numpy as np

from gnnpmb.config import VectorParams
from gnnpmb.events import EventSink, TrackLogic, TrackLogicAction
from gnnpmb.soa import StructOfArrays

_HISTORY_MASK = np.int64((1 << 62) - 1)


@dataclass(frozen=True, slots=True)
class LogicState(StructOfArrays):
    """Track-logic state of K tracks.

    confirmed: (K,) bool; history: (K,) int64 hit bits, bit 0 = the latest frame; age: (K,) int64 frames since
    birth, 1 on the birth frame; misses: (K,) int64 consecutive misses up to the latest frame.
    """

    confirmed: np.ndarray
    history: np.ndarray
    age: np.ndarray
    misses: np.ndarray

    def __len__(self) -> int:
        return int(self.confirmed.shape[0])

    @staticmethod
    def born(n: int, params: VectorParams) -> LogicState:
        """State of n tracks started this frame by a detection (one hit; confirmed at once if M = 1)."""
        return LogicState(
            confirmed=np.full(n, params.confirm_m <= 1),
            history=np.ones(n, dtype=np.int64),
            age=np.ones(n, dtype=np.int64),
            misses=np.zeros(n, dtype=np.int64),
        )

    @staticmethod
    def empty() -> LogicState:
        return LogicState(
            confirmed=np.zeros(0, dtype=bool),
            history=np.zeros(0, dtype=np.int64),
            age=np.zeros(0, dtype=np.int64),
            misses=np.zeros(0, dtype=np.int64),
        )

    def hits(self, window: int) -> np.ndarray:
        """(K,) number of hits in the last ``window`` frames (window <= 62)."""
        return np.bitwise_count(self.history & np.int64((1 << window) - 1)).astype(np.int64)


StateT = TypeVar("StateT")


@dataclass(frozen=True, slots=True)
class LogicUpdate(Generic[StateT]):
    """The state after one frame and what changed: confirmed_now, deleted: (K,) bool over the K tracks (the box
    trackers' ``box.life`` keeps its own state in it too)."""

    state: StateT
    confirmed_now: np.ndarray
    deleted: np.ndarray


def advance(state: LogicState, hit: np.ndarray, params: VectorParams) -> LogicUpdate[LogicState]:
    """Record this frame's hit (K,) bool for tracks that existed before the frame and apply the M/N rules."""
    m, n = params.confirm_m, params.confirm_n
    history = ((state.history << 1) & _HISTORY_MASK) | hit.astype(np.int64)
    age = state.age + 1
    misses = np.where(hit, 0, state.misses + 1)
    new = LogicState(state.confirmed, history, age, misses)
    hits = new.hits(n)
    tentative = ~state.confirmed
    confirmed_now = tentative & (hits >= m)
    deleted = (tentative & ~confirmed_now & (hits + (n - age) < m)) | (
        state.confirmed & (misses >= params.delete_misses)
    )
    return LogicUpdate(
        state=LogicState(state.confirmed | confirmed_now, history, age, misses),
        confirmed_now=confirmed_now,
        deleted=deleted,
    )


def emit_transitions(
    class_name: str,
    track_ids: np.ndarray,
    update: LogicUpdate[LogicState],
    born_ids: np.ndarray,
    params: VectorParams,
    sink: EventSink,
) -> None:
    """TrackLogic events of one frame: TENTATIVE (and CONFIRMED if M = 1) for the tracks born (born_ids),
    then CONFIRMED and DELETED for the K tracks that existed before (track_ids). hits / window: hits in the
    confirmation window N, or for a deleted confirmed track its hits in the last ``delete_misses`` frames."""
    n = params.confirm_n
    for t in born_ids.tolist():
        sink.emit(TrackLogic(class_name, int(t), TrackLogicAction.TENTATIVE, 1, n))
        if params.confirm_m <= 1:
            sink.emit(TrackLogic(class_name, int(t), TrackLogicAction.CONFIRMED, 1, n))
    state = update.state
    hits_n = state.hits(n)
    for i in np.flatnonzero(update.confirmed_now).tolist():
        sink.emit(TrackLogic(class_name, int(track_ids[i]), TrackLogicAction.CONFIRMED, int(hits_n[i]), n))
    window = np.where(state.confirmed, params.delete_misses, n)
    for i in np.flatnonzero(update.deleted).tolist():
        w = min(int(window[i]), 62)
        hits = int(np.bitwise_count(state.history[i] & np.int64((1 << w) - 1)))
        sink.emit(TrackLogic(class_name, int(track_ids[i]), TrackLogicAction.DELETED, hits, w))
