"""Per-class tracker parameters learnt from an annotated split and a detector's boxes on it (``gnnpmb calibrate``).

Detections and annotations are matched as the official tracking evaluation matches them: per keyframe and class,
one-to-one by the Hungarian method on the bird's-eye centre distance, a pair at or beyond ``dist_th_tp`` (2 m)
never matched; an annotation counts only inside the class range around the ego vehicle and with at least one
LiDAR or radar point, a detection only inside the class range (the devkit's ``filter_eval_boxes``; bike racks,
which need the map, are not filtered). From the pairs and the boxes left over, per class (Bar-Shalom, Li &
Kirubarajan 2001, sec. 5.2 for the Gaussian noise; Mahler 2007, ch. 9 for P_D, clutter and birth):

- measurement noise of position r_x, r_y, and of velocity r_vx, r_vy: the variance of the detection minus the
  annotation over the inlier pairs, inliers within ``OUTLIER_SIGMAS`` robust standard deviations (1.4826 x the
  median absolute deviation) on both axes; the annotation's velocity is the devkit's ``box_velocity``: the central
  difference of its centre over the neighbouring keyframes (one-sided at a track's ends);
- heading and size (``box_likelihood``): sigma_psi, the robust standard deviation of the heading residual modulo
  pi; sigma_s, that of log(detected / annotated) width and length; sigma_c, the standard deviation of the class's
  annotated log width and length; eps, the share of pairs whose heading or size residual is an outlier;
- detection probability P_D: the share of annotations matched by a detection at or above the score threshold
  (also per range bin, and the precision of each score bin, written as comments); the PMB trackers take it as
  the cap of a missed Bernoulli's P_D (``[pmb] miss_p_detect_max``; its last detection's score below it), so
  that a miss lowers the existence as much as this detector's misses mean, written with ``miss_p_detect_online =
  0``: learnt from annotations, it replaces the estimate the trackers learn from their own tracks
  (``gnnpmb.pmb.miss_detection``);
- clutter intensity kappa: detections at or above the threshold left unmatched, per keyframe, per m^2 of the
  class's evaluated disc (pi range^2), per score bin as comments; its velocity density (PMB with the velocity
  measured): the mean of a Gaussian fitted to those detections' velocities, 1 / (4 pi sigma_vx sigma_vy);
- birth: new objects per keyframe (annotations whose instance was not counted at an earlier keyframe of the scene,
  after its first keyframe) divided by the detections per keyframe, the weight w_b of each detection's birth
  component (``models.measurement_birth``), with where births happen (median range) as a comment;
- process noise q_x, q_y of the constant-velocity model: the variance of the annotations' velocity change per
  keyframe (``process_noise``);
- score threshold: the lowest score from which every 0.05-wide score window holding ``MIN_SAMPLES`` detections is
  true with probability at least ``MIN_PRECISION``;
- the box Kalman noise of ``prob3dmot`` (``gnnpmb.box.noise``).

A statistic with fewer than ``MIN_SAMPLES`` samples keeps the value of the base configuration. Process noise,
clutter intensity (and its velocity density) and the birth weight are never written below the base
configuration's (the comment then gives the learnt value): the trackers' models are cruder than the data (a
Gaussian for heavy-tailed manoeuvres; a birth component at every detection), and on the dev set's ``mini_train``
the learnt values below the defaults lost AMOTA in-sample (issue 32 in ``docs/results.md``: Q of 1e-4 from the
mostly parked objects, 0.92 -> 0.77; the learnt clutter, ~40 times below the default, made clutter detections
tracks at once).

Which of these values the parameter file holds is decided per class by ``calibration_check``: a cross-validation
on the same split against the defaults.
"""

from __future__ import annotations

import dataclasses
import math
from collections import defaultdict
from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import numpy as np
from scipy.optimize import linear_sum_assignment

from gnnpmb.box.kalman import half_turn_residual
from gnnpmb.box.noise import collect_samples, noise_from_samples
from gnnpmb.config import TrackerConfig
from gnnpmb.data.boxes3d import yaw_from_quat_wxyz
from gnnpmb.data.scene import SceneData
from gnnpmb.types import TRACKING_CLASSES, Boxes

