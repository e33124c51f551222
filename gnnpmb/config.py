"""Tracker parameters: the paper's values as defaults, overridable from one TOML file.

Defaults follow Liu et al., "GNN-PMB", IEEE T-IV 2023, sec. V-B and Table II, and the per-class noise of the
authors' public code (see ``gnnpmb/default_params.toml``, which is the editable copy of these values), except
values chosen on mini_train splits (``ModelParams``, ``PmbParams``, ``PmbmParams``: the velocity measured with the
centre and N_h = 10 chosen on the demo's and the dev set's); ``gnnpmb/params/paper.toml`` restores the paper's.
Each parameter is declared once, as a field of its section's dataclass with ``gnnpmb.param.param``: default,
meaning, unit, allowed range (with the model's overflow limit), the paper's value. The reader, the checks, the
sweeps' ``--param``, ``paper_config`` and the generated files (``gnnpmb.param_docs``) read those declarations.
The models every tracker shares (survival, gate, clutter, birth) are the ``[models]`` section (``ModelParams``,
used through ``gnnpmb.models``); the keys they had in ``[pmb]`` before (``[pmb] p_survive`` ...) still work and
mean the same (``MOVED_KEYS``).
A parameter file may set any subset; unknown keys are an error so typos do not go unnoticed, and every value is
checked against its declared range (the error names the key, the value and the range).

Per-class parameters: ``[classes.<class>]`` holds the class's own models (``ClassParams``: Q, R, the greedy
matching distance) and may override any key of the shared sections for that class only, e.g.
``[classes.pedestrian] birth_weight = 0.05``; a key that two sections share (``p_detect`` of ``[phd]`` and
``[vector]``) goes into a sub-table, ``[classes.car.vector] p_detect = 0.8``. Every tracker of a class sees the
shared section values with its class's overrides applied (``TrackerConfig.resolved``). The canonical name of a
parameter is its dotted path: ``pmb.gate_chi2``, ``classes.car.birth_weight``, ``classes.car.vector.p_detect``
(``get_param``, ``with_params``).
"""

from __future__ import annotations

import dataclasses
import difflib
import re
import tomllib
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import MISSING, dataclass, field
from pathlib import Path
from typing import Any

from gnnpmb.param import (
    FACTOR_LIMIT,
    GIOU,
    NON_NEGATIVE,
    POSITIVE,
    PROB,
    SQUARED_LIMIT,
    STD_LIMIT,
    SWITCH,
    VARIANCE_LIMIT,
    ConfigError,
    Range,
    Section,
    at_least,
    check_section,
    declared,
    paper_values,
    param,
    unit_interval,
)
from gnnpmb.symlinks import refuse_symlink_loop
from gnnpmb.types import TRACKING_CLASSES

_Q = "process noise of x (y) position and velocity per keyframe, Q = diag(q_x, q_y, q_x, q_y)"


@dataclass(frozen=True, slots=True)
class ClassParams(Section):
    """Per-class models ``[classes.<class>]`` (defaults per class: ``DEFAULT_CLASS_PARAMS``)."""

    SECTION = "classes"

    q_x: float = param(MISSING, _Q, NON_NEGATIVE, "m^2", limit=VARIANCE_LIMIT)
    q_y: float = param(MISSING, _Q.replace("x (y)", "y (x)"), NON_NEGATIVE, "m^2", limit=VARIANCE_LIMIT)
    r_x: float = param(
        MISSING, "measurement noise of the centre's x, R = diag(r_x, r_y)", POSITIVE, "m^2", limit=VARIANCE_LIMIT
    )
    r_y: float = param(MISSING, "measurement noise of the centre's y", POSITIVE, "m^2", limit=VARIANCE_LIMIT)
    match_distance_m: float = param(
        4.0, "greedy tracker's matching distance (CenterPoint's per class)", POSITIVE, "m", limit=SQUARED_LIMIT
    )
    r_vx: float = param(
        0.5,
        "velocity measurement noise (only with [pmb] measure_velocity = 1)",
        POSITIVE,
        "(m/s)^2",
        limit=VARIANCE_LIMIT,
    )
    r_vy: float = param(0.5, "as r_vx, of vy", POSITIVE, "(m/s)^2", limit=VARIANCE_LIMIT)
    cbmot_distance_m: float = param(3.0, "CBMOT's matching distance", POSITIVE, "m", limit=SQUARED_LIMIT)


PAPER_CLASS_PARAMS: dict[str, ClassParams] = {
    "car": ClassParams(0.1589, 0.1249, 0.0890, 0.0941, 4.0, cbmot_distance_m=3.0),
    "truck": ClassParams(0.0945, 0.0946, 0.1486, 0.1445, 4.0, cbmot_distance_m=4.0),
    "bus": ClassParams(0.1177, 0.0885, 0.1755, 0.1382, 5.5, cbmot_distance_m=5.5),
    "trailer": ClassParams(0.0420, 0.0369, 0.2323, 0.2223, 3.0, cbmot_distance_m=2.0),
    "pedestrian": ClassParams(0.0335, 0.0247, 0.0386, 0.0377, 1.0, cbmot_distance_m=1.0),
    "bicycle": ClassParams(0.0199, 0.0137, 0.0539, 0.0504, 3.0, cbmot_distance_m=2.5),
    "motorcycle": ClassParams(0.0324, 0.0387, 0.0405, 0.0399, 13.0, cbmot_distance_m=4.0),
}
"""Q and R: the authors' GNN-PMB code; match_distance_m: CenterPoint's ``NUSCENE_CLS_VELOCITY_ERROR`` (Yin et al.
2021, ``det3d/.../pub_tracker.py``); cbmot_distance_m: the same table as CBMOT's ``tracker.py`` ships it (Benbarka
et al. 2021; an earlier CenterPoint version: car 3, trailer 2, motorcycle 4, bicycle 2.5 m)."""

