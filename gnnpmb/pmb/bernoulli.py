"""Multi-Bernoulli components: K potential targets, each existing with probability r and Gaussian state.

A Bernoulli density f(X) = 1 - r if X is empty, r N(x; m, P) if X = {x} (Williams 2015; García-Fernández,
Williams, Granström & Svensson 2018, sec. II). Besides the filtered [x, y, vx, vy], each Bernoulli carries the
box fields of the last detection associated with it (z, size, rotation) and that detection's score, which is
both the tracking score and the P_D used when the track is missed (paper sec. V-B).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from gnnpmb.detection_fields import CarriesDetectionFields, DetectionFields
from gnnpmb.kalman import predict
from gnnpmb.models import MotionModel
from gnnpmb.soa import StructOfArrays


@dataclass(frozen=True, slots=True)
class Bernoullis(CarriesDetectionFields, StructOfArrays):
    """K Bernoulli components, struct-of-arrays.

    track_id: (K,) int, the track label (metadata, kept through updates);
    local_key: (K,) int64, identifies the single-target hypothesis (equal keys = identical component; PMBM);
    existence: (K,) r in [0, 1]; mean: (K, n) ([x, y, vx, vy], or with the turn rate omega); cov: (K, n, n);
    det: the last associated detection's fields (``score``, ``z_m``, ... read through as the Bernoullis' own);
    misses: (K,) int64, frames since the last detection (0 for a Bernoulli detected this frame; the prediction
    adds 1), which sets the decayed output score of a missed track (``PmbParams.miss_score_decay``) and whether it
    is output at all (``PmbParams.output_max_misses``);
    detected_score_sum: (K,) the sum of the Bernoulli's output scores on the frames it was born (s r_b) or detected
    (s), and detected_frames: (K,) int64 the count of those frames: their ratio m is the track's mean score before
    any coasting (``PmbParams.miss_score_mean_min_frames``).
    """

    track_id: np.ndarray
    local_key: np.ndarray
    existence: np.ndarray
    mean: np.ndarray
    cov: np.ndarray
    det: DetectionFields
    misses: np.ndarray
    detected_score_sum: np.ndarray
    detected_frames: np.ndarray

    def __len__(self) -> int:
        return len(self.track_id)

    @staticmethod
    def empty(state_dim: int = 4) -> Bernoullis:
        return Bernoullis(
            track_id=np.zeros(0, dtype=np.int64),
            local_key=np.zeros(0, dtype=np.int64),
            existence=np.zeros(0),
            mean=np.zeros((0, state_dim)),
            cov=np.zeros((0, state_dim, state_dim)),
            det=DetectionFields.empty(),
            misses=np.zeros(0, dtype=np.int64),
            detected_score_sum=np.zeros(0),
            detected_frames=np.zeros(0, dtype=np.int64),
        )


def predict_bernoullis(b: Bernoullis, model: MotionModel, p_survive: float) -> Bernoullis:
    """Prediction: r' = P_S r, (m', P') = Kalman predict (García-Fernández et al. 2018, eq. 8-9); one more
    frame since the last detection. A Bernoulli missed at its last update (misses >= 1) is predicted with
    ``model.coast`` when there is one (its velocity slowed, ``gnnpmb.models.coasting``)."""
    if not len(b):
        return b
    mean, cov = predict(b.mean, b.cov, model)
    coasting = b.misses >= 1
    if model.coast is not None and coasting.any():
        mean[coasting], cov[coasting] = predict(b.mean[coasting], b.cov[coasting], model.coast)
    return Bernoullis(
        b.track_id,
        b.local_key,
        p_survive * b.existence,
        mean,
        cov,
        b.det.undetected(),
        b.misses + 1,
        b.detected_score_sum,
        b.detected_frames,
    )


def missed_update(existence: np.ndarray, p_detect: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Misdetection hypothesis of each Bernoulli (García-Fernández et al. 2018, eq. 12):
    weight l_0 = 1 - r P_D, posterior existence r' = r (1 - P_D) / l_0; the state is unchanged.

    Returns (log l_0 (K,), r' (K,)). P_D is kept below 1 so that a certain track scored 1.0 can still be missed.
    """
    p_detect = np.minimum(p_detect, 1.0 - 1e-9)
    l0 = 1.0 - existence * p_detect
    return np.log(l0), existence * (1.0 - p_detect) / l0