MIN_SAMPLES = 10
"""A statistic over fewer samples keeps the base configuration's value."""
OUTLIER_SIGMAS = 3.0
"""A residual beyond this many robust standard deviations is an outlier."""
MIN_PRECISION = 0.1
"""The score threshold keeps every score window whose detections are true at least this often."""
SCORE_STEP = 0.05
"""Width of the score windows the threshold is chosen from."""
MAX_VELOCITY_GAP_S = 1.5
"""The devkit's ``box_velocity`` gives no velocity over a larger time gap."""
SCORE_BINS = (0.0, 0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.7, 0.8, 0.9, 1.0)
RANGE_BINS_M = (0.0, 10.0, 20.0, 30.0, 40.0, 50.0)
VARIANCE_FLOOR = 1e-4
"""Smallest variance written."""


@dataclass(frozen=True, slots=True)
class ClassSamples:
    """What one class's parameters are learnt from (N matched pairs, G counted annotations, U unmatched
    detections, all detections of any score).

    position_residual_m (N, 2), velocity_residual_mps (N_v, 2), heading_residual_rad (N,), log_size_ratio (N, 2)
    [width, length]; matched_score (N,); gt_log_size (G, 2); gt_range_m (G,) and gt_best_score (G,), the score of
    its matched detection (0 when unmatched); clutter_score (U,), clutter_velocity_mps (U, 2); detection_score
    (all detections, (D,)); births: new objects after a scene's first keyframe, birth_range_m their ranges;
    keyframes: keyframes after a scene's first; frames: all keyframes; objects: the annotated instances with at least
    one counted box; range_m: the class range."""

    position_residual_m: np.ndarray
    velocity_residual_mps: np.ndarray
    heading_residual_rad: np.ndarray
    log_size_ratio: np.ndarray
    matched_score: np.ndarray
    gt_log_size: np.ndarray
    gt_range_m: np.ndarray
    gt_best_score: np.ndarray
    clutter_score: np.ndarray
    clutter_velocity_mps: np.ndarray
    detection_score: np.ndarray
    birth_range_m: np.ndarray
    later_keyframes: int
    frames: int
    objects: int
    range_m: float


def annotation_velocities(scene: SceneData) -> list[np.ndarray]:
    """Per keyframe, (N, 2) the velocity of each annotation: the central difference of its centre over the
    neighbouring keyframes where the instance is annotated (one-sided at its ends; NaN with no neighbour or over a
    gap above ``MAX_VELOCITY_GAP_S``), as the devkit's ``box_velocity``."""
    where: dict[str, dict[int, tuple[float, np.ndarray]]] = defaultdict(dict)
    for kf in scene.keyframes:
        for i, instance in enumerate(kf.gt.instance_id.tolist()):
            where[instance][kf.index] = (kf.timestamp_us * 1e-6, kf.gt.xy[i])
    out = []
    for kf in scene.keyframes:
        v = np.full((len(kf.gt), 2), np.nan)
        for i, instance in enumerate(kf.gt.instance_id.tolist()):
            seen = where[instance]
            first = seen.get(kf.index - 1, seen[kf.index])
            last = seen.get(kf.index + 1, seen[kf.index])
            dt = last[0] - first[0]
            if 0.0 < dt <= MAX_VELOCITY_GAP_S:
                v[i] = (last[1] - first[1]) / dt
        out.append(v)
    return out