TWO_WHEELER_Q = 0.1
"""Default process noise q_x = q_y of bicycles and motorcycles (m^2 per keyframe; the authors' code: 0.02-0.04),
chosen on the mini_train splits (issue 32, ``docs/results.md``)."""
LARGE_VEHICLE_Q_SCALE = 2.0
"""Default process noise of trucks and buses: the authors' q_x, q_y times this, chosen on the mini_train splits
(issue 32, ``docs/results.md``)."""
DEFAULT_CLASS_PARAMS: dict[str, ClassParams] = {
    **PAPER_CLASS_PARAMS,
    **{
        c: dataclasses.replace(PAPER_CLASS_PARAMS[c], q_x=TWO_WHEELER_Q, q_y=TWO_WHEELER_Q)
        for c in ("bicycle", "motorcycle")
    },
    **{
        c: dataclasses.replace(
            PAPER_CLASS_PARAMS[c],
            q_x=LARGE_VEHICLE_Q_SCALE * PAPER_CLASS_PARAMS[c].q_x,
            q_y=LARGE_VEHICLE_Q_SCALE * PAPER_CLASS_PARAMS[c].q_y,
        )
        for c in ("truck", "bus")
    },
}
"""The default per-class models: the paper's (``PAPER_CLASS_PARAMS``) except ``TWO_WHEELER_Q`` and
``LARGE_VEHICLE_Q_SCALE``."""


_BOX_R = "measurement noise R of the box's {}"
_BOX_Q = "process noise of the box's {} per keyframe"
_BOX_P = "initial variance of the box's {}"


def _box(template: str, what: str, unit: str, range_: Any = POSITIVE) -> Any:
    return param(MISSING, template.format(what), range_, unit, limit=VARIANCE_LIMIT)


@dataclass(frozen=True, slots=True)
class BoxNoise(Section):
    """Diagonal noise of one class's 10-D box Kalman filter (``gnnpmb.box.kalman``), state [x, y, z, yaw, l, w,
    h, vx, vy, vz], measurement the first 7, in SI units per keyframe step; the initial variance of the 7
    measured components is p_scale R.

    The defaults (``NUSCENES_BOX_NOISE``) are Probabilistic 3D MOT's statistics of nuScenes train (Chiu et al.
    2020, sec. IV-C, its ``covariance.py`` ``NuScenesCovariance``); its velocities are per 0.5 s keyframe, so its
    velocity entries are divided by 0.5^2 here. ``benchmarks/learn_box_noise.py`` learns them from a split.
    """

    SECTION = "box_noise"

    r_x: float = _box(_BOX_R, "x", "m^2")
    r_y: float = _box(_BOX_R, "y", "m^2")
    r_z: float = _box(_BOX_R, "z", "m^2")
    r_yaw: float = _box(_BOX_R, "heading", "rad^2")
    r_l: float = _box(_BOX_R, "length", "m^2")
    r_w: float = _box(_BOX_R, "width", "m^2")
    r_h: float = _box(_BOX_R, "height", "m^2")
    q_x: float = _box(_BOX_Q, "x", "m^2", NON_NEGATIVE)
    q_y: float = _box(_BOX_Q, "y", "m^2", NON_NEGATIVE)
    q_z: float = _box(_BOX_Q, "z", "m^2", NON_NEGATIVE)
    q_yaw: float = _box(_BOX_Q, "heading", "rad^2", NON_NEGATIVE)
    q_size: float = _box(_BOX_Q, "l, w and h", "m^2", NON_NEGATIVE)
    q_vx: float = _box(_BOX_Q, "vx", "(m/s)^2", NON_NEGATIVE)
    q_vy: float = _box(_BOX_Q, "vy", "(m/s)^2", NON_NEGATIVE)
    q_vz: float = _box(_BOX_Q, "vz", "(m/s)^2", NON_NEGATIVE)
    p_vx: float = _box(_BOX_P, "vx", "(m/s)^2")
    p_vy: float = _box(_BOX_P, "vy", "(m/s)^2")
    p_vz: float = _box(_BOX_P, "vz", "(m/s)^2")
    p_scale: float = param(1.0, "initial variance of the measured components as a multiple of R", POSITIVE)

    def __post_init__(self) -> None:
        check_section(self)
        largest = max(self.r_x, self.r_y, self.r_z, self.r_yaw, self.r_l, self.r_w, self.r_h)
        if self.p_scale * largest > VARIANCE_LIMIT.hi:
            raise ConfigError(
                f"[box_noise] p_scale R must stay <= {VARIANCE_LIMIT.hi:g} ({VARIANCE_LIMIT.why}), got p_scale = "
                f"{self.p_scale!r} with largest R entry {largest!r}"
            )

    @staticmethod
    def uniform(r: float, q: float, q_size: float, q_velocity: float, p_velocity: float, p_scale: float) -> BoxNoise:
        """The same variance for every measured component (r), position and heading (q), ... (AB3DMOT's and
        SimpleTrack's hand-set covariances)."""
        return BoxNoise(*([r] * 7), *([q] * 4), q_size, *([q_velocity] * 3), *([p_velocity] * 3), p_scale=p_scale)


def _prob3dmot_nuscenes(r: tuple[float, ...], q: tuple[float, float, float, float], p_v: tuple[float, ...]) -> BoxNoise:
    """``BoxNoise`` from Probabilistic 3D MOT's published R (x, y, z, yaw, l, w, h), Q (x, y, z, yaw; its
    velocity noise equals the position noise per frame) and initial velocity variance, per 0.5 s frame."""
    per_s2 = 1.0 / 0.5**2
    return BoxNoise(*r, *q, 0.0, *(v * per_s2 for v in q[:3]), *(v * per_s2 for v in p_v), p_scale=1.0)


