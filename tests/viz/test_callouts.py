"""The focus callouts' column: one row per label, never closer than a row, right of every object it names, its
labels' near ends aligned so that no leader runs through a label."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
from rerun.chunk import RrdReader

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


def test_the_column_clears_the_boxes_it_names_not_only_their_centres(saved_stream) -> None:
    """A 12 m truck: a column placed from its centre alone ran over its box (dev set scene-0916, phd,
    ``--focus id_switch:1``); read back from the recording, every label's near end (where its leader meets it)
    lies right of the box's footprint."""
    from tests.viz.rrd import read_rows
    from viz.callouts import Callout, log_callouts
    from viz.colors import TEXT_LUMINANCE_MAX, luminance
    from viz.geometry import RerunBoxes, footprint_corners_xy

    stream, path = saved_stream
    yaw = 0.6
    truck = RerunBoxes(
        np.array([[0.0, 0.0, 1.0]]),
        np.array([[12.0, 3.0, 3.5]]),
        np.array([[0.0, 0.0, np.sin(yaw / 2), np.cos(yaw / 2)]]),
    )
    corners = footprint_corners_xy(truck)
    assert corners.shape == (4, 2) and np.isclose(corners[:, 0].max(), 6.0 * np.cos(yaw) + 1.5 * np.sin(yaw))
    cyan = (120, 230, 240)  # a truck's class colour: light on the label's pale background
    callouts = [Callout((0.0, 0.0, 1.0), "GT f4b6a9", cyan), Callout((0.5, 0.2, 1.0), "m1 0.81", (0, 0, 0))]
    stream.set_time("frame", sequence=0)
    log_callouts(stream, "world/callouts", callouts, HEIGHT_M, clear_xy_m=corners)
    stream.disconnect()
    rows = read_rows(path)
    labels = rows["world/callouts"][-1]
    assert labels["Points3D:labels"] == ["GT f4b6a9", "m1 0.81"]
    (chunk,) = [c for c in RrdReader(path).store().stream() if c.entity_path == "/world/callouts"]
    packed = chunk.to_record_batch().column("Points3D:colors").to_pylist()[-1]
    text_rgb = [((c >> 24) & 0xFF, (c >> 16) & 0xFF, (c >> 8) & 0xFF) for c in packed]
    assert all(luminance(c) <= TEXT_LUMINANCE_MAX for c in text_rgb) and text_rgb[1] == (0, 0, 0)  # darkened to read
    assert rows["world/callouts/leaders"][-1]["LineStrips3D:colors"][0] >> 8 == (120 << 16) | (230 << 8) | 240
    strips = np.array(rows["world/callouts/leaders"][-1]["LineStrips3D:strips"])  # anchor -> the label's near end
    assert np.all(strips[:, 1, 0] > corners[:, 0].max())  # every label's left end right of the truck's box


def test_a_phd_tracks_prediction_callout_names_a_weight_not_an_existence() -> None:
    from gnnpmb.why.facts import Use, UseMode
    from viz.focus import _prediction_callouts

    step = SimpleNamespace(
        predicted_xy_m=(1.0, 2.0),
        prior_existence=0.79,
        decided_existence=None,
        use=Use(((1, 0.78),), 0.1, UseMode.WEIGHTS),
    )
    (weights,) = _prediction_callouts({8: step}, 1.0, {8: (0, 0, 255)}, True, UseMode.WEIGHTS)
    assert weights.text == "8 predicted weight 0.79 → m1 (78 % of its weight)"
    step = SimpleNamespace(
        predicted_xy_m=(1.0, 2.0),
        prior_existence=0.79,
        decided_existence=None,
        use=Use(((1, 1.0),), 0.0, UseMode.ASSIGNED),
    )
    (existence,) = _prediction_callouts({8: step}, 1.0, {8: (0, 0, 255)}, True)
    assert existence.text == "8 predicted r=0.79 → m1"
    # m1's own label says it went to track 8 ("m1 0.81 → track 8"): the track's label does not say it again
    (once,) = _prediction_callouts({8: step}, 1.0, {8: (0, 0, 255)}, True, said={(1, 8)})
    assert once.text == "8 predicted r=0.79"