def collect(
    scenes: Sequence[SceneData],
    detections: Sequence[Mapping[str, Boxes]],
    class_range_m: Mapping[str, float],
    match_distance_m: float,
) -> dict[str, ClassSamples]:
    """The samples of every tracking class over ``scenes`` and their detections (sample token -> boxes, one
    mapping per scene)."""
    parts: dict[str, dict[str, list]] = {c: defaultdict(list) for c in TRACKING_CLASSES}
    counts = {c: {"later": 0, "frames": 0, "objects": 0} for c in TRACKING_CLASSES}
    for scene, dets in zip(scenes, detections, strict=True):
        velocities = annotation_velocities(scene)
        seen: dict[str, set[str]] = defaultdict(set)
        for kf, gt_velocity in zip(scene.keyframes, velocities, strict=True):
            ego = kf.ego_pose.translation_m[:2]
            gt, boxes = kf.gt, dets[kf.sample_token]
            gt_range, det_range = np.linalg.norm(gt.xy - ego, axis=1), np.linalg.norm(boxes.xy - ego, axis=1)
            for cls in TRACKING_CLASSES:
                p, reach = parts[cls], class_range_m[cls]
                g = np.flatnonzero((gt.class_name == cls) & (kf.gt_num_pts > 0) & (gt_range <= reach))
                d = np.flatnonzero((boxes.class_name == cls) & (det_range <= reach))
                counts[cls]["frames"] += 1
                if kf.index > 0:
                    counts[cls]["later"] += 1
                    new = [i for i in g.tolist() if gt.instance_id[i] not in seen[cls]]
                    p["birth_range"].extend(gt_range[new].tolist())
                seen[cls].update(gt.instance_id[g].tolist())
                p["detection_score"].extend(boxes.score[d].tolist())
                dist = np.linalg.norm(boxes.xy[d, None] - gt.xy[None, g], axis=2)
                rows, cols = linear_sum_assignment(dist) if dist.size else (np.zeros(0, int), np.zeros(0, int))
                ok = dist[rows, cols] < match_distance_m
                di, gi = d[rows[ok]], g[cols[ok]]
                best = np.zeros(len(g))
                best[cols[ok]] = boxes.score[di]
                p["gt_range"].extend(gt_range[g].tolist())
                p["gt_best_score"].extend(best.tolist())
                p["gt_log_size"].extend(np.log(gt.size_wlh_m[g, :2]).tolist())
                p["position"].extend((boxes.xy[di] - gt.xy[gi]).tolist())
                v_res = boxes.velocity_mps[di] - gt_velocity[gi]
                p["velocity"].extend(v_res[np.isfinite(v_res).all(axis=1)].tolist())
                yaw = yaw_from_quat_wxyz(boxes.quat_wxyz[di]) - yaw_from_quat_wxyz(gt.quat_wxyz[gi])
                p["heading"].extend(half_turn_residual(yaw).tolist())
                p["log_size"].extend(np.log(boxes.size_wlh_m[di, :2] / gt.size_wlh_m[gi, :2]).tolist())
                p["matched_score"].extend(boxes.score[di].tolist())
                unmatched = np.setdiff1d(d, di)
                p["clutter_score"].extend(boxes.score[unmatched].tolist())
                p["clutter_velocity"].extend(boxes.velocity_mps[unmatched].tolist())
        for cls in TRACKING_CLASSES:
            counts[cls]["objects"] += len(seen[cls])

    def arr(values: list, width: int = 0) -> np.ndarray:
        a = np.array(values, dtype=float)
        return a.reshape(-1, width) if width else a

    return {
        c: ClassSamples(
            position_residual_m=arr(p["position"], 2),
            velocity_residual_mps=arr(p["velocity"], 2),
            heading_residual_rad=arr(p["heading"]),
            log_size_ratio=arr(p["log_size"], 2),
            matched_score=arr(p["matched_score"]),
            gt_log_size=arr(p["gt_log_size"], 2),
            gt_range_m=arr(p["gt_range"]),
            gt_best_score=arr(p["gt_best_score"]),
            clutter_score=arr(p["clutter_score"]),
            clutter_velocity_mps=arr(p["clutter_velocity"], 2),
            detection_score=arr(p["detection_score"]),
            birth_range_m=arr(p["birth_range"]),
            later_keyframes=counts[c]["later"],
            frames=counts[c]["frames"],
            objects=counts[c]["objects"],
            range_m=float(class_range_m[c]),
        )
        for c, p in parts.items()
    }


def robust_std(x: np.ndarray) -> np.ndarray:
    """1.4826 x the median absolute deviation from the median, per column (the standard deviation of a Gaussian)."""
    return 1.4826 * np.median(np.abs(x - np.median(x, axis=0)), axis=0)


def inliers(x: np.ndarray) -> np.ndarray:
    """(N,) bool: rows of ``x`` (N, D) within ``OUTLIER_SIGMAS`` robust standard deviations on every column."""
    scale = np.maximum(robust_std(x), 1e-9)
    return (np.abs(x - np.median(x, axis=0)) <= OUTLIER_SIGMAS * scale).all(axis=1)


@dataclass(frozen=True, slots=True)
class Learnt:
    """One learnt value: the TOML table it goes in (``classes.car``, ``classes.car.pmb``, ...), its key, its value
    and what it was learnt from."""

    table: str
    key: str
    value: float
    source: str


