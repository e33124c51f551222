"""The focus callouts' column is placed for the bird's-eye view's real size: the heights ``viz.callouts`` takes
for each focus layout (one run or several, with or without the camera view below) are the ones the saved focus
blueprint lays out at 1920 x 1080 (``tools.labels.layout_px``), so a column the placement keeps in view is not cut
by the view's edge (three runs with a camera were thought 300 px tall, and were 318)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import rerun as rr

from gnnpmb.eval.failures import Failure, FailureBox, FailureKind, FailureReport
from gnnpmb.focus import FocusTarget
from tools.labels import read_views
from viz.blueprint import FOCUS_HEIGHT_M, default_blueprint
from viz.callouts import COMPARED_CAMERA_HEIGHTS_PX
from viz.failures import FOCUS_MARGIN_M, MARKER_MARGIN_M, MARKER_SCALE
from viz.focus import _marker_corners


@pytest.mark.parametrize("runs", [1, 2, 3])
@pytest.mark.parametrize("camera", [False, True])
def test_the_focus_bev_height_is_the_laid_out_one(tmp_path: Path, runs: int, camera: bool) -> None:
    trackers = ["gnnpmb", "pmbm", "jpda"][:runs]
    focus = FocusTarget("t", 5, (0.0, 0.0), "car", {t: (1,) for t in trackers}, ("abc",))
    blueprint = default_blueprint(
        trackers, ["car"], focus, cameras=("CAM_FRONT",) if camera else (), focus_camera="CAM_FRONT" if camera else None
    )
    path = tmp_path / "bp.rrd"
    stream = rr.RecordingStream("focus-layout-test")
    stream.save(path, default_blueprint=blueprint)
    stream.disconnect()
    (bev, *_) = [v for v in read_views(path) if v.name.endswith("bird's-eye")]
    assert bev.size_px[0] == pytest.approx(1920 * 3 / 5 / runs, rel=0.01)
    assert bev.size_px[1] == pytest.approx(COMPARED_CAMERA_HEIGHTS_PX[runs > 1, camera], rel=0.01)
    # The eye of a narrow view is raised so that its width shows 1.25 x the metres the class's eye height shows up
    # and down (a moving object's labels stay inside); a wide view keeps the class's height.
    assert bev.eye is not None
    (width_px, height_px), eye_m = bev.size_px, bev.eye[0][2]
    if 1.25 * height_px > width_px:
        assert width_px / height_px * eye_m == pytest.approx(1.25 * FOCUS_HEIGHT_M["car"], rel=0.01)
    else:
        assert eye_m == FOCUS_HEIGHT_M["car"]


def test_the_callouts_keep_clear_of_a_focus_tracks_failure_marker_where_the_evaluation_saw_it() -> None:
    """A false track's marker stands at the box the evaluation interpolated, which the track never output: its
    corners (as wide as the focused failure's marker) are among the points the callouts keep clear of; a GT box
    and another track's are not."""
    ghost = FailureBox("false track", "18", (10.0, 5.0, 0.0), (2.0, 4.0, 1.5), (1.0, 0.0, 0.0, 0.0))
    other = FailureBox("false track", "40", (50.0, 5.0, 0.0), (2.0, 4.0, 1.5), (1.0, 0.0, 0.0, 0.0))
    gt = FailureBox("missed gt", "abc", (30.0, 5.0, 0.0), (2.0, 4.0, 1.5), (1.0, 0.0, 0.0, 0.0))
    failure = Failure(FailureKind.FALSE_TRACK, 16, "s16", "bicycle", (), ("18",), (ghost, other, gt))
    report = FailureReport("scene", "phd", ("s16",), (), (failure,))
    corners = _marker_corners(report, 16, (18,))
    half_m = 0.5 * (np.array([4.0, 2.0]) * MARKER_SCALE + MARKER_MARGIN_M + FOCUS_MARGIN_M)  # x: length, y: width
    assert corners.shape == (4, 2)
    assert np.allclose(np.sort(np.abs(corners - (10.0, 5.0)), axis=0), np.tile(half_m, (4, 1)))
    assert _marker_corners(report, 15, (18,)).shape == (0, 2) and _marker_corners(None, 16, (18,)).shape == (0, 2)
