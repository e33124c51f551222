"""The Gaussian-mixture probability hypothesis density (GM-PHD) filter with labelled components.

Per class and frame (Vo & Ma 2006, Table I-III):

1. predict: w <- P_S w, (m, P) <- Kalman predict (eq. 20-21); P_S is ``[models] p_survive``;
2. birth: one component per detection, weight w_b at [z_j, v_j] with covariance P_b (``pmb.poisson``: adaptive,
   measurement-driven birth, Ristic, Clark, Vo & Vo 2012). A birth component describes a target that produced
   detection j, so it is detected with probability 1 and explains z_j only: it has no misdetection term and
   every other detection is outside its gate (as in the PMB core, undetected birth mass is not carried on);
3. gate: persistent component k may explain z_j only if (z_j - H m_k)^T S_k^-1 (z_j - H m_k) < G
   (``[models] gate_chi2``); outside the gate its likelihood q_k(z_j) is taken as 0;
4. update (eq. 23-26), with P_D,k = ``[phd] p_detect`` for persistent and 1 for birth components and clutter
   intensity kappa = ``[models] clutter_intensity`` (the same clutter model as the rest of the study):
     missed:    w_k (1 - P_D,k),           state unchanged,
     detected:  w_kj = P_D,k w_k q_k(z_j) / (kappa + sum_i P_D,i w_i q_i(z_j)),  Kalman update with z_j,
   computed in log space (``phd_update``);
5. reduce: prune, merge, cap (``mixture``, Vo & Ma Table II);
6. extract: every component with w >= ``extraction_weight``, floor(w + 1/2) times (Table III).

Labels. Every component carries a label. Updated components inherit their parent's label and merged ones the
label of their heaviest member (``mixture``). A birth component starts with a *provisional* label (negative,
from a per-filter counter, so clutter burns no track ids); when a component with a provisional label is extracted
for the first time, the label becomes a fresh ``ids.allocate()`` id for every component that carries it (a
``Born`` event). If two extracted components share a label, the lighter one is relabelled with a fresh id (the
split is permanent); the extra copies of a component with round(w) > 1 get ids that are kept per (label, copy)
while the label lives, so ids stay stable over frames. Extraction visits components by decreasing weight, so ids
are allocated deterministically.

Output. An estimate carries the filtered x, y, vx, vy of its component and the z, size, rotation and score of
the detection that last updated it; existence = min(w, 1).

Events (only when ``sink.enabled``): ``Predicted`` and ``Gated`` (persistent components, labels as track ids,
existence = min(w, 1)), ``Merged`` (only coalescence: a merge of components of at least two extracted labels),
``Pruned`` (once per label that had been extracted, when its last component leaves the mixture: in the
reduction with the reason and weight of its heaviest removed component, or in the update when every part of it
got weight 0, possible only with P_D = 1: LOW_WEIGHT, 0), ``IntensityWeights`` (after update, prune, merge,
cap), ``Born`` (labels that got a track id this frame), ``Posterior`` (every component) and ``Extracted``.

References: B.-N. Vo and W.-K. Ma, "The Gaussian mixture probability hypothesis density filter", IEEE Trans.
Signal Processing 54(11), 2006; B. Ristic, D. Clark, B.-N. Vo and B.-T. Vo, "Adaptive target birth intensity for
PHD and CPHD filters", IEEE Trans. Aerospace and Electronic Systems 48(2), 2012.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from gnnpmb.config import TrackerConfig
from gnnpmb.detection_fields import DetectionFields
from gnnpmb.events import (
    Born,
    EventSink,
    IntensityWeights,
    Merged,
    Panel,
    Pruned,
    PruneReason,
    UpdateWeights,
)
from gnnpmb.gating import gate
from gnnpmb.kalman import (
    Innovation,
    gaussian_log_density,
    innovation,
    log_likelihood,
    mahalanobis2,
    paired_mahalanobis2,
    paired_updated_means,
    predict,
)
from gnnpmb.models import MotionModel, cv_model, measurement_birth
from gnnpmb.phd.mixture import GaussianMixture, Reduction, reduce_mixture
from gnnpmb.skeleton import ClassFilter, Gating, TrackView
from gnnpmb.types import IdAllocator, Measurements, TrackEstimate


def log_sum_exp(a: np.ndarray, axis: int) -> np.ndarray:
    """log sum exp(a) along ``axis``, -inf where every term is -inf (no warnings, no NaN)."""
    if a.shape[axis] == 0:
        return np.full(np.delete(a.shape, axis), -np.inf)
    peak = np.maximum(a.max(axis=axis, keepdims=True), -1e300)  # all -inf: exp(-inf) = 0, no inf - inf
    total = np.exp(a - peak).sum(axis=axis)
    with np.errstate(divide="ignore"):
        return np.log(total) + np.squeeze(peak, axis=axis)


def safe_log(x: np.ndarray | float) -> np.ndarray:
    """Natural log with log 0 = -inf and no warning."""
    with np.errstate(divide="ignore"):
        return np.log(x)


@dataclass(frozen=True, slots=True)
class Prediction:
    """The predicted intensity as the update sees it: K persistent components, then one birth component per
    measurement (M).

    mixture: K + M components; n_persistent: K; p_detect: (K + M,) P_D of each component (1 for births);
    inn: innovation quantities (K + M); d2, inside: (K, M) squared Mahalanobis distances and gate of the persistent
    components; log_lik: (K + M, M) log N(z_j; H m_k, S_k), -inf outside the gate (birth K + j sees only z_j).
    """

    mixture: GaussianMixture
    n_persistent: int
    p_detect: np.ndarray
    inn: Innovation
    d2: np.ndarray
    inside: np.ndarray
    log_lik: np.ndarray

    @property
    def persistent(self) -> GaussianMixture:
        return self.mixture.subset(slice(0, self.n_persistent))


def predict_mixture(mix: GaussianMixture, model: MotionModel, p_survive: float) -> GaussianMixture:
    """Vo & Ma 2006, eq. 20-21: w <- P_S w, Kalman predict of every component; nobody is detected yet."""
    if not len(mix):
        return mix
    mean, cov = predict(mix.mean, mix.cov, model)
    return replace(
        mix,
        weight=p_survive * mix.weight,
        mean=mean,
        cov=cov,
        det=mix.det.undetected(),
    )


def birth_mixture(meas: Measurements, config: TrackerConfig, labels: np.ndarray) -> GaussianMixture:
    """One birth component per measurement (``pmb.poisson.measurement_birth``) with the given (M,) labels and the
    measurement's box fields."""
    birth = measurement_birth(meas, config.models)
    return GaussianMixture(
        weight=birth.weight,
        mean=birth.mean,
        cov=birth.cov,
        label=labels,
        det=DetectionFields.from_measurements(meas, np.arange(len(meas))),
    )


