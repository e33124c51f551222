"""A simulated 3D object detector: boxes derived from ground truth, for scenes without real detections.

Three presets (``gnnpmb/data/simdet_presets.py``) are fitted to the published nuScenes figures (val mAP, NDS
and TP errors; test per-class AP) of the detectors the paper tracks with: CenterPoint (best), Megvii (CBGS) and
PointPillars (worst); see ``benchmarks/detector_calibration.py``. Per ground-truth box:

- detection probability ``P_D = recall_near · c_class · f_range(d) · f_vis(n)``, with ``d`` the BEV distance
  to the ego, ``f_range(d) = 1 / (1 + exp((d - range_p50_m) / range_width_m))`` and the visibility factor
  ``f_vis(n) = v0 + (1 - v0)(1 - exp(-n / pts_scale))`` of the box's LiDAR+radar point count ``n`` (v0 = 0.02:
  a box without points, i.e. fully occluded, is almost never detected); ``c_class`` (the preset's
  ``class_recall``) sets each class's recall;
- centre = truth + a persistent per-instance offset + per-frame noise growing with distance; log-normal size
  noise; yaw noise and a heading flip (by pi) with a per-class probability; velocity = truth + noise growing
  with distance (the detector regresses velocity);
- score ``~ Beta(tp_score_beta) · (0.35 + 0.65 · f_range · f_vis)``: lower for far and occluded objects;
- class confusion: with probability ``confusion_scale · confusion_prob(class)`` the detection keeps the true
  object's box but is labelled as a confusable class (truck <-> car/bus/trailer, bicycle <-> motorcycle), with
  0.75 of its score;
- sometimes a duplicate: a slightly shifted copy with a lower score, for NMS to remove.

Per frame, a Poisson number of false positives spread uniformly over the disc of radius ``fp_range_m`` around
the ego, classes weighted towards cars and pedestrians, scores ``~ Beta(fp_score_beta)``, except a fraction
``fp_high_score_frac`` scored like true detections (scores overlap); at each clutter hotspot within range, a
Poisson number of ghost boxes of a class a tracker could confuse with the object nearest the hotspot, scores
``~ Beta(hotspot_score_beta)``. Per scene, persistent false positives ("ghosts"): fixed world places, a
Poisson number over the area the ego sees (``ghost_rate`` within range on average), each with its own class,
box and stable score ``~ Beta(ghost_score_beta)``; a ghost within ``fp_range_m`` of the ego is reported in a
frame with probability ``ghost_presence``, with small jitter, like a real detector's repeated false alarm.

Detector realism (``DetectorPreset.realism``, off in the calibrated presets, on in the named variants
``"<preset>+runs"``, ``+near``, ``+tails``, ``+real``; ``simdet_presets.DetectorRealism``): a latent per-object
hardness, an AR(1) sequence over keyframes, lowers the detection probability's logit and the score (misses in
runs, low scores for several frames); false boxes beside true objects; heavy-tailed velocity errors.

Randomness: each frame draws from its own generator seeded by (seed, scene token, keyframe index), each
instance's persistent offset and hardness sequence from (seed, scene token, instance token) and the scene's ghost
places from (seed, scene token), so one frame's draws never depend on another frame; the realism options draw
only when on, so with them off a frame's detections are what they always were. Boxes of a frame are returned
sorted by score, highest first, like a real detector's output.
"""

from __future__ import annotations

import dataclasses
import hashlib
from collections.abc import Collection, Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from gnnpmb.data.boxes3d import quat_wxyz_from_yaw, yaw_from_quat_wxyz
from gnnpmb.data.detections import LIDAR_ONLY_META
from gnnpmb.data.scene import Keyframe, SceneData
from gnnpmb.data.simdet_presets import (
    CLASS_MODELS,
    CONFUSABLE,
    FP_CLASS_WEIGHTS,
    PRESETS,
    TYPICAL_SIZE_WLH_M,
    DetectorPreset,
    DetectorRealism,
    get_preset,
)
from gnnpmb.types import Boxes

