"""The lost track of a focus recording is drawn at the failure frame (``viz.focus._log_ghosts``), even when the
tracker no longer predicts it (deleted, or it lost the object frames before)."""

from __future__ import annotations

from types import SimpleNamespace

import rerun as rr

from gnnpmb.types import TrackEstimate
from tests.viz.rrd import read_rows
from viz.focus import _log_ghosts, predicted_ghosts

TRACKER = "jpda"
LOST = 20


def _estimate(track_id: int, x_m: float) -> TrackEstimate:
    return TrackEstimate(track_id, "car", (x_m, 2.0, 1.0), (2.0, 4.5, 1.6), (1.0, 0.0, 0.0, 0.0), (0.0, 0.0), 0.8, 0.9)


def _ghost_labels(saved_stream, failure_frame: bool) -> list[str]:
    stream, path = saved_stream
    # track 20 was output at frames 0-3 (last at x = 13 m), then deleted: no prediction at frame 9
    frames = {j: SimpleNamespace(estimates=(_estimate(LOST, 10.0 + j),) if j <= 3 else ()) for j in range(10)}
    stream.set_time("frame", sequence=9)
    callouts = _log_ghosts(
        stream, TRACKER, frames, 9, {LOST: None}, set(), {LOST: (200, 40, 40)}, failure_frame=failure_frame
    )
    stream.disconnect()
    rows = read_rows(path)[predicted_ghosts(TRACKER)]
    if failure_frame:
        assert [c.text for c in callouts] == [f"{LOST} last output at frame 3"]
        assert rows[-1]["Boxes3D:centers"][0][0] == 13.0  # at its last output box
    return rows[-1].get("Boxes3D:labels") or []


def test_a_deleted_lost_track_is_drawn_at_the_failure_frame(saved_stream: tuple[rr.RecordingStream, object]) -> None:
    assert _ghost_labels(saved_stream, failure_frame=True) == [f"{LOST} (last output at frame 3)"]


def test_elsewhere_a_track_no_longer_predicted_is_not(saved_stream: tuple[rr.RecordingStream, object]) -> None:
    assert _ghost_labels(saved_stream, failure_frame=False) == []


def test_at_the_failure_frame_a_lost_track_output_long_ago_is_drawn(saved_stream) -> None:
    stream, path = saved_stream
    step = SimpleNamespace(predicted_xy_m=(40.0, 2.0))  # still predicted, last output 30 frames back
    frames = {j: SimpleNamespace(estimates=(_estimate(LOST, 10.0),) if j == 0 else ()) for j in range(31)}
    stream.set_time("frame", sequence=30)
    _log_ghosts(stream, TRACKER, frames, 30, {LOST: step}, set(), {LOST: (200, 40, 40)}, failure_frame=True)
    stream.disconnect()
    row = read_rows(path)[predicted_ghosts(TRACKER)][-1]
    assert row["Boxes3D:labels"] == [f"{LOST} (predicted)"] and row["Boxes3D:centers"][0][:2] == [40.0, 2.0]
