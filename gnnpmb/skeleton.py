"""The steps every per-class filter shares: predict -> gate -> emit -> *family update* -> extract -> emit.

The PMB core (``pmb.core``), the GM-PHD / CPHD filters (``phd.gmphd``) and the vector trackers
(``vector.tracks``) differ only in their density and its update; the gate and the events around the update are
these functions, so every family gates and reports the same way:

- gate: d2_kj = (z_j - H m_k)^T S_k^-1 (z_j - H m_k), inside iff d2_kj < G (``gating.gate``; paper sec. V-B);
- before the update: ``Predicted`` (track ids, means, covariances, existence) and ``Gated`` (the gate of each
  track in the BEV plane);
- after it: ``Posterior`` and ``Extracted`` (the estimates and the extraction threshold).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from gnnpmb.events import EventSink, Extracted, Gated, Posterior, Predicted
from gnnpmb.gating import gate
from gnnpmb.kalman import Innovation, innovation, mahalanobis2
from gnnpmb.types import TrackEstimate


@dataclass(frozen=True, slots=True)
class Gating:
    """The gate step's result for K tracks and M measurements: inn (K) innovation quantities, d2 (K, M) squared
    Mahalanobis distances, inside (K, M) bool."""

    inn: Innovation
    d2: np.ndarray
    inside: np.ndarray


def gate_tracks(mean: np.ndarray, cov: np.ndarray, R: np.ndarray, z: np.ndarray, gate_chi2: float) -> Gating:
    """Innovations of K tracks ((K, 4) means, (K, 4, 4) covariances) and their gate over measurements z (M, D)."""
    k, m = len(mean), len(z)
    inn = innovation(mean, cov, R)
    d2 = mahalanobis2(inn, z) if k and m else np.zeros((k, m))
    return Gating(inn=inn, d2=d2, inside=gate(d2, gate_chi2))


def emit_prior(
    sink: EventSink,
    class_name: str,
    track_ids: np.ndarray,
    mean: np.ndarray,
    cov: np.ndarray,
    existence: np.ndarray,
    gating: Gating,
    meas_indices: np.ndarray,
    gate_chi2: float,
) -> None:
    """``Predicted`` and ``Gated`` of K predicted tracks (gate ellipses in the BEV plane: the x, y block of S)."""
    sink.emit(Predicted(class_name, track_ids, mean, cov, existence))
    sink.emit(
        Gated(
            class_name,
            track_ids=track_ids,
            meas_indices=np.asarray(meas_indices),
            inside=gating.inside,
            center_xy=gating.inn.z_pred[:, :2],
            innovation_cov=gating.inn.S[:, :2, :2],
            threshold=gate_chi2,
        )
    )


def emit_posterior(
    sink: EventSink,
    class_name: str,
    track_ids: np.ndarray,
    mean: np.ndarray,
    cov: np.ndarray,
    existence: np.ndarray,
    estimates: Sequence[TrackEstimate],
    threshold: float,
) -> None:
    """``Posterior`` of the K updated tracks and ``Extracted`` with the estimates and the extraction threshold."""
    sink.emit(Posterior(class_name, track_ids, mean, cov, existence))
    sink.emit(Extracted(class_name, tuple(estimates), threshold))