def gate_components(
    persistent: GaussianMixture,
    births: GaussianMixture,
    meas: Measurements,
    R: np.ndarray,
    gate_chi2: float,
    p_detect: float,
) -> Prediction:
    """Innovations, gate and log-likelihoods of every (component, measurement) pair (module docstring, 3)."""
    k, m = len(persistent), len(meas)
    mix = GaussianMixture.concatenate([persistent, births])
    inn = innovation(mix.mean, mix.cov, R)
    z = meas.z
    log_lik = np.full((k + m, m), -np.inf)
    if k and m:
        inn_p = inn.subset(slice(0, k))
        d2 = mahalanobis2(inn_p, z)
        inside = gate(d2, gate_chi2)
        log_lik[:k] = np.where(inside, log_likelihood(inn_p, d2), -np.inf)
    else:
        d2 = np.zeros((k, m))
        inside = np.zeros((k, m), dtype=bool)
    if m:
        nu = z - inn.z_pred[k:]  # birth component K + j explains z_j only
        d2_birth = paired_mahalanobis2(inn.S_inv[k:], nu)
        log_lik[k + np.arange(m), np.arange(m)] = gaussian_log_density(d2_birth, inn.log_det_S[k:], nu.shape[1])
    pd = np.concatenate([np.full(k, p_detect), np.ones(m)])
    return Prediction(mixture=mix, n_persistent=k, p_detect=pd, inn=inn, d2=d2, inside=inside, log_lik=log_lik)


