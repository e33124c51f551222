"""Room for labels in the full recording's 3D views (``viz.label_room``): kept apart in the perspective view as in
the bird's-eye view, and never cut off by a view's edge; the focus callouts' column on the side that has room."""

from __future__ import annotations

import numpy as np
import pytest

from gnnpmb.data.scene import Pose
from viz.callouts import M_PER_PX_PER_HEIGHT, column_positions, half_widths_m
from viz.label_room import LABEL_Z_M, Candidate, eyes, keep_apart, px_per_m

IDENTITY = Pose(np.zeros(3), np.array([1.0, 0.0, 0.0, 0.0]))


def test_a_label_the_views_edge_would_cut_is_left_out() -> None:
    bev = eyes()[:1]
    half_height_m = 0.5 * bev[0].height_px / px_per_m()
    near_edge = Candidate(0, "edge", "9 · ID switch, was 4", (bev[0].target_m[0] - half_height_m + 1.0, 0.0))
    inside = Candidate(0, "inside", "9 · ID switch, was 4", (bev[0].target_m[0], 0.0))
    assert keep_apart([near_edge, inside], IDENTITY, bev) == {"inside"}  # its text would run below the view


def test_labels_apart_from_above_but_on_one_line_of_sight_in_the_perspective_view_keep_one() -> None:
    bev, perspective = eyes()
    # 10 m apart on a line of sight of the perspective camera: apart from above, one over the other from behind
    eye = np.array(perspective.position_m[:2])
    ahead = (np.array(perspective.target_m[:2]) - eye) / np.linalg.norm(np.array(perspective.target_m[:2]) - eye)
    a, b = eye + 50.0 * ahead, eye + 60.0 * ahead
    pair = [Candidate(0, "first", "7 · false track", tuple(a)), Candidate(1, "second", "8 · false track", tuple(b))]
    assert keep_apart(pair, IDENTITY, (bev,)) == {"first", "second"}
    assert keep_apart(pair, IDENTITY) == {"first"}


def test_the_callout_column_goes_left_when_only_there_it_stays_in_view() -> None:
    anchors = np.array([[10.0, 0.0], [10.2, 0.5]])
    chars = np.array([30, 12])
    height_m = 18.0
    free = column_positions(anchors, chars, height_m)
    assert np.all(free[:, 0] > anchors[:, 0].max())
    half_label_m = half_widths_m(np.array([30]), M_PER_PX_PER_HEIGHT * height_m)[0]
    tight = column_positions(anchors, chars, height_m, (-5.0, free[0, 0] + half_label_m - 1.0))  # right cut
    assert np.all(tight[:, 0] < anchors[:, 0].min())


def test_the_failure_index_lists_a_rows_ids_when_other_rows_took_numbers_between() -> None:
    from viz.opening import id_span

    assert id_span(["miss:4"]) == "miss:4"
    assert id_span(["miss:4", "miss:5", "miss:6"]) == "miss:4 … miss:6"
    ids = ["false_track:3", "false_track:4", "false_track:5", "false_track:9", "false_track:12", "false_track:13"]
    assert id_span(ids) == "false_track:3–5, 9, 12–13"  # not "false_track:3 … false_track:13"


def test_when_neither_side_has_room_the_column_goes_where_less_is_cut() -> None:
    anchors = np.array([[0.0, 0.0]])
    chars = np.array([40])  # a column about 12 m wide at 18 m: wider than either side of a 5 m view
    assert column_positions(anchors, chars, 18.0, (-2.0, 3.0))[0, 0] > 0.0  # more room on the right
    assert column_positions(anchors, chars, 18.0, (-3.0, 2.0))[0, 0] < 0.0  # more room on the left