__all__ = [
    "CONFUSABLE",
    "PRESETS",
    "DetectorPreset",
    "DetectorRealism",
    "GhostSites",
    "Hotspot",
    "get_preset",
    "scene_ghosts",
    "simulate_detections",
    "simulate_frame",
    "to_submission",
]

Hotspot = tuple[np.ndarray, float] | tuple[np.ndarray, float, Collection[int]]
"""A clutter-prone spot: (xy_global (2,), radius_m), optionally with the keyframe indices it is active in."""

_VIS_FLOOR = 0.02
_SCORE_FLOOR = 0.35
_NOISE_RANGE_M = 50.0
_HOTSPOT_CLASS_REACH_M = 10.0
_DEFAULT_HOTSPOT_CLASSES = ("truck", "bus")
_FP_SPEED_STD_MPS = 0.5
_TAG_FRAME = 1
_TAG_INSTANCE = 2
_TAG_GHOST = 3
_TAG_HARDNESS = 4
_NEAR_FP_SCORE_FACTOR = 0.8
_CONFUSED_SCORE_FACTOR = 0.75
_HIGH_FP_SCORE_FACTOR = 0.8
_GHOST_JITTER_M = 0.1
_GHOST_SCORE_JITTER = 0.03
_SCORE_MIN, _SCORE_MAX = 1e-3, 0.999


@dataclass(frozen=True, slots=True)
class GhostSites:
    """Persistent false positives of one scene: K fixed world places.

    xy_global: (K, 2); yaw_rad: (K,); size_wlh_m: (K, 3); class_name: (K,); score: (K,) stable base scores.
    """

    xy_global: np.ndarray
    yaw_rad: np.ndarray
    size_wlh_m: np.ndarray
    class_name: np.ndarray
    score: np.ndarray

    def __len__(self) -> int:
        return int(self.xy_global.shape[0])

    @staticmethod
    def none() -> GhostSites:
        return GhostSites(np.zeros((0, 2)), np.zeros(0), np.zeros((0, 3)), np.zeros(0, dtype=object), np.zeros(0))


def _hash64(text: str) -> int:
    return int.from_bytes(hashlib.blake2b(text.encode(), digest_size=8).digest(), "little")


def _frame_rng(seed: int, scene_token: str, frame_index: int) -> np.random.Generator:
    return np.random.default_rng(np.random.SeedSequence([seed, _TAG_FRAME, _hash64(scene_token), frame_index]))


def _instance_offsets(seed: int, scene_token: str, instance_ids: Sequence[str]) -> np.ndarray:
    """(N, 3) standard-normal persistent offsets, one per instance token (same token, same row)."""
    out = np.empty((len(instance_ids), 3))
    for k, token in enumerate(instance_ids):
        seq = np.random.SeedSequence([seed, _TAG_INSTANCE, _hash64(scene_token), _hash64(token)])
        out[k] = np.random.default_rng(seq).standard_normal(3)
    return out


def _instance_hardness(
    seed: int, scene_token: str, instance_ids: Sequence[str], n_frames: int, corr: float
) -> np.ndarray:
    """(N, n_frames) stationary AR(1) sequences a_t = corr a_{t-1} + sqrt(1 - corr^2) e_t, a_0 ~ N(0, 1), one per
    instance token (the same token gives the same row)."""
    out = np.empty((len(instance_ids), n_frames))
    innovation_std = np.sqrt(1.0 - corr**2)
    for k, token in enumerate(instance_ids):
        seq = np.random.SeedSequence([seed, _TAG_HARDNESS, _hash64(scene_token), _hash64(token)])
        e = np.random.default_rng(seq).standard_normal(n_frames)
        a = np.empty(n_frames)
        a[0] = e[0]
        for t in range(1, n_frames):
            a[t] = corr * a[t - 1] + innovation_std * e[t]
        out[k] = a
    return out


def _class_field(field: str, names: np.ndarray) -> np.ndarray:
    return np.array([getattr(CLASS_MODELS[str(c)], field) for c in names], dtype=float)


