"""The focus callouts' column is placed for the bird's-eye view's real size: the heights ``viz.callouts`` takes
for each focus layout (one run or several, with or without the camera view below) are the ones the saved focus
blueprint lays out at 1920 x 1080 (``tools.labels.layout_px``), so a column the placement keeps in view is not cut
by the view's edge (three runs with a camera were thought 300 px tall, and were 318)."""

from __future__ import annotations

from pathlib import Path

import pytest
import rerun as rr

from gnnpmb.focus import FocusTarget
from tools.labels import read_views
from viz.blueprint import default_blueprint
from viz.callouts import COMPARED_CAMERA_HEIGHTS_PX


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
