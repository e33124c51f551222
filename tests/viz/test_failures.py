"""Failure markers in a saved recording: boxes only at their frame, labels naming ids, counts, text lines."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
import rerun as rr

from gnnpmb.data.scene import SceneData
from gnnpmb.eval.failures import ClassEvaluation, Failure, FailureBox, FailureKind, FailureReport
from tests.viz.rrd import at_frame, latest_at, read_rows
from viz import paths
from viz.colors import faded, pack_rgba
from viz.failures import (
    FOCUS_MARGIN_M,
    KIND_COLORS,
    MARKER_MARGIN_M,
    MARKER_SCALE,
    failure_label,
    failure_log,
    log_failures,
)

T = "gnnpmb"
GT_ID = "a1b2c3d4e5f6"


def fbox(role: str, object_id: str, x: float) -> FailureBox:
    return FailureBox(role, object_id, (x, 2.0, 1.0), (2.0, 4.0, 1.5), (1.0, 0.0, 0.0, 0.0))


def report_for(scene: SceneData) -> FailureReport:
    tokens = scene.sample_tokens
    switch = Failure(
        FailureKind.ID_SWITCH,
        1,
        tokens[1],
        "car",
        (GT_ID,),
        ("4", "9"),
        (fbox("gt", GT_ID, 11.0), fbox("new track", "9", 11.2), fbox("old track", "4", 14.0)),
    )
    misses = [
        Failure(FailureKind.MISS, 0, tokens[0], "car", (GT_ID,), (), (fbox("missed gt", GT_ID, 10.0),)),
        Failure(FailureKind.MISS, 0, tokens[0], "pedestrian", ("p9",), (), (fbox("missed gt", "p9", 5.0),)),
        Failure(FailureKind.MISS, 2, tokens[2], "pedestrian", ("p9",), (), (fbox("missed gt", "p9", 5.0),)),
    ]
    theft = Failure(
        FailureKind.IDENTITY_THEFT,
        1,
        tokens[1],
        "car",
        (GT_ID,),
        ("9", "4"),
        (fbox("gt", GT_ID, 11.0), fbox("thief track", "9", 11.2)),
        generation=1,
    )
    classes = (ClassEvaluation("car", 0.5, 0.5, 1.0, 0.0, 1.0, 1.0, 0.0),)
    return FailureReport(scene.name, T, tokens, classes, (misses[0], misses[1], switch, theft, misses[2]))


def test_failures_are_logged_per_kind_and_frame(saved_stream, tiny_scene) -> None:
    stream, path = saved_stream
    scene, _ = tiny_scene
    log_failures(stream, T, report_for(scene), scene)
    stream.disconnect()
    rows = read_rows(path)

    switch_rows = rows[paths.failures_world(T, "id_switch")]
    assert [len(r.get("Boxes3D:centers") or []) for r in switch_rows] == [0, 3, 0]
    frame1 = at_frame(switch_rows, 1)[0]
    assert frame1["Boxes3D:labels"] == [
        "ID switch: GT a1b2c3",
        "ID switch: new track 9",
        "ID switch: old track 4",
    ]
    np.testing.assert_allclose(frame1["Boxes3D:centers"][2], [14.0, 2.0, 1.0])
    half = 0.5 * (np.array([4.0, 2.0, 1.5]) * MARKER_SCALE + MARKER_MARGIN_M)  # wlh -> box x, y, z extents
    np.testing.assert_allclose(frame1["Boxes3D:half_sizes"][0], half, rtol=1e-6)
    r, g, b = KIND_COLORS[FailureKind.ID_SWITCH]
    assert set(frame1["Boxes3D:colors"]) == {(r << 24) | (g << 16) | (b << 8) | 255}
    assert not latest_at(switch_rows, 2, "Boxes3D:centers")

    miss_rows = [r for r in rows[paths.failures_world(T, "miss")] if not r["static"]]
    assert [r for r in rows[paths.failures_world(T, "miss")] if r["static"]][0]["Boxes3D:show_labels"] == [False]
    assert [r["Boxes3D:labels"] for r in miss_rows] == [
        ["missed GT a1b2c3", "missed GT p9"],  # the role names the kind: not "miss: missed gt"
        [],
        ["missed GT p9"],
    ]

    counts = {
        kind: [r["Scalars:scalars"][0] for r in rows[paths.failure_count(T, kind.value)] if not r["static"]]
        for kind in FailureKind
    }
    assert counts[FailureKind.MISS] == [2.0, 0.0, 1.0]
    assert counts[FailureKind.ID_SWITCH] == [0.0, 1.0, 0.0]
    assert counts[FailureKind.COALESCENCE] == [0.0, 0.0, 0.0]
    assert paths.failures_world(T, "coalescence") not in rows
    static = [r for r in rows[paths.failure_count(T, "identity_theft")] if r["static"]]
    assert static[0]["SeriesLines:names"] == ["identity theft"]

    log_rows = rows[failure_log(T)]
    lines = [(r["frame"], r["TextLog:text"][0], r["TextLog:level"][0]) for r in log_rows]
    assert lines == [
        (0, "[miss:1] miss: car GT a1b2c3", "INFO"),  # the ids gnnpmb failures prints and --focus takes
        (0, "[miss:2] miss: pedestrian GT p9", "INFO"),
        (1, "[id_switch:1] ID switch: car GT a1b2c3: track 4 -> track 9", "WARN"),
        (1, "[identity_theft:1] identity theft: car track 9 took GT a1b2c3 from track 4", "ERROR"),
        (2, "[miss:3] miss: pedestrian GT p9", "INFO"),
    ]
    timestamps = [r["timestamp"] for r in log_rows]
    assert timestamps[2] == np.datetime64(scene.keyframes[1].timestamp_us, "us")


def test_report_of_another_scene_is_refused(tmp_path: Path, tiny_scene) -> None:
    scene, _ = tiny_scene
    report = report_for(scene)
    other = FailureReport("scene-other", T, ("x", "y", "z"), report.classes, ())
    stream = rr.RecordingStream("gnnpmb-viz-test-refuse")
    stream.save(tmp_path / "refused.rrd")
    with pytest.raises(ValueError, match="not for the samples of scene-test"):
        log_failures(stream, T, other, scene)
    stream.disconnect()


def test_frame_range_limits_markers_counts_and_log(saved_stream, tiny_scene) -> None:
    stream, path = saved_stream
    scene, _ = tiny_scene
    log_failures(stream, T, report_for(scene), scene, frame_range=range(1, 2))
    stream.disconnect()
    rows = read_rows(path)
    misses = [r for r in rows[paths.failure_count(T, "miss")] if not r["static"]]
    assert [r["frame"] for r in misses] == [1] and misses[0]["Scalars:scalars"] == [0.0]
    assert paths.failures_world(T, "miss") not in rows  # both misses lie outside the range
    switches = [r for r in rows[paths.failures_world(T, "id_switch")] if not r["static"]]
    assert [r["frame"] for r in switches] == [1]
    assert {r["frame"] for r in rows[failure_log(T)] if not r["static"]} == {1}


def test_totals_and_the_failure_suggested_first(tiny_scene) -> None:
    scene, _ = tiny_scene
    report = report_for(scene)
    assert report.totals_text() == (
        "1 id_switch, 0 fragmentation, 0 false_track, 3 miss, 0 coalescence, 1 identity_theft"
    )
    # Misses come first in time, but an association error is what a tracker debugger is opened for.
    assert report.ids()[0] == "miss:1" and report.first_worth_opening() == "id_switch:1"
    only_misses = FailureReport(
        scene.name, T, report.sample_tokens, report.classes, tuple(report.of_kind(FailureKind.MISS))
    )
    assert only_misses.first_worth_opening() == "miss:3"  # misses 1 and 2 are at frame 0: no history to show
    at_start = FailureReport(scene.name, T, report.sample_tokens, report.classes, only_misses.failures[:2])
    assert at_start.first_worth_opening() == "miss:1"
    assert FailureReport(scene.name, T, report.sample_tokens, report.classes, ()).first_worth_opening() is None


def test_a_failure_at_an_interpolated_gt_box_is_named_and_suggested_last(tiny_scene) -> None:
    scene, _ = tiny_scene
    report = report_for(scene)
    switch = report.of_kind(FailureKind.ID_SWITCH)[0]
    made_up = tuple(replace(b, interpolated=b.is_gt) for b in switch.boxes)
    interpolated_switch = replace(switch, boxes=made_up)
    assert interpolated_switch.gt_interpolated and not switch.gt_interpolated
    assert interpolated_switch.describe() == switch.describe() + " (GT box interpolated by the evaluation: no points)"
    failures = tuple(interpolated_switch if f is switch else f for f in report.failures)
    mixed = FailureReport(scene.name, T, report.sample_tokens, report.classes, failures)
    # The identity theft (not interpolated) comes before the interpolated switch; both before misses.
    assert mixed.first_worth_opening() == "identity_theft:1"
    assert Failure.from_json(interpolated_switch.to_json()) == interpolated_switch
    scored = replace(mixed, track_scores={"4": 0.25, "9": 0.5})
    assert FailureReport.from_json(scored.to_json()) == scored


def test_a_marker_label_does_not_repeat_the_kind() -> None:
    assert failure_label(FailureKind.FALSE_TRACK, fbox("false track", "20", 0.0)) == "false track 20"
    assert failure_label(FailureKind.FRAGMENTATION, fbox("missed gt", GT_ID, 0.0)) == "fragmentation: missed GT a1b2c3"
    assert failure_label(FailureKind.ID_SWITCH, fbox("gt", GT_ID, 0.0)) == "ID switch: GT a1b2c3"  # as in the camera
    assert failure_label(FailureKind.IDENTITY_THEFT, fbox("thief track", "9", 0.0)) == "identity theft: thief track 9"


def test_a_focus_pales_the_markers_of_other_objects_and_draws_its_kind_around_the_others(
    saved_stream, tiny_scene
) -> None:
    stream, path = saved_stream
    scene, _ = tiny_scene
    # Focused on the identity theft of track 9: old track 4 is not among its objects.
    log_failures(stream, T, report_for(scene), scene, involved={GT_ID, "9"}, focus_kind=FailureKind.IDENTITY_THEFT)
    stream.disconnect()
    rows = read_rows(path)
    switch = at_frame(rows[paths.failures_world(T, "id_switch")], 1)[0]
    strong = int(pack_rgba(np.array([KIND_COLORS[FailureKind.ID_SWITCH]]))[0])
    pale = int(faded(np.array([strong], dtype=np.uint32), 0.35)[0])
    assert switch["Boxes3D:labels"][2] == "ID switch: old track 4"
    assert switch["Boxes3D:colors"] == [strong, strong, pale]
    theft = at_frame(rows[paths.failures_world(T, "identity_theft")], 1)[0]
    widened = 0.5 * (np.array([4.0, 2.0, 1.5]) * MARKER_SCALE + MARKER_MARGIN_M + FOCUS_MARGIN_M)
    np.testing.assert_allclose(theft["Boxes3D:half_sizes"][0], widened, rtol=1e-6)  # encloses the switch's box
