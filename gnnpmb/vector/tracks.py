"""The vector track set and the ``skeleton.ClassFilter`` hooks shared by the vector-type trackers (GNN, JPDA).

A vector-type tracker keeps a fixed list of Kalman tracks, each with an M/N track-logic state, instead of a
random-finite-set density (Blackman & Popoli 1999, ch. 6; Bar-Shalom, Daum & Huang 2009). Per class and frame:

1. Kalman predict every track (``gnnpmb.kalman``, per-class Q and R);
2. ellipsoidal gate: d^2_kj = (z_j - H m_k)^T S_k^-1 (z_j - H m_k) < G (``[models] gate_chi2``);
3. data association and state update: the only part that differs (``gnn.GnnTracker``: the single best
   assignment; ``jpda.JpdaTracker``: marginal association probabilities and the PDA update);
4. measurements left unassociated start tentative tracks: mean [z_j, v_j] with the detector's velocity v_j,
   covariance the Kalman update of diag(s_p^2, s_p^2, s_v^2, s_v^2) by z_j (``[models] birth_pos_std_m``,
   ``birth_vel_std_mps``), i.e. about R in position;
5. M/N track logic (``track_logic``) confirms and deletes tracks; steps 4 and 5 are the initiator / deleter pair
   (``MeasurementInitiator``, ``MofNDeleter``); the frame loop is ``skeleton.ClassFilter.step``;
6. output: the *confirmed* tracks associated with a detection this frame. Coasting tracks (missed, not yet
   deleted) are kept and predicted but not output: a coasted box drifts from the truth and the nuScenes metric
   counts it as a false positive, while the same object's next detection resumes the track under its old id.

Output boxes carry the filtered x, y, vx, vy and the associated detection's z, size, rotation and score;
existence is 1 (vector trackers have no existence probability).
"""

from __future__ import annotations

from abc import abstractmethod
from dataclasses import dataclass, replace

import numpy as np

from gnnpmb.config import ClassParams, ModelParams, TrackerConfig, VectorParams
from gnnpmb.detection_fields import CarriesDetectionFields, DetectionFields
from gnnpmb.events import Born, EventSink, Pruned, PruneReason
from gnnpmb.kalman import innovation, predict
from gnnpmb.models import MotionModel, birth_covariance, cv_model
from gnnpmb.skeleton import ClassFilter, Gating, TrackView, gate_tracks
from gnnpmb.soa import StructOfArrays
from gnnpmb.types import IdAllocator, Measurements, TrackEstimate
from gnnpmb.vector.track_logic import LogicState, LogicUpdate, advance, emit_transitions


@dataclass(frozen=True, slots=True)
class VectorTracks(CarriesDetectionFields, StructOfArrays):
    """K tracks of one class, struct-of-arrays.

    track_id: (K,) int64; mean: (K, 4) [x, y, vx, vy]; cov: (K, 4, 4); det: the fields of the last associated
    detection (``score``, ``z_m``, ... read through as the tracks' own; ``meas_index`` -1 if missed this frame);
    logic: M/N state.
    """

    track_id: np.ndarray
    mean: np.ndarray
    cov: np.ndarray
    det: DetectionFields
    logic: LogicState

    def __len__(self) -> int:
        return int(self.track_id.shape[0])

    @staticmethod
    def empty() -> VectorTracks:
        return VectorTracks(
            track_id=np.zeros(0, dtype=np.int64),
            mean=np.zeros((0, 4)),
            cov=np.zeros((0, 4, 4)),
            det=DetectionFields.empty(),
            logic=LogicState.empty(),
        )

    def predicted(self, model: MotionModel) -> VectorTracks:
        """Kalman prediction m' = F m, P' = F P F^T + Q; no detection associated yet."""
        if not len(self):
            return self
        mean, cov = predict(self.mean, self.cov, model)
        return replace(self, mean=mean, cov=cov, det=self.det.undetected())

    def updated(self, assoc: Association, meas: Measurements) -> VectorTracks:
        """Posterior state from ``assoc``; tracks with a hit take the box fields of their detection."""
        k = np.flatnonzero(assoc.meas_of_track >= 0)
        detected = DetectionFields.from_measurements(meas, assoc.meas_of_track[k])
        return replace(self, mean=assoc.mean, cov=assoc.cov, det=self.det.take(k, detected))


@dataclass(frozen=True, slots=True)
class Association:
    """What a data-association step decides for K prior tracks and M measurements.

    mean: (K, 4), cov: (K, 4, 4) posterior states; meas_of_track: (K,) local index of the detection each track
    is associated with (a *hit*: the track takes its box fields), -1 for a miss; birth: (M,) bool, the
    measurements that start tentative tracks.
    """

    mean: np.ndarray
    cov: np.ndarray
    meas_of_track: np.ndarray
    birth: np.ndarray


