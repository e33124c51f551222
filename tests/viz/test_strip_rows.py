"""The failures-over-time strip of a full recording: its row names never touch, with or without the camera grid
below (the view's height laid out from the saved blueprint at 1920 x 1080, ``tools.labels.layout_px``)."""

from __future__ import annotations

from pathlib import Path

import pytest
import rerun as rr

from gnnpmb.data.sensors import CAMERA_ORDER
from tools.labels import read_views
from viz.blueprint import default_blueprint
from viz.label_room import CLEARANCE_PX
from viz.label_size import HEIGHT_PX
from viz.opening import row_step, timeline_bounds


@pytest.mark.parametrize("cameras", [False, True])
def test_each_row_of_the_failure_strip_is_taller_than_its_name(tmp_path: Path, cameras: bool) -> None:
    for rows in (1, 3, 6):
        path = tmp_path / f"bp{rows}.rrd"
        blueprint = default_blueprint(
            ["gnnpmb", "pmbm"],
            ["car"],
            failure_index=True,
            frames=range(40),
            timeline_rows={"gnnpmb": rows, "pmbm": 1},
            cameras=CAMERA_ORDER if cameras else (),
        )
        stream = rr.RecordingStream("strip-test")
        stream.save(path, default_blueprint=blueprint)
        stream.disconnect()
        strips = [v for v in read_views(path, kinds=("2D",)) if v.name.endswith("failures over time")]
        assert len(strips) == 2
        (x0, x1), (y0, y1) = timeline_bounds(range(40), rows, 2)
        for strip in strips:  # a 2D view shows x and y at one scale: the bounds fitted into the view
            width, height = strip.size_px
            px_per_unit = min(width / (x1 - x0), height / (y1 - y0))
            assert row_step(range(40), 2) * px_per_unit >= HEIGHT_PX + CLEARANCE_PX, (rows, strip.size_px)
        bev = [v for v in read_views(path) if v.name.endswith("bird's-eye")]
        assert all(v.size_px[1] >= 120 for v in bev)  # the bird's-eye view stays usable