def phd_update(
    weight: np.ndarray, p_detect: np.ndarray, log_lik: np.ndarray, clutter_intensity: float
) -> tuple[np.ndarray, np.ndarray]:
    """GM-PHD update weights in log space (Vo & Ma 2006, eq. 23-26).

    weight: (K,) predicted weights w_k; p_detect: (K,) P_D,k; log_lik: (K, M) log q_k(z_j) (-inf = gated out);
    clutter_intensity: kappa (per m^2). Returns (log missed weights (K,) = log((1 - P_D,k) w_k),
    log detected weights (K, M) = log(P_D,k w_k q_k(z_j) / (kappa + sum_i P_D,i w_i q_i(z_j)))).
    """
    log_w = safe_log(weight)
    log_num = (safe_log(p_detect) + log_w)[:, None] + log_lik
    log_den = np.logaddexp(safe_log(clutter_intensity), log_sum_exp(log_num, axis=0))
    finite = np.isfinite(log_num)
    log_detected = np.where(finite, log_num - np.where(finite, log_den[None, :], 0.0), -np.inf)
    return safe_log(1.0 - p_detect) + log_w, log_detected


def posterior_mixture(
    pred: Prediction, meas: Measurements, log_missed: np.ndarray, log_detected: np.ndarray
) -> GaussianMixture:
    """The updated intensity: missed components (state unchanged), then one Kalman-updated component per
    (component k, measurement j) pair with a finite log weight, which inherits k's label and takes j's box
    fields (row-major order, so the result is deterministic)."""
    mix = pred.mixture
    missed_sel = np.flatnonzero(np.isfinite(log_missed))
    missed = replace(mix.subset(missed_sel), weight=np.exp(log_missed[missed_sel]))
    k_idx, j_idx = np.nonzero(np.isfinite(log_detected))
    if not len(k_idx):
        return missed
    detected = GaussianMixture(
        weight=np.exp(log_detected[k_idx, j_idx]),
        mean=paired_updated_means(mix.mean, pred.inn, meas.z, k_idx, j_idx),
        cov=pred.inn.cov_post[k_idx],
        label=mix.label[k_idx],
        det=DetectionFields.from_measurements(meas, j_idx),
    )
    return GaussianMixture.concatenate([missed, detected])


@dataclass(frozen=True, slots=True)
class Selection:
    """Components to extract (indices into the mixture, by decreasing weight), how many estimates each gives,
    and the threshold reported in ``Extracted``."""

    index: np.ndarray
    copies: np.ndarray
    threshold: float


@dataclass(frozen=True, slots=True)
class PhdPosterior:
    """The reduced posterior intensity and, for the events (only when the sink is enabled), the extracted labels
    that vanished in the update (every part got weight 0) and the update's weights (``UpdateSplit``)."""

    reduction: Reduction
    vanished: np.ndarray
    split: UpdateSplit | None = None


@dataclass(frozen=True, slots=True)
class UpdateSplit:
    """The weights of one PHD update per predicted component, for the ``UpdateWeights`` event: labels (K + M,)
    of the K persistent then M birth components (provisional labels negative), prior (K + M,), missed (K + M,)
    and detected (K + M, M) weights; meas_indices (M,) source indices."""

    labels: np.ndarray
    prior: np.ndarray
    missed: np.ndarray
    detected: np.ndarray
    n_persistent: int
    meas_indices: np.ndarray

    def event(self, class_name: str, relabelled: dict[int, int]) -> UpdateWeights:
        """Summed per label of the persistent components (labels as this frame's track ids), births per
        detection."""
        k = self.n_persistent
        labels = np.array([relabelled.get(t, t) for t in self.labels[:k].tolist()], dtype=np.int64)
        unique, row = np.unique(labels, return_inverse=True)
        prior = np.zeros(len(unique))
        missed = np.zeros(len(unique))
        detected = np.zeros((len(unique), self.detected.shape[1]))
        np.add.at(prior, row, self.prior[:k])
        np.add.at(missed, row, self.missed[:k])
        np.add.at(detected, row, self.detected[:k])
        birth = self.detected[k + np.arange(len(self.meas_indices)), np.arange(len(self.meas_indices))]
        return UpdateWeights(class_name, unique, self.meas_indices, prior, missed, detected, birth)


