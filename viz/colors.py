"""Fixed class colours (an AnnotationContext at ``/``) and stable, well-separated per-track colours."""

from __future__ import annotations

import functools
import math
from collections.abc import Iterable, Sequence

import numpy as np
import rerun as rr

from gnnpmb.types import TRACKING_CLASSES

CLASS_COLORS: dict[str, tuple[int, int, int]] = {
    "bicycle": (230, 25, 75),
    "bus": (255, 225, 25),
    "car": (0, 130, 200),
    "motorcycle": (245, 130, 48),
    "pedestrian": (60, 180, 75),
    "trailer": (145, 30, 180),
    "truck": (70, 240, 240),
}
"""One colour per tracking class, fixed so every recording looks the same."""
GREY = (160, 160, 160)
"""The colour of a label whose class has no colour of its own."""

CLASS_IDS: dict[str, int] = {name: i + 1 for i, name in enumerate(TRACKING_CLASSES)}
"""Rerun class ids 1..7 in the devkit's class order (0 is left for 'unknown')."""

_GOLDEN = 0.6180339887498949
TRACK_HUE_BANDS: tuple[tuple[float, float], ...] = ((75.0 / 360, 140.0 / 360), (205.0 / 360, 250.0 / 360))
"""Hues (fractions of the colour wheel) track colours may take: greens and blues. The rest of the wheel is
reserved for markers (failures: reds, oranges, yellows, magentas; comparisons: cyans and violets), so no track is
ever drawn in a marker's colour."""
_SATURATION = np.array([0.85, 0.6, 0.95])
_VALUE = np.array([0.95, 0.8, 0.65])


def class_ids(class_names: np.ndarray) -> np.ndarray:
    """(N,) uint16 class ids of (N,) class names; 0 for names outside the tracking classes."""
    names = np.asarray(class_names, dtype=object)
    out = np.zeros(names.shape[0], dtype=np.uint16)
    for name, cid in CLASS_IDS.items():
        out[names == name] = cid
    return out


def class_colors(class_names: np.ndarray, alpha: int = 255) -> np.ndarray:
    """(N, 4) uint8 RGBA class colours of (N,) class names (grey for unknown names); alpha < 255 dims them."""
    names = np.asarray(class_names, dtype=object)
    out = np.full((names.shape[0], 4), 128, dtype=np.uint8)
    for name, rgb in CLASS_COLORS.items():
        out[names == name, :3] = rgb
    out[:, 3] = alpha
    return out


def annotation_context() -> rr.AnnotationContext:
    """Class id -> label and colour for every tracking class; log it static at ``/``."""
    return rr.AnnotationContext(
        [
            rr.ClassDescription(info=rr.AnnotationInfo(id=cid, label=name, color=CLASS_COLORS[name]))
            for name, cid in CLASS_IDS.items()
        ]
    )