def _fp_classes(rng: np.random.Generator, count: int) -> np.ndarray:
    names = list(FP_CLASS_WEIGHTS)
    weights = np.array([FP_CLASS_WEIGHTS[c] for c in names])
    return np.array(names, dtype=object)[rng.choice(len(names), size=count, p=weights / weights.sum())]


def scene_ghosts(scene: SceneData, preset: str | DetectorPreset, seed: int = 0) -> GhostSites:
    """The persistent false positives of ``scene``: a Poisson number of places, uniform over the ego path's
    bounding box grown by ``fp_range_m``, at density ``ghost_rate / (pi fp_range_m^2)``."""
    p = get_preset(preset)
    if p.ghost_rate <= 0.0 or not scene.keyframes:
        return GhostSites.none()
    rng = np.random.default_rng(np.random.SeedSequence([seed, _TAG_GHOST, _hash64(scene.token)]))
    ego_xy = np.array([k.ego_pose.translation_m[:2] for k in scene.keyframes], dtype=float)
    lo, hi = ego_xy.min(axis=0) - p.fp_range_m, ego_xy.max(axis=0) + p.fp_range_m
    area_m2 = float(np.prod(hi - lo))
    count = int(rng.poisson(p.ghost_rate * area_m2 / (np.pi * p.fp_range_m**2)))
    xy = lo + (hi - lo) * rng.random((count, 2))
    yaw = rng.uniform(-np.pi, np.pi, count)
    classes = _fp_classes(rng, count)
    size = np.array([TYPICAL_SIZE_WLH_M[c] for c in classes], dtype=float).reshape(count, 3)
    size = size * np.exp(p.size_noise_rel * rng.standard_normal((count, 3)))
    score = rng.beta(*p.ghost_score_beta, size=count)
    return GhostSites(xy, yaw, size, classes, score)


def _make_boxes(
    translation: np.ndarray,
    size: np.ndarray,
    yaw: np.ndarray,
    velocity: np.ndarray,
    score: np.ndarray,
    class_name: np.ndarray,
) -> Boxes:
    n = translation.shape[0]
    return Boxes(
        translation_m=translation.reshape(n, 3),
        size_wlh_m=size.reshape(n, 3),
        quat_wxyz=quat_wxyz_from_yaw(yaw).reshape(n, 4),
        velocity_mps=velocity.reshape(n, 2),
        score=score.reshape(n),
        class_name=np.asarray(class_name, dtype=object).reshape(n),
        instance_id=np.full(n, "", dtype=object),
    )


def _confused_classes(
    classes: np.ndarray, p: DetectorPreset, u_confuse: np.ndarray, u_target: np.ndarray
) -> np.ndarray:
    """(N,) reported class names: a confusable class where ``u_confuse`` falls below the class's confusion
    probability (picked by ``u_target`` among ``confused_with``), else the true class."""
    out = classes.astype(object).copy()
    for k, name in enumerate(classes):
        model = CLASS_MODELS[str(name)]
        if model.confused_with and u_confuse[k] < p.confusion_scale * model.confusion_prob:
            options = model.confused_with
            out[k] = options[min(int(u_target[k] * len(options)), len(options) - 1)]
    return out


