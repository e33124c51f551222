"""``BoxTracker``: the frame of AB3DMOT, Probabilistic 3D MOT, SimpleTrack and ImmortalTracker as one
``skeleton.ClassFilter``; each published tracker is a ``BoxTrackerSpec`` (its module in ``gnnpmb.box``).

Per class and frame (Weng et al. 2020, Fig. 1; Pang et al. 2021, Fig. 2):

1. predict every track's box with the 10-D constant-velocity Kalman filter (``kalman``), either from its last
   state every frame (AB3DMOT, Probabilistic 3D MOT: ``Prediction.EVERY_FRAME``, Q added each frame) or once
   from its last update over the time since (SimpleTrack, ImmortalTracker: ``Prediction.FROM_LAST_UPDATE``);
2. the (M, K) association cost of every detection box and predicted box (``cost``);
3. association: the spec's solver over every pair, pairs past the cost threshold dropped, optionally
   SimpleTrack's second stage (``assign.matching.two_stage_match``);
4. a matched track takes the Kalman update with its detection box (heading aligned) and the detection's score;
   a track kept alive by the second stage takes an update with its own prediction (SimpleTrack's mode 3); a
   missed track keeps its prediction, its score times ``miss_score_factor``;
5. every first-stage detection left unmatched starts a track; the life cycle (``life``) confirms and deletes;
6. output: the tracks ``life.output_mask`` selects, each with its filtered box (x, y, z, yaw, l, w, h), velocity
   and score; existence 1 (no existence probability: track logic).

Events: ``Predicted`` (``Gated`` for a Mahalanobis cost), ``CostMatrix`` with its ``CostScale`` and
``Assignment`` over the first-stage detections, ``Born``, ``TrackLogic`` / ``Pruned``, ``Posterior`` with the
track scores and their ``ScoreRule``, ``Extracted``.
"""

from __future__ import annotations

import dataclasses
import enum
from dataclasses import dataclass, replace

import numpy as np

from gnnpmb.assign.matching import BoundedCosts, SecondStage, Solver, StageMatches, two_stage_match
from gnnpmb.box import kalman
from gnnpmb.box.cost import BoxCost
from gnnpmb.box.life import LifeRule, LifeState, advance, emit_transitions, output_mask
from gnnpmb.config import BoxNoise, TrackerConfig
from gnnpmb.detection_fields import DetectionFields
from gnnpmb.events import (
    Assignment,
    AxisKind,
    Born,
    CostMatrix,
    EventSink,
    ScoreOnHit,
    ScoreRule,
    axis_labels,
)
from gnnpmb.kalman import Innovation, innovation, predict
from gnnpmb.skeleton import ClassFilter, Gating, TrackView
from gnnpmb.soa import StructOfArrays
from gnnpmb.track_scores import decay_on_miss
from gnnpmb.types import IdAllocator, Measurements, TrackEstimate
from gnnpmb.vector.track_logic import LogicUpdate


class Prediction(enum.Enum):
    """How a track is predicted (module docstring, step 1)."""

    EVERY_FRAME = "Kalman filter, from its last state, every frame"
    FROM_LAST_UPDATE = "Kalman filter, from its last update, over the time since"
    DETECTOR_VELOCITY = "its last box moved by its detection's velocity; detections stepped back to meet it"


@dataclass(frozen=True, slots=True)
class BoxTrackerSpec:
    """One published box tracker: its cost, solver, life cycle, prediction, noise and score rule.

    miss_score_factor: a missed track's score is multiplied by it every missed frame; first_stage_score:
    detections below it neither take part in the first stage nor start tracks; second: the second stage (None:
    one stage)."""

    cost: BoxCost
    solver: Solver
    life: LifeRule
    prediction: Prediction
    noise: BoxNoise
    miss_score_factor: float = 1.0
    first_stage_score: float = 0.0
    second: SecondStage | None = None

    @property
    def score_rule(self) -> ScoreRule:
        return ScoreRule(ScoreOnHit.DETECTION, miss_factor=self.miss_score_factor)

    @property
    def cost_limit(self) -> float:
        """The largest cost a decision compares with a threshold: costs up to it must be exact."""
        return max(self.cost.max_cost, self.second.max_cost if self.second is not None else -np.inf)


