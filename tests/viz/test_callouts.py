"""The focus callouts' column: one row per label, never closer than a row, right of every object it names."""

from __future__ import annotations

import numpy as np

from viz.callouts import LINE_PX, M_PER_PX_PER_HEIGHT, column_positions

HEIGHT_M = 18.0


def test_labels_of_objects_on_one_spot_get_their_own_rows_in_the_order_of_the_objects() -> None:
    anchors = np.array([[10.0, 5.0], [10.2, 5.1], [10.1, 4.9], [9.0, 7.0]])
    out = column_positions(anchors, np.array([9, 6, 19, 19]), HEIGHT_M)
    line_m = LINE_PX * M_PER_PX_PER_HEIGHT * HEIGHT_M
    assert np.all(out[:, 0] > anchors[:, 0].max())  # the column is right of the objects
    assert np.ptp(out[:, 0]) == 0.0
    rows = np.sort(out[:, 1])
    np.testing.assert_allclose(np.diff(rows), line_m)
    assert list(np.argsort(-out[:, 1])) == [3, 1, 0, 2]  # top-down like the objects: no crossing leaders
    assert np.mean(out[:, 1]) == np.mean(anchors[:, 1])


def test_a_longer_label_moves_the_column_out_and_a_higher_camera_spreads_it() -> None:
    anchors = np.array([[0.0, 0.0], [0.0, 1.0]])
    short = column_positions(anchors, np.array([4, 4]), HEIGHT_M)
    long = column_positions(anchors, np.array([4, 30]), HEIGHT_M)
    assert long[0, 0] > short[0, 0]
    high = column_positions(anchors, np.array([4, 4]), 2 * HEIGHT_M)
    assert np.ptp(high[:, 1]) == 2 * np.ptp(short[:, 1])
    assert column_positions(np.zeros((0, 2)), np.zeros(0, dtype=int), HEIGHT_M).shape == (0, 2)
