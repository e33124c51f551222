"""A simulated 3D object detector: boxes derived from ground truth, for scenes without real detections.

Three presets roughly follow the published nuScenes detectors the paper tracks with: CenterPoint (best: high
recall, small noise, well separated scores), Megvii (CBGS) and PointPillars (worst). Per ground-truth box:

- detection probability ``P_D = recall_near · c_class · f_range(d) · f_vis(n)``, with ``d`` the BEV distance
  to the ego, ``f_range(d) = 1 / (1 + exp((d - range_p50_m) / range_width_m))`` and the visibility factor
  ``f_vis(n) = v0 + (1 - v0)(1 - exp(-n / pts_scale))`` of the box's LiDAR+radar point count ``n`` (v0 = 0.02:
  a box without points is almost never detected); ``c_class`` makes small objects harder;
- centre = truth + a persistent per-instance offset + per-frame noise growing with distance; log-normal size
  noise; yaw noise and an occasional heading flip; velocity = truth + noise (the detector regresses velocity);
- score ``~ Beta(tp_score_beta) · (0.35 + 0.65 · f_range · f_vis)``: lower for far and occluded objects;
- sometimes a duplicate: a slightly shifted copy with a lower score, for NMS to remove.

Per frame, a Poisson number of false positives spread uniformly over the disc of radius ``fp_range_m`` around
the ego, classes weighted towards cars and pedestrians, scores ``~ Beta(fp_score_beta)`` (below true ones);
plus, at each clutter hotspot within range, a Poisson number of ghost boxes of a class a tracker could confuse
with the object nearest the hotspot, with higher scores ``~ Beta(hotspot_score_beta)``.

Randomness: each frame draws from its own generator seeded by (seed, scene token, keyframe index), and each
instance's persistent offset from (seed, scene token, instance token), so one frame's draws never depend on
another frame. Boxes of a frame are returned sorted by score, highest first, like a real detector's output.
"""

from __future__ import annotations

import hashlib
from collections.abc import Collection, Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from gnnpmb.data.boxes3d import quat_wxyz_from_yaw, yaw_from_quat_wxyz
from gnnpmb.data.scene import Keyframe, SceneData
from gnnpmb.errors import UnknownNameError
from gnnpmb.types import Boxes


@dataclass(frozen=True, slots=True)
class DetectorPreset:
    """Quality parameters of a simulated detector (see the module docstring for the model).

    Noise standard deviations are per axis, for a car at the ego; other classes scale them by
    ``CLASS_NOISE_SCALE`` and per-frame noise grows by (1 + d / 50 m). Beta parameters are (a, b).
    """

    name: str
    recall_near: float
    range_p50_m: float
    range_width_m: float
    pts_scale: float
    pos_bias_std_m: float
    pos_noise_std_m: float
    z_noise_std_m: float
    size_noise_rel: float
    yaw_noise_std_rad: float
    yaw_flip_prob: float
    vel_noise_std_mps: float
    fp_rate: float
    fp_range_m: float
    hotspot_rate: float
    dup_prob: float
    dup_shift_rel: float
    tp_score_beta: tuple[float, float]
    fp_score_beta: tuple[float, float]
    hotspot_score_beta: tuple[float, float]


PRESETS: dict[str, DetectorPreset] = {
    "centerpoint": DetectorPreset(
        name="centerpoint",
        recall_near=0.97,
        range_p50_m=62.0,
        range_width_m=6.0,
        pts_scale=4.0,
        pos_bias_std_m=0.08,
        pos_noise_std_m=0.15,
        z_noise_std_m=0.08,
        size_noise_rel=0.05,
        yaw_noise_std_rad=0.05,
        yaw_flip_prob=0.01,
        vel_noise_std_mps=0.3,
        fp_rate=30.0,
        fp_range_m=54.0,
        hotspot_rate=1.0,
        dup_prob=0.10,
        dup_shift_rel=0.10,
        tp_score_beta=(8.0, 2.0),
        fp_score_beta=(1.2, 8.0),
        hotspot_score_beta=(3.0, 5.0),
    ),
    "megvii": DetectorPreset(
        name="megvii",
        recall_near=0.93,
        range_p50_m=55.0,
        range_width_m=7.0,
        pts_scale=6.0,
        pos_bias_std_m=0.12,
        pos_noise_std_m=0.22,
        z_noise_std_m=0.12,
        size_noise_rel=0.07,
        yaw_noise_std_rad=0.08,
        yaw_flip_prob=0.03,
        vel_noise_std_mps=0.5,
        fp_rate=45.0,
        fp_range_m=54.0,
        hotspot_rate=1.5,
        dup_prob=0.15,
        dup_shift_rel=0.12,
        tp_score_beta=(6.0, 2.5),
        fp_score_beta=(1.3, 6.5),
        hotspot_score_beta=(3.0, 4.5),
    ),
    "pointpillars": DetectorPreset(
        name="pointpillars",
        recall_near=0.88,
        range_p50_m=45.0,
        range_width_m=8.0,
        pts_scale=10.0,
        pos_bias_std_m=0.18,
        pos_noise_std_m=0.32,
        z_noise_std_m=0.18,
        size_noise_rel=0.10,
        yaw_noise_std_rad=0.15,
        yaw_flip_prob=0.08,
        vel_noise_std_mps=0.9,
        fp_rate=60.0,
        fp_range_m=54.0,
        hotspot_rate=2.0,
        dup_prob=0.25,
        dup_shift_rel=0.15,
        tp_score_beta=(4.0, 3.0),
        fp_score_beta=(1.5, 5.5),
        hotspot_score_beta=(3.0, 4.0),
    ),
}
"""The three detector presets by CLI name, best first."""

