"""Parameters of the simulated detector (``gnnpmb/data/simdet.py``): the three presets and the per-class tables.

The presets' quality knobs were fitted on the demo ``mini_train`` scenes by ``benchmarks/detector_calibration.py
--fit`` so that the devkit's ``DetectionEval`` of the simulated detections approaches the published nuScenes
figures of the detector each preset is named after: val mATE, mASE, mAOE, mAVE and test per-class AP (the
figures, their splits and sources are in that script). The other knobs are set by hand.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping
from dataclasses import dataclass

from gnnpmb.errors import GnnpmbError, UnknownNameError


@dataclass(frozen=True, slots=True)
class DetectorRealism:
    """Error properties of real detectors that the calibration figures (``DetectionEval``) do not measure: how
    errors are spread over time and where false positives sit. All off (0) in the calibrated presets; the named
    variants (``VARIANTS``, ``"<preset>+<variant>"``) switch some on, so tracker defaults can be chosen to win
    across a family of detector models rather than on one.

    hardness_std_logit: each object has a latent "hardness" a_k, a stationary AR(1) sequence over keyframes
    (standard normal, correlation ``hardness_corr`` from one keyframe to the next); its detection probability's
    logit falls by hardness_std_logit a_k and its score is multiplied by exp(-score_hardness a_k). Misses then
    come in runs and a hard object's detections score low for several frames (real detectors miss the same hard
    object repeatedly: occlusion, sparse points, unusual shape; Hoiem, Chodpathumwan & Dai, "Diagnosing Error in
    Object Detectors", ECCV 2012, sec. 4; Weng et al., AB3DMOT 2020, sec. 4.4, on consecutive misses).
    near_fp_prob: per object and keyframe, the probability of a false box beside it (a box split off a long
    vehicle along its heading, or a neighbour beside a pedestrian or cyclist), of its class, score ~
    Beta(hotspot_score_beta) (most nuScenes false positives of good detectors are localisation and duplicate
    errors next to true objects: Caesar et al., "nuScenes", CVPR 2020, sec. 4.2, and the TIDE breakdown, Bolya et
    al., ECCV 2020). velocity_outlier_prob: the probability that a detection's velocity error is
    ``velocity_outlier_scale`` times its usual spread (heavy tails of regressed velocities, e.g. for objects just
    appearing, which have no motion history in the swept points).
    """

    hardness_std_logit: float = 0.0
    hardness_corr: float = 0.8
    score_hardness: float = 0.0
    near_fp_prob: float = 0.0
    velocity_outlier_prob: float = 0.0
    velocity_outlier_scale: float = 6.0


VARIANTS: dict[str, DetectorRealism] = {
    "runs": DetectorRealism(hardness_std_logit=1.5, score_hardness=0.15),
    "near": DetectorRealism(near_fp_prob=0.04),
    "tails": DetectorRealism(velocity_outlier_prob=0.05),
    "real": DetectorRealism(hardness_std_logit=1.5, score_hardness=0.15, near_fp_prob=0.04, velocity_outlier_prob=0.05),
}
"""The detector-model family: each calibrated preset may be named with one of these (``"pointpillars+runs"``)."""


@dataclass(frozen=True, slots=True)
class DetectorPreset:
    """Quality parameters of a simulated detector (see ``gnnpmb/data/simdet.py`` for the model).

    Noise standard deviations are per axis, for a car at the ego; other classes scale them by their
    ``ClassModel`` and per-frame position and velocity noise grow by (1 + d / 50 m). Beta parameters are (a, b).
    ``class_recall`` is the per-class factor ``c_class`` on the detection probability (fitted per class to the
    published per-class AP); ``confusion_scale`` multiplies every class's confusion probability; ``ghost_rate``
    is the expected number of persistent false positives (fixed world places) within ``fp_range_m`` of the ego,
    each reported in a frame with probability ``ghost_presence``; ``fp_high_score_frac`` of the random false
    positives are scored like true detections (overlapping scores).
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
    confusion_scale: float
    ghost_rate: float
    ghost_presence: float
    ghost_score_beta: tuple[float, float]
    fp_high_score_frac: float
    class_recall: Mapping[str, float]
    realism: DetectorRealism = DetectorRealism()


@dataclass(frozen=True, slots=True)
class ClassModel:
    """How one class fares with every preset.

    noise_scale: factor on position noise (ordered
    like the paper's per-class measurement noise R); yaw_noise_scale and flip_scale: factors on the preset's
    yaw noise and heading-flip probability (small, thin objects have ambiguous headings); confusion_prob:
    probability (times the preset's ``confusion_scale``) that a detection of this class is labelled as one of
    ``confused_with`` (equal odds), keeping the true object's box.
    """

    noise_scale: float
    yaw_noise_scale: float
    flip_scale: float
    confusion_prob: float
    confused_with: tuple[str, ...]