def _true_detections(
    kf: Keyframe, p: DetectorPreset, rng: np.random.Generator, offsets: np.ndarray, hardness: np.ndarray | None
) -> tuple[Boxes, Boxes]:
    """Detections of ground-truth boxes and their duplicates. Every draw is made for every GT box, whatever
    happens to it, so the stream of draws does not depend on earlier outcomes. ``hardness``: (N,) the objects'
    latent hardness this keyframe (None: realism off)."""
    gt = kf.gt
    n = len(gt)
    classes = gt.class_name
    dist = np.hypot(*(gt.xy - kf.ego_pose.translation_m[:2]).T) if n else np.zeros(0)
    f_range = 1.0 / (1.0 + np.exp((dist - p.range_p50_m) / p.range_width_m))
    f_vis = _VIS_FLOOR + (1.0 - _VIS_FLOOR) * (1.0 - np.exp(-np.asarray(kf.gt_num_pts, float) / p.pts_scale))
    c_class = np.array([p.class_recall[str(c)] for c in classes], dtype=float)
    p_detect = p.recall_near * c_class * f_range * f_vis

    u_detect = rng.random(n)
    pos_noise = rng.standard_normal((n, 2))
    z_noise = rng.standard_normal(n)
    size_noise = rng.standard_normal((n, 3))
    yaw_noise = rng.standard_normal(n)
    u_flip = rng.random(n)
    vel_noise = rng.standard_normal((n, 2))
    score_beta = rng.beta(*p.tp_score_beta, size=n)
    u_dup = rng.random(n)
    dup_shift = rng.standard_normal((n, 2))
    dup_size = rng.standard_normal((n, 3))
    dup_score = rng.uniform(0.3, 0.9, size=n)
    u_confuse = rng.random(n)
    u_target = rng.random(n)
    real = p.realism
    if hardness is not None and real.hardness_std_logit > 0.0:
        logit = np.log(np.clip(p_detect, 1e-6, 1 - 1e-6)) - np.log1p(-np.clip(p_detect, 1e-6, 1 - 1e-6))
        p_detect = 1.0 / (1.0 + np.exp(-(logit - real.hardness_std_logit * hardness)))
    if real.velocity_outlier_prob > 0.0:
        outlier = rng.random(n) < real.velocity_outlier_prob
        vel_noise = vel_noise * np.where(outlier, real.velocity_outlier_scale, 1.0)[:, None]

    noise_scale = _class_field("noise_scale", classes)
    range_growth = 1.0 + dist / _NOISE_RANGE_M
    xy_std = noise_scale * p.pos_noise_std_m * range_growth
    translation = gt.translation_m.astype(float).copy()
    translation[:, :2] += noise_scale[:, None] * p.pos_bias_std_m * offsets[:, :2] + xy_std[:, None] * pos_noise
    translation[:, 2] += noise_scale * p.z_noise_std_m * (offsets[:, 2] + z_noise)
    size = gt.size_wlh_m * np.exp(p.size_noise_rel * size_noise)
    flip = u_flip < p.yaw_flip_prob * _class_field("flip_scale", classes)
    yaw_std = p.yaw_noise_std_rad * _class_field("yaw_noise_scale", classes)
    yaw = yaw_from_quat_wxyz(gt.quat_wxyz) + yaw_std * yaw_noise + np.pi * flip
    velocity = np.nan_to_num(gt.velocity_mps.astype(float)) + (p.vel_noise_std_mps * range_growth)[:, None] * vel_noise
    score = score_beta * (_SCORE_FLOOR + (1.0 - _SCORE_FLOOR) * f_range * f_vis)
    if hardness is not None and real.score_hardness > 0.0:
        score = np.clip(score * np.exp(-real.score_hardness * hardness), _SCORE_MIN, _SCORE_MAX)
    reported = _confused_classes(classes, p, u_confuse, u_target)
    score = np.where(reported != classes, _CONFUSED_SCORE_FACTOR * score, score)

    detected = u_detect < p_detect
    dup = detected & (u_dup < p.dup_prob)
    shift = p.dup_shift_rel * np.minimum(size[:, 0], size[:, 1])[:, None] * dup_shift
    dup_translation = translation.copy()
    dup_translation[:, :2] += shift
    true_boxes = _make_boxes(translation, size, yaw, velocity, score, reported).subset(np.flatnonzero(detected))
    dup_boxes = _make_boxes(
        dup_translation,
        size * np.exp(0.5 * p.size_noise_rel * dup_size),
        yaw,
        velocity,
        score * dup_score,
        reported,
    ).subset(np.flatnonzero(dup))
    return true_boxes, dup_boxes


