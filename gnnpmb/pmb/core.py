"""The shared Poisson multi-Bernoulli (mixture) core: predict, gate, cost, *strategy*, update, prune, extract.

GNN-PMB, PMBM and TO-PMB differ only in how the strategy manages data-association hypotheses (paper sec. III-IV):
``gnnpmb.BestAssignment`` keeps the single best global hypothesis (GNN-PMB), ``pmbm.KBest`` keeps up to N_h
(PMBM, Murty), ``topmb.MarginalMerge`` merges every local hypothesis by its marginal probability (TO-PMB, LBP).
Everything else in a frame is this module, per class (``PmbCore``: the hooks of ``skeleton.ClassFilter``):

1. predict every hypothesis' Bernoullis (``bernoulli.predict_bernoullis``);
2. birth intensity at this frame's detections and new-track hypotheses (``poisson``);
3. per hypothesis: gate and local hypothesis likelihoods, cost matrix (``cost``);
4. the strategy turns prior hypotheses + local hypotheses into posterior hypotheses;
5. prune Bernoullis with r below the threshold, and tracks absent from every hypothesis;
6. extract tracks with r >= the extraction threshold from the most likely hypothesis (paper Table II).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Protocol, overload

import numpy as np

from gnnpmb.box_likelihood import BoxShapeModel
from gnnpmb.config import TrackerConfig
from gnnpmb.events import (
    AxisLabel,
    Born,
    EventSink,
    Panel,
    Pruned,
    PruneReason,
)
from gnnpmb.models import MotionModel, birth_covariance, clutter_intensity, measurement_birth, motion_model
from gnnpmb.pmb.bernoulli import Bernoullis, predict_bernoullis
from gnnpmb.pmb.cost import LocalHypotheses, detected_means, local_hypotheses
from gnnpmb.pmb.miss_detection import MissDetectionCounts, crowded
from gnnpmb.pmb.poisson import NewTrackHypotheses, birth_update, new_track_hypotheses
from gnnpmb.skeleton import ClassFilter, Gating, TrackView
from gnnpmb.types import STATE_DIM, IdAllocator, Measurements, TrackEstimate


@dataclass(frozen=True, slots=True)
class GlobalHypothesis:
    """One global data-association hypothesis: its log weight and the Bernoullis it contains, the rows ``index``
    (K,) of ``store`` (all of ``store`` when ``index`` is None).

    PMBM's hypotheses share one store per class and frame that holds every distinct single-target hypothesis
    once (track-oriented storage, García-Fernández et al. 2018, sec. V): a global hypothesis is an index array
    into it, and its own ``Bernoullis`` are gathered only when asked for.
    """

    log_weight: float
    store: Bernoullis
    index: np.ndarray | None = None

    @property
    def bernoullis(self) -> Bernoullis:
        """The K Bernoullis of this hypothesis, in order (a copy gathered from the store for an indexed one)."""
        return self.store if self.index is None else self.store.subset(self.index)

    @property
    def track_id(self) -> np.ndarray:
        """(K,) the Bernoullis' track ids (one array gathered, not all)."""
        return self.store.track_id if self.index is None else self.store.track_id[self.index]

    @property
    def existence(self) -> np.ndarray:
        """(K,) the Bernoullis' existence probabilities."""
        return self.store.existence if self.index is None else self.store.existence[self.index]

    @property
    def local_key(self) -> np.ndarray:
        """(K,) the Bernoullis' single-target hypothesis keys."""
        return self.store.local_key if self.index is None else self.store.local_key[self.index]

    @property
    def n_bernoullis(self) -> int:
        return len(self.store) if self.index is None else len(self.index)

    def without_existence_below(self, threshold: float) -> GlobalHypothesis:
        """This hypothesis without its Bernoullis of existence r < ``threshold`` (itself if it has none)."""
        existence = self.existence
        if existence.min(initial=1.0) >= threshold:
            return self
        keep = existence >= threshold
        if self.index is None:
            return GlobalHypothesis(self.log_weight, self.store.subset(keep))
        return GlobalHypothesis(self.log_weight, self.store, self.index[keep])


