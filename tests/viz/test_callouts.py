"""The focus callouts' column: one row per label, never closer than a row, right of every object it names, its
labels' near ends aligned so that no leader runs through a label."""

from __future__ import annotations

import numpy as np

from viz.callouts import LINE_PX, M_PER_PX_PER_HEIGHT, column_positions, half_widths_m, leader_ends

HEIGHT_M = 18.0


def test_labels_of_objects_on_one_spot_get_their_own_rows_in_the_order_of_the_objects() -> None:
    anchors = np.array([[10.0, 5.0], [10.2, 5.1], [10.1, 4.9], [9.0, 7.0]])
    chars = np.array([9, 6, 19, 19])
    out = column_positions(anchors, chars, HEIGHT_M)
    line_m = LINE_PX * M_PER_PX_PER_HEIGHT * HEIGHT_M
    left_ends = out[:, 0] - half_widths_m(chars, M_PER_PX_PER_HEIGHT * HEIGHT_M)
    assert np.all(left_ends > anchors[:, 0].max())  # the column is right of the objects
    assert np.ptp(left_ends) < 1e-9  # its left ends aligned
    ends = leader_ends(anchors, out, chars, HEIGHT_M)
    np.testing.assert_allclose(ends[:, 0], left_ends)  # each leader stops at its label's aligned left end
    np.testing.assert_allclose(ends[:, 1], out[:, 1])
    rows = np.sort(out[:, 1])
    np.testing.assert_allclose(np.diff(rows), line_m)
    assert list(np.argsort(-out[:, 1])) == [3, 1, 0, 2]  # top-down like the objects: no crossing leaders
    assert np.mean(out[:, 1]) == np.mean(anchors[:, 1])


def test_a_longer_label_reaches_further_out_and_a_higher_camera_spreads_the_column() -> None:
    anchors = np.array([[0.0, 0.0], [0.0, 1.0]])
    short = column_positions(anchors, np.array([4, 4]), HEIGHT_M)
    long = column_positions(anchors, np.array([4, 30]), HEIGHT_M)
    assert long[1, 0] > short[1, 0] and long[0, 0] == short[0, 0]  # the longer label reaches further right
    high = column_positions(anchors, np.array([4, 4]), 2 * HEIGHT_M)
    assert np.ptp(high[:, 1]) == 2 * np.ptp(short[:, 1])
    assert column_positions(np.zeros((0, 2)), np.zeros(0, dtype=int), HEIGHT_M).shape == (0, 2)