_PROB3DMOT_R: dict[str, tuple[float, ...]] = {  # x, y, z, yaw, l, w, h
    "car": (0.08900372, 0.09412005, 0.03265469, 1.00535696, 0.10912802, 0.02359175, 0.02455134),
    "truck": (0.14862173, 0.1444596, 0.05417157, 0.73122169, 0.69387238, 0.05484365, 0.07748085),
    "bus": (0.17546469, 0.13818929, 0.05947248, 0.1979503, 0.78867322, 0.05507407, 0.06684149),
    "trailer": (0.23228021, 0.22229261, 0.07006275, 1.05163481, 1.37451601, 0.06354783, 0.10500918),
    "pedestrian": (0.03855275, 0.0377111, 0.02482115, 2.0751833, 0.02286483, 0.0136347, 0.0203149),
    "bicycle": (0.05390982, 0.05039431, 0.01863044, 1.29464435, 0.02713823, 0.01169572, 0.01295084),
    "motorcycle": (0.04052819, 0.0398904, 0.01511711, 1.06442726, 0.03291016, 0.00957574, 0.0111605),
}
_PROB3DMOT_Q_P: dict[str, tuple[tuple[float, float, float, float], tuple[float, float, float]]] = {
    # Q (x, y, z, yaw), initial velocity variance (vx, vy, vz)
    "car": ((0.158918523, 0.124935318, 0.00535573165, 0.0922800791), (0.08120681, 0.08224643, 0.02266425)),
    "truck": ((0.0945275998, 0.0945620374, 0.00838061721, 0.14168046), (0.10683797, 0.10248689, 0.0378078)),
    "bus": ((0.117729925, 0.0884659079, 0.011761644, 0.209050032), (0.13263319, 0.11508148, 0.05033665)),
    "trailer": ((0.0419985099, 0.0368661552, 0.011941505, 0.056316624), (0.2138643, 0.19625241, 0.05231335)),
    "pedestrian": ((0.0334814566, 0.0247354921, 0.00594592529, 0.424962535), (0.04237008, 0.04092393, 0.01482923)),
    "bicycle": ((0.0198881347, 0.0136552276, 0.00510175742, 0.133430252), (0.04560422, 0.04097244, 0.01725477)),
    "motorcycle": ((0.032364759, 0.0386650974, 0.00547421635, 0.234967407), (0.0437039, 0.04327734, 0.01465631)),
}
NUSCENES_BOX_NOISE: dict[str, BoxNoise] = {
    c: _prob3dmot_nuscenes(r, *_PROB3DMOT_Q_P[c]) for c, r in _PROB3DMOT_R.items()
}
"""Per-class box noise of nuScenes train as Probabilistic 3D MOT publishes it (``BoxNoise``)."""


@dataclass(frozen=True, slots=True)
class PreprocessParams(Section):
    """Detection preprocessing (paper sec. V-B, Table II)."""

    SECTION = "preprocess"

    score_threshold: float = param(0.1, "detections scoring below it are dropped", PROB)
    nms_iou_3d: float = param(0.1, "non-maximum suppression's 3D IoU threshold", PROB)


@dataclass(frozen=True, slots=True)
class ModelParams(Section):
    """The models every tracker shares (``gnnpmb.models``): survival P_S, the gate, the clutter intensity and the
    measurement-driven birth, birth covariance diag(s_p^2, s_p^2, s_v^2, s_v^2) (paper sec. V-B). P_D is the
    detection's score for the PMB family and ``p_detect`` of ``[phd]`` / ``[vector]`` for the others. p_survive and
    birth_weight differ from the paper's, chosen on the demo ``mini_train`` split (``docs/architecture.md``). The
    coordinated-turn model (``motion_model = 1``, the PMB family's default since issue 32 Round 10: objects turning
    while missed; the paper's is constant velocity) has state [x, y, vx, vy, omega] and the extended Kalman predict
    (``gnnpmb.models.ct_model``); a new track's turn rate starts at 0 and decays by ``turn_rate_decay`` a keyframe.
    ``coast_velocity_decay`` b < 1 slows a coasting Bernoulli (missed at its last update): v' = b v.
    Its four values were chosen on the mini_train splits of the demo and the dev set (``docs/results.md``).
    """

    SECTION = "models"

    p_survive: float = param(
        0.95, "P_S, the probability an object survives one keyframe", unit_interval(False, True), paper=0.7
    )
    clutter_intensity: float = param(1e-3, "kappa, the clutter intensity", POSITIVE, "1/m^2", limit=FACTOR_LIMIT)
    gate_chi2: float = param(40.0, "G, the squared Mahalanobis gate", POSITIVE)
    birth_weight: float = param(0.3, "w_b, the birth weight per detection", POSITIVE, paper=0.1)
    birth_pos_std_m: float = param(15.0, "s_p, a new track's position std", POSITIVE, "m", limit=STD_LIMIT)
    birth_vel_std_mps: float = param(1.0, "s_v, a new track's velocity std", POSITIVE, "m/s", limit=STD_LIMIT)
    motion_model: int = param(
        1, "0 = constant velocity (the paper's), 1 = coordinated turn (PMB family)", SWITCH, paper=0
    )
    turn_rate_std_rps: float = param(
        0.05, "the turn rate's process noise per keyframe", NON_NEGATIVE, "rad/s", limit=STD_LIMIT
    )
    birth_turn_rate_std_rps: float = param(0.05, "a new track's turn-rate std", POSITIVE, "rad/s", limit=STD_LIMIT)
    turn_rate_decay: float = param(
        0.8, "a: the turn rate is multiplied by a each keyframe (1: a constant turn rate)", unit_interval(False, True)
    )
    coast_velocity_decay: float = param(
        1.0,
        "b: a PMB Bernoulli missed at its last update has its velocity multiplied by b each keyframe (1: off)",
        unit_interval(False, True),
    )


