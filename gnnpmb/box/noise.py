"""Per-class box Kalman noise learned from a training split, as Probabilistic 3D MOT does from nuScenes train.

Chiu, Prioletti, Li & Bohg 2020, sec. IV-C (its ``get_nuscenes_stats.py``), per class, in SI units per keyframe
step (``config.BoxNoise``):

- process noise Q from the ground truth: for an object annotated in three keyframes in a row, the second
  difference of its position and heading, d2p = p_t - 2 p_(t-1) + p_(t-2) (yaw differences wrapped to [-pi, pi)),
  and of its velocity, dv = v_t - v_(t-1) with v_t = (p_t - p_(t-1)) / dt_t: q_x, q_y, q_z, q_yaw = Var(d2p),
  q_vx, q_vy, q_vz = Var(dv); the size does not change (q_size = 0);
- measurement noise R from the detections: per keyframe, detections and annotations of the class are matched by
  the Hungarian algorithm on their BEV centre distance, pairs closer than 2 m kept; r = Var(detection -
  annotation) of x, y, z, yaw (modulo pi, as the filter's heading alignment sees it), l, w, h;
- initial velocity variance: for an object matched in two keyframes in a row, the change of its detection error
  over the step, p_v = Var((e_t - e_(t-1)) / dt_t) of x, y, z; the measured components start at R (p_scale 1).

Differences from its script: the heading residual is taken modulo pi (its raw difference counts a detector's
heading flip as a 3 rad error), velocities are in m/s with the real time between keyframes (it counts frames),
and a class with fewer than ``MIN_SAMPLES`` samples of a statistic keeps the given fallback.
"""

from __future__ import annotations

import dataclasses
from collections import defaultdict
from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import numpy as np

from gnnpmb.assign.lsap import linear_sum_assignment
from gnnpmb.box.kalman import half_turn_residual, measurements, wrap_angle
from gnnpmb.config import BoxNoise
from gnnpmb.data.scene import SceneData
from gnnpmb.types import Boxes

MATCH_DISTANCE_M = 2.0
"""Detections and annotations closer than this (BEV centres) are matched (its '2d_center' matching)."""
MIN_SAMPLES = 10
"""A statistic over fewer samples keeps the fallback value."""
VARIANCE_FLOOR = 1e-6
"""Smallest variance written (a class whose boxes never change size or height in the data would give 0)."""


@dataclass(frozen=True, slots=True)
class NoiseSamples:
    """What one class's statistics are computed from: second differences d2p (N, 4) [x, y, z, yaw] and velocity
    changes dv (N, 3) of the annotations, detection residuals (N, 7), detection-error velocities (N, 3)."""

    d2p: np.ndarray
    dv: np.ndarray
    residual: np.ndarray
    error_velocity: np.ndarray


def collect_samples(
    scenes: Sequence[SceneData], detections: Sequence[Mapping[str, Boxes]], classes: Sequence[str]
) -> dict[str, NoiseSamples]:
    """The samples of every class over ``scenes`` and their detections (one mapping sample token -> boxes per
    scene; several detectors may be pooled by passing each scene once per detector)."""
    d2p: dict[str, list] = defaultdict(list)
    dv: dict[str, list] = defaultdict(list)
    residual: dict[str, list] = defaultdict(list)
    error_velocity: dict[str, list] = defaultdict(list)
    for scene, dets in zip(scenes, detections, strict=True):
        history: dict[str, list[tuple[float, np.ndarray, int]]] = defaultdict(list)  # instance -> (t, box7, keyframe)
        errors: dict[str, tuple[int, float, np.ndarray]] = {}  # instance -> (keyframe, t, error xyz)
        for kf in scene.keyframes:
            t_s = kf.timestamp_us * 1e-6
            gt = kf.gt
            gt7 = measurements(gt)
            for i, instance in enumerate(gt.instance_id.tolist()):
                track = history[instance]
                if track and kf.index - track[-1][2] != 1:
                    track.clear()
                track.append((t_s, gt7[i], kf.index))
                cls = str(gt.class_name[i])
                if len(track) >= 3 and cls in classes:
                    (t0, b0, _), (t1, b1, _), (t2, b2, _) = track[-3:]
                    p0, p1, p2 = b0[[0, 1, 2, 3]], b1[[0, 1, 2, 3]], b2[[0, 1, 2, 3]]
                    step1, step2 = p1 - p0, p2 - p1
                    step1[3], step2[3] = wrap_angle(step1[3]), wrap_angle(step2[3])
                    d2p[cls].append(step2 - step1)
                    dv[cls].append(step2[:3] / (t2 - t1) - step1[:3] / (t1 - t0))
            boxes = dets[kf.sample_token]
            z = measurements(boxes)
            for cls in classes:
                g = np.flatnonzero(gt.class_name == cls)
                d = np.flatnonzero(boxes.class_name == cls)
                if not len(g) or not len(d):
                    continue
                dist = np.linalg.norm(z[d, None, :2] - gt7[None, g, :2], axis=2)
                rows, cols = linear_sum_assignment(dist)
                for r, c in zip(rows.tolist(), cols.tolist(), strict=True):
                    if dist[r, c] >= MATCH_DISTANCE_M:
                        continue
                    res = z[d[r]] - gt7[g[c]]
                    res[3] = half_turn_residual(res[3])
                    residual[cls].append(res)
                    instance = str(gt.instance_id[g[c]])
                    previous = errors.get(instance)
                    if previous is not None and previous[0] == kf.index - 1:
                        error_velocity[cls].append((res[:3] - previous[2]) / (t_s - previous[1]))
                    errors[instance] = (kf.index, t_s, res[:3])
    return {
        cls: NoiseSamples(
            np.array(d2p[cls]).reshape(-1, 4),
            np.array(dv[cls]).reshape(-1, 3),
            np.array(residual[cls]).reshape(-1, 7),
            np.array(error_velocity[cls]).reshape(-1, 3),
        )
        for cls in classes
    }


def noise_from_samples(samples: NoiseSamples, fallback: BoxNoise) -> BoxNoise:
    """The class's ``BoxNoise`` from its samples (module docstring); statistics with fewer than
    ``MIN_SAMPLES`` samples keep ``fallback``'s values."""

    def var(x: np.ndarray, fallback_values: tuple[float, ...]) -> tuple[float, ...]:
        if len(x) < MIN_SAMPLES:
            return fallback_values
        return tuple(max(float(v), VARIANCE_FLOOR) for v in np.var(x, axis=0))

    f = fallback
    r = var(samples.residual, (f.r_x, f.r_y, f.r_z, f.r_yaw, f.r_l, f.r_w, f.r_h))
    q = var(samples.d2p, (f.q_x, f.q_y, f.q_z, f.q_yaw))
    q_v = var(samples.dv, (f.q_vx, f.q_vy, f.q_vz))
    p_v = var(samples.error_velocity, (f.p_vx, f.p_vy, f.p_vz))
    return dataclasses.replace(
        f, **dict(zip(_R + _Q + _QV + _PV, r + q + q_v + p_v, strict=True)), q_size=0.0, p_scale=1.0
    )


_R = ("r_x", "r_y", "r_z", "r_yaw", "r_l", "r_w", "r_h")
_Q = ("q_x", "q_y", "q_z", "q_yaw")
_QV = ("q_vx", "q_vy", "q_vz")
_PV = ("p_vx", "p_vy", "p_vz")
