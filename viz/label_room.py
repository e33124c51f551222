"""Room for labels in the bird's-eye view: which of a frame's labels fit side by side without covering each other.

Rerun draws a 3D label centred under its anchor in screen space, at a fixed font size, so in the full recording's
bird's-eye camera (``BEV_EYE_POSITION_M``: 80 m above a point ahead of the ego car, Rerun's default
``FOV_Y_DEG``, forward up the screen) a label of 15 characters spans about 25 m of ground: two failures a few
metres apart would print one label over the other. ``keep_apart`` goes through a frame's labels by rank (the
failure kinds' order, ``gnnpmb.eval.failures.OPEN_FIRST``) and keeps one only if its text box, projected to the
ground in the ego frame, stays clear of the ones already kept; a label left out keeps its box, colour and marker,
and its words stay a click away (Rerun shows them on hover).

The text box is estimated as ``tools.labels`` does it for the check: ``CHAR_PX`` per character, ``HEIGHT_PX``
tall, in a bird's-eye view ``VIEW_HEIGHT_PX`` tall (the default layout at 1920 x 1080).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from gnnpmb.data.scene import Pose

BEV_EYE_POSITION_M = (12.0, 0.0, 80.0)
BEV_TARGET_M = (12.0, 0.0, 0.0)
"""Bird's-eye camera in the ego frame: straight down on a point 12 m ahead, forward pointing up the screen."""
FOV_Y_DEG = 55.0
"""Vertical field of view of Rerun's default 3D eye."""
VIEW_HEIGHT_PX = 380.0
"""Height of the full recording's bird's-eye view at 1920 x 1080 (measured on the web viewer's screenshots)."""
CHAR_PX = 7.0
HEIGHT_PX = 18.0
PAD_PX = 4.0
CLEARANCE_PX = 4.0
"""Air kept between two labels' text boxes."""


@dataclass(frozen=True, slots=True)
class Candidate:
    """A label that would be shown: its rank (lower is kept first), a key the caller knows it by, its text and
    its anchor's global x, y (metres)."""

    rank: int
    key: object
    text: str
    xy_global_m: tuple[float, float]


def px_per_m(height_m: float = BEV_EYE_POSITION_M[2]) -> float:
    """Screen pixels per metre of ground seen from ``height_m`` above it in the bird's-eye view."""
    focal_px = 0.5 * VIEW_HEIGHT_PX / math.tan(math.radians(FOV_Y_DEG) / 2)
    return focal_px / height_m


def _screen_box(c: Candidate, ego: Pose, scale: float) -> tuple[float, float, float, float]:
    """(x0, y0, x1, y1) in pixels, screen x to the right (-y of the ego frame), screen y down (-x of the ego
    frame), relative to the ego car."""
    w, x, y, z = (float(v) for v in ego.quat_wxyz)
    yaw = math.atan2(2 * (w * z + x * y), 1 - 2 * (y * y + z * z))
    d = np.asarray(c.xy_global_m, dtype=np.float64) - np.asarray(ego.translation_m[:2], dtype=np.float64)
    fwd = d[0] * math.cos(yaw) + d[1] * math.sin(yaw)
    left = -d[0] * math.sin(yaw) + d[1] * math.cos(yaw)
    sx, sy = -left * scale, -fwd * scale
    half = 0.5 * (CHAR_PX * len(c.text) + 2 * PAD_PX)
    return sx - half, sy + 3.0, sx + half, sy + 3.0 + HEIGHT_PX


def keep_apart(candidates: Sequence[Candidate], ego: Pose) -> set[object]:
    """The keys of the labels to show at one frame (module docstring): by rank, then in the given order, each
    kept when its text box is at least ``CLEARANCE_PX`` from every one kept before."""
    scale = px_per_m()
    kept: list[tuple[float, float, float, float]] = []
    keys: set[object] = set()
    for c in sorted(candidates, key=lambda c: c.rank):
        box = _screen_box(c, ego, scale)
        if all(
            box[0] >= k[2] + CLEARANCE_PX
            or k[0] >= box[2] + CLEARANCE_PX
            or box[1] >= k[3] + CLEARANCE_PX
            or k[1] >= box[3] + CLEARANCE_PX
            for k in kept
        ):
            kept.append(box)
            keys.add(c.key)
    return keys