@dataclass(frozen=True, slots=True)
class PmbParams(Section):
    """The Poisson multi-Bernoulli family (GNN-PMB, PMBM, TO-PMB), beyond the shared ``[models]``.

    A Bernoulli with existence r >= extraction_threshold is output with tracking score s r (s: its detection
    score); a missed track's P_D is its last detection score capped at miss_p_detect_max, or at the cap learnt per
    class from the gaps its tracks closed (miss_p_detect_online, ``gnnpmb.pmb.miss_detection``; apart for weak and
    strong last detections with miss_p_detect_score_split), except beside a
    neighbour of its class (miss_p_detect_neighbour_m). measure_velocity adds [vx, vy] to the measurement (R adds
    r_vx, r_vy; clutter intensity x clutter_velocity_density per (m/s)^2). A Bernoulli missed n frames in a row is
    scored s r d^n (miss_score_decay d; with miss_score_mean_min_frames N > 0, one born or detected on at least N
    frames max(s, m) r d^n, m its mean score on those frames) and not output beyond output_max_misses, nor
    while missed with r below coasting_min_existence. Heading and
    size likelihood (``gnnpmb.box_likelihood``): a sigma of 0 leaves that part out. gate_giou_min gates on the
    bird's-eye GIoU of the predicted box (the filtered centre with the last detection's size and heading). Defaults
    that differ from the paper's were chosen on the mini_train splits: why and the figures, ``docs/results.md`` and
    ``docs/architecture.md``.
    """

    SECTION = "pmb"

    prune_existence: float = param(1e-6, "Bernoullis with existence r below it are dropped", unit_interval(True, False))
    extraction_threshold: float = param(0.01, "Bernoullis with r at least this are output", PROB, paper=0.9)
    miss_p_detect_max: float = param(
        0.3, "cap of a missed track's P_D (its last detection score)", unit_interval(False, True), paper=1.0
    )
    miss_p_detect_online: int = param(
        1,
        "1 = the cap learnt online per class from gaps closed by a detection, miss_p_detect_max its prior mean",
        SWITCH,
        paper=0,
    )
    miss_p_detect_prior_frames: float = param(
        10.0,
        "w, the weight of miss_p_detect_max as the online cap's Beta prior",
        POSITIVE,
        "frames",
        limit=FACTOR_LIMIT,
    )
    miss_p_detect_bins: int = param(
        2, "N: the online cap is learnt apart after 0, 1, ..., N - 1 or more misses in a row", at_least(1)
    )
    miss_p_detect_score_split: float = param(
        0.0,
        "s > 0: the online cap is learnt apart for tracks whose last detection scored below s and at least s (0: one)",
        unit_interval(True, False),
    )
    miss_p_detect_neighbour_m: float = param(
        2.0,
        "a missed Bernoulli with another of its class this near keeps the fixed cap, not the online one (0: off)",
        NON_NEGATIVE,
        "m",
        limit=FACTOR_LIMIT,
        paper=0.0,
    )
    miss_p_detect_neighbour_existence: float = param(
        0.5, "least existence r of such a neighbour", unit_interval(True, True)
    )
    miss_p_detect_last_score: int = param(
        1,
        "1 = a missed track's P_D is min(its last detection score, the cap) (the paper's), 0 = the cap alone",
        SWITCH,
    )
    measure_velocity: int = param(1, "1 = measure [x, y, vx, vy], 0 = the paper's [x, y]", SWITCH, paper=0)
    clutter_velocity_density: float = param(
        0.02,
        "density of a clutter detection's velocity (measure_velocity = 1)",
        POSITIVE,
        "1/(m/s)^2",
        limit=FACTOR_LIMIT,
    )
    miss_score_decay: float = param(
        1.0, "d: a track missed n frames is scored s r d^n (1: the paper's s r)", unit_interval(False, True), paper=1.0
    )
    miss_score_mean_min_frames: int = param(
        0,
        "N > 0: a missed Bernoulli born or detected on >= N frames is scored max(s, m) r, m its mean score on them"
        " (0: s r)",
        at_least(0),
    )
    output_max_misses: int = param(
        1000, "a Bernoulli missed more than this many frames in a row is not output (kept in the filter)", at_least(0)
    )
    coasting_min_existence: float = param(
        0.0,
        "a Bernoulli missed this frame is output only while its existence r is at least this (0: off)",
        unit_interval(True, True),
    )
    heading_std_rad: float = param(
        0.0, "sigma_psi of a detection's heading (0: heading not used)", Range(0.0, 1.5, True, True), "rad", paper=0.0
    )
    size_log_std: float = param(
        0.0, "sigma_s of a detection's log width and length (0: size not used)", Range(0.0, 2.0, True, True), paper=0.0
    )
    size_log_spread: float = param(0.2, "sigma_c, the spread of the class's log sizes", POSITIVE, limit=STD_LIMIT)
    box_outlier_prob: float = param(0.1, "eps, the share of outlier headings and sizes", unit_interval(False, False))
    gate_giou_min: float = param(
        -1.0, "least bird's-eye GIoU of a gated pair (-1: no overlap gate, the paper's)", GIOU, paper=-1.0
    )


@dataclass(frozen=True, slots=True)
class PmbmParams(Section):
    """PMBM hypothesis management (``gnnpmb.pmb.pmbm``; García-Fernández et al. 2018, sec. V).

    Prior hypothesis h of weight w_h gets its ceil(N_h w_h) best assignments (Murty); N_h = 1 is exactly GNN-PMB.
    n_scan N > 0: after each update only the hypotheses descending from the best one's ancestor N frames back are
    kept (N-scan pruning). N_h = 10 and N = 1 were chosen on the mini_train splits (``docs/results.md``).
    """

    SECTION = "pmbm"

    n_hypotheses: int = param(10, "N_h, the most global hypotheses kept", at_least(1), paper=100)
    hypothesis_prune: float = param(
        1e-4, "global hypotheses lighter than this are dropped (the best always stays)", unit_interval(True, False)
    )
    n_scan: int = param(
        1,
        "N-scan pruning: only hypotheses sharing the best one's ancestor N frames back stay (0: off)",
        at_least(0),
        paper=0,
    )
    duplicate_birth_existence: float = param(
        0.0,
        "a hypothesis other than the heaviest in which a detection starts a Bernoulli inside the gate of a"
        " Bernoulli of predicted existence >= this that it leaves missed is dropped (0: off)",
        unit_interval(True, True),
        paper=0.0,
    )


