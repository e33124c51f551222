"""``gnnpmb-viz SCENE --tracker A --tracker B``: one recording with both trackers, their comparison,
failures, the comparison blueprint and provenance; ``gnnpmb-viz reproduce`` on it (identical, tampered,
changed inputs)."""

from __future__ import annotations

import contextlib
import dataclasses
import io
import json
from pathlib import Path

import numpy as np
import pytest
import rerun as rr

from cli.app import main
from gnnpmb.compare import Comparison, DisagreementKind
from gnnpmb.data.scene import Keyframe, Pose, SceneData
from gnnpmb.pipeline import run_tracker
from gnnpmb.provenance import Provenance, TrackDigest
from gnnpmb.stages.findings import compare_runs
from gnnpmb.stages.runs import Run
from tests.gnnpmb.test_compare import A_FRAMES, B_FRAMES, GT
from tests.inprocess import run_main
from tests.pipeline import prepare
from tests.viz.rrd import at_frame, read_rows
from tests.viz.test_blueprint import stored_views
from viz import compare, paths
from viz.provenance import log_provenance, read_provenance

SCENE = "scene-0103"
N_FRAMES = 40
TRACKERS = ("gnnpmb", "gnn")
MAX_RECORDING_BYTES = 50_000_000


def run(argv: list[str], capsys: pytest.CaptureFixture[str]) -> tuple[int, str, str]:
    """The command in-process: (exit code, stdout, stderr)."""
    return run_main(main, argv, capsys)


@pytest.fixture(scope="module")
def saved(demo_dataroot: Path, tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, str]:
    """The two-tracker comparison of the 40-frame demo scene saved to an .rrd; the file and stdout."""
    out = tmp_path_factory.mktemp("compare") / "cmp.rrd"
    argv = [SCENE, "-t", TRACKERS[0], "-t", TRACKERS[1], "--dataroot", str(demo_dataroot), "--save", str(out)]
    stdout = io.StringIO()
    with contextlib.redirect_stdout(stdout):
        main([*argv, "--no-progress"])
    return out, stdout.getvalue().strip()


@pytest.fixture(scope="module")
def rows(saved: tuple[Path, str]) -> dict:
    return read_rows(saved[0])


@pytest.fixture(scope="module")
def expected(demo_dataroot: Path) -> Comparison:
    """The comparison computed apart from the recording (same inputs, trackers without a sink)."""
    request = prepare(SCENE, TRACKERS, dataroot=demo_dataroot)
    runs = [
        Run(
            run_tracker(
                request.scene,
                request.frame_detections,
                t,
                request.config,
                classes=request.classes,
            )
        )
        for t in TRACKERS
    ]
    return compare_runs(runs)


def test_summary_size_and_name(saved: tuple[Path, str], expected: Comparison, rows: dict) -> None:
    out, stdout = saved
    summary, *hints = stdout.splitlines()
    # --focus ids name the first tracker's failures: the second tracker's hint says to put it first.
    assert [h.split(" failures: ")[0] for h in hints] == list(TRACKERS)
    assert "add --focus " in hints[0] and f"give --tracker {TRACKERS[1]} first and add --focus " in hints[1]
    assert summary.startswith(f"{SCENE}: {N_FRAMES} frames, gnnpmb ")
    assert " ms/frame, gnn " in summary
    assert summary.endswith(f"; {len(expected.disagreements)} disagreements; saved {out}")
    assert out.stat().st_size <= MAX_RECORDING_BYTES
    info = [r for r in rows["__properties"] if "RecordingInfo:name" in r]
    assert info[0]["RecordingInfo:name"] == [f"{SCENE} · gnnpmb vs gnn · synthetic demo"]


def test_both_trackers_share_one_timeline(rows: dict) -> None:
    lidar_frames = [r["frame"] for r in rows[paths.LIDAR] if not r["static"]]
    assert lidar_frames == list(range(N_FRAMES))  # the scene is logged once
    for tracker in TRACKERS:
        for class_name in ("car", "pedestrian"):
            assert {r["frame"] for r in rows[paths.events(tracker, class_name)]} == set(range(N_FRAMES))
        boxes = [
            r
            for p in rows
            if p.startswith(paths.tracks(tracker, "car") + "/")
            for r in rows[p]
            if "Boxes3D:centers" in r
        ]
        assert boxes and max(r["frame"] for r in boxes) >= N_FRAMES - 5
        misses = [r for r in rows[paths.failure_count(tracker, "miss")] if not r["static"]]
        assert [r["frame"] for r in misses] == list(range(N_FRAMES))
    assert paths.failures_world("gnnpmb", "id_switch") in rows or paths.failures_world("gnn", "id_switch") in rows