@dataclass(frozen=True, slots=True)
class BoxTracks(StructOfArrays):
    """K tracks of one class.

    track_id (K,); mean (K, 10), cov (K, 10, 10): the current state (posterior if updated this frame, else the
    prediction); anchor_mean, anchor_cov: the state the next prediction starts from, anchor_age_s (K,) seconds
    since it; life: hits, misses, confirmed; score (K,): the track score; meas_index (K,): the source index of
    this frame's detection, -1 if none.
    """

    track_id: np.ndarray
    mean: np.ndarray
    cov: np.ndarray
    anchor_mean: np.ndarray
    anchor_cov: np.ndarray
    anchor_age_s: np.ndarray
    life: LifeState
    score: np.ndarray
    meas_index: np.ndarray

    @staticmethod
    def empty() -> BoxTracks:
        d = kalman.STATE_DIM
        return BoxTracks(
            track_id=np.zeros(0, dtype=np.int64),
            mean=np.zeros((0, d)),
            cov=np.zeros((0, d, d)),
            anchor_mean=np.zeros((0, d)),
            anchor_cov=np.zeros((0, d, d)),
            anchor_age_s=np.zeros(0),
            life=LifeState.empty(),
            score=np.zeros(0),
            meas_index=np.zeros(0, dtype=np.int64),
        )


@dataclass(frozen=True, slots=True)
class BoxPrior:
    """The K predicted tracks (``tracks.mean`` / ``cov`` the predictions), the seconds each was predicted over
    (``elapsed_s`` (K,), from its anchor), their innovation quantities (K; only for a gating cost, which needs
    them for every track: the others compute them for the tracks they update) and the (M, K) association costs
    of this frame's M detections (``z`` (M, 7) their boxes)."""

    tracks: BoxTracks
    elapsed_s: np.ndarray
    inn: Innovation | None
    z: np.ndarray
    cost: BoundedCosts


