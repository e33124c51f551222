"""``viz.legend.place_legend``: a legend corner that covers no line, or room made for it above the lines."""

from __future__ import annotations

import numpy as np
import pytest
import rerun.blueprint as rrb

from viz.legend import PROBABILITY_RANGE, LegendPlacement, existence_range, legend_height, place_legend

Corner = rrb.components.Corner2D


def line(x: list[float], y: list[float]) -> tuple[np.ndarray, np.ndarray]:
    return np.array(x, dtype=np.float64), np.array(y, dtype=np.float64)


def test_the_legend_height_grows_with_its_rows_up_to_a_cap() -> None:
    assert legend_height(1, 100.0) == (10.0 + 21.0) / 100.0
    assert legend_height(4, 180.0) > legend_height(2, 180.0)
    assert legend_height(40, 180.0) == 0.75


def test_a_corner_no_line_passes_through_is_taken_in_order_of_preference() -> None:
    low = line([0, 10], [0, 0])  # along the bottom: both bottom corners hold data
    assert place_legend([low, line([0, 4], [1, 1])]) == LegendPlacement(Corner.RightTop)  # high on the left
    assert place_legend([low, line([6, 10], [1, 1])]) == LegendPlacement(Corner.LeftTop)  # high on the right
    high = line([0, 10], [1, 1])
    assert place_legend([high, line([0, 4], [0, 0])]) == LegendPlacement(Corner.RightBottom)


def test_a_line_crossing_a_corner_between_its_points_occupies_it() -> None:
    # Two points only, at the bottom left and the top right: the straight line between them crosses neither
    # top-left nor bottom-right box, but it ends in the top-right one.
    diagonal = line([0, 10], [0, 1])
    assert place_legend([diagonal], 1) == LegendPlacement(Corner.LeftTop)
    # A rise late in the plot (a track confirmed at the last frame) occupies the top right.
    rise = line([0, 8, 9, 10], [0.1, 0.1, 0.1, 1.0])
    assert place_legend([rise, line([0, 10], [0.5, 0.5])], 3).corner is Corner.LeftTop


def test_when_every_corner_holds_data_the_y_range_leaves_the_top_band_to_the_legend() -> None:
    lines = [line([0, 10], [0, 0]), line([0, 10], [1, 1])]
    placed = place_legend(lines, 3)
    assert placed.corner is Corner.RightTop and placed.y_range is not None
    lo, hi = placed.y_range
    height = legend_height(3)
    # The highest line, in the new range, ends below the legend's box.
    assert (1.0 - lo) / (hi - lo) < 1.0 - height
    assert lo < 0.0  # and the lowest line keeps a margin above the plot's bottom
    args = placed.view_args()
    assert set(args) == {"plot_legend", "axis_y"}


def test_gaps_and_empty_plots() -> None:
    assert place_legend([]) == LegendPlacement(Corner.RightTop)
    assert place_legend([line([0, 1], [np.nan, np.nan])]) == LegendPlacement(Corner.RightTop)
    # NaN samples are skipped: the line's finite points alone decide.
    gap = line([0, 5, 10], [0.0, np.nan, 0.0])
    assert place_legend([gap, line([0, 10], [1, 1])], 2).corner is Corner.RightTop
    assert place_legend([gap, line([0, 10], [1, 1])], 2).y_range is not None
    single = line([3], [0.5])  # one point, in the middle: every corner is free
    assert place_legend([single]) == LegendPlacement(Corner.RightTop)