CLASS_MODELS: dict[str, ClassModel] = {
    "car": ClassModel(1.0, 1.0, 1.0, 0.02, ("truck",)),
    "truck": ClassModel(1.5, 1.0, 1.5, 0.12, ("car", "bus", "trailer")),
    "bus": ClassModel(1.6, 0.8, 1.0, 0.10, ("truck",)),
    "trailer": ClassModel(1.8, 2.0, 6.0, 0.12, ("truck",)),
    "pedestrian": ClassModel(0.5, 4.0, 8.0, 0.0, ()),
    "motorcycle": ClassModel(0.7, 2.0, 8.0, 0.10, ("bicycle",)),
    "bicycle": ClassModel(0.6, 3.0, 12.0, 0.12, ("motorcycle",)),
}
"""Per-class factors of the simulated detector, shared by the presets. The orientation factors follow the
pattern of published per-class nuScenes AOE (cars, buses, trucks small; trailers, pedestrians, motorcycles,
bicycles large)."""

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
"""Class mix of false positives (random and persistent)."""

CONFUSABLE: dict[str, tuple[str, ...]] = {
    "car": ("car", "truck"),
    "truck": ("truck", "bus", "trailer"),
    "bus": ("bus", "truck"),
    "trailer": ("trailer", "truck"),
    "pedestrian": ("pedestrian",),
    "bicycle": ("bicycle", "motorcycle"),
    "motorcycle": ("motorcycle", "bicycle"),
}
"""Classes a hotspot ghost box near an object of the key class is drawn from (the first with probability 0.75)."""

_KNOBS: dict[str, tuple[float | tuple[float, float], ...]] = {
    # knob: (centerpoint, megvii, pointpillars)
    "recall_near": (0.99, 0.99, 0.99),
    "range_p50_m": (65.18, 68.8, 77.14),
    "range_width_m": (6.0, 7.0, 7.0),
    "pts_scale": (3.811, 2.996, 4.412),
    "pos_bias_std_m": (0.07192, 0.07918, 0.08849),
    "pos_noise_std_m": (0.1349, 0.1451, 0.1572),
    "z_noise_std_m": (0.08, 0.12, 0.18),
    "size_noise_rel": (0.1359, 0.1369, 0.143),
    "yaw_noise_std_rad": (0.09107, 0.03355, 0.03333),
    "yaw_flip_prob": (0.01822, 0.01257, 0.01779),
    "vel_noise_std_mps": (0.1219, 0.1488, 0.1584),
    "fp_rate": (30.0, 32.78, 19.04),
    "fp_range_m": (54.0, 54.0, 54.0),
    "hotspot_rate": (1.0, 1.5, 2.0),
    "dup_prob": (0.1, 0.15, 0.25),
    "dup_shift_rel": (0.1, 0.12, 0.15),
    "tp_score_beta": ((8.0, 2.0), (6.0, 2.5), (5.0, 2.5)),
    "fp_score_beta": ((1.2, 8.0), (1.3, 6.5), (1.5, 5.5)),
    "hotspot_score_beta": ((3.0, 5.0), (3.0, 4.5), (3.0, 4.0)),
    "confusion_scale": (1.0, 1.5, 2.0),
    "ghost_rate": (2.0, 2.185, 1.904),
    "ghost_presence": (0.7, 0.7, 0.7),
    "ghost_score_beta": ((3.0, 4.0), (3.0, 4.0), (3.0, 4.0)),
    "fp_high_score_frac": (0.03, 0.02914, 0.0238),
}
"""Each preset's quality knobs (``DetectorPreset``), one column per preset of ``PRESETS``."""

_CLASS_RECALL: dict[str, tuple[float, ...]] = {
    # class: (centerpoint, megvii, pointpillars)
    "car": (1.005, 1.005, 1.005),
    "truck": (0.8329, 1.005, 0.8778),
    "bus": (0.9055, 0.9439, 0.7271),
    "trailer": (0.8971, 0.9298, 0.9343),
    "pedestrian": (0.9725, 0.9481, 0.8881),
    "motorcycle": (0.7952, 0.7823, 0.782),
    "bicycle": (0.4425, 0.4868, 0.347),
}
"""Each preset's per-class recall factor ``c_class``, one column per preset."""

PRESETS: dict[str, DetectorPreset] = {
    name: DetectorPreset(
        name=name,
        **{knob: values[column] for knob, values in _KNOBS.items()},
        class_recall={cls: values[column] for cls, values in _CLASS_RECALL.items()},
    )
    for column, name in enumerate(("centerpoint", "megvii", "pointpillars"))
}
"""The three detector presets by CLI name, best first."""


def get_preset(preset: str | DetectorPreset) -> DetectorPreset:
    """The preset itself, or the one named ``preset`` (``"<preset>"`` or ``"<preset>+<variant>"``, a variant of
    ``VARIANTS``); an unknown name raises ``UnknownNameError``."""
    if isinstance(preset, DetectorPreset):
        return preset
    name, _, variant = preset.partition("+")
    if name not in PRESETS or (variant and variant not in VARIANTS):
        raise UnknownNameError(
            f"unknown detector preset '{preset}' (choose one of: {', '.join(PRESETS)}, optionally followed by "
            f"+{' / +'.join(VARIANTS)})"
        )
    base = PRESETS[name]
    if not variant:
        return base
    return dataclasses.replace(base, name=preset, realism=VARIANTS[variant])


def detector_choice(detections_file: object | None, detector: str | None, default: str = "centerpoint") -> str:
    """The simulated preset a command uses (checked), refusing a detection file together with a preset."""
    if detections_file is not None and detector is not None:
        raise GnnpmbError("pass either --detections FILE or --detector PRESET, not both")
    get_preset(detector or default)
    return detector or default