class BoxTracker(ClassFilter[BoxPrior, BoxTracks]):
    """One class's box tracker (module docstring); the frame loop is ``skeleton.ClassFilter.step``."""

    has_existence = False  # hits / misses life cycle
    keeps_detection_box = False  # the 10-D Kalman filter smooths size and heading too

    def __init__(self, class_name: str, config: TrackerConfig, ids: IdAllocator, spec: BoxTrackerSpec):
        super().__init__(class_name, config, ids)
        self.spec = spec
        self.has_gates = spec.cost.gate
        self.tracks = BoxTracks.empty()
        self.frame = 0

    @property
    def gate_threshold(self) -> float:
        """A Mahalanobis cost's threshold squared (``Gated`` reports squared distances)."""
        return self.spec.cost.max_cost**2

    def predict(self, meas: Measurements, dt_s: float) -> BoxPrior:
        """Step 1-2 of the module docstring: every track's predicted box and the association costs."""
        self.frame += 1
        t = self.tracks
        noise = self.spec.noise
        z = kalman.measurements(meas.boxes)
        inn = None
        if self.spec.prediction is Prediction.DETECTOR_VELOCITY:
            elapsed = np.zeros(len(t))
            mean, cov = kalman.moved(t.mean, dt_s), t.cov
            track_boxes, det_boxes = t.mean[:, : kalman.MEAS_DIM], kalman.moved_back(z, meas.boxes.velocity_mps, dt_s)
        else:
            elapsed = t.anchor_age_s + dt_s
            mean, cov = predict(t.anchor_mean, t.anchor_cov, kalman.box_models(elapsed, noise))
            mean[:, kalman.YAW] = kalman.wrap_angle(mean[:, kalman.YAW])
            if self.spec.cost.gate:
                inn = innovation(mean, cov, kalman.box_model(0.0, noise).R)
            track_boxes, det_boxes = mean[:, : kalman.MEAS_DIM], z
        prior = replace(t, mean=mean, cov=cov, meas_index=np.full(len(t), -1, dtype=np.int64))
        if len(t) and len(z):
            cost = self.spec.cost.matrix(track_boxes, inn, det_boxes, self.spec.cost_limit)
        else:
            cost = BoundedCosts.of(np.zeros((len(z), len(t))))
        return BoxPrior(prior, elapsed, inn, z, cost)

    def prior_view(self, prior: BoxPrior) -> tuple[TrackView, Gating | None]:
        t = prior.tracks
        mean, cov = kalman.view(t.mean, t.cov)
        view = TrackView(t.track_id, mean, cov, np.ones(len(t)))
        if not self.spec.cost.gate:
            return view, None
        distance = prior.cost.value.T
        return view, Gating(inn=prior.inn, d2=distance**2, inside=distance <= self.spec.cost.max_cost)

    def update(self, prior: BoxPrior, meas: Measurements, sink: EventSink) -> BoxTracks:
        """Steps 3-5 of the module docstring. Events: ``CostMatrix``, ``Assignment``, ``Born``, ``TrackLogic``,
        ``Pruned``."""
        spec, t = self.spec, prior.tracks
        score = np.asarray(meas.boxes.score, dtype=float)
        matches = two_stage_match(
            prior.cost, score, spec.first_stage_score, spec.cost.max_cost, spec.solver, spec.second
        )
        meas_of_track = matches.meas_of_track
        hit_k = np.flatnonzero(meas_of_track >= 0)
        alive_k = np.flatnonzero(matches.kept_alive)
        mean, cov = t.mean.copy(), t.cov.copy()
        if spec.prediction is Prediction.DETECTOR_VELOCITY:
            if len(hit_k):
                mean[hit_k], cov[hit_k] = kalman.box_with_velocity(
                    prior.z[meas_of_track[hit_k]], meas.boxes.velocity_mps[meas_of_track[hit_k]]
                )
        else:
            for rows, z in ((hit_k, prior.z[meas_of_track[hit_k]]), (alive_k, t.mean[alive_k, : kalman.MEAS_DIM])):
                if len(rows):
                    inn = self._innovation(prior, rows)
                    mean[rows] = kalman.update(t.mean[rows], inn, z)
                    cov[rows] = inn.cov_post
        updated = (meas_of_track >= 0) | matches.kept_alive
        life = advance(t.life, updated, spec.life)
        new_score = decay_on_miss(t.score, spec.miss_score_factor)
        new_score[hit_k] = score[meas_of_track[hit_k]]
        meas_index = np.full(len(t), -1, dtype=np.int64)
        meas_index[hit_k] = meas.source_index[meas_of_track[hit_k]]
        if spec.prediction in (Prediction.EVERY_FRAME, Prediction.DETECTOR_VELOCITY):
            anchor_mean, anchor_cov, anchor_age = mean, cov, np.zeros(len(t))
        elif spec.prediction is Prediction.FROM_LAST_UPDATE:
            anchor_mean = np.where(updated[:, None], mean, t.anchor_mean)
            anchor_cov = np.where(updated[:, None, None], cov, t.anchor_cov)
            anchor_age = np.where(updated, 0.0, prior.elapsed_s)
        else:
            raise ValueError(f"unknown prediction {spec.prediction!r}")
        kept = BoxTracks(
            t.track_id, mean, cov, anchor_mean, anchor_cov, anchor_age, life.state, new_score, meas_index
        ).subset(~life.deleted)
        born = self._births(meas, prior.z, matches)
        self.tracks = BoxTracks.concatenate([kept, born])
        if sink.enabled:
            self._emit(prior, meas, matches, life, born, sink)
        return self.tracks

    def _innovation(self, prior: BoxPrior, rows: np.ndarray) -> Innovation:
        """The innovation quantities of the prior tracks ``rows``."""
        if prior.inn is not None:
            return prior.inn.subset(rows)
        t = prior.tracks
        return innovation(t.mean[rows], t.cov[rows], kalman.box_model(0.0, self.spec.noise).R)

    def _births(self, meas: Measurements, z: np.ndarray, matches: StageMatches) -> BoxTracks:
        """Tracks started by the first-stage detections the association left unmatched, ids in detection order."""
        new_j = np.flatnonzero(matches.first_stage & (matches.track_of_meas < 0))
        if not len(new_j):
            return BoxTracks.empty()
        if self.spec.prediction is Prediction.DETECTOR_VELOCITY:
            mean, cov = kalman.box_with_velocity(z[new_j], meas.boxes.velocity_mps[new_j])
        else:
            mean, cov = kalman.initial_state(z[new_j], self.spec.noise)
        return BoxTracks(
            track_id=np.array([self.ids.allocate() for _ in new_j], dtype=np.int64),
            mean=mean,
            cov=cov,
            anchor_mean=mean.copy(),
            anchor_cov=cov.copy(),
            anchor_age_s=np.zeros(len(new_j)),
            life=LifeState.born(len(new_j), self.spec.life),
            score=np.asarray(meas.boxes.score[new_j], dtype=float),
            meas_index=np.asarray(meas.source_index[new_j], dtype=np.int64),
        )

    def extract(self, posterior: BoxTracks, sink: EventSink) -> tuple[list[TrackEstimate], float]:
        """Step 6: the tracks ``life.output_mask`` selects, with their filtered boxes and scores (threshold 1)."""
        sel = posterior.subset(np.flatnonzero(output_mask(posterior.life, self.spec.life, self.frame)))
        _, size_wlh, _ = kalman.box_fields(sel.mean)
        det = DetectionFields(
            score=sel.score,
            z_m=sel.mean[:, kalman.Z],
            size_wlh_m=size_wlh,
            quat_wxyz=kalman.quat_of(sel.mean),
            meas_index=sel.meas_index,
        )
        mean4 = sel.mean[:, kalman.VIEW]
        return det.to_estimates(self.class_name, sel.track_id, mean4, sel.score, np.ones(len(sel))), 1.0

    def posterior_view(self, posterior: BoxTracks) -> TrackView:
        mean, cov = kalman.view(posterior.mean, posterior.cov)
        t = posterior
        return TrackView(t.track_id, mean, cov, np.ones(len(t)), t.score.copy(), self.spec.score_rule)

    def _emit(
        self,
        prior: BoxPrior,
        meas: Measurements,
        matches: StageMatches,
        life: LogicUpdate[LifeState],
        born: BoxTracks,
        sink: EventSink,
    ) -> None:
        """``CostMatrix`` and ``Assignment`` over the first-stage detections (track entries past the threshold
        +inf, new-track columns = the threshold), ``Born``, ``TrackLogic`` and ``Pruned``."""
        t = prior.tracks
        rows_j = np.flatnonzero(matches.first_stage)
        m, k = len(rows_j), len(t)
        scale = dataclasses.replace(self.spec.cost.scale, optimal=self.spec.solver is Solver.HUNGARIAN)
        threshold = self.spec.cost.max_cost
        full = np.full((m, k + m), np.inf)
        track_cost = prior.cost.value[rows_j]
        full[:, :k] = np.where(track_cost <= threshold, track_cost, np.inf)
        full[np.arange(m), k + np.arange(m)] = threshold
        rows = axis_labels(AxisKind.MEASUREMENT, meas.source_index[rows_j])
        track_cols = axis_labels(AxisKind.TRACK, t.track_id)
        new_cols = axis_labels(AxisKind.NEW_TRACK, meas.source_index[rows_j])
        sink.emit(
            CostMatrix(
                self.class_name,
                full,
                rows,
                track_cols + new_cols,
                description=self.spec.cost.description,
                scale=scale,
            )
        )
        chosen = matches.track_of_meas[rows_j].tolist()
        pairs = tuple((rows[r], track_cols[c] if c >= 0 else new_cols[r]) for r, c in enumerate(chosen))
        total = float(sum(full[r, c] if c >= 0 else full[r, k + r] for r, c in enumerate(chosen)))
        missed = tuple(int(i) for i in t.track_id[matches.meas_of_track < 0])
        sink.emit(Assignment(self.class_name, pairs, total, missed))
        if len(born):
            mean4, _ = kalman.view(born.mean, born.cov)
            sink.emit(Born(self.class_name, born.track_id, born.meas_index, mean4, np.ones(len(born))))
        emit_transitions(self.class_name, t.track_id, life, born.track_id, self.spec.life, sink)