def _ground_z(kf: Keyframe) -> float:
    """Height of the ground under the ego: the median bottom of the GT boxes, else the ego's height."""
    if len(kf.gt):
        return float(np.median(kf.gt.translation_m[:, 2] - 0.5 * kf.gt.size_wlh_m[:, 2]))
    return float(kf.ego_pose.translation_m[2])


def _clutter(
    rng: np.random.Generator,
    count: int,
    centre_xy: np.ndarray,
    radius_m: float,
    classes: np.ndarray,
    score: np.ndarray,
    ground_z: float,
    size_noise_rel: float,
) -> Boxes:
    """``count`` false boxes of the given classes spread uniformly over a disc."""
    r = radius_m * np.sqrt(rng.random(count))
    phi = rng.uniform(-np.pi, np.pi, count)
    yaw = rng.uniform(-np.pi, np.pi, count)
    size = np.array([TYPICAL_SIZE_WLH_M[c] for c in classes], dtype=float).reshape(count, 3)
    size = size * np.exp(2.0 * size_noise_rel * rng.standard_normal((count, 3)))
    translation = np.column_stack(
        [centre_xy[0] + r * np.cos(phi), centre_xy[1] + r * np.sin(phi), ground_z + 0.5 * size[:, 2]]
    )
    velocity = _FP_SPEED_STD_MPS * rng.standard_normal((count, 2))
    return _make_boxes(translation, size, yaw, velocity, score, classes)


def _false_positives(kf: Keyframe, p: DetectorPreset, rng: np.random.Generator) -> Boxes:
    """Random false positives around the ego; a fraction ``fp_high_score_frac`` scored like true detections."""
    count = int(rng.poisson(p.fp_rate))
    classes = _fp_classes(rng, count)
    score = rng.beta(*p.fp_score_beta, size=count)
    ego_xy = kf.ego_pose.translation_m[:2]
    boxes = _clutter(rng, count, ego_xy, p.fp_range_m, classes, score, _ground_z(kf), p.size_noise_rel)
    high = rng.random(count) < p.fp_high_score_frac
    high_score = _HIGH_FP_SCORE_FACTOR * rng.beta(*p.tp_score_beta, size=count)
    return dataclasses.replace(boxes, score=np.where(high, high_score, boxes.score))


def _ghost_detections(kf: Keyframe, p: DetectorPreset, rng: np.random.Generator, ghosts: GhostSites) -> Boxes:
    """The persistent false positives within ``fp_range_m`` of the ego reported in this frame. Draws are made for
    every site of the scene, in range or not."""
    k = len(ghosts)
    u_present = rng.random(k)
    jitter = rng.standard_normal((k, 2))
    score_jitter = rng.standard_normal(k)
    vel_noise = rng.standard_normal((k, 2))
    in_range = np.hypot(*(ghosts.xy_global - kf.ego_pose.translation_m[:2]).T) <= p.fp_range_m
    shown = np.flatnonzero(in_range & (u_present < p.ghost_presence))
    translation = np.column_stack(
        [ghosts.xy_global + _GHOST_JITTER_M * jitter, _ground_z(kf) + 0.5 * ghosts.size_wlh_m[:, 2]]
    )
    score = np.clip(ghosts.score + _GHOST_SCORE_JITTER * score_jitter, _SCORE_MIN, _SCORE_MAX)
    velocity = p.vel_noise_std_mps * vel_noise
    boxes = _make_boxes(translation, ghosts.size_wlh_m, ghosts.yaw_rad, velocity, score, ghosts.class_name)
    return boxes.subset(shown)


