"""A measurement model for a detection's heading and size beside its position: how much a box's shape says about
which track it came from.

The Kalman measurement is the BEV centre (``gnnpmb.kalman``); a detection box also has a heading and a size that
a track carries from its last detection (``detection_fields``). Heading and size are modelled as independent of
the position, so their likelihood multiplies the positional one. For a detection j and a track k whose last
box has heading psi_k and size (w_k, l_k):

- heading residual dpsi = psi_j - psi_k modulo pi, in [-pi/2, pi/2) (a box turned by pi is the same box, and
  detectors confuse the two): same object dpsi ~ N(0, 2 sigma_psi^2) (two detections, each with noise
  sigma_psi); a clutter or new-object box has a heading uniform over the half turn, density 1 / pi;
- log-size residual ds = log(w_j, l_j) - log(w_k, l_k) (2,): same object ds ~ N(0, 2 sigma_s^2 I); another
  object's box of the class ds ~ N(0, (2 sigma_s^2 + sigma_c^2) I), sigma_c the spread of the class's sizes.

Each same-object density is a mixture (1 - eps) N + eps g with the other-object density g, so a detection whose
heading or size is wrong (an outlier) costs at most -log eps nats more than clutter would. Clutter and birth
explain a detection with the other-object densities; multiplying every hypothesis of a detection by its box
density leaves the new-track column unchanged up to a factor common to all hypotheses, so only the track
entries change, by the log-likelihood ratio

    log_ratio_kj = log[(1 - eps) N(dpsi) + eps / pi] - log(1 / pi) + log[(1 - eps) N(ds) + eps g(ds)] - log g(ds)

added to log l_kj (``pmb.cost``; ``events.CostTerms.box_nats`` = -log_ratio). A term whose sigma is 0 is off
(ratio 1): the paper's model measures the centre only. References: Bar-Shalom, Willett & Tian, "Tracking and
Data Fusion", 2011, sec. 9 (feature-aided association: independent feature likelihoods multiply the kinematic
one); Poly-MOT (Li et al., IROS 2023) and SimpleTrack (Pang et al. 2021) associate by box overlap for the same
reason.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from gnnpmb.box.kalman import half_turn_residual
from gnnpmb.data.boxes3d import yaw_from_quat_wxyz
from gnnpmb.kalman import gaussian_log_density


@dataclass(frozen=True, slots=True)
class BoxShapeModel:
    """Per-class noise of a detection's heading and size (module docstring).

    heading_std_rad: sigma_psi of one detection's heading (0: heading not used); size_log_std: sigma_s of one
    detection's log width and length (0: size not used); size_log_spread: sigma_c, the spread of the class's log
    sizes; outlier_prob: eps."""

    heading_std_rad: float
    size_log_std: float
    size_log_spread: float
    outlier_prob: float

    @property
    def enabled(self) -> bool:
        return self.heading_std_rad > 0.0 or self.size_log_std > 0.0


def heading_log_ratio(track_yaw_rad: np.ndarray, det_yaw_rad: np.ndarray, model: BoxShapeModel) -> np.ndarray:
    """(K, M) log[(1 - eps) N(dpsi; 0, 2 sigma^2) + eps / pi] + log pi for K track and M detection headings."""
    d = half_turn_residual(det_yaw_rad[None, :] - track_yaw_rad[:, None])
    var = 2.0 * model.heading_std_rad**2
    same = np.exp(gaussian_log_density(d * d / var, np.log(var), 1))
    return np.log((1.0 - model.outlier_prob) * same * np.pi + model.outlier_prob)


def size_log_ratio(track_size_wl_m: np.ndarray, det_size_wl_m: np.ndarray, model: BoxShapeModel) -> np.ndarray:
    """(K, M) log[(1 - eps) N(ds; 0, 2 sigma_s^2 I) + eps g(ds)] - log g(ds), g = N(0, (2 sigma_s^2 + sigma_c^2)
    I), for K track and M detection sizes (w, l) (each (N, 2), metres)."""
    ds = np.log(det_size_wl_m)[None, :, :] - np.log(track_size_wl_m)[:, None, :]  # (K, M, 2)
    d2 = np.einsum("kmi,kmi->km", ds, ds)
    var_same = 2.0 * model.size_log_std**2
    var_other = var_same + model.size_log_spread**2
    log_same = gaussian_log_density(d2 / var_same, 2.0 * np.log(var_same), 2)
    log_other = gaussian_log_density(d2 / var_other, 2.0 * np.log(var_other), 2)
    return np.logaddexp(np.log1p(-model.outlier_prob) + log_same - log_other, np.log(model.outlier_prob))


def box_log_ratio(
    track_quat_wxyz: np.ndarray,
    track_size_wlh_m: np.ndarray,
    det_quat_wxyz: np.ndarray,
    det_size_wlh_m: np.ndarray,
    model: BoxShapeModel,
) -> np.ndarray | None:
    """(K, M) log-likelihood ratio of the heading and size of M detections for K tracks (module docstring), from
    quaternions (N, 4) and sizes (w, l, h) (N, 3); None when the model uses neither."""
    if not model.enabled:
        return None
    out = np.zeros((len(track_quat_wxyz), len(det_quat_wxyz)))
    if model.heading_std_rad > 0.0:
        out += heading_log_ratio(yaw_from_quat_wxyz(track_quat_wxyz), yaw_from_quat_wxyz(det_quat_wxyz), model)
    if model.size_log_std > 0.0:
        out += size_log_ratio(track_size_wlh_m[:, :2], det_size_wlh_m[:, :2], model)
    return out