def score_threshold(s: ClassSamples) -> float | None:
    """The lowest score t such that every ``SCORE_STEP`` window from t up that holds ``MIN_SAMPLES`` detections is
    true at least ``MIN_PRECISION`` of the time (module docstring); None with too few detections."""
    if len(s.detection_score) < MIN_SAMPLES:
        return None
    edges = np.arange(0.0, 1.0, SCORE_STEP)
    low = []
    for t in edges:
        n_true = np.sum((s.matched_score >= t) & (s.matched_score < t + SCORE_STEP))
        n_false = np.sum((s.clutter_score >= t) & (s.clutter_score < t + SCORE_STEP))
        low.append(n_true + n_false >= MIN_SAMPLES and n_true < MIN_PRECISION * (n_true + n_false))
    last_low = max((i for i, is_low in enumerate(low) if is_low), default=-1)
    return float(round(edges[last_low + 1], 2)) if last_low >= 0 else 0.0


def _variances(path: str, key: str, residual: np.ndarray, what: str, outliers: str) -> list[Learnt]:
    """The variances of the x and y columns of ``residual`` (N, 2) without its outliers (``inliers``), at least
    ``VARIANCE_FLOOR``, as parameters ``key`` (a template of the axis) of ``path``; none below ``MIN_SAMPLES``."""
    n = len(residual)
    if n < MIN_SAMPLES:
        return []
    keep = inliers(residual)
    var = np.maximum(np.var(residual[keep], axis=0), VARIANCE_FLOOR)
    share = f"{100 * (1 - keep.mean()):.1f} % {outliers} left out"
    return [
        Learnt(path, key.format(axis), v, f"variance of {what.format(axis)}, {n} pairs, {share}")
        for axis, v in zip("xy", var.tolist(), strict=True)
    ]


def learn_class(cls: str, s: ClassSamples, base: TrackerConfig) -> list[Learnt]:
    """The learnt values of one class (module docstring), each with its source."""
    out: list[Learnt] = []
    own, pmb = f"classes.{cls}", f"classes.{cls}.pmb"
    n = len(s.position_residual_m)
    beyond = f"outliers beyond {OUTLIER_SIGMAS:g} robust sigma"
    out += _variances(own, "r_{}", s.position_residual_m, "detection - annotation {} (m^2)", beyond)
    out += _variances(own, "r_v{}", s.velocity_residual_mps, "detected - annotated v{} ((m/s)^2)", "outliers")
    if n >= MIN_SAMPLES:
        heading = s.heading_residual_rad[:, None]
        sigma_psi = max(float(robust_std(heading)[0]), 1e-3)
        sigma_s = max(float(robust_std(s.log_size_ratio.reshape(-1, 1))[0]), 1e-3)
        outlier = ~(inliers(heading) & inliers(s.log_size_ratio))
        out.append(
            Learnt(pmb, "heading_std_rad", sigma_psi, f"robust sigma of the heading residual modulo pi, {n} pairs")
        )
        out.append(
            Learnt(pmb, "size_log_std", sigma_s, f"robust sigma of log(detected / annotated) w and l, {n} pairs")
        )
        out.append(
            Learnt(
                pmb,
                "box_outlier_prob",
                float(np.clip(outlier.mean(), 1e-3, 0.5)),
                f"share of {n} pairs whose heading or size residual is beyond {OUTLIER_SIGMAS:g} robust sigma",
            )
        )
    if len(s.gt_log_size) >= MIN_SAMPLES:
        spread = max(float(np.std(s.gt_log_size)), 1e-2)
        out.append(
            Learnt(pmb, "size_log_spread", spread, f"std of the annotated log w and l, {len(s.gt_log_size)} boxes")
        )
    threshold = score_threshold(s)
    if threshold is not None:
        out.append(
            Learnt(
                own,
                "score_threshold",
                threshold,
                f"lowest score from which every {SCORE_STEP:g}-wide window of >= {MIN_SAMPLES} detections is true "
                f">= {MIN_PRECISION:g} of the time, {len(s.detection_score)} detections",
            )
        )
    t = base.resolved(cls).preprocess.score_threshold if threshold is None else threshold
    g = len(s.gt_range_m)
    if g >= MIN_SAMPLES:
        detected = s.gt_best_score >= t
        p_d = float(np.clip(detected.mean(), 0.01, 0.99))
        source = f"share of {g} annotations matched by a detection with score >= {t:g}"
        out.append(Learnt(f"{own}.phd", "p_detect", p_d, source))
        out.append(Learnt(f"{own}.vector", "p_detect", p_d, source))
        out.append(
            Learnt(pmb, "miss_p_detect_max", p_d, f"the P_D above, the cap of a missed Bernoulli's P_D; {source}")
        )
        out.append(Learnt(pmb, "miss_p_detect_online", 0, "the cap above is kept, not learnt again from the tracks"))
    frames = max(s.frames, 1)
    clutter = s.clutter_score[s.clutter_score >= t]
    area_m2 = math.pi * s.range_m**2
    if len(s.detection_score) >= MIN_SAMPLES:
        kappa, floor = len(clutter) / frames / area_m2, base.resolved(cls).models.clutter_intensity
        out.append(
            Learnt(
                own,
                "clutter_intensity",
                max(kappa, floor),
                f"{len(clutter)} unmatched detections with score >= {t:g} over {s.frames} keyframes and "
                f"pi {s.range_m:g}^2 m^2 (1/m^2){_raised(kappa, floor)}",
            )
        )
    if len(clutter) >= MIN_SAMPLES:
        v = s.clutter_velocity_mps[s.clutter_score >= t]
        sx, sy = np.maximum(np.std(v, axis=0), 0.1).tolist()
        density, floor = 1.0 / (4.0 * math.pi * sx * sy), base.resolved(cls).pmb.clutter_velocity_density
        out.append(
            Learnt(
                pmb,
                "clutter_velocity_density",
                max(density, floor),
                f"mean density 1/(4 pi sx sy) of a Gaussian fitted to {len(v)} clutter velocities, sx {sx:.2f}, "
                f"sy {sy:.2f} m/s (1/(m/s)^2){_raised(density, floor)}",
            )
        )
    kept = np.sum(s.detection_score >= t)
    if s.later_keyframes and kept >= MIN_SAMPLES:
        births = len(s.birth_range_m)
        per_frame = births / s.later_keyframes
        rate = per_frame / (kept / frames)
        floor = base.resolved(cls).models.birth_weight
        w_b = float(np.clip(max(rate, floor), 1e-4, 1.0))
        where = f", median range {np.median(s.birth_range_m):.0f} m" if births else ""
        where += _raised(rate, floor)
        out.append(
            Learnt(
                own,
                "birth_weight",
                w_b,
                f"{births} new objects over {s.later_keyframes} keyframes after the first ({per_frame:.3f}/keyframe"
                f"{where}) / {kept / frames:.2f} detections with score >= {t:g} per keyframe",
            )
        )
    return out


