"""Room for labels in the full recording's 3D views: which of a frame's labels fit side by side without covering
each other, in the bird's-eye and in the perspective view.

Rerun draws a 3D label centred under its anchor in screen space, at a fixed font size, so in the full recording's
bird's-eye camera (``BEV_EYE_POSITION_M``: 80 m above a point ahead of the ego car, Rerun's default
``FOV_Y_DEG``, forward up the screen) a label of 15 characters spans about 25 m of ground: two failures a few
metres apart would print one label over the other; the perspective camera (``EYE_POSITION_M``, behind and above
the car) squeezes the ground ahead further. ``keep_apart`` goes through a frame's labels by rank (the failure
kinds' order, ``gnnpmb.eval.failures.OPEN_FIRST``) and keeps one only if its text box, projected with each view's
camera in the ego frame, stays clear of the ones already kept in every view; a label left out keeps its box,
colour and marker, and its words stay a click away (Rerun shows them on hover).

The text box is the one ``viz.label_size`` measured in the web viewer (``tools.labels`` checks with it too), in
views as tall as the layout at 1920 x 1080 makes them (``VIEW_HEIGHT_PX`` for the bird's-eye view without
cameras; ``viz.opening.view_heights_px`` for the layout at hand).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from gnnpmb.data.scene import Pose
from viz.label_size import CLEARANCE_PX, text_box

BEV_EYE_POSITION_M = (6.0, 0.0, 80.0)
BEV_TARGET_M = (6.0, 0.0, 0.0)
BEV_UP = (1.0, 0.0, 0.0)
"""Bird's-eye camera in the ego frame: straight down on a point 6 m ahead, forward pointing up the screen (the
labels, centred under their boxes, then run across the road, where the wide view has room for them)."""
EYE_POSITION_M = (-18.0, -14.0, 22.0)
EYE_TARGET_M = (10.0, 0.0, 0.0)
"""Default camera of the perspective views in the ego frame (x forward, z up): behind, left of and above the car,
looking at a point 10 m ahead. The views' origin is the ego vehicle, so the camera follows the car."""
FOV_Y_DEG = 55.0
"""Vertical field of view of Rerun's default 3D eye."""
VIEW_HEIGHT_PX = 380.0
"""Height of the full recording's bird's-eye view at 1920 x 1080 without cameras (measured on the web viewer's
screenshots); with the camera grid below it is smaller (``viz.opening.view_heights_px``)."""
PERSPECTIVE_HEIGHT_PX = 255.0
"""The same for the perspective view (its share 4 against the bird's-eye view's 6)."""
VIEW_WIDTH_PX = 576.0
"""Width of each run's 3D views in a two-run recording at 1920 x 1080 (3/5 of the width, halved)."""
LABEL_Z_M = 1.0
"""Height above the ego frame's ground a label's anchor (a box centre) is taken at."""


@dataclass(frozen=True, slots=True)
class Candidate:
    """A label that would be shown: its rank (lower is kept first), a key the caller knows it by, its text and
    its anchor's global x, y (and z) in metres."""

    rank: int
    key: object
    text: str
    xy_global_m: tuple[float, float]
    z_global_m: float | None = None
    """The anchor's height (a box centre's); None: ``LABEL_Z_M`` above the ego frame's ground."""


@dataclass(frozen=True, slots=True)
class Eye:
    """A 3D view's default camera in the ego frame (position, look target, up) and its size in pixels."""

    position_m: tuple[float, float, float]
    target_m: tuple[float, float, float]
    up: tuple[float, float, float]
    height_px: float
    width_px: float = VIEW_WIDTH_PX

    def cuts(self, box: tuple[float, float, float, float], anchor: tuple[float, float]) -> bool:
        """Whether the view's edge cuts off a text box (screen pixels from the view's centre) whose anchor is
        inside the view, or leaves it less than ``CLEARANCE_PX`` (the anchor's height is an estimate,
        ``LABEL_Z_M``: a pixel either way)."""
        w, h = 0.5 * self.width_px, 0.5 * self.height_px
        if not (-w <= anchor[0] <= w and -h <= anchor[1] <= h):
            return False
        w, h = w - CLEARANCE_PX, h - CLEARANCE_PX
        return box[0] < -w or box[2] > w or box[1] < -h or box[3] > h

    def screen_px(self, point_ego_m: np.ndarray) -> tuple[float, float] | None:
        """A point in the ego frame -> screen pixels relative to the view's centre (x right, y down); None
        behind the camera."""
        eye, target, up = (np.asarray(v, dtype=np.float64) for v in (self.position_m, self.target_m, self.up))
        forward = (target - eye) / np.linalg.norm(target - eye)
        right = np.cross(forward, up)
        right /= np.linalg.norm(right)
        screen_up = np.cross(right, forward)
        d = point_ego_m - eye
        depth = float(d @ forward)
        if depth <= 0:
            return None
        focal = 0.5 * self.height_px / math.tan(math.radians(FOV_Y_DEG) / 2)
        return focal * float(d @ right) / depth, -focal * float(d @ screen_up) / depth