def test_in_a_view_too_narrow_for_either_side_the_column_stacks_above_the_objects_inside_the_view() -> None:
    anchors = np.array([[0.0, 0.0], [1.0, -1.0]])
    chars = np.array([24, 9])
    height_m = 16.0
    half_label_m = half_widths_m(np.array([24]), M_PER_PX_PER_HEIGHT * height_m)[0]
    view_x_m, view_y_m = (-1.5 * half_label_m, 1.2 * half_label_m), (-8.0, 8.0)  # no side holds a label whole
    out = column_positions(anchors, chars, height_m, view_x_m, view_y_m)
    assert np.all(out[:, 1] > anchors[:, 1].max())  # above the objects
    assert np.all(out[:, 0] - half_label_m >= view_x_m[0]) and np.all(out[:, 0] + half_label_m <= view_x_m[1])
    assert out[0, 1] > out[1, 1]  # the higher object's label on the upper row
    low = column_positions(anchors, chars, height_m, view_x_m, (-8.0, 0.5))  # no room above: below
    assert np.all(low[:, 1] < anchors[:, 1].min()) and np.all(low[:, 1] - 0.5 >= -8.0)
    side = column_positions(anchors, chars, height_m, view_x_m)  # the view's height unknown: on the side cut less,
    right_ends = side[:, 0] + half_widths_m(chars, M_PER_PX_PER_HEIGHT * height_m)  # pushed inside the view
    assert np.ptp(right_ends) < 1e-9 and side[0, 0] - half_label_m >= view_x_m[0] - 1e-9  # ends aligned


def test_when_no_place_holds_the_column_it_is_pushed_inside_a_view_wide_enough() -> None:
    """Three runs side by side, a tall object in the middle: neither side, above nor below holds the column, but
    the view is wider than it: over the object it can be read, past the edge it could not (demo scene-0103,
    cphd beside ab3dmot and pmbm, ``--focus id_switch:1``)."""
    anchors = np.array([[0.0, 0.0]])
    clear = np.array([[-1.0, -9.0], [1.0, 9.0]])  # a box from the view's bottom to its top
    chars = np.array([27])
    height_m = 16.0
    half_label_m = half_widths_m(chars, M_PER_PX_PER_HEIGHT * height_m)[0]
    view_x_m = (-1.2 * half_label_m, 1.2 * half_label_m)
    out = column_positions(anchors, chars, height_m, view_x_m, (-8.0, 8.0), clear)
    assert view_x_m[0] <= out[0, 0] - half_label_m and out[0, 0] + half_label_m <= view_x_m[1] + 1e-9


def test_near_the_views_bottom_edge_the_column_moves_up_to_stay_inside() -> None:
    """Frames before the failure: the object near the bottom of the fixed bird's-eye view, its labels hanging
    below it would run past the edge (demo scene-0916, centerpoint, cbmot, ``--focus id_switch:1``, frame 24)."""
    from viz.label_size import BELOW_ANCHOR_PX, HEIGHT_PX

    anchors = np.array([[0.0, -7.9], [0.3, -7.8]])
    chars = np.array([9, 20])
    height_m = 16.0
    m_per_px = M_PER_PX_PER_HEIGHT * height_m
    out = column_positions(anchors, chars, height_m, (-20.0, 20.0), (-8.0, 8.0))
    assert out[:, 1].min() - (BELOW_ANCHOR_PX + HEIGHT_PX) * m_per_px >= -8.0 - 1e-9
    free = column_positions(anchors, chars, height_m, (-20.0, 20.0), (-20.0, 20.0))
    np.testing.assert_allclose(free[:, 1].mean(), anchors[:, 1].mean())  # with room: centred on the objects


def test_a_labels_anchor_is_taken_at_its_boxs_height() -> None:
    """A truck's box centre 1.56 m up, just inside the perspective view's bottom edge: its label would run past
    the edge; taken at the default 1 m the anchor was below the edge and the label kept (dev set scene-0916,
    pmbm, full recording, frame 24: 'false track 13' cut)."""
    _, perspective = eyes()
    half_h = 0.5 * perspective.height_px
    places = [(x, y) for x in np.linspace(-30.0, 40.0, 701) for y in np.linspace(-20.0, 20.0, 41)]
    for x, y in places:  # on the ground near the view's bottom edge
        high = perspective.screen_px(np.array([x, y, 1.56]))
        low = perspective.screen_px(np.array([x, y, LABEL_Z_M]))
        if high is not None and low is not None and abs(high[0]) < 100 and half_h - 3.0 < high[1] <= half_h < low[1]:
            break
    else:
        pytest.fail("no such place")
    at = Candidate(0, "truck", "false track 13", (x, y), 1.56)
    assert keep_apart([at], IDENTITY, (perspective,)) == set()
    assert keep_apart([Candidate(0, "truck", "false track 13", (x, y))], IDENTITY, (perspective,)) == {"truck"}