CLASS_RECALL: dict[str, float] = {
    "car": 1.0,
    "bus": 0.95,
    "truck": 0.90,
    "trailer": 0.80,
    "pedestrian": 0.92,
    "motorcycle": 0.85,
    "bicycle": 0.75,
}
"""Per-class factor ``c_class`` on the detection probability (small, thin objects are harder)."""

CLASS_NOISE_SCALE: dict[str, float] = {
    "car": 1.0,
    "truck": 1.5,
    "bus": 1.6,
    "trailer": 1.8,
    "pedestrian": 0.5,
    "bicycle": 0.6,
    "motorcycle": 0.7,
}
"""Per-class factor on position noise (ordered like the paper's per-class measurement noise R)."""

TYPICAL_SIZE_WLH_M: dict[str, tuple[float, float, float]] = {
    "car": (1.95, 4.6, 1.7),
    "truck": (2.5, 6.9, 2.9),
    "bus": (2.95, 11.0, 3.5),
    "trailer": (2.9, 12.3, 3.9),
    "pedestrian": (0.67, 0.73, 1.77),
    "bicycle": (0.6, 1.7, 1.3),
    "motorcycle": (0.77, 2.1, 1.5),
}
"""Mean box size (w, l, h) of each class on nuScenes, for false positives."""

FP_CLASS_WEIGHTS: dict[str, float] = {
    "car": 0.42,
    "pedestrian": 0.30,
    "truck": 0.08,
    "trailer": 0.04,
    "bus": 0.03,
    "bicycle": 0.07,
    "motorcycle": 0.06,
}
"""Class mix of false positives."""

CONFUSABLE: dict[str, tuple[str, ...]] = {
    "car": ("car", "truck"),
    "truck": ("truck", "bus", "trailer"),
    "bus": ("bus", "truck"),
    "trailer": ("trailer", "truck"),
    "pedestrian": ("pedestrian",),
    "bicycle": ("bicycle", "motorcycle"),
    "motorcycle": ("motorcycle", "bicycle"),
}
"""Classes a ghost box near an object of the key class is drawn from (the first with probability 0.75)."""

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


def get_preset(preset: str | DetectorPreset) -> DetectorPreset:
    """The preset itself, or the one named ``preset``; an unknown name raises ``UnknownNameError``."""
    if isinstance(preset, DetectorPreset):
        return preset
    try:
        return PRESETS[preset]
    except KeyError:
        raise UnknownNameError(f"unknown detector preset '{preset}' (choose one of: {', '.join(PRESETS)})") from None


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


def _class_table(table: Mapping[str, float], names: np.ndarray) -> np.ndarray:
    return np.array([table[str(c)] for c in names], dtype=float)


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


