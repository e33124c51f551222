"""Tracker parameters: the paper's values as defaults, overridable from one TOML file.

Defaults follow Liu et al., "GNN-PMB", IEEE T-IV 2023, sec. V-B and Table II, and the per-class noise of the
authors' public code (see ``gnnpmb/default_params.toml``, which is the editable copy of these values).
A parameter file may set any subset; unknown keys are an error so typos do not go unnoticed.
"""

from __future__ import annotations

import dataclasses
import tomllib
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from gnnpmb.errors import GnnpmbError
from gnnpmb.types import TRACKING_CLASSES


class ConfigError(GnnpmbError):
    """A parameter file that cannot be used; the message says what to fix."""


@dataclass(frozen=True, slots=True)
class ClassParams:
    """Per-class models: process noise Q = diag(q_x, q_y, q_x, q_y), measurement noise R = diag(r_x, r_y), and
    the greedy tracker's matching distance (``gnnpmb.greedy``; CenterPoint's per-class values)."""

    q_x: float
    q_y: float
    r_x: float
    r_y: float
    match_distance_m: float = 4.0


PAPER_CLASS_PARAMS: dict[str, ClassParams] = {
    "car": ClassParams(0.1589, 0.1249, 0.0890, 0.0941, 4.0),
    "truck": ClassParams(0.0945, 0.0946, 0.1486, 0.1445, 4.0),
    "bus": ClassParams(0.1177, 0.0885, 0.1755, 0.1382, 5.5),
    "trailer": ClassParams(0.0420, 0.0369, 0.2323, 0.2223, 3.0),
    "pedestrian": ClassParams(0.0335, 0.0247, 0.0386, 0.0377, 1.0),
    "bicycle": ClassParams(0.0199, 0.0137, 0.0539, 0.0504, 3.0),
    "motorcycle": ClassParams(0.0324, 0.0387, 0.0405, 0.0399, 13.0),
}
"""Q and R: the authors' GNN-PMB code; match_distance_m: CenterPoint's ``NUSCENE_CLS_VELOCITY_ERROR`` (Yin et al.
2021, ``det3d/.../pub_tracker.py``)."""


@dataclass(frozen=True, slots=True)
class PreprocessParams:
    """Detection preprocessing (paper sec. V-B, Table II)."""

    score_threshold: float = 0.1
    nms_iou_3d: float = 0.1


@dataclass(frozen=True, slots=True)
class PmbParams:
    """Shared by the Poisson multi-Bernoulli family (GNN-PMB, PMBM, TO-PMB)."""

    p_survive: float = 0.7
    clutter_intensity: float = 1e-3
    gate_chi2: float = 40.0
    birth_weight: float = 0.1
    birth_pos_std_m: float = 15.0
    birth_vel_std_mps: float = 1.0
    prune_existence: float = 1e-6
    extraction_threshold: float = 0.9


@dataclass(frozen=True, slots=True)
class PmbmParams:
    """PMBM hypothesis management (``gnnpmb.pmb.pmbm``; García-Fernández et al. 2018, sec. V).

    n_hypotheses: N_h, the most global hypotheses kept; prior hypothesis h of weight w_h gets its
    ceil(N_h w_h) best assignments (Murty). Default N_h = 100; N_h = 1 is exactly GNN-PMB.
    hypothesis_prune: global hypotheses whose normalised weight falls below it are dropped (the most likely one
    always stays).
    """

    n_hypotheses: int = 100
    hypothesis_prune: float = 1e-4

    def __post_init__(self) -> None:
        if self.n_hypotheses < 1:
            raise ConfigError(f"[pmbm] n_hypotheses must be at least 1, got {self.n_hypotheses}")
        if not 0.0 <= self.hypothesis_prune < 1.0:
            raise ConfigError(f"[pmbm] hypothesis_prune must be in [0, 1), got {self.hypothesis_prune}")


@dataclass(frozen=True, slots=True)
class LbpParams:
    """Loopy belief propagation for marginal association probabilities (TO-PMB, JPDA; ``gnnpmb.assign.lbp``,
    Williams & Lau 2014).

    max_iterations: at most this many message-passing rounds (>= 1); tolerance: stop once no marginal
    probability changes by more than this between two rounds (> 0). On the demo scenes TO-PMB's LBP stops after
    2 rounds (median; 8 at most), so the cap is a safeguard rather than a speed setting.
    """

    max_iterations: int = 100
    tolerance: float = 1e-7

    def __post_init__(self) -> None:
        if self.max_iterations < 1:
            raise ConfigError(f"[lbp] max_iterations must be at least 1, got {self.max_iterations}")
        if not self.tolerance > 0.0:
            raise ConfigError(f"[lbp] tolerance must be > 0, got {self.tolerance}")


