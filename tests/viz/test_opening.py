"""A full recording (no ``--focus``) as a way in (``viz.opening``): it opens at the first failure worth a look, its
failure index is the first tab, failures are over time below the views, one label per box, the lost track drawn
pale, and panels a run cannot fill are left out."""

from __future__ import annotations

import contextlib
import io
from pathlib import Path

import numpy as np
import pytest
from rerun.chunk import RrdReader

from cli.app import main
from tests.pipeline import POSITION_ONLY, prepare, reports_of
from tests.viz.rrd import at_frame, read_rows
from tests.viz.test_blueprint import stored_views
from tools.labels import Recording, camera_boxes, camera_rect, inside, overlaps, screen_boxes
from viz import compare, paths
from viz.opening import TIMELINE_KINDS, failure_timeline, lost_tracks, row_step, timeline_bounds, timeline_rows
from viz.paths import failure_index_doc

SCENE = "scene-0103"


@pytest.fixture(scope="module")
def recorded(demo_dataroot: Path, tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, dict, dict]:
    """GNN-PMB beside JPDA on the pointpillars preset (ID switches and an identity theft), its rows and reports."""
    out = tmp_path_factory.mktemp("full") / "full.rrd"
    argv = [SCENE, "-t", "gnnpmb", "-t", "jpda", "--detector", "pointpillars", "--dataroot", str(demo_dataroot)]
    argv += ["--params", str(POSITION_ONLY)]  # the model set whose GNN-PMB switches IDs on this scene
    with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(io.StringIO()):
        main([*argv, "--save", str(out), "--no-progress"])
    request = prepare(SCENE, ["gnnpmb", "jpda"], dataroot=demo_dataroot, detector="pointpillars", params=POSITION_ONLY)
    reports, _ = reports_of(request)
    return out, read_rows(out), reports


def _focus_max(path: Path) -> int:
    top = -1
    for chunk in RrdReader(path).store().stream():
        batch = chunk.to_record_batch()
        if not chunk.is_static and "focus" in batch.schema.names and batch.num_rows:
            top = max(top, max(v for v in batch.column("focus").to_pylist() if v is not None))
    return top


def test_it_opens_at_the_first_failure_worth_a_look_with_its_index_first(recorded) -> None:
    path, rows, reports = recorded
    first = reports["gnnpmb"].first_worth_opening()
    assert first.startswith("id_switch:")  # association errors come first
    opened = reports["gnnpmb"].by_id(first)
    assert _focus_max(path) == opened.frame_index  # the focus timeline ends there: the viewer opens there
    index = rows[failure_index_doc("gnnpmb")][0]["TextDocument:text"][0]
    assert f"Opened at frame **{opened.frame_index}** on **{first}**" in index
    assert f"| **{first}** (opened) | {opened.frame_index} | ID switch |" in index
    other = rows[failure_index_doc("jpda")][0]["TextDocument:text"][0]
    assert "give `--tracker jpda` first and add `--focus ID`" in other and "Opened at" not in other
    body = [line for line in index.splitlines() if line.startswith("| ") and "---" not in line][1:]
    kinds = [line.split(" | ")[2] for line in body]
    assert kinds.index("ID switch") < kinds.index("false track") < kinds.index("miss")  # association errors first


def test_layout_index_tab_failures_over_time_and_only_fillable_panels(recorded) -> None:
    path, _, reports = recorded
    views = stored_views(path)
    assert views["gnnpmb failures"][1] == failure_index_doc("gnnpmb")
    assert views["gnnpmb failures over time"] == ("2D", failure_timeline("gnnpmb"))
    assert "gnnpmb decisions" in views and "gnnpmb cost grid" in views
    assert "jpda decisions" not in views and "jpda cost grid" not in views  # JPDA chooses no assignment
    opened = reports["gnnpmb"].by_id(reports["gnnpmb"].first_worth_opening())
    existence = next(name for name in views if name.startswith("gnnpmb existence"))
    assert existence.endswith(f" · tracks at {reports['gnnpmb'].first_worth_opening()}")
    assert opened.class_name  # the plots hold that failure's tracks (its class), with a legend naming them


def test_one_label_per_box_and_the_lost_track_drawn(recorded) -> None:
    _, rows, reports = recorded
    report = reports["gnnpmb"]
    false = next(f for f in report.failures if f.kind.value == "false_track")
    track = paths.track("gnnpmb", false.class_name, int(false.track_ids[0]))
    labels = [r["Boxes3D:labels"] for r in at_frame(rows[track], false.frame_index) if r.get("Boxes3D:labels")]
    if labels:  # the false track is drawn there (shown): the words are on its own label, not on the marker
        assert labels[-1][0].startswith(f"{false.track_ids[0]} · ") and "false track" in labels[-1][0]
        marker = at_frame(rows[paths.failures_world("gnnpmb", "false_track")], false.frame_index)[0]
        assert f"false track {false.track_ids[0]}" not in marker["Boxes3D:labels"]
    switch = next(f for f in report.failures if f.kind.value == "id_switch")
    lost = at_frame(rows[lost_tracks("gnnpmb")], switch.frame_index)[0]["Boxes3D:labels"]
    assert any(label.startswith(f"{switch.track_ids[0]} (lost)") for label in lost)
    for viewer in ("gnnpmb", "jpda"):  # comparison markers per tracker's views
        assert compare.markers_path(compare.DisagreementKind.MISSED_BY_ONE, viewer) in rows


