"""Ellipsoidal (Mahalanobis) gating and gate outlines.

A measurement z is inside track k's gate iff (z - H m_k)^T S_k^-1 (z - H m_k) < G; the paper uses G = 40
(sec. V-B). The gate region is the ellipse {z : d^2(z) = G}.
"""

from __future__ import annotations

import numpy as np


def gate(d2: np.ndarray, threshold: float) -> np.ndarray:
    """(K, M) bool: squared Mahalanobis distance strictly below the gate threshold."""
    return d2 < threshold


def ellipse_outline(center_xy: np.ndarray, S: np.ndarray, threshold: float, n_points: int = 32) -> np.ndarray:
    """(K, n_points + 1, 2) closed outlines of the gate ellipses {z : (z - c)^T S^-1 (z - c) = threshold}.

    Uses the Cholesky factor: z = c + sqrt(threshold) L u for unit vectors u, since S = L L^T.
    """
    angles = np.linspace(0.0, 2.0 * np.pi, n_points + 1)
    unit = np.stack([np.cos(angles), np.sin(angles)], axis=-1)  # (n+1, 2)
    L = np.linalg.cholesky(S)  # (K, 2, 2)
    return center_xy[:, None, :] + np.sqrt(threshold) * np.einsum("kij,nj->kni", L, unit)