def _true_detections(
    kf: Keyframe, p: DetectorPreset, rng: np.random.Generator, offsets: np.ndarray
) -> tuple[Boxes, Boxes]:
    """Detections of ground-truth boxes and their duplicates. Every draw is made for every GT box, whatever
    happens to it, so the stream of draws does not depend on earlier outcomes."""
    gt = kf.gt
    n = len(gt)
    classes = gt.class_name
    dist = np.hypot(*(gt.xy - kf.ego_pose.translation_m[:2]).T) if n else np.zeros(0)
    f_range = 1.0 / (1.0 + np.exp((dist - p.range_p50_m) / p.range_width_m))
    f_vis = _VIS_FLOOR + (1.0 - _VIS_FLOOR) * (1.0 - np.exp(-np.asarray(kf.gt_num_pts, float) / p.pts_scale))
    p_detect = p.recall_near * _class_table(CLASS_RECALL, classes) * f_range * f_vis

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

    noise_scale = _class_table(CLASS_NOISE_SCALE, classes)
    xy_std = noise_scale * p.pos_noise_std_m * (1.0 + dist / _NOISE_RANGE_M)
    translation = gt.translation_m.astype(float).copy()
    translation[:, :2] += noise_scale[:, None] * p.pos_bias_std_m * offsets[:, :2] + xy_std[:, None] * pos_noise
    translation[:, 2] += noise_scale * p.z_noise_std_m * (offsets[:, 2] + z_noise)
    size = gt.size_wlh_m * np.exp(p.size_noise_rel * size_noise)
    yaw = yaw_from_quat_wxyz(gt.quat_wxyz) + p.yaw_noise_std_rad * yaw_noise + np.pi * (u_flip < p.yaw_flip_prob)
    velocity = np.nan_to_num(gt.velocity_mps.astype(float)) + p.vel_noise_std_mps * vel_noise
    score = score_beta * (_SCORE_FLOOR + (1.0 - _SCORE_FLOOR) * f_range * f_vis)

    detected = u_detect < p_detect
    dup = detected & (u_dup < p.dup_prob)
    shift = p.dup_shift_rel * np.minimum(size[:, 0], size[:, 1])[:, None] * dup_shift
    dup_translation = translation.copy()
    dup_translation[:, :2] += shift
    true_boxes = _make_boxes(translation, size, yaw, velocity, score, classes).subset(np.flatnonzero(detected))
    dup_boxes = _make_boxes(
        dup_translation,
        size * np.exp(0.5 * p.size_noise_rel * dup_size),
        yaw,
        velocity,
        score * dup_score,
        classes,
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
    names = list(FP_CLASS_WEIGHTS)
    weights = np.array([FP_CLASS_WEIGHTS[c] for c in names])
    count = int(rng.poisson(p.fp_rate))
    classes = np.array(names, dtype=object)[rng.choice(len(names), size=count, p=weights / weights.sum())]
    score = rng.beta(*p.fp_score_beta, size=count)
    ego_xy = kf.ego_pose.translation_m[:2]
    return _clutter(rng, count, ego_xy, p.fp_range_m, classes, score, _ground_z(kf), p.size_noise_rel)


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


def simulate_frame(
    kf: Keyframe,
    preset: DetectorPreset,
    rng: np.random.Generator,
    offsets: np.ndarray,
    hotspots: Sequence[Hotspot] = (),
) -> Boxes:
    """Detections of one keyframe, sorted by score (highest first; ties keep generation order).

    offsets: (N, 3) standard-normal persistent offsets of the keyframe's N GT boxes.
    """
    true_boxes, dup_boxes = _true_detections(kf, preset, rng, offsets)
    fp_boxes = _false_positives(kf, preset, rng)
    hot_boxes = _hotspot_clutter(kf, preset, rng, hotspots)
    boxes = Boxes.concatenate([true_boxes, dup_boxes, fp_boxes, hot_boxes])
    return boxes.subset(np.argsort(-boxes.score, kind="stable"))


def simulate_detections(
    scene: SceneData,
    preset: str | DetectorPreset,
    seed: int = 0,
    hotspots: Sequence[Hotspot] = (),
) -> dict[str, Boxes]:
    """Simulated detections of every keyframe of ``scene``, keyed by sample token, in the global frame.

    hotspots: clutter-prone spots as (xy_global (2,), radius_m) or (xy_global, radius_m, keyframe indices);
    the third element limits a spot to those keyframes. Same inputs give the same output.
    """
    p = get_preset(preset)
    cache: dict[str, np.ndarray] = {}
    out: dict[str, Boxes] = {}
    for kf in scene.keyframes:
        ids = [str(i) for i in kf.gt.instance_id]
        new = sorted({i for i in ids if i not in cache})
        cache.update(zip(new, _instance_offsets(seed, scene.token, new), strict=True))
        offsets = np.array([cache[i] for i in ids]).reshape(len(ids), 3)
        out[kf.sample_token] = simulate_frame(kf, p, _frame_rng(seed, scene.token, kf.index), offsets, hotspots)
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
    meta = {
        "use_camera": False,
        "use_lidar": True,
        "use_radar": False,
        "use_map": False,
        "use_external": False,
    }
    return {"meta": meta, "results": results}