def test_a_fixed_range_is_kept_and_the_least_covered_corner_taken() -> None:
    # Existence of a healthy track (top, whole width) and a starving one (falling to 0 on the right).
    healthy = line([0, 10], [0.95, 0.95])
    starving = line([0, 4, 10], [0.9, 0.9, 0.0])
    placed = place_legend([healthy, starving], 3, y_range=(-0.02, 1.02))
    assert placed.y_range == (-0.02, 1.02)
    assert placed.corner is Corner.LeftBottom  # the only corner no line passes through
    full = [line([0, 10], [0.0, 0.0]), line([0, 10], [1.0, 1.0]), line([0, 2, 10], [0.5, 0.98, 0.98])]
    crowded = place_legend(full, 3, y_range=(-0.02, 1.02))
    assert crowded.y_range == (-0.02, 1.02)  # never stretched
    assert crowded.corner in (Corner.RightBottom, Corner.LeftBottom)  # the top holds two lines, the bottom one


def test_with_every_corner_taken_the_legend_spares_the_last_frame(monkeypatch: pytest.MonkeyPatch) -> None:
    """The dev set's phd id_switch:1 shape: a line at the top, a dip early at the bottom left, and a fall below
    the threshold at the failure frame, the last, at the bottom right."""
    weight = line([1, 2, 3, 4, 11, 12, 13], [1.0, 0.1, 0.87, 1.0, 1.0, 0.83, 0.32])
    threshold = line([0, 13], [0.5, 0.5])
    started = line([13], [0.64])
    lines = [weight, threshold, started]
    assert place_legend(lines, 3, y_range=(-0.02, 1.02), past_frames=1).corner is Corner.LeftBottom
    # Counted as any other sample, the fall (fewer samples in the box than the early dip's) would be covered.
    monkeypatch.setattr("viz.legend.LAST_FRAME_WEIGHT", 1)
    assert place_legend(lines, 3, y_range=(-0.02, 1.02), past_frames=1).corner is Corner.RightBottom


def test_an_existence_plot_of_tracks_that_all_stay_low_is_zoomed_to_them() -> None:
    assert existence_range([np.array([0.1, 0.9]), np.array([0.02])]) == PROBABILITY_RANGE
    low = existence_range([np.array([0.03, 0.01]), np.array([0.07, 0.0]), np.array([])])
    assert low == pytest.approx((PROBABILITY_RANGE[0] * 0.07, PROBABILITY_RANGE[1] * 0.07))
    assert existence_range([np.zeros(3)]) == pytest.approx((PROBABILITY_RANGE[0] * 0.01, PROBABILITY_RANGE[1] * 0.01))
    assert existence_range([]) == PROBABILITY_RANGE


def test_near_the_scenes_start_the_legend_is_placed_for_the_axis_the_view_shows() -> None:
    """A focus at frame 3 shows frames 0-9 (``viz.blueprint.focus_axis_frames``): placed for the lines' own 0-4,
    the legend went top left, where in the real plot it hid the two lines it named near 1.0 at frames 1-3 (demo
    scene-9001 cphd ``--focus identity_theft:1``, tracks 4 and 7); placed for the axis, it avoids them."""
    from types import SimpleNamespace

    from viz.blueprint import focus_axis_frames

    axis = focus_axis_frames(SimpleNamespace(frame_index=3))
    assert axis == (0, 9)
    lines = [
        (np.array([0.0, 1.0, 2.0, 3.0]), np.array([0.18, 0.33, 0.30, 0.04])),  # track 2's weight
        (np.array([1.0, 2.0, 3.0]), np.array([0.69, 1.0, 1.0])),  # track 4's, capped at 1
        (np.array([2.0, 3.0]), np.array([0.73, 1.0])),  # track 7's
        (np.array([0.0, 1.0, 2.0, 3.0]), np.full(4, 0.5)),  # the threshold line
    ]
    placed = place_legend(lines, 4, y_range=PROBABILITY_RANGE, x_range=axis)
    assert placed.corner == rrb.components.Corner2D.RightTop  # frames 4-9 of the plot hold no line
    for_data = place_legend(lines, 4, y_range=PROBABILITY_RANGE, past_frames=1)  # as placed before, for 0-4
    assert for_data.corner == rrb.components.Corner2D.LeftTop  # where lines 4 and 7 run in the real plot