@dataclass(frozen=True, slots=True)
class LbpParams(Section):
    """Loopy belief propagation for marginal association probabilities (TO-PMB, JPDA; ``gnnpmb.assign.lbp``,
    Williams & Lau 2014). On the demo scenes TO-PMB's LBP stops after 2 rounds (median; 8 at most), so the cap is
    a safeguard rather than a speed setting.
    """

    SECTION = "lbp"

    max_iterations: int = param(100, "at most this many message-passing rounds", at_least(1))
    tolerance: float = param(1e-7, "stop once no marginal changes by more than this in a round", POSITIVE)


@dataclass(frozen=True, slots=True)
class PhdParams(Section):
    """GM-PHD / GM-CPHD filters (``gnnpmb.phd``; Vo & Ma 2006; Vo, Vo & Cantoni 2007).

    A measurement-driven birth component is detected by construction. Below max_cardinality the CPHD's
    cardinality support follows the previous posterior plus the birth count, so most frames use far fewer terms
    (median 7, at most 21 on the demo scenes). Survival, gate, clutter intensity and birth come from ``[models]``
    so every tracker of the study sees the same models. T, U, J_max and the 0.5 extraction weight are Vo & Ma's.
    """

    SECTION = "phd"

    p_detect: float = param(0.9, "P_D of a persistent component", unit_interval(False, True))
    prune_weight: float = param(1e-5, "T: components lighter than this are dropped", NON_NEGATIVE)
    merge_threshold: float = param(4.0, "U: squared Mahalanobis distance within which components merge", NON_NEGATIVE)
    max_components: int = param(100, "J_max: the most components kept per class", at_least(1))
    extraction_weight: float = param(0.5, "components at least this heavy are reported, round(w) times", POSITIVE)
    max_cardinality: int = param(100, "the CPHD's largest cardinality (most tracks per class)", at_least(1))


@dataclass(frozen=True, slots=True)
class VectorParams(Section):
    """Vector-type trackers (GNN, JPDA; ``gnnpmb.vector``; Blackman & Popoli 1999, ch. 6; Bar-Shalom, Daum &
    Huang 2009). A tentative track is confirmed once it has confirm_m hits within its first confirm_n frames (the
    birth frame counts as a hit) and deleted as soon as it can no longer get there. JPDA enumerates a gated
    cluster exactly when it has at most exact_cluster_max tracks (and at most
    ``vector.jpda.EXACT_ASSOCIATION_BUDGET`` joint events), otherwise it uses loopy belief propagation
    (``[lbp]``). The gate, clutter intensity and the initial covariance of a new track come from ``[models]``.
    """

    SECTION = "vector"

    p_detect: float = param(0.9, "constant P_D of the association likelihoods", unit_interval(False, False))
    confirm_m: int = param(2, "M of M-of-N confirmation", Range(1.0, 62.0, True, True))
    confirm_n: int = param(3, "N of M-of-N confirmation", Range(1.0, 62.0, True, True))
    delete_misses: int = param(3, "a confirmed track missed this many frames in a row is deleted", at_least(1))
    exact_cluster_max: int = param(8, "JPDA enumerates clusters of at most this many tracks", at_least(1))

    def __post_init__(self) -> None:
        check_section(self)
        if self.confirm_m > self.confirm_n:
            raise ConfigError(
                f"[vector] need confirm_m <= confirm_n, got confirm_m = {self.confirm_m}, confirm_n = {self.confirm_n}"
            )


_MIN_HITS = "a track is output from its min_hits-th hit on"
_MAX_MISSES = "a track missed this many frames in a row is deleted"


@dataclass(frozen=True, slots=True)
class GreedyParams(Section):
    """The greedy closest-pair baseline (``gnnpmb.greedy``; CenterPoint, Yin et al. 2021)."""

    SECTION = "greedy"

    max_age: int = param(3, _MAX_MISSES + " (CenterPoint's nuScenes 3)", at_least(1))


@dataclass(frozen=True, slots=True)
class Ab3dmotParams(Section):
    """AB3DMOT (Weng, Wang, Held & Kitani, IROS 2020) as it runs on nuScenes (the configuration Probabilistic 3D
    MOT published for it, ``config/AB3DMOT.yaml``; ``gnnpmb.box.ab3dmot``). Every track is output in the first
    min_hits frames; a track missed fewer than max_misses frames is output at its prediction (AB3DMOT's max_age).
    """

    SECTION = "ab3dmot"

    iou_threshold: float = param(0.1, "a matched pair's 3D IoU must exceed this", unit_interval(True, False))
    min_hits: int = param(3, _MIN_HITS, at_least(0))
    max_misses: int = param(2, _MAX_MISSES, at_least(1))


@dataclass(frozen=True, slots=True)
class Prob3dmotParams(Section):
    """Probabilistic 3D MOT (Chiu, Prioletti, Li & Bohg, 2020; ``gnnpmb.box.prob3dmot``); its per-class noise is
    ``[box_noise.<class>]``; min_hits and max_misses as ``[ab3dmot]`` (AB3DMOT's 3 and 2)."""

    SECTION = "prob3dmot"

    distance_threshold: float = param(
        11.0, "a matched pair's box Mahalanobis distance sqrt(nu' S^-1 nu) is below this", POSITIVE, limit=SQUARED_LIMIT
    )
    min_hits: int = param(3, _MIN_HITS, at_least(0))
    max_misses: int = param(2, _MAX_MISSES, at_least(1))