def _hotspot_clutter(kf: Keyframe, p: DetectorPreset, rng: np.random.Generator, hotspots: Sequence[Hotspot]) -> Boxes:
    """Ghost boxes at clutter-prone spots in range, of a class confusable with the object nearest the spot."""
    parts = []
    ego_xy = kf.ego_pose.translation_m[:2]
    for spot in hotspots:
        centre, radius = np.asarray(spot[0], dtype=float)[:2], float(spot[1])
        if len(spot) > 2 and kf.index not in spot[2]:
            continue
        if np.hypot(*(centre - ego_xy)) > p.fp_range_m + radius:
            continue
        count = int(rng.poisson(p.hotspot_rate))
        near_class = None
        if len(kf.gt):
            d = np.hypot(*(kf.gt.xy - centre).T)
            k = int(np.argmin(d))
            if d[k] <= radius + _HOTSPOT_CLASS_REACH_M:
                near_class = str(kf.gt.class_name[k])
        if near_class is None:
            options = _DEFAULT_HOTSPOT_CLASSES
            probs = np.full(len(options), 1.0 / len(options))
        elif len(CONFUSABLE[near_class]) == 1:
            options, probs = CONFUSABLE[near_class], np.ones(1)
        else:
            options = CONFUSABLE[near_class]
            probs = np.full(len(options), 0.25 / (len(options) - 1))
            probs[0] = 0.75
        classes = np.array(options, dtype=object)[rng.choice(len(options), size=count, p=probs)]
        score = rng.beta(*p.hotspot_score_beta, size=count)
        parts.append(_clutter(rng, count, centre, radius, classes, score, _ground_z(kf), p.size_noise_rel))
    return Boxes.concatenate(parts)


def _near_object_fps(kf: Keyframe, p: DetectorPreset, rng: np.random.Generator) -> Boxes:
    """False boxes beside true objects (``DetectorRealism.near_fp_prob``): along the heading of a vehicle, one to
    one and a half lengths from its centre (a split-off box), beside a pedestrian or cyclist one to two widths
    away; of the object's class, its size, score ~ 0.8 Beta(hotspot_score_beta). Draws for every GT box."""
    gt, n = kf.gt, len(kf.gt)
    u = rng.random(n)
    side = rng.choice([-1.0, 1.0], size=n)
    reach = rng.uniform(1.0, 1.5, size=n)
    score = _NEAR_FP_SCORE_FACTOR * rng.beta(*p.hotspot_score_beta, size=n)
    chosen = np.flatnonzero(u < p.realism.near_fp_prob)
    if not len(chosen):
        return Boxes.empty()
    yaw = yaw_from_quat_wxyz(gt.quat_wxyz[chosen])
    classes = gt.class_name[chosen]
    size = gt.size_wlh_m[chosen].astype(float)
    small = np.isin(classes.astype(str), ["pedestrian", "bicycle", "motorcycle"])
    along = np.where(small, 0.0, reach[chosen] * size[:, 1])
    across = np.where(small, 2.0 * reach[chosen] * size[:, 0], 0.0)
    c, s = np.cos(yaw), np.sin(yaw)
    d = side[chosen]
    translation = gt.translation_m[chosen].astype(float).copy()
    translation[:, 0] += d * (along * c - across * s)
    translation[:, 1] += d * (along * s + across * c)
    velocity = np.nan_to_num(gt.velocity_mps[chosen].astype(float))
    return _make_boxes(translation, size, yaw, velocity, score[chosen], classes)


def simulate_frame(
    kf: Keyframe,
    preset: DetectorPreset,
    rng: np.random.Generator,
    offsets: np.ndarray,
    hotspots: Sequence[Hotspot] = (),
    ghosts: GhostSites | None = None,
    hardness: np.ndarray | None = None,
) -> Boxes:
    """Detections of one keyframe, sorted by score (highest first; ties keep generation order).

    offsets: (N, 3) standard-normal persistent offsets of the keyframe's N GT boxes; ghosts: the scene's
    persistent false positives (``scene_ghosts``), none if not given; hardness: (N,) the GT boxes' latent
    hardness this keyframe (``DetectorRealism``; None: not modelled).
    """
    true_boxes, dup_boxes = _true_detections(kf, preset, rng, offsets, hardness)
    fp_boxes = _false_positives(kf, preset, rng)
    hot_boxes = _hotspot_clutter(kf, preset, rng, hotspots)
    ghost_boxes = _ghost_detections(kf, preset, rng, GhostSites.none() if ghosts is None else ghosts)
    parts = [true_boxes, dup_boxes, fp_boxes, hot_boxes, ghost_boxes]
    if preset.realism.near_fp_prob > 0.0:
        parts.append(_near_object_fps(kf, preset, rng))
    boxes = Boxes.concatenate(parts)
    return boxes.subset(np.argsort(-boxes.score, kind="stable"))


