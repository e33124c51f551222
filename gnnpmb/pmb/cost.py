"""Single-target (local) hypotheses of one global hypothesis and the labelled assignment cost matrix.

For Bernoulli k with prior (r_k, m_k, P_k) and measurement j (García-Fernández et al. 2018, eq. 12-13):
  missed:    l_k0 = 1 - r_k P_D,k                 r = r_k (1 - P_D,k) / l_k0, state unchanged
  detected:  l_kj = r_k P_D,j N(z_j; H m_k, S_k)   r = 1, state = Kalman update with z_j (only inside the gate)
with P_D,j the score of detection j and P_D,k the score of the track's last detection (paper sec. V-B). With the
heading and size measurement model (``gnnpmb.box_likelihood``) l_kj is also multiplied by the likelihood ratio
of the detection's heading and size against the track's last box (1 without it, the paper's model).
New-track hypotheses l_j come from ``poisson.new_track_hypotheses``.

Cost matrix (M rows = measurements, K + M columns = [tracks | new track per measurement]):
  C[j, k]     = -(log l_kj - log l_k0)   (inf outside the gate)
  C[j, K + j] = -log l_j,  C[j, K + i] = inf for i != j.
A full row assignment a then has log weight  sum_k log l_k0 - sum_j C[j, a(j)]  (the global hypothesis weight
up to normalisation), so minimising the cost maximises the hypothesis likelihood.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from gnnpmb.box.overlap import giou_bev
from gnnpmb.box_likelihood import BoxShapeModel, box_log_ratio
from gnnpmb.data.boxes3d import yaw_from_quat_wxyz
from gnnpmb.events import AxisKind, AxisLabel, CostMatrix, CostTerms, axis_labels
from gnnpmb.kalman import Innovation, log_likelihood, paired_updated_means
from gnnpmb.pmb.bernoulli import Bernoullis, missed_update
from gnnpmb.pmb.poisson import NewTrackHypotheses
from gnnpmb.skeleton import gate_tracks
from gnnpmb.types import Measurements


@dataclass(frozen=True, slots=True)
class LocalHypotheses:
    """Everything the update needs for one prior global hypothesis.

    prior: K predicted Bernoullis; meas: M measurements; inn: innovation quantities (K);
    d2: (K, M) squared Mahalanobis distances; inside: (K, M) gate; miss_log_lik / miss_existence: (K,);
    det_log_lik: (K, M), -inf outside the gate; new: the M new-track hypotheses; box_log_ratio: (K, M) the
    heading and size log-likelihood ratio in det_log_lik (``box_likelihood``), None when not used; giou: (K, M)
    the bird's-eye GIoU of the pairs inside the Mahalanobis gate (NaN elsewhere) when the overlap gate
    (``gate_giou_min``) applies, else None.
    """

    prior: Bernoullis
    meas: Measurements
    inn: Innovation
    d2: np.ndarray
    inside: np.ndarray
    miss_log_lik: np.ndarray
    miss_existence: np.ndarray
    det_log_lik: np.ndarray
    new: NewTrackHypotheses
    box_log_ratio: np.ndarray | None = None
    giou: np.ndarray | None = None
    gate_giou_min: float | None = None

    @property
    def n_tracks(self) -> int:
        return len(self.prior)

    @property
    def n_meas(self) -> int:
        return len(self.meas)

    def cost_matrix(self) -> np.ndarray:
        """(M, K + M) cost matrix described in the module docstring."""
        k, m = self.n_tracks, self.n_meas
        cost = np.empty((m, k + m))
        cost.fill(np.inf)
        cost[:, :k] = (self.miss_log_lik[:, None] - self.det_log_lik).T  # = -(log l_kj - log l_k0), exactly
        cost.reshape(-1)[k :: k + m + 1] = -self.new.log_likelihood  # C[j, K + j]: flat index K + j (K + M + 1)
        return cost

    def cost_terms(self) -> CostTerms:
        """The track entries of ``cost_matrix`` taken apart: C[j, k] = (log l_k0 - log r_k) - log P_D,j
        - log N(z_j; H m_k, S_k) - box log-likelihood ratio (``events.CostTerms``), from the arrays already
        computed."""
        return CostTerms(
            box_nats=None if self.box_log_ratio is None else -self.box_log_ratio,
            existence=self.prior.existence,
            miss_log_lik=self.miss_log_lik,
            score=self.meas.boxes.score,
            d2=self.d2,
            log_det_S=self.inn.log_det_S,
            dim=self.inn.z_pred.shape[1],
            track_ids=self.prior.track_id,
        )

    def cost_event(self, class_name: str, hypothesis: int = 0) -> CostMatrix:
        """The ``CostMatrix`` event of this matrix: its labels and what its entries are made of (``cost_terms``);
        ``hypothesis``: the prior global hypothesis it belongs to."""
        return CostMatrix(
            class_name,
            self.cost_matrix(),
            self.row_labels(),
            self.col_labels(),
            hypothesis=hypothesis,
            terms=self.cost_terms(),
        )

    def base_log_weight(self) -> float:
        """sum_k log l_k0: the log weight of the hypothesis before subtracting the assignment cost."""
        return float(self.miss_log_lik.sum())

    def subset(self, index: np.ndarray) -> LocalHypotheses:
        """The local hypotheses of the prior Bernoullis ``index`` (an integer array; same measurements and
        new-track hypotheses)."""
        return LocalHypotheses(
            prior=self.prior.subset(index),
            meas=self.meas,
            inn=self.inn.subset(index),
            d2=self.d2[index],
            inside=self.inside[index],
            miss_log_lik=self.miss_log_lik[index],
            miss_existence=self.miss_existence[index],
            det_log_lik=self.det_log_lik[index],
            new=self.new,
            box_log_ratio=None if self.box_log_ratio is None else self.box_log_ratio[index],
            giou=None if self.giou is None else self.giou[index],
            gate_giou_min=self.gate_giou_min,
        )

    def row_labels(self) -> tuple[AxisLabel, ...]:
        return axis_labels(AxisKind.MEASUREMENT, self.meas.source_index)

    def col_labels(self) -> tuple[AxisLabel, ...]:
        tracks = axis_labels(AxisKind.TRACK, self.prior.track_id)
        return tracks + axis_labels(AxisKind.NEW_TRACK, self.meas.source_index)


def local_hypotheses(
    prior: Bernoullis,
    meas: Measurements,
    new: NewTrackHypotheses,
    R: np.ndarray,
    gate_chi2: float,
    miss_p_detect_max: float | np.ndarray = 1.0,
    box: BoxShapeModel | None = None,
    gate_giou_min: float = -1.0,
    last_score: bool = True,
) -> LocalHypotheses:
    """Gate every (track, measurement) pair and compute the local hypothesis likelihoods (module docstring); a
    missed track's P_D is its last detection score capped at ``miss_p_detect_max`` (``PmbParams``; one cap, or (K,)
    one per Bernoulli, ``PmbCore.miss_p_detect_max``); ``box``: the
    heading and size model (None or disabled: position only); ``gate_giou_min`` > -1: a pair must also overlap
    with bird's-eye GIoU >= it (``overlap_gate``); ``last_score`` False: a missed track's P_D is the cap alone
    (``[pmb] miss_p_detect_last_score = 0``)."""
    gating = gate_tracks(prior.mean, prior.cov, R, meas.z, gate_chi2)
    inn, d2, inside = gating.inn, gating.d2, gating.inside
    giou = None
    if gate_giou_min > -1.0:
        giou = overlap_gate(prior, meas, inside)
        inside = inside & (giou >= gate_giou_min)
    # missed_update caps P_D below 1 itself: a cap at or above 1 changes nothing
    if not last_score:
        p_detect = np.broadcast_to(np.asarray(miss_p_detect_max, dtype=float), prior.score.shape)
    elif np.all(miss_p_detect_max >= 1.0):
        p_detect = prior.score
    else:
        p_detect = np.minimum(prior.score, miss_p_detect_max)
    miss_log_lik, miss_existence = missed_update(prior.existence, p_detect)
    with np.errstate(divide="ignore"):
        det = np.log(prior.existence)[:, None] + np.log(meas.boxes.score)[None, :] + log_likelihood(inn, d2)
    ratio = None
    if box is not None and len(prior) and len(meas):
        boxes = meas.boxes
        ratio = box_log_ratio(prior.quat_wxyz, prior.size_wlh_m, boxes.quat_wxyz, boxes.size_wlh_m, box)
        if ratio is not None:
            det = det + ratio
    det_log_lik = np.where(inside, det, -np.inf)
    return LocalHypotheses(
        prior=prior,
        meas=meas,
        inn=inn,
        d2=d2,
        inside=inside,
        miss_log_lik=miss_log_lik,
        miss_existence=miss_existence,
        det_log_lik=det_log_lik,
        new=new,
        box_log_ratio=ratio,
        giou=giou,
        gate_giou_min=None if giou is None else gate_giou_min,
    )


def overlap_gate(prior: Bernoullis, meas: Measurements, inside: np.ndarray) -> np.ndarray:
    """(K, M) bird's-eye GIoU (``box.overlap.giou_bev``) of every pair inside the Mahalanobis gate: the
    detection's box against the track's predicted box (predicted centre, last detection's width, length and
    heading); NaN for the pairs outside."""
    out = np.full(inside.shape, np.nan)
    k, j = np.nonzero(inside)
    if len(k):
        tracks, boxes = prior.size_wlh_m, meas.boxes
        out[k, j] = giou_bev(
            prior.mean[k, :2],
            tracks[k, :2],
            yaw_from_quat_wxyz(prior.quat_wxyz[k]),
            boxes.xy[j],
            boxes.size_wlh_m[j, :2],
            yaw_from_quat_wxyz(boxes.quat_wxyz[j]),
        )
    return out


def detected_means(local: LocalHypotheses, track_index: np.ndarray, meas_index: np.ndarray) -> np.ndarray:
    """(P, 4) Kalman-updated means for P (track, measurement) pairs given as local row/column indices."""
    if len(track_index) == 0:
        return np.zeros((0, local.prior.mean.shape[1]))
    return paired_updated_means(local.prior.mean, local.inn, local.meas.z, track_index, meas_index)
