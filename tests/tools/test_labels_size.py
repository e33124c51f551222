"""One size for a label everywhere: the focus column (``viz.callouts``), the full recording's room
(``viz.label_room``), the camera labels and the check (``tools.labels``) all use ``viz.label_size``, whose widths
are the ones measured in the web viewer at 1920 x 1080."""

from __future__ import annotations

import numpy as np
import pytest

from viz.callouts import M_PER_PX_PER_HEIGHT, half_widths_m
from viz.label_size import HEIGHT_PX, text_box, width_px

MEASURED_PX = {9: 74, 19: 135, 20: 140, 37: 236, 44: 270}
"""Label widths with their background, measured on web-viewer screenshots (``viz.label_size``)."""


@pytest.mark.parametrize(("chars", "measured"), sorted(MEASURED_PX.items()))
def test_a_labels_width_is_the_measured_one(chars: int, measured: int) -> None:
    assert abs(width_px(chars) - measured) <= 0.03 * measured


def test_the_check_the_room_and_the_column_agree_on_a_labels_box() -> None:
    import tools.labels
    import viz.camera_boxes
    import viz.label_room

    assert tools.labels.text_box is text_box and viz.label_room.text_box is text_box
    assert viz.camera_boxes.text_box is text_box
    x0, y0, x1, y1 = text_box("8 predicted → m3", 100.0, 50.0)
    np.testing.assert_allclose([x1 - x0, y1 - y0, 0.5 * (x0 + x1)], [width_px(16), HEIGHT_PX, 100.0])
    m_per_px = M_PER_PX_PER_HEIGHT * 18.0
    np.testing.assert_allclose(2 * half_widths_m(np.array([16]), m_per_px), [width_px(16) * m_per_px])