def _without_existence_below(hypotheses: list[GlobalHypothesis], threshold: float) -> list[GlobalHypothesis]:
    """``[h.without_existence_below(threshold) for h in hypotheses]``; for hypotheses indexing one store (PMBM),
    its low-existence rows are found once and only the hypotheses holding one are cut."""
    store = hypotheses[0].store
    indices = [h.index for h in hypotheses if h.store is store and h.index is not None]
    if len(indices) < len(hypotheses):
        return [h.without_existence_below(threshold) for h in hypotheses]
    low = store.existence < threshold
    if not low.any():
        return list(hypotheses)
    kept = []
    for h, index in zip(hypotheses, indices, strict=True):
        drop = low[index]
        kept.append(GlobalHypothesis(h.log_weight, store, index[~drop]) if drop.any() else h)
    return kept


def hypothesis_union(hypotheses: Sequence[GlobalHypothesis]) -> tuple[Bernoullis, list[np.ndarray]]:
    """The distinct Bernoullis of ``hypotheses`` (one per ``local_key``, by increasing key; the first met of
    equal keys) and each hypothesis' rows of it, (K_h,) in the hypothesis' order. Hypotheses indexing one
    shared store are read through their indices, without gathering their Bernoullis."""
    store = hypotheses[0].store
    bounds = np.cumsum([0] + [h.n_bernoullis for h in hypotheses]).tolist()
    if all(h.store is store and h.index is not None for h in hypotheses):
        rows = np.concatenate([h.index for h in hypotheses])
        union_rows, inverse = _union_rows(store.local_key, rows)
        union = store.subset(union_rows)
    else:
        every = Bernoullis.concatenate([h.bernoullis for h in hypotheses])
        _, first, inverse = np.unique(every.local_key, return_index=True, return_inverse=True)
        union = every.subset(first)
    return union, [inverse[start:stop] for start, stop in zip(bounds[:-1], bounds[1:], strict=True)]