def test_comparison_counts_log_and_markers(rows: dict, expected: Comparison) -> None:
    assert all(n > 0 for n in expected.totals().values())  # the demo exercises every kind
    for kind in DisagreementKind:
        counts = [r for r in rows[compare.count_path(kind)] if not r["static"]]
        assert [r["frame"] for r in counts] == list(range(N_FRAMES))
        assert [r["Scalars:scalars"][0] for r in counts] == expected.counts(kind).astype(float).tolist()
        for viewer in expected.trackers:
            every = rows[compare.markers_path(kind, viewer)]
            # "only in one run" is the marker's colour: its words are data (hover), never shown as a label
            assert [r["Boxes3D:show_labels"] for r in every if r["static"]] == [[False]]
            markers = [r for r in every if not r["static"]]
            assert [r["frame"] for r in markers] == list(range(N_FRAMES))
            for frame in range(N_FRAMES):
                found = [d for d in expected.of_kind(kind) if d.frame_index == frame]
                labels = at_frame(markers, frame)[0]["Boxes3D:labels"] or []
                objects = {d.gt_id or f"{d.tracker}/{d.track_ids[0]}" for d in found}
                assert len(labels) == len(objects)
                assert all(compare.marker_label(d) in "; ".join(labels) for d in found)
    logged = [(r["frame"], r["TextLog:text"][0]) for r in rows[compare.log_path()]]
    assert logged == [(d.frame_index, f"{compare.KIND_LABELS[d.kind]}: {d.describe()}") for d in expected.disagreements]


def test_few_chunks_one_per_entity_not_per_bernoulli_or_frame(saved: tuple[Path, str], rows: dict) -> None:
    """The web viewer's load time grows with the number of chunks: a saved recording sends each entity's rows
    in one chunk (LiDAR split by size), and candidate Bernoullis get no entities of their own."""
    from rerun.chunk import RrdReader

    chunks = list(RrdReader(saved[0]).store().stream())
    entities = {c.entity_path for c in chunks}
    assert len(chunks) <= 1500
    # static + temporal part per entity, the temporal part in two where the recording opens at a failure (the
    # rows up to it are on the focus timeline too, viz.opening), a few split
    assert len(chunks) <= 3 * len(entities) + 20
    assert not any("/candidates/" in p and p.rsplit("/", 1)[1].isdigit() for p in rows)


def test_comparison_blueprint_is_stored(saved: tuple[Path, str]) -> None:
    stored = stored_views(saved[0])
    assert stored["gnnpmb 3D"] == ("3D", paths.EGO) and stored["gnn 3D"] == ("3D", paths.EGO)
    assert stored["disagreements"] == ("TextLog", compare.log_path())
    assert stored["gnn story"] == ("TextLog", paths.events.root("gnn"))
    assert stored["gnnpmb decisions"] == ("TextDocument", paths.decisions("gnnpmb"))
    assert stored["gnn bird's-eye"] == ("3D", paths.EGO)


def provenance_recording(path: Path, provenance: Provenance) -> Path:
    """A recording holding only ``provenance`` (all that ``reproduce`` reads)."""
    stream = rr.RecordingStream("gnnpmb-viz-test")
    stream.save(path)
    log_provenance(stream, provenance)
    stream.disconnect()
    return path


def test_reproduce_identical(saved: tuple[Path, str], capsys: pytest.CaptureFixture[str]) -> None:
    p = read_provenance(saved[0])
    assert p.trackers == TRACKERS and set(p.track_digests) == set(TRACKERS)
    code, out, err = run(["reproduce", str(saved[0])], capsys)
    assert (code, err) == (0, "")
    assert out.strip().splitlines()[1:] == [f"{t}: identical ({N_FRAMES} frames)" for t in TRACKERS]