@dataclass(frozen=True, slots=True)
class PhdParams:
    """GM-PHD / GM-CPHD filters (``gnnpmb.phd``; Vo & Ma 2006; Vo, Vo & Cantoni 2007).

    p_detect: detection probability P_D in (0, 1] of a persistent component (a measurement-driven birth component
    is detected by construction). prune_weight: components lighter than this are dropped (Vo & Ma Table II, T).
    merge_threshold: components within this squared Mahalanobis distance (4-D state) of a heavier one are merged
    into it (U). max_components: at most this many components are kept per class (J_max). extraction_weight: the
    PHD filter reports every component at least this heavy, round(w) times (Table III). max_cardinality: hard
    upper bound of the CPHD cardinality support per class; below it the support follows the previous posterior
    plus the birth count, so most frames use far fewer terms (median 7, at most 21 on the demo scenes); the CPHD
    reports at most this many tracks per class. Survival, gate, clutter intensity and birth come from ``[pmb]``
    so every tracker of the study sees the same models. T, U, J_max and the 0.5 extraction weight are Vo & Ma's.
    """

    p_detect: float = 0.9
    prune_weight: float = 1e-5
    merge_threshold: float = 4.0
    max_components: int = 100
    extraction_weight: float = 0.5
    max_cardinality: int = 100

    def __post_init__(self) -> None:
        if not 0.0 < self.p_detect <= 1.0:
            raise ConfigError(f"[phd] p_detect must be in (0, 1], got {self.p_detect}")
        if not self.prune_weight >= 0.0:
            raise ConfigError(f"[phd] prune_weight must be >= 0, got {self.prune_weight}")
        if not self.merge_threshold >= 0.0:
            raise ConfigError(f"[phd] merge_threshold must be >= 0, got {self.merge_threshold}")
        if self.max_components < 1:
            raise ConfigError(f"[phd] max_components must be at least 1, got {self.max_components}")
        if not self.extraction_weight > 0.0:
            raise ConfigError(f"[phd] extraction_weight must be > 0, got {self.extraction_weight}")
        if self.max_cardinality < 1:
            raise ConfigError(f"[phd] max_cardinality must be at least 1, got {self.max_cardinality}")


@dataclass(frozen=True, slots=True)
class VectorParams:
    """Vector-type trackers (GNN, JPDA; ``gnnpmb.vector``).

    p_detect: constant detection probability P_D in (0, 1) of the association likelihoods (Blackman & Popoli
    1999, ch. 6; Bar-Shalom, Daum & Huang 2009). confirm_m / confirm_n: a tentative track is confirmed once it
    has confirm_m hits within its first confirm_n frames (the birth frame counts as a hit) and deleted as soon
    as it can no longer get there. delete_misses: a confirmed track is deleted after this many consecutive
    misses. exact_cluster_max: JPDA enumerates a gated cluster exactly when it has at most this many tracks
    (and at most ``vector.jpda.EXACT_ASSOCIATION_BUDGET`` joint events), otherwise it uses loopy belief
    propagation (``[lbp]``). The gate, clutter intensity kappa and
    the initial covariance of a new track come from ``[pmb]`` (gate_chi2, clutter_intensity, birth_pos_std_m,
    birth_vel_std_mps), so every tracker of the study sees the same gate and clutter model.
    """

    p_detect: float = 0.9
    confirm_m: int = 2
    confirm_n: int = 3
    delete_misses: int = 3
    exact_cluster_max: int = 8

    def __post_init__(self) -> None:
        if not 0.0 < self.p_detect < 1.0:
            raise ConfigError(f"[vector] p_detect must be strictly between 0 and 1, got {self.p_detect}")
        if not 1 <= self.confirm_m <= self.confirm_n <= 62:
            raise ConfigError(
                f"[vector] need 1 <= confirm_m <= confirm_n <= 62, got confirm_m = {self.confirm_m}, "
                f"confirm_n = {self.confirm_n}"
            )
        if self.delete_misses < 1:
            raise ConfigError(f"[vector] delete_misses must be at least 1, got {self.delete_misses}")
        if self.exact_cluster_max < 1:
            raise ConfigError(f"[vector] exact_cluster_max must be at least 1, got {self.exact_cluster_max}")


@dataclass(frozen=True, slots=True)
class GreedyParams:
    """The greedy closest-pair baseline (``gnnpmb.greedy``; CenterPoint, Yin et al. 2021).

    max_age: a track missed this many frames in a row is deleted (CenterPoint's nuScenes setting: 3).
    """

    max_age: int = 3

    def __post_init__(self) -> None:
        if self.max_age < 1:
            raise ConfigError(f"[greedy] max_age must be at least 1, got {self.max_age}")