@dataclass(frozen=True, slots=True)
class SimpleTrackParams(Section):
    """SimpleTrack (Pang, Li & Wang, 2021; ``gnnpmb.box.simpletrack``), its nuScenes 2 Hz configurations
    (``configs/nu_configs/giou.yaml`` and ``velo_giou.yaml``); ImmortalTracker reads them too.

    giou_threshold -0.5 is its 1 - GIoU <= 1.5; first_stage_score 0.01 is its score_threshold, below the
    preprocessing threshold, so by default every kept detection takes part. two_stage = 1 is its "mm" redundancy
    mode (off in both nuScenes 2 Hz configurations): a track the first stage left unmatched stays alive, not
    updated by the detection, when a detection scoring above second_stage_score has GIoU >= second_stage_giou
    with it. detector_velocity = 1 is its "velo" model (``velo_giou.yaml``: a track is its last detection moved by
    that detection's velocity, and detections are stepped back by their own velocity to meet the tracks; the
    SimpleTrack paper finds this the more robust model at low frame rates), 0 its Kalman filter (``giou.yaml``).
    1 was chosen on the demo mini_train split (centerpoint / pointpillars presets, seed 0: simpletrack AMOTA 0.753
    / 0.602 against 0.697 / 0.522 with the Kalman filter; immortal 0.822 / 0.682 against 0.771 / 0.659): at 2 Hz
    a new Kalman track has no velocity, so a fast, small object (a motorcycle moving 5 m per keyframe) misses its
    second detection's GIoU gate.
    """

    SECTION = "simpletrack"

    giou_threshold: float = param(-0.5, "a matched pair's 3D GIoU is at least this", GIOU)
    first_stage_score: float = param(0.01, "detections below it skip the first stage and start no track", PROB)
    min_hits: int = param(0, _MIN_HITS + " (0: at once)", at_least(0))
    max_misses: int = param(2, _MAX_MISSES + " (its max_age_since_update)", at_least(1))
    miss_score_factor: float = param(0.01, "a missed track's score is multiplied by this each frame", PROB)
    two_stage: int = param(0, "1 = the second association stage", SWITCH)
    second_stage_score: float = param(0.1, "least score of a second-stage detection", PROB)
    second_stage_giou: float = param(-0.5, "least GIoU of a second-stage pair", GIOU)
    detector_velocity: int = param(1, "motion model: 1 = the detector's velocity, 0 = the Kalman filter", SWITCH)


@dataclass(frozen=True, slots=True)
class ImmortalParams(Section):
    """ImmortalTracker (Wang, Chen, Pang, Wang & Zhang, 2021; ``gnnpmb.box.simpletrack``): SimpleTrack
    (``[simpletrack]``, its motion model included: ImmortalTracker's own code has only the Kalman filter,
    ``[simpletrack] detector_velocity = 0``) whose tracks are never deleted (its ``configs/nu_configs/
    immortal.yaml``; its nuScenes result creation keeps tracks updated at most one frame ago).
    """

    SECTION = "immortal"

    min_hits: int = param(1, _MIN_HITS, at_least(0))
    output_max_misses: int = param(1, "a track is output while missed at most this many frames in a row", at_least(0))


@dataclass(frozen=True, slots=True)
class CbmotParams(Section):
    """CBMOT (Benbarka, Schröder & Zell, "Score refinement for confidence-based 3D multi-object tracking", IROS
    2021; ``gnnpmb.cbmot``), its LiDAR-only configuration (multiplication score update, score decay 0.2)."""

    SECTION = "cbmot"

    score_decay: float = param(0.2, "subtracted from a track's score every frame before the update", PROB)
    max_misses: int = param(40, _MAX_MISSES + " (its max_age)", at_least(1))
    delete_score: float = param(0.0, "a missed track scoring at or below this is deleted", unit_interval(True, False))


Overrides = dict[str, dict[str, dict[str, float]]]
"""Per-class overrides of shared-section keys: class name -> section -> key -> value."""


@dataclass(frozen=True, slots=True)
class TrackerConfig:
    """Everything a tracker needs; one instance for all classes (``resolved`` gives one class's view)."""

    classes: dict[str, ClassParams] = field(default_factory=lambda: dict(DEFAULT_CLASS_PARAMS))
    preprocess: PreprocessParams = PreprocessParams()
    models: ModelParams = ModelParams()
    pmb: PmbParams = PmbParams()
    pmbm: PmbmParams = PmbmParams()
    lbp: LbpParams = LbpParams()
    phd: PhdParams = PhdParams()
    vector: VectorParams = VectorParams()
    greedy: GreedyParams = GreedyParams()
    ab3dmot: Ab3dmotParams = Ab3dmotParams()
    prob3dmot: Prob3dmotParams = Prob3dmotParams()
    simpletrack: SimpleTrackParams = SimpleTrackParams()
    immortal: ImmortalParams = ImmortalParams()
    cbmot: CbmotParams = CbmotParams()
    class_overrides: Overrides = field(default_factory=dict)
    box_noise: dict[str, BoxNoise] = field(default_factory=lambda: dict(NUSCENES_BOX_NOISE))

    def for_class(self, class_name: str) -> ClassParams:
        return self.classes[class_name]

    def replace(self, **changes: Any) -> TrackerConfig:
        return dataclasses.replace(self, **changes)

    def resolved(self, class_name: str) -> TrackerConfig:
        """This config as class ``class_name`` sees it: every shared section with the class's overrides applied
        (no overrides left, so a tracker just reads ``config.pmb`` and so on)."""
        own = self.class_overrides.get(class_name)
        if not own:
            return self if not self.class_overrides else self.replace(class_overrides={})
        changes: dict[str, Any] = {s: dataclasses.replace(getattr(self, s), **v) for s, v in own.items()}
        return self.replace(class_overrides={}, **changes)

    def preprocess_by_class(self) -> dict[str, PreprocessParams]:
        """Class name -> the preprocessing parameters of that class."""
        return {name: self.resolved(name).preprocess for name in TRACKING_CLASSES}

    def as_dict(self) -> dict[str, Any]:
        """Plain nested dict in the TOML layout (for provenance and TOML output; ``config_from_dict`` reads it)."""
        out: dict[str, Any] = {name: dataclasses.asdict(getattr(self, name)) for name in _SECTIONS}
        classes: dict[str, Any] = {}
        for name, p in self.classes.items():
            entry: dict[str, Any] = dataclasses.asdict(p)
            for section, values in self.class_overrides.get(name, {}).items():
                for key, value in values.items():
                    if len(_SECTIONS_OF_KEY[key]) == 1:
                        entry[key] = value
                    else:
                        entry.setdefault(section, {})[key] = value
            classes[name] = entry
        out["classes"] = classes
        out["box_noise"] = {name: dataclasses.asdict(n) for name, n in self.box_noise.items()}
        return out


