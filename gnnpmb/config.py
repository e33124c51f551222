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
    """Per-class noise: process noise Q = diag(q_x, q_y, q_x, q_y), measurement noise R = diag(r_x, r_y)."""

    q_x: float
    q_y: float
    r_x: float
    r_y: float


PAPER_CLASS_PARAMS: dict[str, ClassParams] = {
    "car": ClassParams(0.1589, 0.1249, 0.0890, 0.0941),
    "truck": ClassParams(0.0945, 0.0946, 0.1486, 0.1445),
    "bus": ClassParams(0.1177, 0.0885, 0.1755, 0.1382),
    "trailer": ClassParams(0.0420, 0.0369, 0.2323, 0.2223),
    "pedestrian": ClassParams(0.0335, 0.0247, 0.0386, 0.0377),
    "bicycle": ClassParams(0.0199, 0.0137, 0.0539, 0.0504),
    "motorcycle": ClassParams(0.0324, 0.0387, 0.0405, 0.0399),
}


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
    poisson_prune_weight: float = 1e-3
    extraction_threshold: float = 0.9


@dataclass(frozen=True, slots=True)
class PmbmParams:
    """PMBM hypothesis management: at most n_hypotheses global hypotheses, drop those below hypothesis_prune
    (normalised weight)."""

    n_hypotheses: int = 100
    hypothesis_prune: float = 1e-4


@dataclass(frozen=True, slots=True)
class LbpParams:
    """Loopy belief propagation for marginal association probabilities (TO-PMB, JPDA)."""

    max_iterations: int = 100
    tolerance: float = 1e-7


@dataclass(frozen=True, slots=True)
class PhdParams:
    """GM-PHD / GM-CPHD mixture management (Vo & Ma 2006; Vo, Vo & Cantoni 2007)."""

    p_detect: float = 0.9
    prune_weight: float = 1e-5
    merge_threshold: float = 4.0
    max_components: int = 100
    extraction_weight: float = 0.5
    max_cardinality: int = 60


@dataclass(frozen=True, slots=True)
class VectorParams:
    """Vector-type trackers (GNN, JPDA): M/N confirmation, deletion after `delete_misses` consecutive misses."""

    p_detect: float = 0.9
    confirm_m: int = 2
    confirm_n: int = 3
    delete_misses: int = 3
    exact_cluster_max: int = 8


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
            "classes": {name: dataclasses.asdict(p) for name, p in self.classes.items()},
        }


_SECTIONS = {
    "preprocess": PreprocessParams,
    "pmb": PmbParams,
    "pmbm": PmbmParams,
    "lbp": LbpParams,
    "phd": PhdParams,
    "vector": VectorParams,
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
