"""Layout types of the synthetic demo scenes (road coordinates, motions, objects), shared by the hand-built
``mini_val`` scenes (``demo``) and the generated ``mini_train`` ones (``demo_train``)."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

SYNTHETIC_MARKER = "SYNTHETIC gnnpmb-viz demo"
"""Every demo scene description starts with this."""


@dataclass(frozen=True, slots=True)
class Segment:
    """A piece of motion: constant longitudinal acceleration and turn rate for ``duration_s``."""

    duration_s: float
    accel_mps2: float = 0.0
    yaw_rate_rps: float = 0.0


@dataclass(frozen=True, slots=True)
class Motion:
    """Start pose and speed in road coordinates, then segments; after the last one speed and heading stay."""

    s_m: float
    d_m: float
    heading_rad: float
    speed_mps: float
    segments: tuple[Segment, ...] = ()


@dataclass(frozen=True, slots=True)
class ObjectSpec:
    """One annotated object: a unique ``name`` (seeds its tokens), nuScenes category, size (w, l, h) and motion."""

    name: str
    category: str
    size_wlh_m: tuple[float, float, float]
    motion: Motion
    intensity: float


@dataclass(frozen=True, slots=True)
class SceneSpec:
    """A scene's road placement (origin (2,) global metres, heading rad), ego motion and objects."""

    name: str
    description: str
    location: str
    start_us: int
    road_origin_m: tuple[float, float]
    road_heading_rad: float
    ego: Motion
    objects: tuple[ObjectSpec, ...]

    def to_global(self, s_m: np.ndarray, d_m: np.ndarray) -> np.ndarray:
        """(..., 2) global x, y of road coordinates."""
        c, s = math.cos(self.road_heading_rad), math.sin(self.road_heading_rad)
        x = self.road_origin_m[0] + c * s_m - s * d_m
        y = self.road_origin_m[1] + s * s_m + c * d_m
        return np.stack([x, y], axis=-1)