def test_a_columns_rows_stay_a_row_apart_on_screen_whatever_their_objects_heights(saved_stream) -> None:
    """The labels lie in one plane: each at its own object's height, a detection's box 0.9 m above the evaluation
    range's circle, the rows showed unevenly spaced in the bird's-eye camera and two touched (demo scene-0103
    pointpillars, gnnpmb beside pmbm, ``--focus miss:2``, frame 7). Read back and projected with a camera looking
    straight down from ``HEIGHT_M`` above the plane the column is sized for, rows are ``LINE_PX`` apart."""
    from tests.viz.rrd import read_rows
    from viz.callouts import FOCUS_BEV_HEIGHT_PX, FOV_Y_DEG, Callout, log_callouts

    stream, path = saved_stream
    plane_z_m, eye = 0.8, np.array([0.0, 20.0])  # the eye sits HEIGHT_M above the plane, left of and below
    heights = [0.8, 1.7, -0.2, 0.8]  # a GT, a tall detection, the evaluation range's circle, a prediction
    callouts = [Callout((0.3 * k, 24.0 + 0.2 * k, z), f"label {k}", (0, 0, 0)) for k, z in enumerate(heights)]
    stream.set_time("frame", sequence=0)
    log_callouts(stream, "world/callouts", callouts, HEIGHT_M, label_z_m=plane_z_m)
    stream.disconnect()
    (chunk,) = [c for c in RrdReader(path).store().stream() if c.entity_path == "/world/callouts"]
    at = np.array(chunk.to_record_batch().column("Points3D:positions").to_pylist()[-1])
    np.testing.assert_allclose(at[:, 2], plane_z_m)
    strips = np.array(read_rows(path)["world/callouts/leaders"][-1]["LineStrips3D:strips"])
    np.testing.assert_allclose(strips[:, 0, 2], heights, rtol=1e-6)  # each leader starts at its object
    np.testing.assert_allclose(strips[:, 1, 2], plane_z_m)  # and ends at its label
    focal_px = 0.5 * FOCUS_BEV_HEIGHT_PX / np.tan(np.radians(0.5 * FOV_Y_DEG))
    screen_y = focal_px * (at[:, 1] - eye[1]) / (plane_z_m + HEIGHT_M - at[:, 2])
    np.testing.assert_allclose(np.diff(np.sort(screen_y)), LINE_PX, rtol=1e-6)


def test_a_detections_label_says_when_the_track_it_went_to_was_not_output() -> None:
    """ab3dmot gave m1 to its tentative track 103, first output a frame later: "m1 0.85 → track 103" pointed at no
    box (dev set scene-0916 centerpoint, gnn beside ab3dmot ``--focus id_switch:1``, frame 16). The label says so;
    a track output there, a new one too, reads as before; a results file's "under ..." is about output already."""
    from gnnpmb.types import Boxes
    from gnnpmb.why.facts import Destination, UseMode, Went
    from viz.focus import _detection_callouts

    went = {
        1: Destination(1, Went.TRACK, 103),
        2: Destination(2, Went.NEW_TRACK, 104),
        3: Destination(3, Went.TRACK, 7),
    }
    facts = SimpleNamespace(destination=lambda frame, class_name, m: went.get(m))
    n = 4
    detections = Boxes(
        translation_m=np.zeros((n, 3)),
        size_wlh_m=np.ones((n, 3)),
        quat_wxyz=np.tile([1.0, 0.0, 0.0, 0.0], (n, 1)),
        velocity_mps=np.zeros((n, 2)),
        score=np.array([0.5, 0.85, 0.4, 0.9]),
        class_name=np.array(["truck"] * n),
        instance_id=np.array([""] * n),
    )
    texts = [c.text for c in _detection_callouts(detections, [1, 2, 3], facts, 16, "truck", UseMode.ASSIGNED, {7})]
    assert texts == ["m1 0.85 → track 103, not output", "m2 0.40 → new track 104, not output", "m3 0.90 → track 7"]
    unknown = [c.text for c in _detection_callouts(detections, [1], facts, 16, "truck", UseMode.ASSIGNED)]
    assert unknown == ["m1 0.85 → track 103"]
    results = [c.text for c in _detection_callouts(detections, [1], facts, 16, "truck", UseMode.OUTPUT, {7})]
    assert results == ["m1 0.85 under track 103's box"]


def test_the_column_of_objects_beside_the_view_starts_inside_it() -> None:
    """Before the failure the object can still be on its way, beside the view: the column placed right of it ran
    half past the view's left edge (demo scene-0103 pointpillars gnnpmb beside pmbm ``--focus fragmentation:1``,
    frames 8-9, "26 predicted r=0.95, missed" cut). It starts at the view's edge; its leaders run out to them."""
    anchors = np.array([[-17.0, 0.0], [-16.8, 0.5]])
    chars = np.array([9, 26])
    view_x, view_y = (-11.0, 11.0), (-9.0, 9.0)
    out = column_positions(anchors, chars, HEIGHT_M, view_x, view_y)
    halves = half_widths_m(chars, M_PER_PX_PER_HEIGHT * HEIGHT_M)
    assert np.all(out[:, 0] - halves >= view_x[0] - 1e-9) and np.all(out[:, 0] + halves <= view_x[1])
    assert np.ptp(out[:, 0] - halves) < 1e-9  # left ends still aligned