def paper_config() -> TrackerConfig:
    """The defaults with the paper's own ``[models]``, ``[pmb]`` and ``[pmbm]`` values: the trackers exactly as
    published."""
    changes = {name: kind(**paper_values(kind)) for name, kind in _SECTIONS.items() if paper_values(kind)}
    return TrackerConfig(classes=dict(PAPER_CLASS_PARAMS), **changes)


_SECTIONS: dict[str, type] = {
    f.name: type(f.default) for f in dataclasses.fields(TrackerConfig) if isinstance(f.default, Section)
}
"""The shared sections, in file order: name -> its dataclass (whose ``SECTION`` is that name)."""

MOVED_KEYS: dict[tuple[str, str], str] = {("pmb", f.name): "models" for f in dataclasses.fields(ModelParams)}
"""(old section, key) -> the section the key lives in now; parameter files and dotted names may still use the old
section (``[pmb] p_survive``, ``pmb.gate_chi2``)."""


def current_section(section: str, key: str) -> str:
    """The section that holds ``key`` given as a key of ``section`` (``MOVED_KEYS``)."""
    return MOVED_KEYS.get((section, key), section)


_SECTIONS_OF_KEY: dict[str, tuple[str, ...]] = {}
for _section, _kind in _SECTIONS.items():
    for _f in dataclasses.fields(_kind):
        _SECTIONS_OF_KEY[_f.name] = (*_SECTIONS_OF_KEY.get(_f.name, ()), _section)


def unknown_parameter(where: str, key: str, known: Iterable[str]) -> str:
    """The message for a parameter name the place does not know: the closest name it or any section declares, if
    one is close (a typo: ``neighbor`` for ``neighbour``), then every name the place knows."""
    names = sorted(known)
    close = difflib.get_close_matches(key, sorted({*names, *_SECTIONS_OF_KEY}), n=1, cutoff=0.8)
    hint = f"; did you mean '{close[0]}'?" if close else ""
    return f"{where}: unknown parameter '{key}'{hint} (known: {', '.join(names)})"


def _typed_value(kind: type, key: str, value: Any, where: str) -> float | int:
    """``value`` as the declared type of parameter ``key`` of section ``kind``, checked against its declared
    range, or a ``ConfigError``."""
    known = {d.name: d for d in declared(kind)}
    if key not in known:
        raise ConfigError(unknown_parameter(where, key, known))
    if isinstance(value, bool) or not isinstance(value, int | float):
        raise ConfigError(f"{where} {key}: expected a number, got {value!r}")
    if known[key].type is int and not float(value).is_integer():
        raise ConfigError(f"{where} {key}: expected an integer, got {value!r}")
    typed = known[key].type(value)
    known[key].spec.check(key, typed, where)
    return typed


def _typed_section(kind: type, values: Any, where: str, base: Any) -> Any:
    if not isinstance(values, dict):
        raise ConfigError(f"{where} must be a table of parameters, got {values!r}")
    changes = {}
    for key, value in values.items():
        changes[key] = _typed_value(kind, key, value, where)
    return dataclasses.replace(base, **changes)


def _class_table(name: str, values: Any, params: ClassParams, overrides: dict[str, dict[str, float]]) -> ClassParams:
    """Read ``[classes.<name>]``: own models into a new ``ClassParams``, shared-section keys into ``overrides``."""
    where = f"[classes.{name}]"
    if not isinstance(values, dict):
        raise ConfigError(f"{where} must be a table of parameters, got {values!r}")
    own = {f.name for f in dataclasses.fields(ClassParams)}
    model = {k: v for k, v in values.items() if k in own}
    for key, value in values.items():
        if key in own:
            continue
        if key in _SECTIONS and isinstance(value, dict):
            for sub_key, sub_value in value.items():
                section = current_section(key, sub_key)
                typed = _typed_value(_SECTIONS[section], sub_key, sub_value, f"[classes.{name}.{key}]")
                overrides.setdefault(section, {})[sub_key] = typed
            continue
        sections = _SECTIONS_OF_KEY.get(key, ())
        if not sections:
            known = sorted(own | set(_SECTIONS_OF_KEY))
            raise ConfigError(unknown_parameter(where, key, known))
        if len(sections) > 1:
            raise ConfigError(
                f"{where}: '{key}' is a parameter of several sections ({', '.join(sections)}); set it in a "
                f"sub-table such as [classes.{name}.{sections[0]}]"
            )
        typed = _typed_value(_SECTIONS[sections[0]], key, value, where)
        overrides.setdefault(sections[0], {})[key] = typed
    return _typed_section(ClassParams, model, where, params)


def _box_noise_tables(values: Any, base: dict[str, BoxNoise]) -> dict[str, BoxNoise]:
    """Read ``[box_noise.<class>]`` tables on top of ``base`` (class name -> ``BoxNoise``)."""
    if not isinstance(values, dict):
        raise ConfigError("[box_noise] must be a table of per-class tables")
    out = dict(base)
    for name, table in values.items():
        if name not in TRACKING_CLASSES:
            raise ConfigError(f"[box_noise.{name}]: unknown class (known: {', '.join(TRACKING_CLASSES)})")
        out[name] = _typed_section(BoxNoise, table, f"[box_noise.{name}]", out[name])
    return out


