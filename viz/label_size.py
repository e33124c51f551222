"""The size of a label as Rerun 0.41's web viewer draws it at 1920 x 1080: the one estimate every label layout
(``viz.callouts``, ``viz.label_room``, ``viz.camera_boxes``) and the label check (``tools.labels``) use.

Rerun draws a label's text on a rounded background, centred under its anchor in screen space, at a fixed font
size whatever the zoom. Measured on web-viewer screenshots at 1920 x 1080: labels of 9, 19, 20, 37 and 44
characters were 74, 135, 140, 236 and 270 px wide with their background (dev set scene-0916, megvii,
``diff:introduced:38``, and ``--tracker phd --focus id_switch:1``), and the background 22 px tall.
"""

from __future__ import annotations

import numpy as np

CHAR_PX = 5.8
"""Width of one label character in pixels."""
PAD_PX = 11.0
"""The label's background beyond its text on each side, in pixels."""
HEIGHT_PX = 22.0
"""Height of a label with its background, in pixels."""
CLEARANCE_PX = 4.0
"""Air kept between two labels' boxes (and between a label and a view's edge)."""
BELOW_ANCHOR_PX = 3.0
"""The label's top edge lies this far below its anchor."""


def width_px(chars: float | np.ndarray) -> float | np.ndarray:
    """Width in pixels of a label of ``chars`` characters (a number, or an array of them), with its background."""
    return CHAR_PX * chars + 2.0 * PAD_PX


def text_box(text: str, x_px: float, y_px: float) -> tuple[float, float, float, float]:
    """(x0, y0, x1, y1): the box Rerun draws for ``text`` anchored at screen pixel (x, y), centred under it."""
    half = 0.5 * float(width_px(len(text)))
    return x_px - half, y_px + BELOW_ANCHOR_PX, x_px + half, y_px + BELOW_ANCHOR_PX + HEIGHT_PX
