"""Track scores of trackers without existence probabilities: how a track's confidence moves between detections.

A tracking score is what the nuScenes evaluation thresholds (AMOTA sweeps it); these rules are confidences, not
probabilities that the object exists (``events.ScoreRule`` describes a tracker's rule to the viewer):

- decay on a miss (SimpleTrack, Pang et al. 2021, and ImmortalTracker: the score of a track predicted without a
  detection is multiplied by 0.01 per missed frame): s' = f s;
- CBMOT's refinement (Benbarka, Schröder & Zell 2021, sec. III, eq. 6, the "multiplication" update): every
  frame the track's score drops by a step d, s_trk' = s_trk - d; a matched detection of score s_det then gives
  s = 1 - (1 - s_trk')(1 - s_det), so repeated detections raise the confidence above any single one and a
  track unseen for a few frames fades out.
"""

from __future__ import annotations

import numpy as np


def decay_on_miss(score: np.ndarray, factor: float) -> np.ndarray:
    """(K,) s f: the scores of K tracks after one missed frame."""
    return np.asarray(score, dtype=float) * factor


def step_down(score: np.ndarray, step: float, clip: bool) -> np.ndarray:
    """(K,) s - d, clipped to [0, 1] when ``clip`` (CBMOT clips a matched track's score, not a missed one's: a
    missed track is deleted once its score is at most 0)."""
    out = np.asarray(score, dtype=float) - step
    return np.clip(out, 0.0, 1.0) if clip else out


def fuse_confidence(track_score: np.ndarray, det_score: np.ndarray) -> np.ndarray:
    """(P,) 1 - (1 - s_trk)(1 - s_det) for P matched pairs: in [max(s_trk, s_det), 1] for scores in [0, 1]."""
    return 1.0 - (1.0 - np.asarray(track_score, dtype=float)) * (1.0 - np.asarray(det_score, dtype=float))