def config_from_dict(data: Mapping[str, Any], base: TrackerConfig | None = None) -> TrackerConfig:
    """Apply a nested dict of overrides (the TOML layout) to ``base`` (paper defaults if None)."""
    cfg = base or TrackerConfig()
    changes: dict[str, Any] = {}
    for key, values in data.items():
        if key == "classes":
            if not isinstance(values, dict):
                raise ConfigError("[classes] must be a table of per-class tables")
            classes = dict(cfg.classes)
            overrides = {c: {s: dict(v) for s, v in o.items()} for c, o in cfg.class_overrides.items()}
            for name, cvalues in values.items():
                if name not in TRACKING_CLASSES:
                    raise ConfigError(f"[classes.{name}]: unknown class (known: {', '.join(TRACKING_CLASSES)})")
                own = overrides.setdefault(name, {})
                classes[name] = _class_table(name, cvalues, classes[name], own)
                if not own:
                    del overrides[name]
            changes["classes"] = classes
            changes["class_overrides"] = overrides
        elif key == "box_noise":
            changes["box_noise"] = _box_noise_tables(values, changes.get("box_noise", cfg.box_noise))
        elif key in _SECTIONS:
            if not isinstance(values, dict):
                raise ConfigError(f"[{key}] must be a table")
            by_section: dict[str, dict[str, Any]] = {}
            for sub_key, value in values.items():
                section = current_section(key, sub_key)
                if section != key and sub_key in data.get(section, {}):
                    raise ConfigError(
                        f"[{key}] {sub_key} and [{section}] {sub_key} are the same parameter (it moved to "
                        f"[{section}]); give it once"
                    )
                by_section.setdefault(section, {})[sub_key] = value
            for section, section_values in by_section.items():
                base_section = changes.get(section, getattr(cfg, section))
                changes[section] = _typed_section(_SECTIONS[section], section_values, f"[{key}]", base_section)
        else:
            raise ConfigError(f"unknown section [{key}] (known: classes, box_noise, {', '.join(_SECTIONS)})")
    out = cfg.replace(**changes)
    for name in out.class_overrides:
        try:
            out.resolved(name)  # cross-field checks (e.g. confirm_m <= confirm_n) of every class's view
        except ConfigError as exc:  # found in the class's view: name its section, not the shared one
            raise ConfigError(re.sub(r"^\[\w+\]", f"[classes.{name}]", str(exc))) from None
    return out


def _nest(dotted: str, value: Any) -> dict[str, Any]:
    parts = dotted.split(".")
    if len(parts) < 2 or not all(parts):
        raise ConfigError(f"'{dotted}' is not a parameter name; use section.key or classes.<class>.key")
    out: dict[str, Any] = {parts[-1]: value}
    for part in reversed(parts[:-1]):
        out = {part: out}
    return out


def with_params(cfg: TrackerConfig, values: Mapping[str, Any]) -> TrackerConfig:
    """``cfg`` with parameters set by dotted name, e.g. ``{"pmb.gate_chi2": 30, "classes.car.birth_weight": 0.2}``."""
    for dotted, value in values.items():
        cfg = config_from_dict(_nest(dotted, value), cfg)
    return cfg


def get_param(cfg: TrackerConfig, dotted: str) -> float | int:
    """The value of the parameter with dotted name ``dotted`` (per-class names resolve through the fall-back)."""
    parts = dotted.split(".")
    if parts[0] == "classes" and len(parts) in (3, 4):
        name, key = parts[1], parts[-1]
        if name not in cfg.classes:
            raise ConfigError(f"unknown class in '{dotted}' (known: {', '.join(TRACKING_CLASSES)})")
        if len(parts) == 3 and hasattr(cfg.classes[name], key):
            return getattr(cfg.classes[name], key)
        sections = (current_section(parts[2], key),) if len(parts) == 4 else _SECTIONS_OF_KEY.get(key, ())
        if len(sections) == 1 and sections[0] in _SECTIONS and hasattr(getattr(cfg, sections[0]), key):
            return getattr(getattr(cfg.resolved(name), sections[0]), key)
    elif parts[0] == "box_noise" and len(parts) == 3 and parts[1] in cfg.box_noise:
        if hasattr(cfg.box_noise[parts[1]], parts[2]):
            return getattr(cfg.box_noise[parts[1]], parts[2])
    elif len(parts) == 2 and parts[0] in _SECTIONS:
        section = current_section(parts[0], parts[1])
        if hasattr(getattr(cfg, section), parts[1]):
            return getattr(getattr(cfg, section), parts[1])
    raise ConfigError(f"unknown parameter '{dotted}'")


def load_config(path: Path | None) -> TrackerConfig:
    """Paper defaults, overridden by the TOML file at ``path`` if given."""
    if path is None:
        return TrackerConfig()
    path = Path(path)
    refuse_symlink_loop(path, "parameter file")
    if path.is_dir():
        raise ConfigError(f"parameter file {path} is a folder; pass a .toml file")
    try:
        data = tomllib.loads(path.read_text())
    except FileNotFoundError as exc:
        raise ConfigError(f"parameter file not found: {path}") from exc
    except (tomllib.TOMLDecodeError, UnicodeDecodeError) as exc:
        raise ConfigError(f"parameter file {path} is not valid TOML: {exc}") from exc
    except OSError as exc:
        raise ConfigError(f"cannot read parameter file {path}: {exc.strerror or exc}") from exc
    return config_from_dict(data)


def _toml_value(value: Any) -> str:
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, int | float):
        return repr(value)
    if isinstance(value, str):
        import json

        return json.dumps(value)
    raise ConfigError(f"cannot write {value!r} to TOML")


def dump_toml(data: Mapping[str, Any], header: Sequence[str] = ()) -> str:
    """TOML text of a nested dict of tables and scalars, ``header`` lines first as ``#`` comments; a table of
    tables only gets no header line of its own."""
    lines = [f"# {h}".rstrip() for h in header]

    def table(path: tuple[str, ...], node: Mapping[str, Any]) -> None:
        scalars = [(k, v) for k, v in node.items() if not isinstance(v, Mapping)]
        if scalars and path:
            lines.extend(["", f"[{'.'.join(path)}]"] if lines else [f"[{'.'.join(path)}]"])
        lines.extend(f"{k} = {_toml_value(v)}" for k, v in scalars)
        for k, v in node.items():
            if isinstance(v, Mapping):
                table((*path, k), v)

    table((), data)
    return "\n".join(lines) + "\n"


def dump_config(cfg: TrackerConfig) -> str:
    """TOML text of ``cfg`` that ``load_config`` reads back to an equal config."""
    return dump_toml(cfg.as_dict())