def track_colors(track_ids: np.ndarray) -> np.ndarray:
    """(N, 3) uint8 RGB colours of (N,) track ids, a pure function of the id.

    Hue steps by the golden ratio per id (consecutive ids land far apart) and is mapped onto the allowed
    ``TRACK_HUE_BANDS``; saturation and value cycle over three levels so ids with nearby hues still differ in
    brightness.
    """
    ids = np.asarray(track_ids, dtype=np.int64).reshape(-1)
    h = _band_hue(np.mod(ids * _GOLDEN, 1.0))
    s = _SATURATION[np.mod(ids, 3)]
    v = _VALUE[np.mod(ids // 3, 3)]
    return (_hsv_to_rgb(h, s, v) * 255.0 + 0.5).astype(np.uint8)


_PACKED: list[np.ndarray] = [np.zeros(0, dtype=np.uint32)]
"""Packed colours of track ids 0..N-1, grown on demand (``packed_track_colors``)."""


def packed_track_colors(track_ids: np.ndarray, alpha: int = 255) -> np.ndarray:
    """(N,) uint32 0xRRGGBBAA track colours of (N,) ids: ``pack_rgba(track_colors(ids))``, for non-negative ids
    from a table that grows with the largest id seen (the logger asks for the same ids every frame); negative ids
    (GM-PHD's unlabelled components) are computed directly."""
    ids = np.asarray(track_ids, dtype=np.int64).reshape(-1)
    table = _PACKED[0]
    if ids.size and ids.max() >= table.size:
        size = max(int(ids.max()) + 1, 2 * table.size, 1024)
        _PACKED[0] = table = pack_rgba(track_colors(np.arange(size)))
    negative = ids < 0
    if negative.any():
        packed = np.empty(ids.size, dtype=np.uint32)
        packed[~negative] = table[ids[~negative]]
        packed[negative] = pack_rgba(track_colors(ids[negative]))
    else:
        packed = table[ids]
    return packed if alpha == 255 else (packed & np.uint32(0xFFFFFF00)) | np.uint32(alpha)


def pack_rgba(colors: np.ndarray, alpha: int = 255) -> np.ndarray:
    """(N, 3) RGB or (N, 4) RGBA uint8 -> (N,) uint32 0xRRGGBBAA, the layout Rerun stores (cheapest to log)."""
    c = np.asarray(colors, dtype=np.uint32).reshape(-1, colors.shape[-1])
    a = c[:, 3] if c.shape[1] == 4 else np.uint32(alpha)
    return (c[:, 0] << 24) | (c[:, 1] << 16) | (c[:, 2] << 8) | a


@functools.lru_cache(maxsize=4096)
def track_color(track_id: int) -> tuple[int, int, int]:
    """RGB colour of one track id (see ``track_colors``; looked up in ``packed_track_colors``'s table)."""
    packed = int(packed_track_colors(np.array([track_id]))[0])
    return (packed >> 24) & 0xFF, (packed >> 16) & 0xFF, (packed >> 8) & 0xFF


INVOLVED_PALETTE: tuple[tuple[int, int, int], ...] = (
    (0, 90, 230),  # blue
    (40, 170, 30),  # green
    (35, 35, 35),  # black
    (110, 170, 255),  # light blue
    (170, 220, 90),  # lime
    (15, 100, 35),  # dark green
)
"""Colours of the tracks involved in a focused failure, in the order of their ids, so that no two involved tracks
look alike (hash colours of nearby hues are hard to tell apart in a legend). Greens, blues and black, the colours
no marker uses (``TRACK_HUE_BANDS``), each far from the next in hue or brightness; tracks beyond the palette keep
their own colour."""


AVOID_DISTANCE = 130.0
"""An involved track's colour lies at least this far (RGB distance) from its class's colour, which its detections
and ground truth are drawn in."""


def involved_track_colors(
    track_ids: Iterable[int], avoid: tuple[int, int, int] | None = None
) -> dict[int, tuple[int, int, int]]:
    """Track id -> RGB for the involved tracks of a focus: ``INVOLVED_PALETTE`` in increasing id order (the same
    in every view and module that draws them), without the colours within ``AVOID_DISTANCE`` of ``avoid`` (the
    focus class's colour: a car track must not look like a car detection); the id's own ``track_color`` beyond
    the palette."""
    palette = [rgb for rgb in INVOLVED_PALETTE if avoid is None or math.dist(rgb, avoid) >= AVOID_DISTANCE]
    ordered = sorted(set(int(t) for t in track_ids))
    return {t: palette[k] if k < len(palette) else track_color(t) for k, t in enumerate(ordered)}


def _band_hue(u: np.ndarray) -> np.ndarray:
    """(N,) hues in ``TRACK_HUE_BANDS`` from (N,) uniform values in [0, 1): the bands laid end to end."""
    widths = np.array([b - a for a, b in TRACK_HUE_BANDS])
    edges = np.concatenate([[0.0], np.cumsum(widths) / widths.sum()])
    band = np.clip(np.searchsorted(edges, u, side="right") - 1, 0, len(widths) - 1)
    starts = np.array([a for a, _ in TRACK_HUE_BANDS])
    return starts[band] + (u - edges[band]) * widths.sum()


def _hsv_to_rgb(h: np.ndarray, s: np.ndarray, v: np.ndarray) -> np.ndarray:
    """(N, 3) RGB in [0, 1] from (N,) hue, saturation, value in [0, 1] (standard hexcone model)."""
    k = np.mod(np.array([5.0, 3.0, 1.0])[None, :] + h[:, None] * 6.0, 6.0)
    return v[:, None] - v[:, None] * s[:, None] * np.clip(np.minimum(k, 4.0 - k), 0.0, 1.0)


TEXT_LUMINANCE_MAX = 0.35
"""Largest luminance of a label's text: the viewer draws labels on a pale pill, on which a light colour (the
orange of a fragmentation) cannot be read (seen on the demo's camera views)."""


def luminance(rgb: Sequence[int]) -> float:
    """0.2126 R + 0.7152 G + 0.0722 B of 0..255 channels, in 0..1 (ITU-R BT.709 weights)."""
    return (0.2126 * rgb[0] + 0.7152 * rgb[1] + 0.0722 * rgb[2]) / 255.0


def readable_text(rgb: tuple[int, int, int]) -> tuple[int, int, int]:
    """``rgb`` darkened (same hue, scaled) until its ``luminance`` is at most ``TEXT_LUMINANCE_MAX``; a dark
    enough colour unchanged."""
    if luminance(rgb) <= TEXT_LUMINANCE_MAX:
        return rgb
    scale = TEXT_LUMINANCE_MAX / luminance(rgb)
    r, g, b = (int(c * scale) for c in rgb)
    return r, g, b


FADE_TO = np.array([236, 236, 236], dtype=np.float64)
"""The light grey that faded colours are mixed towards (near the viewer's white background)."""


def faded(packed: np.ndarray, keep: float) -> np.ndarray:
    """(N,) packed 0xRRGGBBAA colours mixed towards ``FADE_TO``, keeping ``keep`` (0..1) of each colour; opaque.
    Rerun draws lines with a colour's alpha darker rather than see-through on a white background, so receding
    lines are made pale instead."""
    p = np.asarray(packed, dtype=np.uint32).reshape(-1)
    rgb = np.stack([(p >> 24) & 0xFF, (p >> 16) & 0xFF, (p >> 8) & 0xFF], axis=1).astype(np.float64)
    mixed = np.rint(keep * rgb + (1.0 - keep) * FADE_TO).astype(np.uint8)
    return pack_rgba(mixed)
