"""GNN: global nearest neighbour Kalman tracking with M/N track logic (Blackman & Popoli 1999, ch. 6).

Each frame the single most likely assignment of measurements to tracks is chosen. With a constant detection
probability P_D and a Poisson clutter intensity kappa, the likelihood of an assignment in which pairs (j, k)
are associated, the other tracks are missed and the other measurements are clutter (or new objects) is

    prod_(j,k) P_D N(z_j; H m_k, S_k)  *  prod_(missed k) (1 - P_D)  *  prod_(unassigned j) kappa.

Dividing by the assignment with no pairs, prod_k (1 - P_D) prod_j kappa, leaves a product over the pairs
only, so the best assignment minimises the sum of the pair costs

    C[j, k] = -log [ P_D N(z_j; H m_k, S_k) / ((1 - P_D) kappa) ]     (+inf outside the gate)

over an (M, K + M) matrix augmented with one dummy column per measurement, C[j, K + j] = 0 ("measurement j
is not assigned to any track": it starts a tentative track; the other dummy entries are +inf). A pair is
only taken when its likelihood ratio exceeds 1, so leaving a track missed is always possible. Assigned tracks
get the Kalman update with their measurement; missed tracks keep their prediction. Everything else
(prediction, gate, births, track logic, output) is ``tracks.VectorTracker``.
"""

from __future__ import annotations

import numpy as np

from gnnpmb.assign.hungarian import solve
from gnnpmb.events import Assignment, AxisKind, CostMatrix, CostTerms, EventSink, axis_labels
from gnnpmb.kalman import log_likelihood, paired_updated_means
from gnnpmb.skeleton import Gating
from gnnpmb.types import Measurements
from gnnpmb.vector.tracks import Association, VectorTracker, VectorTracks

COST_DESCRIPTION = "-log[P_D N(z; Hm, S) / ((1 - P_D) kappa)]; new-track column 0 = unassigned"


def pair_offset_nats(p_detect: float, clutter_intensity: float) -> float:
    """-log(P_D / ((1 - P_D) kappa)): the part of every pair cost that does not depend on the pair."""
    return -float(np.log(p_detect) - np.log1p(-p_detect) - np.log(clutter_intensity))


def pair_costs(log_lik: np.ndarray, inside: np.ndarray, p_detect: float, clutter_intensity: float) -> np.ndarray:
    """(M, K) costs C[j, k] = pair_offset_nats - log N(z_j; H m_k, S_k) (module docstring) from (K, M)
    log N(z_j; H m_k, S_k) and gate; +inf outside."""
    return np.where(inside, pair_offset_nats(p_detect, clutter_intensity) - log_lik, np.inf).T  # = -(log_lik + offset)


def best_assignment(cost: np.ndarray) -> tuple[np.ndarray, float]:
    """Optimal assignment for (M, K) pair costs augmented with the zero-cost dummy columns.

    Returns (track_of_meas (M,) int, -1 = unassigned; total cost). Only rows and columns with a finite pair
    enter the Hungarian solve, which keeps it small when most measurements are far from every track.
    """
    m, _ = cost.shape
    track_of_meas = np.full(m, -1, dtype=np.int64)
    finite = np.isfinite(cost)
    rows, cols = np.flatnonzero(finite.any(axis=1)), np.flatnonzero(finite.any(axis=0))
    if len(rows) == 0:
        return track_of_meas, 0.0
    r, c = len(rows), len(cols)
    sub = np.full((r, c + r), np.inf)
    sub[:, :c] = cost[np.ix_(rows, cols)]
    sub[np.arange(r), c + np.arange(r)] = 0.0
    col_of_row, total = solve(sub)
    on_track = col_of_row < c
    track_of_meas[rows[on_track]] = cols[col_of_row[on_track]]
    return track_of_meas, total


class GnnTracker(VectorTracker):
    """One class's GNN tracker (module docstring): ``tracks.VectorTracker`` with this ``_associate``."""

    def _associate(self, prior: VectorTracks, gating: Gating, meas: Measurements, sink: EventSink) -> Association:
        k, m = gating.inside.shape
        inn = gating.inn
        cost = pair_costs(log_likelihood(inn, gating.d2), gating.inside, self.params.p_detect, self.clutter_intensity)
        track_of_meas, total = best_assignment(cost)
        det_j = np.flatnonzero(track_of_meas >= 0)
        det_k = track_of_meas[det_j]
        mean, cov = prior.mean.copy(), prior.cov.copy()
        if len(det_j):
            mean[det_k] = paired_updated_means(prior.mean, inn, meas.z, det_k, det_j)
            cov[det_k] = inn.cov_post[det_k]
        meas_of_track = np.full(k, -1, dtype=np.int64)
        meas_of_track[det_k] = det_j
        if sink.enabled:
            terms = CostTerms(
                existence=None,
                miss_log_lik=None,
                score=None,
                d2=gating.d2,
                log_det_S=inn.log_det_S,
                dim=inn.z_pred.shape[1],
                offset_nats=pair_offset_nats(self.params.p_detect, self.clutter_intensity),
                offset_text=f"a detection against clutter (P_D {self.params.p_detect:g})",
                track_ids=prior.track_id,
            )
            self._emit_assignment(prior, meas, cost, terms, track_of_meas, meas_of_track, total, sink)
        return Association(mean=mean, cov=cov, meas_of_track=meas_of_track, birth=track_of_meas < 0)

    def _emit_assignment(
        self,
        prior: VectorTracks,
        meas: Measurements,
        cost: np.ndarray,
        terms: CostTerms,
        track_of_meas: np.ndarray,
        meas_of_track: np.ndarray,
        total: float,
        sink: EventSink,
    ) -> None:
        m, k = cost.shape
        full = np.full((m, k + m), np.inf)
        full[:, :k] = cost
        full[np.arange(m), k + np.arange(m)] = 0.0
        rows = axis_labels(AxisKind.MEASUREMENT, meas.source_index)
        track_cols = axis_labels(AxisKind.TRACK, prior.track_id)
        new_cols = axis_labels(AxisKind.NEW_TRACK, meas.source_index)
        cols = track_cols + new_cols
        sink.emit(CostMatrix(self.class_name, full, rows, cols, description=COST_DESCRIPTION, terms=terms))
        pairs = tuple((rows[j], track_cols[t] if t >= 0 else new_cols[j]) for j, t in enumerate(track_of_meas.tolist()))
        missed = tuple(int(t) for t in prior.track_id[meas_of_track < 0])
        sink.emit(Assignment(self.class_name, pairs, total, missed))