def simulate_detections(
    scene: SceneData,
    preset: str | DetectorPreset,
    seed: int = 0,
    hotspots: Sequence[Hotspot] = (),
) -> dict[str, Boxes]:
    """Simulated detections of every keyframe of ``scene``, keyed by sample token, in the global frame.

    hotspots: clutter-prone spots as (xy_global (2,), radius_m) or (xy_global, radius_m, keyframe indices);
    the third element limits a spot to those keyframes. The scene's persistent false positives come from
    ``scene_ghosts(scene, preset, seed)``. Same inputs give the same output.
    """
    p = get_preset(preset)
    ghosts = scene_ghosts(scene, p, seed)
    real = p.realism
    with_hardness = real.hardness_std_logit > 0.0 or real.score_hardness > 0.0
    n_frames = 1 + max((kf.index for kf in scene.keyframes), default=0)
    cache: dict[str, np.ndarray] = {}
    hard_cache: dict[str, np.ndarray] = {}
    out: dict[str, Boxes] = {}
    for kf in scene.keyframes:
        ids = [str(i) for i in kf.gt.instance_id]
        new = sorted({i for i in ids if i not in cache})
        cache.update(zip(new, _instance_offsets(seed, scene.token, new), strict=True))
        offsets = np.array([cache[i] for i in ids]).reshape(len(ids), 3)
        hardness = None
        if with_hardness:
            sequences = _instance_hardness(seed, scene.token, new, n_frames, real.hardness_corr)
            hard_cache.update(zip(new, sequences, strict=True))
            hardness = np.array([hard_cache[i][kf.index] for i in ids], dtype=float)
        rng = _frame_rng(seed, scene.token, kf.index)
        out[kf.sample_token] = simulate_frame(kf, p, rng, offsets, hotspots, ghosts, hardness)
    return out


def _attribute(class_name: str, speed_mps: float) -> str:
    """A plausible nuScenes attribute for a box of this class moving at this speed."""
    if class_name == "pedestrian":
        return "pedestrian.moving" if speed_mps > 0.3 else "pedestrian.standing"
    if class_name in ("bicycle", "motorcycle"):
        return "cycle.with_rider" if speed_mps > 0.5 else "cycle.without_rider"
    if class_name in ("car", "bus", "truck", "trailer", "construction_vehicle"):
        return "vehicle.moving" if speed_mps > 0.5 else "vehicle.parked"
    return ""


def to_submission(detections: Mapping[str, Boxes]) -> dict[str, Any]:
    """The nuScenes detection submission (``{"meta": ..., "results": {sample_token: [box, ...]}}``) of
    ``detections``, as written by CenterPoint, Megvii and PointPillars (LiDAR-only meta)."""
    results: dict[str, list[dict[str, Any]]] = {}
    for token, boxes in detections.items():
        speed = np.hypot(boxes.velocity_mps[:, 0], boxes.velocity_mps[:, 1]).tolist()
        names = [str(c) for c in boxes.class_name]
        columns = zip(
            boxes.translation_m.astype(float).tolist(),
            boxes.size_wlh_m.astype(float).tolist(),
            boxes.quat_wxyz.astype(float).tolist(),
            boxes.velocity_mps.astype(float).tolist(),
            names,
            boxes.score.astype(float).tolist(),
            speed,
            strict=True,
        )
        results[token] = [
            {
                "sample_token": token,
                "translation": translation,
                "size": size,
                "rotation": rotation,
                "velocity": velocity,
                "detection_name": name,
                "detection_score": score,
                "attribute_name": _attribute(name, v),
            }
            for translation, size, rotation, velocity, name, score, v in columns
        ]
    return {"meta": dict(LIDAR_ONLY_META), "results": results}
