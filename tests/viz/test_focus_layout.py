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


@pytest.mark.parametrize("runs", [1, 2])
@pytest.mark.parametrize("camera", [False, True])
def test_the_focus_views_sizes_are_the_laid_out_ones(tmp_path: Path, runs: int, camera: bool) -> None:
    """``focus_views_px``, which decides whose ids would cover each other, gives both 3D views' sizes as the saved
    blueprint lays them out (one run's perspective view: 159 px tall with a camera below)."""
    from viz.callouts import focus_views_px

    trackers = ["gnnpmb", "pmbm"][:runs]
    focus = FocusTarget("t", 5, (0.0, 0.0), "car", {t: (1,) for t in trackers}, ("abc",))
    cams = ("CAM_FRONT",) if camera else ()
    blueprint = default_blueprint(trackers, ["car"], focus, cameras=cams, focus_camera=cams[0] if cams else None)
    path = tmp_path / "bp.rrd"
    stream = rr.RecordingStream("focus-layout-test")
    stream.save(path, default_blueprint=blueprint)
    stream.disconnect()
    views = {v.name: v.size_px for v in read_views(path)}
    bev, perspective = focus_views_px(runs, camera)
    assert views["gnnpmb bird's-eye"] == pytest.approx(bev, rel=0.01)
    assert views["gnnpmb 3D"] == pytest.approx(perspective, rel=0.01)


@pytest.mark.parametrize("apart_m", [0.4, 12.0])
def test_two_involved_tracks_ids_that_would_cover_each_other_go_to_the_callout_column(
    tmp_path: Path, apart_m: float
) -> None:
    """Two tracks on one object (an ID switch's old and new track) printed one id over the other in the perspective
    view: "2" under "164" (demo scene-0103 pointpillars immortal ``--focus id_switch:1``, frames 11-15). Read back
    as the viewer draws it (``tools.labels``): their ids leave their boxes for the callout column (``track 2``,
    ``track 164``) and no two labels overlap in either view; tracks 12 m apart keep their ids on their boxes."""
    from gnnpmb.types import TrackEstimate
    from tools.labels import Recording, summarize
    from viz import paths
    from viz.callouts import focus_height_m, log_callouts
    from viz.focus import focus_eyes, log_track_ids

    focus = FocusTarget("t", 0, (100.0, 50.0), "car", {"immortal": (2, 164)}, ("abc",))
    tracks = [
        TrackEstimate(t, "car", (100.0 + x, 50.0, 0.9), (2.0, 4.5, 1.6), (1.0, 0.0, 0.0, 0.0), (0.0, 0.0), 0.8, 1.0)
        for t, x in ((2, 0.0), (164, apart_m))
    ]
    path = tmp_path / "ids.rrd"
    stream = rr.RecordingStream("focus-ids-test")
    stream.save(path, default_blueprint=default_blueprint(["immortal"], ["car"], focus))
    stream.set_time("frame", sequence=0)
    for e in tracks:  # as the logger draws an involved track: its id as its box's label
        stream.log(
            paths.track("immortal", "car", e.track_id),
            rr.Boxes3D(centers=[e.translation_m], sizes=[[4.5, 2.0, 1.6]], labels=[str(e.track_id)]),
        )
    eyes = focus_eyes(focus, 1, False)
    callouts = log_track_ids(stream, "immortal", tracks, {2: (0, 128, 0), 164: (0, 0, 0)}, eyes)
    height_m = focus_height_m(eyes[0].position_m[2] - 0.9, False, False)
    log_callouts(stream, paths.focus_callouts("immortal"), callouts, height_m, label_z_m=0.9)
    stream.disconnect()
    summary = summarize(path, [0])
    assert not summary.overlapping and not summary.clipped
    bev = {v.name: v for v in read_views(path)}["immortal bird's-eye"]
    texts = sorted(label.text for label in Recording(path).labels(bev, 0))
    assert texts == (["track 164", "track 2"] if apart_m < 1.0 else ["164", "2"])


def test_an_object_the_why_names_is_labelled_at_the_failure_frame_only_where_the_view_shows_it() -> None:
    """The Why names a truck for frame 15 ("lay 0.4 m from truck GT 9da03c"); at the failure's frame 24 it was 21 m
    away, out of the two-run view, and its label led a line across the view and out (demo scene-0103 ``--tracker
    gnnpmb:gnnpmb/params/paper.toml --tracker gnnpmb --focus diff:fixed:1``). A named object beside the failure
    keeps its label."""
    from gnnpmb.types import Boxes
    from viz.focus import focus_eyes, named_in_view, named_objects

    focus = FocusTarget("t", 24, (480.0, 1196.0), "bicycle", {"a": (400,), "b": (21,)}, ("bf3d85aaaa",))
    ids = np.array(["9da03c11aa", "9d0a7322aa", "bf3d85aaaa"])
    gt = Boxes(
        translation_m=np.array([[459.0, 1192.0, 1.5], [481.5, 1197.0, 0.8], [479.0, 1196.5, 0.8]]),
        size_wlh_m=np.ones((3, 3)),
        quat_wxyz=np.tile([1.0, 0.0, 0.0, 0.0], (3, 1)),
        velocity_mps=np.zeros((3, 2)),
        score=np.ones(3),
        class_name=np.array(["truck", "pedestrian", "bicycle"]),
        instance_id=ids,
    )
    why = "at frame 15 m4 lay 0.4 m from truck GT 9da03c; at frame 24 it lay 0.3 m from pedestrian GT 9d0a73"
    named = named_objects(why, gt, {"bf3d85aaaa"})
    assert named == ["9da03c11aa", "9d0a7322aa"]
    bev = focus_eyes(focus, 2, True)[0]
    assert named_in_view(named, gt, bev) == ["9d0a7322aa"]
