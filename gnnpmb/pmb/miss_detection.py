"""A class's P_D for a missed Bernoulli, learnt online from the tracker's own tracks (``[pmb] miss_p_detect_online``).

An object missed for g frames and then detected again on the same track was present while missed. Over the tracks
of one class seen so far (one scene, causal: frames up to the previous one), the detection probability of a present
object that has been missed n frames in a row is estimated from D_n, the detections of existing tracks that had
been missed n frames in a row, and G_n, the misses at position n + 1 of gaps a later detection closed (a gap still
open, or a track that never came back, says nothing about presence and is not counted). n runs over N bins
(``[pmb] miss_p_detect_bins``), the last pooling every n >= N - 1; N = 1 pools every frame of the class. With the
cap c = ``[pmb] miss_p_detect_max`` as a Beta prior of w = ``miss_p_detect_prior_frames`` pseudo-frames (mean c),
the posterior mean

    P_D(n) = (w c + D_n) / (w + D_n + G_n)

replaces the fixed cap: a missed Bernoulli's P_D is min(its last detection's score, P_D(n)) (``cost.local_hypotheses``).
With N > 1 a detector whose misses come in long runs (occlusions) gets a lower P_D after the first misses than
after none, so a track coasts through a run the class's tracks were seen to come back from. With a score split
s > 0 (``[pmb] miss_p_detect_score_split``) tracks whose last detection scored below s and at least s are counted
apart, P_D(b, n) per score bin b: whether a weak detection's object is found again is learnt, not assumed.

A Bernoulli with another of its class near it (``crowded``: another track, existence >= r_n, within d metres,
``[pmb] miss_p_detect_neighbour_m`` and ``miss_p_detect_neighbour_existence``) keeps the fixed cap c instead of
P_D(n): next to another object a miss is often an occlusion, or the detector's one box for two, rather than the
object gone, and the learnt P_D (mostly from lone objects) made such a track fade and its neighbour's track take
its detections (issue 32, Round 7 of ``docs/results.md``).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np


def pooled_p_detect(prior_mean: float, prior_frames: float, detected: np.ndarray, missed: np.ndarray) -> np.ndarray:
    """(N,) (w c + D_n) / (w + D_n + G_n): the Beta posterior mean of P_D per bin (module docstring); the prior
    mean c where nothing is counted yet."""
    return (prior_frames * prior_mean + detected) / (prior_frames + detected + missed)


@dataclass(slots=True)
class MissDetectionCounts:
    """D_n and G_n of one class, (S, N) each: S score bins (1, or 2 with a score split), N miss bins (module
    docstring), counted on the most likely hypothesis frame by frame.

    ``last_ids`` (L,) sorted, ``last_misses`` (L,) and ``last_score_bins`` (L,): the track ids of the previous
    frame's most likely hypothesis, the frames each had been missed in a row then (0: detected), so a detection now
    closes a gap of that many misses, and the score bin of each one's last detection.
    """

    detected: np.ndarray
    missed: np.ndarray
    score_split: float = 0.0
    last_ids: np.ndarray = field(default_factory=lambda: np.zeros(0, dtype=np.int64))
    last_misses: np.ndarray = field(default_factory=lambda: np.zeros(0, dtype=np.int64))
    last_score_bins: np.ndarray = field(default_factory=lambda: np.zeros(0, dtype=np.int64))

    @staticmethod
    def empty(n_bins: int, score_split: float = 0.0) -> MissDetectionCounts:
        """No counts: N = ``n_bins`` miss bins, and two score bins when ``score_split`` > 0, else one."""
        shape = (1 + int(score_split > 0.0), n_bins)
        return MissDetectionCounts(np.zeros(shape, dtype=np.int64), np.zeros(shape, dtype=np.int64), score_split)

    def score_bins(self, score: np.ndarray) -> np.ndarray:
        """(K,) the score bin of K last detection scores (K,): 1 at or above the split, else 0."""
        if self.score_split <= 0.0:
            return np.zeros(len(score), dtype=np.int64)
        return (score >= self.score_split).astype(np.int64)

    def p_detect(self, prior_mean: float, prior_frames: float, misses: np.ndarray, score: np.ndarray) -> np.ndarray:
        """(K,) the P_D of K predicted Bernoullis missed ``misses`` (K,) frames in a row before this frame whose last
        detection scored ``score`` (K,) (``pooled_p_detect`` of their bins)."""
        by_bin = pooled_p_detect(prior_mean, prior_frames, self.detected, self.missed)
        return by_bin[self.score_bins(score), np.minimum(misses, by_bin.shape[1] - 1)]

    def count(self, track_id: np.ndarray, misses: np.ndarray, score: np.ndarray) -> None:
        """Count one frame's most likely posterior: K Bernoullis' distinct track ids (K,), frames missed in a row
        (K,) (0: detected this frame) and last detection scores (K,). A detected track that was in the previous
        frame's, missed g frames in a row then with its last detection in score bin b, adds 1 to D_bg and 1 to
        each G_bn, n < g (bins as ``p_detect``); a new track adds nothing (its first detection says nothing about
        a miss)."""
        seen = track_id[misses == 0]
        at = np.searchsorted(self.last_ids, seen)
        known = at < len(self.last_ids)
        known[known] = self.last_ids[at[known]] == seen[known]
        gaps = self.last_misses[at[known]]
        bins = self.last_score_bins[at[known]]
        last_bin = self.detected.shape[1] - 1
        np.add.at(self.detected, (bins, np.minimum(gaps, last_bin)), 1)
        for b in range(self.detected.shape[0]):
            in_bin = gaps[bins == b]
            self.missed[b, :last_bin] += (in_bin[:, None] > np.arange(last_bin)).sum(axis=0)
            self.missed[b, last_bin] += np.maximum(in_bin - last_bin, 0).sum()
        order = np.argsort(track_id, kind="stable")
        self.last_ids, self.last_misses = track_id[order], misses[order]
        self.last_score_bins = self.score_bins(score[order])


def crowded(
    xy_m: np.ndarray, existence: np.ndarray, track_id: np.ndarray, near_m: float, min_existence: float
) -> np.ndarray:
    """(K,) whether each of K Bernoullis (centres ``xy_m`` (K, 2), ``existence`` (K,), ``track_id`` (K,)) has
    another track's Bernoulli of existence >= ``min_existence`` closer than ``near_m`` metres (the same track in
    other global hypotheses is not a neighbour); all False when ``near_m`` is 0."""
    out = np.zeros(len(xy_m), dtype=bool)
    sure = np.flatnonzero(existence >= min_existence)
    if near_m <= 0.0 or len(xy_m) < 2 or not len(sure):
        return out
    dist_m = np.linalg.norm(xy_m[:, None, :] - xy_m[None, sure, :], axis=2)
    dist_m[track_id[:, None] == track_id[None, sure]] = np.inf
    return dist_m.min(axis=1) < near_m