def test_reproduce_finds_a_tampered_digest(
    saved: tuple[Path, str], tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    p = read_provenance(saved[0])
    gnn = p.track_digests["gnn"]
    frames = list(gnn.frames)
    frames[7] = "0" * 64
    tampered = dataclasses.replace(
        p, track_digests={**p.track_digests, "gnn": TrackDigest("f" * 64, gnn.frame_indices, tuple(frames))}
    )
    code, out, err = run(["reproduce", str(provenance_recording(tmp_path / "t.rrd", tampered))], capsys)
    assert (code, err) == (1, "")
    assert out.strip().splitlines()[1:] == [
        f"gnnpmb: identical ({N_FRAMES} frames)",
        f"gnn: DIFFERENT from keyframe 7 on (1 of {N_FRAMES} frames differ)",
    ]


def test_reproduce_with_other_parameters_differs(
    saved: tuple[Path, str], tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    p = read_provenance(saved[0])
    config = json.loads(json.dumps(p.config))
    config["preprocess"]["score_threshold"] = 0.4  # both trackers see fewer detections
    other = provenance_recording(tmp_path / "o.rrd", dataclasses.replace(p, config=config))
    code, out, _ = run(["reproduce", str(other)], capsys)
    assert code == 1
    lines = out.strip().splitlines()[1:]
    assert [line.split(":")[0] for line in lines] == list(TRACKERS)
    assert all(": DIFFERENT from keyframe " in line for line in lines)


def test_reproduce_missing_dataroot_and_override(
    saved: tuple[Path, str], demo_dataroot: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    p = read_provenance(saved[0])
    moved = provenance_recording(tmp_path / "m.rrd", dataclasses.replace(p, dataroot=str(tmp_path / "gone")))
    code, out, err = run(["reproduce", str(moved)], capsys)
    assert (code, out) == (2, "")
    gone = tmp_path / "gone"
    assert err == f"error: the recorded dataroot {gone} does not exist; pass --dataroot DIR with a copy of it\n"
    code, out, err = run(["reproduce", str(moved), "--dataroot", str(demo_dataroot)], capsys)
    assert (code, err) == (0, "") and out.count(": identical") == 2


def test_reproduce_rejects_files_without_provenance(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    plain = tmp_path / "plain.rrd"
    stream = rr.RecordingStream("other-app")
    stream.save(plain)
    stream.log("x", rr.Points3D([[0.0, 0.0, 0.0]]))
    stream.disconnect()
    junk = tmp_path / "junk.rrd"
    junk.write_bytes(b"not a recording")
    for path, message in [
        (plain, "has no gnnpmb-viz provenance"),
        (junk, "is not a readable Rerun recording"),
        (tmp_path / "none.rrd", "does not exist"),
    ]:
        code, out, err = run(["reproduce", str(path)], capsys)
        assert (code, out) == (2, "")
        assert err.startswith("error: ") and message in err and err.count("\n") == 1


def gt_detections_file(path: Path, scene: SceneData) -> Path:
    """The scene's ground truth as a detection submission (score 0.8)."""
    results = {
        k.sample_token: [
            {
                "sample_token": k.sample_token,
                "translation": k.gt.translation_m[i].tolist(),
                "size": k.gt.size_wlh_m[i].tolist(),
                "rotation": k.gt.quat_wxyz[i].tolist(),
                "velocity": np.nan_to_num(k.gt.velocity_mps[i]).tolist(),
                "detection_name": str(k.gt.class_name[i]),
                "detection_score": 0.8,
                "attribute_name": "",
            }
            for i in range(len(k.gt))
        ]
        for k in scene.keyframes
    }
    path.write_text(json.dumps({"meta": {"use_lidar": True}, "results": results}))
    return path


def test_reproduce_a_detections_file_and_save(
    demo_dataroot: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    scene = prepare(SCENE, ["gnn"], dataroot=demo_dataroot, frames="0:2").scene
    dets = gt_detections_file(tmp_path / "dets.json", scene)
    rec = tmp_path / "small.rrd"
    argv = [SCENE, "-t", "gnnpmb", "-t", "jpda", "--dataroot", str(demo_dataroot), "--detections", str(dets)]
    argv += [
        "--frames",
        "3:9",
        "--classes",
        "car,pedestrian",
        "--no-failures",
        "--no-progress",
        "--save",
        str(rec),
    ]
    assert run(argv, capsys)[0] == 0
    p = read_provenance(rec)
    assert (p.detections.kind, p.detections.path, p.frame_range) == ("file", str(dets), range(3, 9))
    assert p.track_digests["jpda"].frame_indices == tuple(range(3, 9))

    again = tmp_path / "again.rrd"
    code, out, err = run(["reproduce", str(rec), "--save", str(again), "--no-progress"], capsys)
    assert (code, err) == (0, "")
    assert out.strip().splitlines()[1:] == [
        "gnnpmb: identical (6 frames)",
        "jpda: identical (6 frames)",
        f"saved {again}",
    ]
    redone = read_provenance(again)
    assert redone.argv[:3] == ("gnnpmb-viz", "reproduce", str(rec))
    assert redone.track_digests == p.track_digests and redone.detections == p.detections

    copy = tmp_path / "copy.json"
    copy.write_bytes(dets.read_bytes())
    dets.write_text(dets.read_text() + " ")
    code, out, err = run(["reproduce", str(rec)], capsys)
    assert (code, out) == (2, "") and err.count("\n") == 1
    assert f"error: detections file {dets} has changed since the recording (sha256 " in err
    dets.unlink()
    code, out, err = run(["reproduce", str(rec)], capsys)
    assert (code, out, err) == (
        2,
        "",
        f"error: the recorded detections file {dets} is missing; pass --detections FILE.json\n",
    )
    code, out, err = run(["reproduce", str(rec), "--detections", str(copy)], capsys)
    assert (code, err) == (0, "") and out.count(": identical (6 frames)") == 2


def tiny_scene(n: int) -> SceneData:
    """n keyframes 0.5 s apart (only the timestamps matter for logging a comparison)."""
    pose = Pose(np.zeros(3), np.array([1.0, 0.0, 0.0, 0.0]))
    keyframes = tuple(
        Keyframe(i, f"s{i}", 1_000_000 + 500_000 * i, pose, pose, Path("none"), GT, np.ones(len(GT))) for i in range(n)
    )
    return SceneData("scene-x", "tok", "", Path("."), "v1.0-mini", True, keyframes)


def test_log_comparison_of_a_hand_made_case(tmp_path: Path) -> None:
    from gnnpmb.compare import compare_trackers
    from viz.compare import log_comparison

    comparison = compare_trackers([GT] * 3, {"A": A_FRAMES, "B": B_FRAMES}, frame_indices=[4, 5, 6])
    path = tmp_path / "c.rrd"
    stream = rr.RecordingStream("gnnpmb-viz-test")
    stream.save(path)
    log_comparison(stream, comparison, tiny_scene(8))
    stream.disconnect()
    rows = read_rows(path)
    missed = rows[compare.markers_path(DisagreementKind.MISSED_BY_ONE, "A")]
    assert [r["frame"] for r in missed] == [4, 5, 6]
    assert [r["Boxes3D:labels"] for r in missed] == [
        ["only A tracks GT g2 (track 2)", "only B tracks GT p1 (track 12)"],
        ["only B tracks GT p1 (track 12)"],
        ["only B tracks GT p1 (track 12)"],
    ]
    np.testing.assert_allclose(missed[0]["Boxes3D:centers"], [[10.0, 0.0, 1.0], [20.0, 5.0, 1.0]])
    half = 0.5 * (np.array([4.5, 2.0, 1.6]) * compare.MARKER_SCALE + compare.MARKER_MARGIN_M)
    np.testing.assert_allclose(missed[0]["Boxes3D:half_sizes"][0], half, rtol=1e-6)
    switch = rows[compare.markers_path(DisagreementKind.ID_CHANGE, "B")]
    assert [r["Boxes3D:labels"] or [] for r in switch] == [[], ["A 1->5, B kept 11: GT g1-tok"], []]
    only = rows[compare.markers_path(DisagreementKind.ONLY_IN_ONE, "A")]
    assert [r["Boxes3D:labels"] or [] for r in only] == [
        [],
        ["only A: track 6", "only B: track 15"],
        ["only A: track 8"],
    ]
    counts = [
        r["Scalars:scalars"][0] for r in rows[compare.count_path(DisagreementKind.ONLY_IN_ONE)] if not r["static"]
    ]
    assert counts == [0.0, 2.0, 1.0]
    log = [(r["frame"], r["TextLog:level"][0], r["TextLog:text"][0]) for r in rows[compare.log_path()]]
    assert log[3] == (
        5,
        "WARN",
        "id changed in one only: car GT g1-tok: A switched track 1 -> 5, B kept 11",
    )
    assert len(log) == len(comparison.disagreements) == 8
    assert rows[compare.log_path()][0]["timestamp"] == np.datetime64(3_000_000, "us")