def test_failures_over_the_whole_scene_whatever_the_timeline(recorded) -> None:
    _, rows, reports = recorded
    report = reports["gnnpmb"]
    root = failure_timeline("gnnpmb")
    dots = rows[f"{root}/failures"][0]  # static: seen on the focus timeline too, which ends at the opening
    kinds = timeline_rows(report, range(40))
    step = row_step(range(40), 2)  # rows a name's height apart (two runs side by side)
    expected = {(f.frame_index, kinds.index(f.kind)) for f in report.failures}
    assert {(int(x), round(y / step)) for x, y in dots["Points2D:positions"]} == expected
    names = rows[f"{root}/kinds"][0]["Points2D:labels"]
    assert names[0].startswith("ID switch (") and names[-1].startswith("miss (")  # the kinds that occurred
    assert [k for k in TIMELINE_KINDS if k in kinds] == kinds and len(names) == len(kinds)
    opened = report.by_id(report.first_worth_opening())
    assert np.allclose(
        rows[f"{root}/opened"][0]["Boxes2D:centers"], [[opened.frame_index, kinds.index(opened.kind) * step]]
    )
    assert sorted({r["frame"] for r in rows[f"{root}/now"] if not r["static"]}) == list(range(40))


MOST_LABELS = 15
"""Issue 31: at most this many labels per view per frame in a full recording."""


def test_labels_only_where_they_carry_the_story(recorded) -> None:
    """Counted as the viewer draws them (``tools.labels``): at most ``MOST_LABELS`` per 3D view and frame, none
    overlapping in the 3D and camera views' default cameras at 1920 x 1080, no comparison sentences, and a labelled
    track only where a failure of its run names it at that frame."""
    path, _, reports = recorded
    rec = Recording(path)
    views = [v for v in rec.views if v.name.startswith(("gnnpmb ", "jpda ")) or v.camera]
    assert sum(not v.camera for v in views) == 4 and sum(v.camera for v in views) == 6
    failing = {
        run: {(f.frame_index, t) for f in report.failures for t in f.track_ids} for run, report in reports.items()
    }
    for view in views:
        run = view.name.split(" ")[0]  # a camera view's tracks are drawn under the camera, not under /tracks/
        for frame in sorted(rec.frames):
            labels = rec.labels(view, frame)
            assert len(labels) <= MOST_LABELS, (view.name, frame, [label.text for label in labels])
            for label in labels:
                assert not label.text.startswith("only ") and "on it, " not in label.text
                if "/tracks/" in label.entity:
                    assert (frame, label.entity.rsplit("/", 1)[1]) in failing[run], (view.name, frame, label.text)
            boxes = camera_boxes(rec, view, frame) if view.camera else screen_boxes(rec, view, frame, view.size_px)
            assert not overlaps(boxes), (view.name, frame)
            rect = camera_rect(rec, view) if view.camera else (0.0, 0.0, *view.size_px)
            assert all(inside(box, rect) for _, box in boxes), (view.name, frame)  # none cut by the view's edge


@pytest.mark.parametrize("runs", [1, 2, 3])
def test_the_failure_timeline_leaves_room_for_its_longest_row_name(runs: int) -> None:
    """The row names are centred in the room left of frame 0; the view spans that room and the frames over its
    width (the scene column shared by ``runs``), so the longest name fits: "oalescence (8)" was clipped."""
    from viz.label_size import width_px
    from viz.opening import LONGEST_NAME, SCENE_COLUMN_PX, label_span

    frames = range(40)
    (x0, x1), _ = timeline_bounds(frames, 4, runs)
    px_per_frame = SCENE_COLUMN_PX / runs / (x1 - x0)
    assert label_span(frames, runs) * px_per_frame >= width_px(LONGEST_NAME)
    assert x0 == frames.start - label_span(frames, runs) and x1 == frames.stop + 0.5


def test_a_noted_tracks_label_is_dark_enough_to_read(recorded) -> None:
    """Rerun writes a box's label in the box's colour on a pale background: where a failure notes a track, its box
    takes its colour darkened (``colors.readable_text``); a pale olive "13 · ID switch: …" could not be read."""
    from viz.colors import TEXT_LUMINANCE_MAX, luminance

    _, rows, _ = recorded
    noted = [
        r
        for path, entity in rows.items()
        if "/tracks/" in path
        for r in entity
        if any(" · " in text for text in r.get("Boxes3D:labels") or [])
    ]
    assert noted
    for r in noted:
        (packed,) = r["Boxes3D:colors"]
        assert luminance(((packed >> 24) & 0xFF, (packed >> 16) & 0xFF, (packed >> 8) & 0xFF)) <= TEXT_LUMINANCE_MAX
