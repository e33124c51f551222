"""The focus summary's object table names the nearest detection preprocessing kept as such (truth45 checker)."""

from __future__ import annotations

from types import SimpleNamespace

from gnnpmb.eval.evaluated import GtFrame, GtStatus
from gnnpmb.focus import FocusTarget
from gnnpmb.why.facts import Destination, UseMode, Went
from gnnpmb.why.findings import Near, Sighting
from viz.focus_summary import _gt_markdown


def test_the_object_table_says_its_nearest_detection_is_the_nearest_kept_one() -> None:
    # dev set scene-1077 megvii cphd identity_theft:2, frame 23: "nearest detection: m20 at 0.2 m (score 0.46)"
    # while m26 (score 0.24) lay 0.1 m from the object; NMS had removed it beside m20
    g = GtFrame(23, GtStatus.SCORED, (0.0, 0.0), (0.0, 0.0), None, 9, 20.0, 40.0)
    kept, removed = Near(20, "pedestrian", 0.46, 0.2, True), Near(26, "pedestrian", 0.24, 0.1, False)
    seen = (Sighting(23, 9, g, removed, kept, Destination(20, Went.TRACK, 107, 0.94), (), removed),)
    view = SimpleNamespace(
        facts=SimpleNamespace(mode=lambda c, frames: UseMode.WEIGHTS),
        evidence=SimpleNamespace(report=SimpleNamespace(threshold_of=lambda c: 0.452)),
    )
    focus = FocusTarget("t", 23, (0.0, 0.0), "pedestrian", {"cphd": (107,)}, ())
    text = "\n".join(_gt_markdown(focus, view, "ceb713" + "0" * 26, seen))
    assert "| frame | points in box | nearest kept detection |" in text
    assert "a kept pedestrian detection within 2 m at frame 23." in text
    assert "| 23 | 9 | m20 at 0.2 m (score 0.46) |" in text