def _union_rows(store_keys: np.ndarray, rows: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``np.unique(store_keys[rows], return_index=True, return_inverse=True)`` as (store rows of the distinct
    keys, inverse): when the store rows used hold distinct keys (as a posterior store does), by sorting only
    those rows instead of every occurrence."""
    seen = np.zeros(len(store_keys), dtype=bool)
    seen[rows] = True
    used = np.flatnonzero(seen)
    order = np.argsort(store_keys[used], kind="stable")
    sorted_keys = store_keys[used[order]]
    if not (sorted_keys[1:] > sorted_keys[:-1]).all():
        _, first, inverse = np.unique(store_keys[rows], return_index=True, return_inverse=True)
        return rows[first], inverse
    position = np.empty(len(store_keys), dtype=np.intp)
    position[used[order]] = np.arange(len(used))
    return used[order], position[rows]


_MASK63 = np.uint64((1 << 63) - 1)


def combine_keys(parent: np.ndarray, outcome: np.ndarray) -> np.ndarray:
    """Deterministic 63-bit key of a child single-target hypothesis from its parent key and outcome
    (0 = missed, j + 1 = detected by local measurement j; new tracks use a negative parent). SplitMix64 finaliser.
    ``parent`` and ``outcome`` are (N,) arrays: array arithmetic on uint64 wraps modulo 2^64 without a warning."""
    x = parent.astype(np.uint64) * np.uint64(0x9E3779B97F4A7C15) + outcome.astype(np.uint64)
    x ^= x >> np.uint64(30)
    x *= np.uint64(0xBF58476D1CE4E5B9)
    x ^= x >> np.uint64(27)
    x *= np.uint64(0x94D049BB133111EB)
    x ^= x >> np.uint64(31)
    return (x & _MASK63).view(np.int64)  # below 2^63: the same values


@dataclass(slots=True)
class UpdateContext:
    """What a strategy needs besides the hypotheses: the class, the sink, and lazily allocated birth ids.

    ``birth_id(j)`` gives the track id of the Bernoulli started by local measurement j; the same j always gets the
    same id within a frame (so every hypothesis agrees), and ids are allocated in the order first asked for.
    ``prune_existence``: the core drops Bernoullis with r below it right after the strategy (so a strategy can
    tell which hypotheses will become identical).
    """

    class_name: str
    sink: EventSink
    ids: IdAllocator
    frame_serial: int
    prune_existence: float = 0.0
    _birth_ids: dict[int, int] = field(default_factory=dict)

    def birth_id(self, j: int) -> int:
        if j not in self._birth_ids:
            self._birth_ids[j] = self.ids.allocate()
        return self._birth_ids[j]

    @property
    def born_ids(self) -> dict[int, int]:
        """Local measurement index -> track id of the births allocated this frame."""
        return dict(self._birth_ids)


class HypothesisLocals(Sequence[LocalHypotheses]):
    """The local hypotheses of every prior global hypothesis, cut on first use from those of ``union``, the
    set of all their distinct Bernoullis: hypothesis h holds the union's Bernoullis ``members[h]``."""

    def __init__(self, union: LocalHypotheses, members: list[np.ndarray]):
        self.union = union
        self.members = members
        self._cut: dict[int, LocalHypotheses] = {}

    def __len__(self) -> int:
        return len(self.members)

    @overload
    def __getitem__(self, h: int) -> LocalHypotheses: ...

    @overload
    def __getitem__(self, h: slice) -> list[LocalHypotheses]: ...

    def __getitem__(self, h: int | slice) -> LocalHypotheses | list[LocalHypotheses]:
        if isinstance(h, slice):
            return [self[i] for i in range(len(self))[h]]
        h = range(len(self))[h]
        if h not in self._cut:
            self._cut[h] = self.union.subset(self.members[h])
        return self._cut[h]


class HypothesisStrategy(Protocol):
    """Data-association hypothesis management: the only thing that differs across GNN-PMB, PMBM and TO-PMB.
    ``panels``: the viewer panels its events fill; ``chooses_assignment``: whether its update follows one chosen
    assignment of the cost matrix (a soft update, TO-PMB's, has no chosen cost)."""

    name: str
    panels: tuple[Panel, ...]
    chooses_assignment: bool

    def update(
        self, priors: list[GlobalHypothesis], locals_: Sequence[LocalHypotheses], ctx: UpdateContext
    ) -> list[GlobalHypothesis]:
        """Posterior hypotheses, sorted by decreasing weight, log weights normalised (logsumexp = 0)."""
        ...


def posterior_from_assignment(local: LocalHypotheses, col_of_row: np.ndarray, ctx: UpdateContext) -> Bernoullis:
    """Bernoullis of the posterior hypothesis that follows one assignment of measurements to columns
    (``cost.LocalHypotheses.cost_matrix``): detected tracks get r = 1 and the Kalman update, missed tracks the
    misdetection update, measurements on their new-track column start a Bernoulli (module ``cost`` docstring)."""
    k = local.n_tracks
    new_j = (col_of_row == k + np.arange(local.n_meas)).nonzero()[0]
    return updated_bernoullis(local, np.arange(k), meas_of_track(k, col_of_row) + 1, new_j, ctx)


def posteriors_from_assignments(
    union: LocalHypotheses, members: list[np.ndarray], assignments: list[np.ndarray], ctx: UpdateContext
) -> tuple[Bernoullis, list[np.ndarray]]:
    """``posterior_from_assignment`` for H hypotheses at once (PMBM): hypothesis i holds the Bernoullis
    ``members[i]`` of ``union`` and assigns measurements by ``assignments[i]`` (M,), given as columns of the
    union's cost matrix (u < U: union Bernoulli u, U + j: new track of measurement j).

    Returns one store holding each distinct (Bernoulli, outcome) once, updated once, then the births in
    measurement order, and per hypothesis its rows of the store (``GlobalHypothesis.index``): its Bernoullis in
    the order of ``members[i]``, then its births in measurement order. Birth ids are allocated hypothesis by
    hypothesis, all as calling ``posterior_from_assignment`` on each hypothesis' own local hypotheses in turn
    would."""
    n_union, m = union.n_tracks, union.n_meas
    assigned = np.stack(assignments)
    n_hyp = len(members)
    meas = np.full((n_hyp, n_union), -1, dtype=np.int64)
    hyp, row = np.nonzero(assigned < n_union)
    meas[hyp, assigned[hyp, row]] = row
    lengths = np.array([len(index) for index in members], dtype=np.int64)
    index = np.concatenate(members)
    codes = index * (m + 1) + meas[np.repeat(np.arange(n_hyp), lengths), index] + 1
    is_birth = assigned == n_union + np.arange(m)
    birth_j = np.nonzero(is_birth)[1]
    born, first = np.unique(birth_j, return_index=True)
    for j in birth_j[np.sort(first)].tolist():
        ctx.birth_id(j)
    distinct, inverse = _unique_codes(codes, n_union * (m + 1))
    store = updated_bernoullis(union, distinct // (m + 1), distinct % (m + 1), born, ctx)
    birth_rows = len(distinct) + np.searchsorted(born, birth_j)
    n_births = is_birth.sum(axis=1)
    sizes = lengths + n_births
    starts = np.cumsum(sizes) - sizes  # each hypothesis' rows: its tracks, then its births, laid end to end
    rows = np.empty(int(sizes.sum()), dtype=np.int64)
    hyp_of_track = np.repeat(np.arange(n_hyp), lengths)
    rows[starts[hyp_of_track] + np.arange(len(index)) - (np.cumsum(lengths) - lengths)[hyp_of_track]] = inverse
    hyp_of_birth = np.repeat(np.arange(n_hyp), n_births)
    birth_starts = np.cumsum(n_births) - n_births
    rows[(starts + lengths)[hyp_of_birth] + np.arange(len(birth_j)) - birth_starts[hyp_of_birth]] = birth_rows
    bounds = np.cumsum(sizes).tolist()
    return store, [rows[start:stop] for start, stop in zip([0, *bounds[:-1]], bounds, strict=True)]


def _unique_codes(codes: np.ndarray, n_codes: int) -> tuple[np.ndarray, np.ndarray]:
    """``np.unique(codes, return_inverse=True)`` for integer codes in [0, n_codes), by a presence table when that
    is small (no sort)."""
    if n_codes > 1 << 20:
        return np.unique(codes, return_inverse=True)
    seen = np.zeros(n_codes, dtype=bool)
    seen[codes] = True
    return np.flatnonzero(seen), (np.cumsum(seen) - 1)[codes]


def meas_of_track(n_tracks: int, col_of_row: np.ndarray) -> np.ndarray:
    """(K,) the measurement an assignment (M,) gives each of the K track columns, -1 if none."""
    out = np.full(n_tracks, -1, dtype=np.int64)
    on_track = col_of_row < n_tracks
    out[col_of_row[on_track]] = on_track.nonzero()[0]
    return out


def updated_bernoullis(
    local: LocalHypotheses, rows: np.ndarray, outcome: np.ndarray, new_j: np.ndarray, ctx: UpdateContext
) -> Bernoullis:
    """Prior Bernoullis ``rows`` of ``local`` after the single-target hypotheses ``outcome`` (0 = missed: the
    misdetection update; j + 1 = detected by local measurement j: r = 1 and the Kalman update, box fields and
    score from the detection), then the Bernoullis started by local measurements ``new_j`` (existence r_j and
    state from ``poisson``). The local key becomes ``combine_keys(parent key, outcome)``, a new Bernoulli's
    ``combine_keys(-frame serial, j + 1)``.

    Every field is gathered in one indexing from the prior's rows followed by the new-track hypotheses' (K + M
    sources; the prior's alone when nothing is born), so the posterior is built without intermediate
    Bernoullis."""
    prior, new = local.prior, local.new
    k, n_new = len(prior), len(new_j)
    det = (outcome > 0).nonzero()[0]
    det_k, det_j = rows[det], outcome[det] - 1
    source = np.concatenate([rows, k + new_j]) if n_new else rows  # row of the sources each Bernoulli copies
    existence = _gather(local.miss_existence, new.existence, source, n_new)
    existence[det] = 1.0
    mean = _gather(prior.mean, new.mean, source, n_new)
    mean[det] = detected_means(local, det_k, det_j)
    cov = _gather(prior.cov, new.cov, source, n_new)
    cov[det] = local.inn.cov_post[det_k]
    if len(det) or n_new:
        det_source = source.copy()
        det_source[det] = k + det_j  # detected Bernoullis take their detection's box fields
        fields = prior.det.gather_with(local.meas, det_source)
    else:
        fields = prior.det.subset(rows)
    track_id, parent, outcome = prior.track_id[rows], prior.local_key[rows], outcome
    misses = _gather(prior.misses, np.zeros(len(new.existence), dtype=np.int64), source, n_new)
    misses[det] = 0
    score_sum = _gather(prior.detected_score_sum, local.meas.boxes.score * new.existence, source, n_new)
    score_sum[det] += fields.score[det]
    frames = _gather(prior.detected_frames, np.ones(len(new.existence), dtype=np.int64), source, n_new)
    frames[det] += 1
    if n_new:
        births = np.array([ctx.birth_id(j) for j in new_j.tolist()], dtype=np.int64)
        track_id = np.concatenate([track_id, births])
        parent = np.concatenate([parent, np.full(n_new, -ctx.frame_serial)])
        outcome = np.concatenate([outcome, new_j + 1])
    return Bernoullis(
        track_id=track_id,
        local_key=combine_keys(parent, outcome),
        existence=existence,
        mean=mean,
        cov=cov,
        det=fields,
        misses=misses,
        detected_score_sum=score_sum,
        detected_frames=frames,
    )


def coasting_scores(b: Bernoullis, mean_min_frames: int) -> np.ndarray:
    """(K,) output scores s r (s the last detection's score, r the existence). With ``mean_min_frames`` N > 0
    (``[pmb] miss_score_mean_min_frames``), a missed Bernoulli born or detected on at least N frames is scored
    max(s, m) r instead, m = ``detected_score_sum / detected_frames`` its mean output score on those frames (s r_b
    at birth, s after each detection), so that one low last detection does not rank a long, sure track's
    coasting boxes below its detected ones."""
    score = b.det.score * b.existence
    if mean_min_frames <= 0:
        return score
    coasting = (b.misses > 0) & (b.detected_frames >= mean_min_frames)
    mean = b.detected_score_sum / np.maximum(b.detected_frames, 1)
    return np.where(coasting, np.maximum(score, mean * b.existence), score)


def _gather(own: np.ndarray, born: np.ndarray, source: np.ndarray, n_new: int) -> np.ndarray:
    """Rows ``source`` of ``own`` followed by ``born`` (of ``own`` alone when no row is born: ``n_new`` 0; of
    ``born`` alone when ``own`` has no rows, whose trailing shape may then be a default one)."""
    if not n_new:
        return own[source]
    return (np.concatenate([own, born]) if len(own) else born)[source]


def new_bernoullis(local: LocalHypotheses, new_j: np.ndarray, ctx: UpdateContext) -> Bernoullis:
    """The Bernoullis started by local measurements ``new_j`` (existence r_j from ``poisson``); none of the
    class's state dimension (4, or 5 with the turn rate) when nothing is born."""
    if len(new_j) == 0:
        return Bernoullis.empty(local.new.mean.shape[1])
    none = np.zeros(0, dtype=np.int64)
    return updated_bernoullis(local, none, none, new_j, ctx)


def assignment_pairs(
    local: LocalHypotheses, col_of_row: np.ndarray
) -> tuple[tuple[tuple[AxisLabel, AxisLabel], ...], tuple[int, ...]]:
    """(row label, column label) of every assigned measurement, and the ids of tracks left undetected."""
    cols = local.col_labels()
    pairs = tuple(zip(local.row_labels(), map(cols.__getitem__, col_of_row.tolist()), strict=True))
    missed = local.prior.track_id[meas_of_track(local.n_tracks, col_of_row) < 0]
    return pairs, tuple(missed.tolist())


def _track_rows(hypotheses: list[GlobalHypothesis]) -> tuple[np.ndarray, np.ndarray]:
    """(N,) track ids and (N,) existence probabilities of the Bernoullis of ``hypotheses``: for hypotheses
    indexing one store (PMBM), each store row used once (a row repeated across hypotheses adds nothing to a
    maximum or a set); otherwise every hypothesis' Bernoullis laid end to end."""
    store = hypotheses[0].store
    if len(hypotheses) > 1 and all(h.store is store and h.index is not None for h in hypotheses):
        used = np.zeros(len(store), dtype=bool)
        used[np.concatenate([h.index for h in hypotheses])] = True
        return store.track_id[used], store.existence[used]
    return np.concatenate([h.track_id for h in hypotheses]), np.concatenate([h.existence for h in hypotheses])


_PYTHON_MAX_ROWS = 512
"""``_max_existence`` reads up to this many Bernoullis in plain Python: NumPy's set routines cost more below."""


def _max_existence(hypotheses: list[GlobalHypothesis]) -> dict[int, float]:
    """Track id -> its largest existence probability over the hypotheses (at least 0)."""
    ids, existence = _track_rows(hypotheses)
    if len(ids) > _PYTHON_MAX_ROWS:
        ids, inverse = np.unique(ids, return_inverse=True)
        largest = np.zeros(len(ids))
        np.maximum.at(largest, inverse, existence)
        return dict(zip(ids.tolist(), largest.tolist(), strict=True))
    id_list, r_list = ids.tolist(), existence.tolist()
    out = dict(zip(id_list, r_list, strict=True))
    if len(out) == len(id_list) and not (np.signbit(existence) | np.isnan(existence)).any():
        return out  # distinct ids (one hypothesis): each value is its own maximum, and max(0, r) is r
    out = {}
    for t, r in zip(id_list, r_list, strict=True):
        out[t] = max(out.get(t, 0.0), r)
    return out


@dataclass(frozen=True, slots=True)
class VelocityMeasurements(Measurements):
    """Measurements whose vector is z = [x, y, vx, vy]: the BEV centre and the detector's velocity (M, 4), for the
    opt-in ``[pmb] measure_velocity = 1`` variant (measurement matrix H = I, R = diag(r_x, r_y, r_vx, r_vy))."""

    @property
    def z(self) -> np.ndarray:
        return np.concatenate([self.boxes.xy, self.boxes.velocity_mps], axis=1)


@dataclass(frozen=True, slots=True)
class PmbPrior:
    """The predicted prior global hypotheses and the local hypotheses of each over this frame's measurements."""

    hypotheses: list[GlobalHypothesis]
    locals_: Sequence[LocalHypotheses]


class PmbCore(ClassFilter[PmbPrior, Bernoullis]):
    """One class's PMB / PMBM filter; ``strategy`` decides the hypothesis management (module docstring). The
    frame loop is ``skeleton.ClassFilter.step``; the posterior it extracts from is the most likely hypothesis."""

    def __init__(self, class_name: str, config: TrackerConfig, strategy: HypothesisStrategy, ids: IdAllocator):
        super().__init__(class_name, config, ids)
        self.params = config.pmb
        self.models = config.models
        self.strategy = strategy
        self.turn_rate = self.models.motion_model == 1
        p = self.params
        box = BoxShapeModel(p.heading_std_rad, p.size_log_std, p.size_log_spread, p.box_outlier_prob)
        self.box = box if box.enabled else None
        self.frame_serial = 0
        self.miss_counts = MissDetectionCounts.empty(p.miss_p_detect_bins, p.miss_p_detect_score_split)
        state_dim = STATE_DIM + int(self.turn_rate)  # [x, y, vx, vy], and omega for the coordinated turn
        self.hypotheses: list[GlobalHypothesis] = [GlobalHypothesis(0.0, Bernoullis.empty(state_dim))]
        self.birth_update = birth_update(
            birth_covariance(self.models, self.turn_rate),
            motion_model(0.0, self.class_params, self.models, self.params.measure_velocity == 1).R,
        )

    @property
    def panels(self) -> tuple[Panel, ...]:
        """The viewer panels this tracker's events fill beyond the common ones: its strategy's."""
        return self.strategy.panels

    @property
    def has_costs(self) -> bool:  # type: ignore[override]
        """Whether its update follows a chosen assignment (``HypothesisStrategy.chooses_assignment``)."""
        return self.strategy.chooses_assignment

    def predict(self, meas: Measurements, dt_s: float) -> PmbPrior:
        """Steps 1-3 of the module docstring: the birth intensity at the M measurements, then every hypothesis'
        Bernoullis predicted and gated (z = [x, y], or [x, y, vx, vy] with ``[pmb] measure_velocity = 1``)."""
        p = self.params
        self.frame_serial += 1
        model = motion_model(dt_s, self.class_params, self.models, p.measure_velocity == 1)
        if p.measure_velocity == 1:
            meas = VelocityMeasurements(meas.boxes, meas.source_index)
        clutter = clutter_intensity(self.models, p)
        birth = measurement_birth(meas, self.models, self.turn_rate)
        new = new_track_hypotheses(birth, meas, model.R, clutter, self.birth_update)
        return self._predict_and_localise(meas, model, new)

    def prior_view(self, prior: PmbPrior) -> tuple[TrackView, Gating]:
        """The K Bernoullis of the most likely prior hypothesis and their gate."""
        local = prior.locals_[0]
        b = local.prior
        return _view(b), Gating(local.inn, local.d2, local.inside, local.giou, local.gate_giou_min)

    def update(self, prior: PmbPrior, meas: Measurements, sink: EventSink) -> Bernoullis:
        """Steps 4-5: the strategy's posterior hypotheses, pruned, become the state; returns the Bernoullis of the
        most likely one. Events: ``CostMatrix`` (of the most likely prior hypothesis), the strategy's, ``Pruned``,
        ``Born``."""
        if sink.enabled:
            sink.emit(prior.locals_[0].cost_event(self.class_name))
        ctx = UpdateContext(self.class_name, sink, self.ids, self.frame_serial, self.params.prune_existence)
        posteriors = self.strategy.update(prior.hypotheses, prior.locals_, ctx)
        self.hypotheses = self._prune(prior.hypotheses, posteriors, ctx, sink)
        best = self.hypotheses[0].bernoullis
        if self.params.miss_p_detect_online == 1:
            self.miss_counts.count(best.track_id, best.misses, best.score)
        if sink.enabled:
            self._emit_born(best, ctx, sink)
        return best

    def extract(self, posterior: Bernoullis, sink: EventSink) -> tuple[list[TrackEstimate], float]:
        """Step 6: Bernoullis with r >= the extraction threshold, missed at most ``[pmb] output_max_misses`` frames
        in a row; tracking score = detection score x r (``coasting_scores`` for a missed one), times d^n for a
        Bernoulli missed n frames in a row (``[pmb] miss_score_decay`` d)."""
        threshold = self.params.extraction_threshold
        b = posterior
        keep = (b.existence >= threshold) & (b.misses <= self.params.output_max_misses)
        if self.params.coasting_min_existence > 0.0:
            keep &= (b.misses == 0) | (b.existence >= self.params.coasting_min_existence)
        score = coasting_scores(b, self.params.miss_score_mean_min_frames)
        det, track_id, mean, existence, misses = b.det, b.track_id, b.mean, b.existence, b.misses
        if not keep.all():
            sel = keep.nonzero()[0]
            det, track_id, mean, existence, misses, score = (
                det.subset(sel),
                track_id[sel],
                mean[sel],
                existence[sel],
                misses[sel],
                score[sel],
            )
        decay = self.params.miss_score_decay
        if decay < 1.0:
            score = score * decay ** misses.astype(float)
        estimates = det.to_estimates(self.class_name, track_id, mean, score, existence)
        return estimates, threshold

    def posterior_view(self, posterior: Bernoullis) -> TrackView:
        return _view(posterior)

    def miss_p_detect_max(self, prior: Bernoullis) -> float | np.ndarray:
        """This frame's cap of the P_D of the predicted Bernoullis ``prior`` when missed: ``[pmb]
        miss_p_detect_max``, or with ``[pmb] miss_p_detect_online = 1`` the class's P_D learnt from the frames
        before, per Bernoulli by the frames it has been missed in a row (``miss_detection``), (K,); a Bernoulli
        with another track of its class near it keeps ``miss_p_detect_max`` (``miss_detection.crowded``)."""
        p = self.params
        if p.miss_p_detect_online != 1:
            return p.miss_p_detect_max
        learnt = self.miss_counts.p_detect(
            p.miss_p_detect_max, p.miss_p_detect_prior_frames, prior.misses - 1, prior.score
        )
        near = crowded(
            prior.mean[:, :2],
            prior.existence,
            prior.track_id,
            p.miss_p_detect_neighbour_m,
            p.miss_p_detect_neighbour_existence,
        )
        return np.where(near, p.miss_p_detect_max, learnt)

    def _predict_and_localise(self, meas: Measurements, model: MotionModel, new: NewTrackHypotheses) -> PmbPrior:
        """Predicted prior hypotheses and their local hypotheses. Global hypotheses share most Bernoullis
        (equal ``local_key`` = identical component), so with several hypotheses every distinct Bernoulli is
        predicted and gated once and each hypothesis takes its rows when asked (``HypothesisLocals``; PMBM,
        García-Fernández et al. 2018, sec. V)."""
        p = self.models

        def localise(prior: Bernoullis) -> LocalHypotheses:  # one call for both paths: they once gated differently
            return local_hypotheses(
                prior,
                meas,
                new,
                model.R,
                p.gate_chi2,
                self.miss_p_detect_max(prior),
                self.box,
                self.params.gate_giou_min,
                self.params.miss_p_detect_last_score == 1,
            )

        if len(self.hypotheses) == 1:
            h = self.hypotheses[0]
            prior = predict_bernoullis(h.bernoullis, model, p.p_survive)
            return PmbPrior([GlobalHypothesis(h.log_weight, prior)], [localise(prior)])
        union, members = hypothesis_union(self.hypotheses)
        union_prior = predict_bernoullis(union, model, p.p_survive)
        union_local = localise(union_prior)
        priors = [GlobalHypothesis(h.log_weight, union_prior, i) for h, i in zip(self.hypotheses, members, strict=True)]
        return PmbPrior(priors, HypothesisLocals(union_local, members))

    def _prune(
        self, priors: list[GlobalHypothesis], posteriors: list[GlobalHypothesis], ctx: UpdateContext, sink: EventSink
    ) -> list[GlobalHypothesis]:
        """Drop Bernoullis with r < threshold from every hypothesis; report tracks that vanished from all."""
        threshold = self.params.prune_existence
        kept = _without_existence_below(posteriors, threshold)
        if sink.enabled:
            posterior_r = _max_existence(posteriors)
            prior_r = _max_existence(priors)
            alive = set(_track_rows(kept)[0].tolist())
            for t in sorted((posterior_r.keys() | prior_r.keys()) - alive):
                if t in posterior_r:
                    sink.emit(Pruned(self.class_name, t, PruneReason.LOW_EXISTENCE, posterior_r[t]))
                else:
                    sink.emit(Pruned(self.class_name, t, PruneReason.NOT_IN_ANY_HYPOTHESIS, prior_r[t]))
        return kept

    def _emit_born(self, best: Bernoullis, ctx: UpdateContext, sink: EventSink) -> None:
        """``Born`` of the Bernoullis of ``best`` started this frame."""
        born = set(ctx.born_ids.values())
        if not born:
            return
        sel = np.array([k for k, t in enumerate(best.track_id.tolist()) if t in born], dtype=np.intp)
        if len(sel):
            sink.emit(
                Born(
                    self.class_name,
                    best.track_id[sel],
                    best.meas_index[sel],
                    best.mean[sel, :STATE_DIM],
                    best.existence[sel],
                )
            )


def _view(b: Bernoullis) -> TrackView:
    """K Bernoullis as events show them: [x, y, vx, vy] (K, 4) and its covariance (K, 4, 4) (a turn rate left
    out)."""
    if b.mean.shape[1] == STATE_DIM:
        return TrackView(b.track_id, b.mean, b.cov, b.existence)
    return TrackView(b.track_id, b.mean[:, :STATE_DIM], b.cov[:, :STATE_DIM, :STATE_DIM], b.existence)