def _raised(learnt: float, floor: float) -> str:
    """The comment saying a learnt value below the base configuration's was raised to it (module docstring)."""
    return f"; {learnt:.3g} raised to the base's {floor:g}" if learnt < floor else ""


def process_noise(cls: str, velocity_change_mps: np.ndarray, base: TrackerConfig) -> list[Learnt]:
    """q_x, q_y of the constant-velocity model (``ClassParams``; Q = diag(q_x, q_y, q_x, q_y) per keyframe): the
    variance of the annotations' velocity change from one keyframe to the next (``box.noise``: dv (N, 3), x y z),
    the white-acceleration model's velocity noise per step (Bar-Shalom, Li & Kirubarajan 2001, sec. 6.2), never
    below the base configuration's: parked and cruising objects make most changes ~0, while the changes that
    matter, a cyclist braking or turning while missed, are the tails a Gaussian fitted to all of them
    under-states (a smaller Q loses such an object's track: ``config.TWO_WHEELER_Q``). Nothing below
    ``MIN_SAMPLES`` changes."""
    dv = velocity_change_mps[:, :2]
    dv = dv[np.isfinite(dv).all(axis=1)]
    if len(dv) < MIN_SAMPLES:
        return []
    own = base.classes[cls]
    out = []
    for axis, v, floor in zip("xy", np.var(dv, axis=0).tolist(), (own.q_x, own.q_y), strict=True):
        source = f"variance of the annotated velocity change per keyframe ((m/s)^2), {len(dv)} changes"
        source += _raised(v, floor)
        out.append(Learnt(f"classes.{cls}", f"q_{axis}", max(v, floor), source))
    return out