@dataclass(frozen=True, slots=True)
class TrackerConfig:
    """Everything a tracker needs; one instance for all classes."""

    classes: dict[str, ClassParams] = field(default_factory=lambda: dict(PAPER_CLASS_PARAMS))
    preprocess: PreprocessParams = PreprocessParams()
    pmb: PmbParams = PmbParams()
    pmbm: PmbmParams = PmbmParams()
    lbp: LbpParams = LbpParams()
    phd: PhdParams = PhdParams()
    vector: VectorParams = VectorParams()
    greedy: GreedyParams = GreedyParams()

    def for_class(self, class_name: str) -> ClassParams:
        return self.classes[class_name]

    def replace(self, **changes: Any) -> TrackerConfig:
        return dataclasses.replace(self, **changes)

    def as_dict(self) -> dict[str, Any]:
        """Plain nested dict (for provenance and TOML output)."""
        return {
            "preprocess": dataclasses.asdict(self.preprocess),
            "pmb": dataclasses.asdict(self.pmb),
            "pmbm": dataclasses.asdict(self.pmbm),
            "lbp": dataclasses.asdict(self.lbp),
            "phd": dataclasses.asdict(self.phd),
            "vector": dataclasses.asdict(self.vector),
            "greedy": dataclasses.asdict(self.greedy),
            "classes": {name: dataclasses.asdict(p) for name, p in self.classes.items()},
        }


_SECTIONS = {
    "preprocess": PreprocessParams,
    "pmb": PmbParams,
    "pmbm": PmbmParams,
    "lbp": LbpParams,
    "phd": PhdParams,
    "vector": VectorParams,
    "greedy": GreedyParams,
}


def _typed_section(kind: type, values: dict[str, Any], where: str, base: Any) -> Any:
    known = {f.name: f for f in dataclasses.fields(kind)}
    changes = {}
    for key, value in values.items():
        if key not in known:
            raise ConfigError(f"{where}: unknown parameter '{key}' (known: {', '.join(sorted(known))})")
        want = int if known[key].type in ("int", int) else float
        if isinstance(value, bool) or not isinstance(value, int | float):
            raise ConfigError(f"{where}.{key}: expected a number, got {value!r}")
        if want is int and not float(value).is_integer():
            raise ConfigError(f"{where}.{key}: expected an integer, got {value!r}")
        changes[key] = want(value)
    return dataclasses.replace(base, **changes)


def config_from_dict(data: dict[str, Any], base: TrackerConfig | None = None) -> TrackerConfig:
    """Apply a nested dict of overrides (the TOML layout) to ``base`` (paper defaults if None)."""
    cfg = base or TrackerConfig()
    changes: dict[str, Any] = {}
    for key, values in data.items():
        if key == "classes":
            if not isinstance(values, dict):
                raise ConfigError("[classes] must be a table of per-class tables")
            classes = dict(cfg.classes)
            for name, cvalues in values.items():
                if name not in TRACKING_CLASSES:
                    raise ConfigError(f"[classes.{name}]: unknown class (known: {', '.join(TRACKING_CLASSES)})")
                classes[name] = _typed_section(ClassParams, cvalues, f"[classes.{name}]", classes[name])
            changes["classes"] = classes
        elif key in _SECTIONS:
            if not isinstance(values, dict):
                raise ConfigError(f"[{key}] must be a table")
            changes[key] = _typed_section(_SECTIONS[key], values, f"[{key}]", getattr(cfg, key))
        else:
            raise ConfigError(f"unknown section [{key}] (known: classes, {', '.join(_SECTIONS)})")
    return cfg.replace(**changes)


def load_config(path: Path | None) -> TrackerConfig:
    """Paper defaults, overridden by the TOML file at ``path`` if given."""
    if path is None:
        return TrackerConfig()
    try:
        data = tomllib.loads(Path(path).read_text())
    except FileNotFoundError as exc:
        raise ConfigError(f"parameter file not found: {path}") from exc
    except (tomllib.TOMLDecodeError, UnicodeDecodeError) as exc:
        raise ConfigError(f"parameter file {path} is not valid TOML: {exc}") from exc
    return config_from_dict(data)


def dump_config(cfg: TrackerConfig) -> str:
    """TOML text of ``cfg`` that ``load_config`` reads back to an equal config."""
    out: list[str] = []
    d = cfg.as_dict()
    for section in _SECTIONS:
        out.append(f"[{section}]")
        out.extend(f"{k} = {v!r}" for k, v in d[section].items())
        out.append("")
    for name, values in d["classes"].items():
        out.append(f"[classes.{name}]")
        out.extend(f"{k} = {v!r}" for k, v in values.items())
        out.append("")
    return "\n".join(out)