class MeasurementInitiator:
    """Starts a tentative track at each measurement the association gives to no track (module docstring, step 4):
    mean [z_j, v_j], covariance the Kalman update of P_b = diag(s_p^2, s_p^2, s_v^2, s_v^2) by z_j."""

    def __init__(self, class_params: ClassParams, models: ModelParams, params: VectorParams, ids: IdAllocator):
        R = cv_model(0.0, class_params).R
        self.birth_cov = innovation(np.zeros((1, 4)), birth_covariance(models)[None], R).cov_post[0]
        self.params = params
        self.ids = ids

    def initiate(self, meas: Measurements, new_j: np.ndarray) -> VectorTracks:
        """Tentative tracks started by local measurements ``new_j``, ids allocated in measurement order."""
        b = len(new_j)
        if b == 0:
            return VectorTracks.empty()
        return VectorTracks(
            track_id=np.array([self.ids.allocate() for _ in range(b)], dtype=np.int64),
            mean=np.concatenate([meas.z[new_j], meas.boxes.velocity_mps[new_j]], axis=1),
            cov=np.broadcast_to(self.birth_cov, (b, 4, 4)).copy(),
            det=DetectionFields.from_measurements(meas, new_j),
            logic=LogicState.born(b, self.params),
        )


class MofNDeleter:
    """Confirms and deletes tracks by the M/N track logic (``track_logic``; module docstring, step 5)."""

    def __init__(self, params: VectorParams):
        self.params = params

    def update(self, logic: LogicState, hit: np.ndarray) -> LogicUpdate[LogicState]:
        """The track logic after a frame in which tracks ``hit`` (K,) bool were associated with a detection."""
        return advance(logic, hit, self.params)

    def emit(
        self,
        class_name: str,
        track_ids: np.ndarray,
        update: LogicUpdate[LogicState],
        born_ids: np.ndarray,
        sink: EventSink,
    ) -> None:
        """``TrackLogic`` events of the frame and ``Pruned`` for every track the logic deleted."""
        emit_transitions(class_name, track_ids, update, born_ids, self.params, sink)
        for t in track_ids[update.deleted].tolist():
            sink.emit(Pruned(class_name, int(t), PruneReason.TRACK_LOGIC, 1.0))


class VectorTracker(ClassFilter[tuple[VectorTracks, Gating], VectorTracks]):
    """One class's vector-type tracker: the frame loop ``skeleton.ClassFilter.step``, an initiator / deleter pair
    for track logic, and the association that subclasses implement (``_associate``, module docstring, step 3)."""

    has_existence = False  # M-of-N track logic: a track exists or not

    def __init__(self, class_name: str, config: TrackerConfig, ids: IdAllocator):
        super().__init__(class_name, config, ids)
        self.params = config.vector
        self.gate_chi2 = config.models.gate_chi2
        self.clutter_intensity = config.models.clutter_intensity
        self.lbp = config.lbp
        self.initiator = MeasurementInitiator(self.class_params, config.models, config.vector, ids)
        self.deleter = MofNDeleter(config.vector)
        self.tracks = VectorTracks.empty()

    def predict(self, meas: Measurements, dt_s: float) -> tuple[VectorTracks, Gating]:
        """Steps 1-2 of the module docstring: the K predicted tracks and their gate over the M measurements."""
        model = cv_model(dt_s, self.class_params)
        prior = self.tracks.predicted(model)
        return prior, gate_tracks(prior.mean, prior.cov, model.R, meas.z, self.gate_chi2)

    def prior_view(self, prior: tuple[VectorTracks, Gating]) -> tuple[TrackView, Gating]:
        t, gating = prior
        return TrackView(t.track_id, t.mean, t.cov, np.ones(len(t))), gating

    def update(self, prior: tuple[VectorTracks, Gating], meas: Measurements, sink: EventSink) -> VectorTracks:
        """Steps 3-5: association and state update (``_associate``), track logic (``deleter``), new tentative
        tracks (``initiator``); the surviving and new tracks become the state. Events: the association's,
        ``Born``, ``TrackLogic``, ``Pruned``."""
        tracks, gating = prior
        assoc = self._associate(tracks, gating, meas, sink)
        logic = self.deleter.update(tracks.logic, assoc.meas_of_track >= 0)
        posterior = replace(tracks.updated(assoc, meas), logic=logic.state)
        born = self.initiator.initiate(meas, np.flatnonzero(assoc.birth))
        self.tracks = VectorTracks.concatenate([posterior.subset(~logic.deleted), born])
        if sink.enabled:
            if len(born):
                sink.emit(Born(self.class_name, born.track_id, born.meas_index, born.mean, np.ones(len(born))))
            self.deleter.emit(self.class_name, tracks.track_id, logic, born.track_id, sink)
        return self.tracks

    def extract(self, posterior: VectorTracks, sink: EventSink) -> tuple[list[TrackEstimate], float]:
        """Step 6: the confirmed tracks hit this frame, scored by their detection; existence 1 (threshold 1)."""
        sel = posterior.subset(np.flatnonzero(posterior.logic.confirmed & (posterior.meas_index >= 0)))
        return sel.det.to_estimates(self.class_name, sel.track_id, sel.mean, sel.score, np.ones(len(sel))), 1.0

    def posterior_view(self, posterior: VectorTracks) -> TrackView:
        t = posterior
        return TrackView(t.track_id, t.mean, t.cov, np.ones(len(t)))

    @abstractmethod
    def _associate(self, prior: VectorTracks, gating: Gating, meas: Measurements, sink: EventSink) -> Association:
        """Data association and state update of the K prior tracks with the M measurements, given their gate
        (``gating``: innovations, (K, M) squared Mahalanobis distances and gate). Emits its own events."""