def curves(s: ClassSamples, threshold: float) -> list[str]:
    """Comment lines: how many annotated objects and boxes the values rest on, P_D per range bin, precision and
    clutter per score bin."""
    lines = [f"learnt from {s.objects} annotated objects ({len(s.gt_range_m)} boxes the evaluation counts)"]
    cells = []
    for lo, hi in zip(RANGE_BINS_M[:-1], RANGE_BINS_M[1:], strict=True):
        in_bin = (s.gt_range_m >= lo) & (s.gt_range_m < hi)
        if in_bin.any():
            cells.append(f"{lo:g}-{hi:g} m {np.mean(s.gt_best_score[in_bin] >= threshold):.2f} ({in_bin.sum()})")
    if cells:
        lines.append("P_D by range: " + ", ".join(cells))
    cells = []
    for lo, hi in zip(SCORE_BINS[:-1], SCORE_BINS[1:], strict=True):
        n_true = int(np.sum((s.matched_score >= lo) & (s.matched_score < hi)))
        n_false = int(np.sum((s.clutter_score >= lo) & (s.clutter_score < hi)))
        if n_true + n_false:
            cells.append(f"{lo:.1f}-{hi:.1f} {n_true}/{n_true + n_false}")
    if cells:
        lines.append("true/all detections by score: " + ", ".join(cells))
    return lines


def calibrate(
    scenes: Sequence[SceneData],
    detections: Sequence[Mapping[str, Boxes]],
    base: TrackerConfig,
    class_range_m: Mapping[str, float],
    match_distance_m: float,
) -> tuple[dict[str, list[Learnt]], dict[str, list[str]], TrackerConfig]:
    """Per class, the learnt values and comment lines; and ``base`` with ``prob3dmot``'s box noise learnt."""
    samples = collect(scenes, detections, class_range_m, match_distance_m)
    box = collect_samples(scenes, detections, TRACKING_CLASSES)
    learnt = {c: process_noise(c, box[c].dv, base) + learn_class(c, samples[c], base) for c in TRACKING_CLASSES}
    notes = {}
    for c in TRACKING_CLASSES:
        t = next((v.value for v in learnt[c] if v.key == "score_threshold"), None)
        notes[c] = curves(samples[c], base.resolved(c).preprocess.score_threshold if t is None else t)
    noise = {c: noise_from_samples(box[c], base.box_noise[c]) for c in TRACKING_CLASSES}
    return learnt, notes, dataclasses.replace(base, box_noise=noise)


_BOX_NOISE_SOURCE = {
    "r": "variance of detection - annotation (Hungarian pairs within 2 m)",
    "q": "variance of the annotations' second differences (velocity changes for q_v*; 0 for the size)",
    "p": "variance of the detection error's change per second (p_v*), or the initial-covariance scale (p_scale)",
}
"""What each ``BoxNoise`` value is learnt from, by the first part of its name (``gnnpmb.box.noise``)."""


def calibration_toml(
    learnt: Mapping[str, list[Learnt]],
    notes: Mapping[str, list[str]],
    with_box_noise: TrackerConfig,
    header: str,
    withheld: Mapping[str, list[Learnt]] | None = None,
) -> str:
    """The parameter file: ``header`` (comment lines), then per class its tables with a comment per value and the
    ``withheld`` values (learnt, not written: ``calibration_check``) as comment lines, then ``prob3dmot``'s
    ``[box_noise.<class>]`` tables."""
    lines = [f"# {line}" for line in header.splitlines()]
    for cls in TRACKING_CLASSES:
        tables: dict[str, list[Learnt]] = defaultdict(list)
        for item in learnt[cls]:
            tables[item.table].append(item)
        lines.append("")
        lines.extend(f"# {cls}: {note}" for note in notes[cls])
        kept_back = (withheld or {}).get(cls, [])
        lines.extend(f"# not written: [{i.table}] {i.key} = {i.value!r}  ({i.source})" for i in kept_back)
        for table, items in sorted(tables.items(), key=lambda kv: kv[0].count(".")):
            lines.append(f"[{table}]")
            lines.extend(f"{i.key} = {i.value!r}  # {i.source}" for i in items)
    lines.append("")
    lines.append(
        "# prob3dmot's box Kalman noise (gnnpmb.box.noise); a statistic over fewer than 10 samples keeps "
        "Probabilistic 3D MOT's published nuScenes value"
    )
    for cls in TRACKING_CLASSES:
        lines.append(f"[box_noise.{cls}]")
        lines.extend(
            f"{k} = {v!r}  # {_BOX_NOISE_SOURCE[k.split('_')[0]]}"
            for k, v in dataclasses.asdict(with_box_noise.box_noise[cls]).items()
        )
    return "\n".join(lines) + "\n"