def eyes(
    bev_height_px: float = VIEW_HEIGHT_PX,
    perspective_height_px: float = PERSPECTIVE_HEIGHT_PX,
    width_px: float = VIEW_WIDTH_PX,
) -> tuple[Eye, ...]:
    """The full recording's bird's-eye and perspective cameras at these view sizes."""
    return (
        Eye(BEV_EYE_POSITION_M, BEV_TARGET_M, BEV_UP, bev_height_px, width_px),
        Eye(EYE_POSITION_M, EYE_TARGET_M, (0.0, 0.0, 1.0), perspective_height_px, width_px),
    )


def px_per_m(height_m: float = BEV_EYE_POSITION_M[2], view_height_px: float = VIEW_HEIGHT_PX) -> float:
    """Screen pixels per metre of ground seen from ``height_m`` above it in a bird's-eye view ``view_height_px``
    tall."""
    focal_px = 0.5 * view_height_px / math.tan(math.radians(FOV_Y_DEG) / 2)
    return focal_px / height_m


def to_ego(xy_global_m: tuple[float, float], ego: Pose, z_m: float = LABEL_Z_M) -> np.ndarray:
    """A global x, y -> the ego frame (x forward, y left), at height ``z_m``."""
    w, x, y, z = (float(v) for v in ego.quat_wxyz)
    yaw = math.atan2(2 * (w * z + x * y), 1 - 2 * (y * y + z * z))
    d = np.asarray(xy_global_m, dtype=np.float64) - np.asarray(ego.translation_m[:2], dtype=np.float64)
    fwd = d[0] * math.cos(yaw) + d[1] * math.sin(yaw)
    left = -d[0] * math.sin(yaw) + d[1] * math.cos(yaw)
    return np.array([fwd, left, z_m])


def keep_apart(candidates: Sequence[Candidate], ego: Pose, views: Sequence[Eye] | None = None) -> set[object]:
    """The keys of the labels to show at one frame (module docstring): by rank, then in the given order, each
    kept when its text box is at least ``CLEARANCE_PX`` from every one kept before in each of ``views`` (default:
    ``eyes()``) and not cut off by a view's edge (half a label reads as something else); a label behind a view's
    camera does not count there."""
    kept: set[object] = set(c.key for c in candidates)
    for eye in views if views is not None else eyes():
        boxes = []
        for c in candidates:
            z_m = LABEL_Z_M if c.z_global_m is None else c.z_global_m - float(ego.translation_m[2])
            at = eye.screen_px(to_ego(c.xy_global_m, ego, z_m))
            if at is None:
                continue
            box = text_box(c.text, *at)
            if eye.cuts(box, at):
                kept.discard(c.key)
            else:
                boxes.append((c.rank, c.key, box))
        shown = keep_clear([b for b in sorted(boxes, key=lambda b: b[0]) if b[1] in kept])
        kept = {c.key for c in candidates if c.key in shown or c.key not in {b[1] for b in boxes}} & kept
    return kept


def keep_clear(boxes: Sequence[tuple[int, object, tuple[float, float, float, float]]]) -> set[object]:
    """The keys of the (rank, key, screen text box) to show: by rank, then in the given order, each kept when its
    box is at least ``CLEARANCE_PX`` from every one kept before."""
    kept: list[tuple[float, float, float, float]] = []
    keys: set[object] = set()
    for _, key, box in sorted(boxes, key=lambda b: b[0]):
        if all(
            box[0] >= k[2] + CLEARANCE_PX
            or k[0] >= box[2] + CLEARANCE_PX
            or box[1] >= k[3] + CLEARANCE_PX
            or k[1] >= box[3] + CLEARANCE_PX
            for k in kept
        ):
            kept.append(box)
            keys.add(key)
    return keys
