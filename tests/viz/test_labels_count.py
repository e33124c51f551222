"""Counting labels as the viewer draws them (``tools.labels``) and keeping a frame's labels apart in the bird's-eye
view (``viz.label_room``), on small hand-made recordings."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import rerun as rr
import rerun.blueprint as rrb

from gnnpmb.data.scene import Pose
from tools.labels import Recording, overlaps, screen_boxes
from viz.blueprint import bev_view
from viz.colors import annotation_context
from viz.label_room import Candidate, eyes, keep_apart, px_per_m

IDENTITY = Pose(np.zeros(3), np.array([1.0, 0.0, 0.0, 0.0]))


def _record(path: Path, log) -> Recording:
    stream = rr.RecordingStream("labels-test")
    stream.set_log_time_enabled(False)
    stream.save(path, default_blueprint=rrb.Blueprint(rrb.Horizontal(bev_view("a"), bev_view("b"))))
    stream.log("/", annotation_context(), static=True)
    stream.log("world/ego_vehicle", rr.Transform3D(translation=[0, 0, 0]), static=False)
    log(stream)
    stream.disconnect()
    return Recording(path)


def test_labels_are_counted_as_rerun_shows_them(tmp_path: Path, strict: None) -> None:
    def log(stream: rr.RecordingStream) -> None:
        stream.set_time("frame", sequence=0)
        stream.log("world/ego_vehicle", rr.Transform3D(translation=[0, 0, 0]))
        stream.log("world/trackers/a/tracks/car/1", rr.Boxes3D(centers=[[10, 0, 0]], sizes=[[4, 2, 2]], labels=["1"]))
        stream.log(
            "world/trackers/a/tracks/car/2",
            rr.Boxes3D(centers=[[20, 0, 0]], sizes=[[4, 2, 2]], labels=["2"], show_labels=False),
        )
        many = np.column_stack([np.arange(40.0), np.zeros(40), np.zeros(40)])
        stream.log("world/trackers/a/many", rr.Boxes3D(centers=many, sizes=np.ones((40, 3)), labels=["x"] * 40))
        stream.log("world/gt", rr.Boxes3D(centers=[[0, 5, 0], [0, -5, 0]], sizes=np.ones((2, 3)), class_ids=[3, 3]))
        stream.log("world/trackers/b/tracks/car/9", rr.Boxes3D(centers=[[5, 0, 0]], sizes=[[1, 1, 1]], labels=["9"]))
        stream.log("world/trackers/a/candidates", rr.Points3D([[1, 1, 0]], labels=["hidden"]))
        stream.set_time("frame", sequence=1)
        stream.log("world/trackers/a/tracks/car/1", rr.Clear(recursive=False))

    rec = _record(tmp_path / "t.rrd", log)
    view = next(v for v in rec.views if v.name == "a bird's-eye")
    at0 = sorted(label.text for label in rec.labels(view, 0))
    # track 1; GT boxes named by class (no text, few instances); not: show_labels False, 40 instances, the other
    # run's track, the hidden candidates
    assert at0 == ["1", "car", "car"]
    assert sorted(label.text for label in rec.labels(view, 1)) == ["car", "car"]  # the Clear ended track 1
    other = next(v for v in rec.views if v.name == "b bird's-eye")
    assert sorted(label.text for label in rec.labels(other, 0)) == ["9", "car", "car"]


def test_labels_at_one_spot_overlap_and_far_apart_do_not(tmp_path: Path, strict: None) -> None:
    def log(stream: rr.RecordingStream) -> None:
        stream.set_time("frame", sequence=0)
        stream.log("world/ego_vehicle", rr.Transform3D(translation=[100, 0, 0]))
        stream.log("world/trackers/a/p", rr.Points3D([[112, 0, 0]], labels=["ID switch, was 4"]))
        stream.log("world/trackers/a/q", rr.Points3D([[113, 0.5, 0]], labels=["false track"]))
        stream.log("world/trackers/a/r", rr.Points3D([[130, 0, 0]], labels=["far ahead"]))

    rec = _record(tmp_path / "o.rrd", log)
    view = next(v for v in rec.views if v.name == "a bird's-eye")
    boxes = screen_boxes(rec, view, 0, (560.0, 348.0))
    assert len(boxes) == 3
    assert [{a.text, b.text} for a, b in overlaps(boxes)] == [{"ID switch, was 4", "false track"}]


def test_keep_apart_keeps_the_more_important_of_two_close_labels() -> None:
    near = [
        Candidate(4, "false", "7 · false track", (12.0, 1.0)),
        Candidate(0, "switch", "9 · ID switch, was 4", (12.5, 0.0)),
    ]
    bev = eyes()[:1]
    assert keep_apart(near, IDENTITY, bev) == {"switch"}
    metres = 150.0 / px_per_m()  # sideways by more than the two half-widths (56 + 74 px) and the clearance
    far = [near[0], Candidate(0, "switch", "9 · ID switch, was 4", (12.0, 1.0 + metres))]
    assert keep_apart(far, IDENTITY, bev) == {"false", "switch"}
    ahead = [near[0], Candidate(0, "switch", "9 · ID switch, was 4", (34.0, 1.0))]  # 22 m ahead, forward is right
    assert keep_apart(ahead, IDENTITY, bev) == {"false", "switch"}