class GmPhdTracker(ClassFilter[Prediction, PhdPosterior]):
    """One class's GM-PHD filter with labelled components (module docstring); the frame loop is
    ``skeleton.ClassFilter.step``. ``CphdTracker`` reuses everything but the weight update (``_correct``), the
    extraction rule (``_select``) and ``idle``."""

    name = "phd"
    panels: tuple[Panel, ...] = (Panel.INTENSITY,)
    has_costs = False

    def __init__(self, class_name: str, config: TrackerConfig, ids: IdAllocator):
        super().__init__(class_name, config, ids)
        self.params = config.phd
        self.mixture = GaussianMixture.empty()
        self._next_provisional = -1
        self._copy_ids: dict[tuple[int, int], int] = {}

    def idle(self) -> bool:
        """True when the filter is empty, so a frame without measurements leaves it unchanged."""
        return not len(self.mixture)

    def predict(self, meas: Measurements, dt_s: float) -> Prediction:
        """Steps 1-3 of the module docstring: K predicted components, M birth components, their gate."""
        models = self.config.models
        model = cv_model(dt_s, self.class_params)
        persistent = predict_mixture(self.mixture, model, models.p_survive)
        births = birth_mixture(meas, self.config, self._provisional_labels(len(meas)))
        return gate_components(persistent, births, meas, model.R, models.gate_chi2, self.params.p_detect)

    def prior_view(self, prior: Prediction) -> tuple[TrackView, Gating]:
        """The K persistent components (labels as track ids, existence = min(w, 1)) and their gate."""
        mix, k = prior.persistent, prior.n_persistent
        gating = Gating(prior.inn.subset(slice(0, k)), prior.d2, prior.inside)
        return TrackView(mix.label, mix.mean, mix.cov, np.minimum(mix.weight, 1.0)), gating

    def update(self, prior: Prediction, meas: Measurements, sink: EventSink) -> PhdPosterior:
        """Steps 4-5: the weight update (``_correct``), the updated components, and the reduction, whose mixture
        becomes the state."""
        p = self.params
        log_missed, log_detected = self._correct(prior, meas, sink)
        posterior = posterior_mixture(prior, meas, log_missed, log_detected)
        reduction = reduce_mixture(posterior, p.prune_weight, p.merge_threshold, p.max_components)
        self.mixture = reduction.mixture
        if not sink.enabled:
            return PhdPosterior(reduction, np.zeros(0, np.int64))
        vanished = np.setdiff1d(prior.persistent.label, posterior.label)
        split = UpdateSplit(
            prior.mixture.label,
            prior.mixture.weight,
            np.exp(log_missed),
            np.exp(log_detected),
            prior.n_persistent,
            np.asarray(meas.source_index),
        )
        return PhdPosterior(reduction, vanished, split)

    def extract(self, posterior: PhdPosterior, sink: EventSink) -> tuple[list[TrackEstimate], float]:
        """Step 6 (``_select``) with the label bookkeeping of the module docstring (``_label``); emits ``Merged``,
        ``Pruned``, ``IntensityWeights`` and ``Born``."""
        selection = self._select(self.mixture)
        estimates, born, relabelled = self._label(selection)
        if sink.enabled:
            self._emit_reduction(posterior, relabelled, born, sink)
        return estimates, selection.threshold

    def posterior_view(self, posterior: PhdPosterior) -> TrackView:
        """Every component of the labelled posterior (existence = min(w, 1))."""
        mix = self.mixture
        return TrackView(mix.label, mix.mean, mix.cov, np.minimum(mix.weight, 1.0))

    def _correct(self, pred: Prediction, meas: Measurements, sink: EventSink) -> tuple[np.ndarray, np.ndarray]:
        """Log missed (K + M,) and detected (K + M, M) weights of the PHD update (``phd_update``)."""
        return phd_update(pred.mixture.weight, pred.p_detect, pred.log_lik, self.config.models.clutter_intensity)

    def _select(self, mix: GaussianMixture) -> Selection:
        """Vo & Ma 2006, Table III: w >= extraction_weight, floor(w + 1/2) copies (at least one)."""
        threshold = self.params.extraction_weight
        order = np.argsort(-mix.weight, kind="stable")
        index = order[mix.weight[order] >= threshold]
        copies = np.maximum(1, np.floor(mix.weight[index] + 0.5)).astype(np.int64)
        return Selection(index=index, copies=copies, threshold=threshold)

    def _provisional_labels(self, n: int) -> np.ndarray:
        labels = self._next_provisional - np.arange(n, dtype=np.int64)
        self._next_provisional -= n
        return labels

    def _label(self, sel: Selection) -> tuple[list[TrackEstimate], np.ndarray, dict[int, int]]:
        """Estimates of the selected components and the label bookkeeping of the module docstring.

        Returns the estimates, the indices of components that got a new track id this frame, and the map
        provisional label -> track id of this frame."""
        mix = self.mixture
        labels = mix.label.copy()
        used: set[int] = set()
        born: list[int] = []
        relabelled: dict[int, int] = {}
        track_ids: list[list[int]] = []
        for i, n_copies in zip(sel.index.tolist(), sel.copies.tolist(), strict=True):
            label = int(labels[i])
            if label < 0:
                new = self.ids.allocate()
                labels[labels == label] = new
                relabelled[label] = new
                label = new
                born.append(i)
            elif label in used:
                label = self.ids.allocate()
                labels[i] = label
                born.append(i)
            used.add(label)
            track_ids.append([label] + [self._copy_id(label, c) for c in range(1, n_copies)])
        self.mixture = replace(mix, label=labels)
        alive = set(labels.tolist())
        self._copy_ids = {key: v for key, v in self._copy_ids.items() if key[0] in alive}
        rows = np.array([i for i, ids in zip(sel.index.tolist(), track_ids, strict=True) for _ in ids], dtype=np.int64)
        chosen = self.mixture.subset(rows)
        weight = np.minimum(chosen.weight, 1.0)
        flat_ids = np.array([t for ids in track_ids for t in ids], dtype=np.int64)
        estimates = chosen.det.to_estimates(self.class_name, flat_ids, chosen.mean, chosen.score, weight)
        return estimates, np.asarray(born, dtype=np.int64), relabelled

    def _copy_id(self, label: int, copy: int) -> int:
        key = (label, copy)
        if key not in self._copy_ids:
            self._copy_ids[key] = self.ids.allocate()
        return self._copy_ids[key]

    def _emit_reduction(
        self, posterior: PhdPosterior, relabelled: dict[int, int], born: np.ndarray, sink: EventSink
    ) -> None:
        """``UpdateWeights``, ``Merged`` (coalescence only), ``Pruned``, ``IntensityWeights`` and ``Born`` (module
        docstring)."""
        reduction, vanished = posterior.reduction, posterior.vanished
        if posterior.split is not None:
            sink.emit(posterior.split.event(self.class_name, relabelled))
        for group in reduction.merges():
            into = relabelled.get(group.into_label, group.into_label)
            from_ids = tuple(relabelled.get(t, t) for t in group.from_labels)
            if len({t for t in from_ids if t > 0}) >= 2:
                sink.emit(Merged(self.class_name, into, from_ids, group.weights))
        for label in vanished[vanished > 0].tolist():  # every part had zero weight after the update (P_D = 1)
            sink.emit(Pruned(self.class_name, label, PruneReason.LOW_WEIGHT, 0.0))
        for lost in reduction.lost_labels():
            if lost.label > 0:
                sink.emit(Pruned(self.class_name, lost.label, lost.reason, lost.weight))
        mix = self.mixture
        sink.emit(IntensityWeights(self.class_name, mix.label, mix.weight))
        if len(born):
            sink.emit(
                Born(
                    self.class_name,
                    mix.label[born],
                    mix.meas_index[born],
                    mix.mean[born],
                    np.minimum(mix.weight[born], 1.0),
                )
            )
