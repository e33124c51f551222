"""``gnnpmb-viz`` end to end on the synthetic demo, and its one-line errors."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

from cli.app import main
from gnnpmb.config import TrackerConfig
from gnnpmb.errors import DataError, GnnpmbError, UnknownNameError
from gnnpmb.pipeline import run_tracker
from gnnpmb.provenance import PACKAGES, SOURCE_KEY
from gnnpmb.registry import TRACKER_NAMES
from gnnpmb.stages.evaluation import find_reports
from gnnpmb.stages.request import parse_classes, parse_frames
from gnnpmb.stages.runs import Run
from tests.inprocess import run_main, run_script
from tests.pipeline import prepare, reports_of
from tests.viz.rrd import at_frame, read_rows
from viz import paths
from viz.provenance import PROPERTY_ENTITY, read_provenance

SCENE = "scene-0103"
N_FRAMES = 40
SCRIPT = Path(sys.executable).parent / "gnnpmb-viz"


def run(argv: list[str], capsys: pytest.CaptureFixture[str]) -> tuple[int, str, str]:
    """The command in-process: (exit code, stdout, stderr)."""
    return run_main(main, argv, capsys)


@pytest.fixture(scope="module")
def full_run(demo_recording: tuple[Path, str]) -> tuple[Path, str]:
    """scene-0103 with gnnpmb (all defaults) saved to an .rrd (``tests/conftest.py``); the file and stdout."""
    return demo_recording


@pytest.fixture(scope="module")
def rows(full_run: tuple[Path, str]) -> dict:
    return read_rows(full_run[0])


def test_summary_line_and_where_to_look_next(
    full_run: tuple[Path, str], demo_dataroot: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    out, stdout = full_run
    summary, *hints = stdout.splitlines()
    assert summary.startswith(f"{SCENE}: {N_FRAMES} frames, gnnpmb ")
    assert "ms/frame" in summary and summary.endswith(f"saved {out}")
    assert sorted(p.name for p in out.parent.iterdir()) == ["x.rrd"]
    # The failures found, and the id of the one to open first with --focus (the same ids `gnnpmb failures` prints).
    request = prepare(SCENE, ["gnnpmb"], dataroot=demo_dataroot)
    report = reports_of(request)[0]["gnnpmb"]
    first = report.first_worth_opening()
    assert first is not None and report.by_id(first) is not None
    (hint,) = hints
    assert hint.startswith(f"gnnpmb failures: {report.totals_text()}")
    interpolated = sum(f.gt_interpolated for f in report.failures)
    assert (f"({interpolated} at a GT box the evaluation interpolated" in hint) == (interpolated > 0)
    assert f"To open {first} at its frame, add --focus {first} to this command" in hint
    listing = f"gnnpmb failures {SCENE} --tracker gnnpmb --dataroot {demo_dataroot}"
    assert hint.endswith(f"to list them all: {listing}")  # the command as it runs, the viewer's options left out
    listed = run_script(listing.split(), capsys)
    assert listed.returncode == 0, listed.stderr
    assert listed.stdout.rstrip().endswith(f"{SCENE}, gnnpmb: {report.totals_text()}")


def test_sensors_and_ground_truth_on_every_frame(rows: dict) -> None:
    lidar = [r for r in rows[paths.LIDAR] if not r["static"]]
    assert [r["frame"] for r in lidar] == list(range(N_FRAMES))
    assert all(r["Points3D:positions.len"] > 1000 for r in lidar)
    assert [r["frame"] for r in rows[paths.EGO]] == list(range(N_FRAMES))
    gt = [r for r in rows[paths.GT] if not r["static"]]
    assert len(gt) == N_FRAMES and sum(len(r["Boxes3D:centers"]) for r in gt) > N_FRAMES
    kept = rows[paths.DETECTIONS_KEPT]
    assert len(kept) == N_FRAMES and sum(len(r["Boxes3D:centers"]) for r in kept) > N_FRAMES
    assert paths.DETECTIONS_SUPPRESSED in rows


def test_tracks_decisions_existence_and_story(rows: dict) -> None:
    car_tracks = [p for p in rows if p.startswith(paths.tracks("gnnpmb", "car") + "/")]
    assert len(car_tracks) >= 5  # one entity per reported track
    boxes = [r for p in car_tracks for r in rows[p] if "Boxes3D:centers" in r]
    assert max(r["frame"] for r in boxes) >= N_FRAMES - 5
    labels = [(p.rsplit("/", 1)[1], r["Boxes3D:labels"]) for p in car_tracks for r in rows[p] if "Boxes3D:labels" in r]
    # its id while reported (with what a failure says of it at that frame: viz.opening), an empty batch once it is not
    assert all(got in ([t], []) or (len(got) == 1 and got[0].startswith(f"{t} · ")) for t, got in labels)
    assert any(got and got[0].endswith(" · false track") for _, got in labels)
    docs = rows[paths.decisions("gnnpmb")]
    assert at_frame(docs, 0) and at_frame(docs, N_FRAMES - 1)
    assert any("| detection | chosen | cost | next best | cost | margin |" in r["TextDocument:text"][0] for r in docs)
    lines = [r for r in rows[paths.associations("gnnpmb", "car")] if "LineStrips3D:labels" in r]
    assert lines and all(" → " in label for r in lines for label in r["LineStrips3D:labels"])
    existence = [p for p in rows if p.startswith(paths.existence_root("gnnpmb") + "/car/")]
    assert len(existence) >= 5
    events = rows[paths.events("gnnpmb", "car")]
    assert {r["frame"] for r in events} >= {0, N_FRAMES - 1}
    texts = [t for r in events for t in r["TextLog:text"]]
    assert any(t.startswith("track ") and " confirmed " in t for t in texts)
    assert any("new candidates" in t for t in texts)


def test_failure_markers_of_the_tracker(rows: dict) -> None:
    misses = [r for r in rows[paths.failure_count("gnnpmb", "miss")] if not r["static"]]
    assert [r["frame"] for r in misses] == list(range(N_FRAMES))
    assert sum(r["Scalars:scalars"][0] for r in misses) > 0
    assert paths.failures_world("gnnpmb", "miss") in rows
    assert not any(p.startswith("comparison/") for p in rows)  # one tracker: nothing to compare


def test_recording_name_and_provenance(full_run: tuple[Path, str], demo_dataroot: Path, rows: dict) -> None:
    out, _ = full_run
    info = [r for r in rows["__properties"] if "RecordingInfo:name" in r]
    assert info[0]["RecordingInfo:name"] == [f"{SCENE} · gnnpmb · synthetic demo"]
    p = read_provenance(out)
    assert p.argv == (
        "gnnpmb-viz",
        SCENE,
        "--dataroot",
        str(demo_dataroot),
        "--save",
        str(out),
        "--no-progress",
    )
    assert set(p.versions) == {*PACKAGES, SOURCE_KEY} and p.versions["rerun-sdk"].startswith("0.41")
    assert p.config == TrackerConfig().as_dict()
    assert p.dataroot == str(demo_dataroot.resolve()) and p.version == "v1.0-mini" and p.synthetic
    assert p.scene_name == SCENE and len(p.scene_token) == 32
    assert (p.detections.kind, p.detections.preset, p.detections.seed) == ("simulated", "centerpoint", 0)
    assert len(p.detections.sha256) == 64 and p.seed == 0
    assert (p.frame_start, p.frame_end, p.trackers) == (0, N_FRAMES, ("gnnpmb",))
    assert len(p.classes) == 7
    digest = p.track_digests["gnnpmb"]
    assert digest.frame_indices == tuple(range(N_FRAMES)) and len(set(digest.frames)) > N_FRAMES // 2
    readable = rows[PROPERTY_ENTITY.lstrip("/")][0]
    assert readable["command"] == [f"gnnpmb-viz {SCENE} --dataroot {demo_dataroot} --save {out} --no-progress"]
    assert readable["frames"] == [f"0:{N_FRAMES}"] and readable["seed"] == ["0"]
    assert readable["track_digests"] == [f"gnnpmb {digest.overall[:16]}"]


def test_reproduce_reports_identical_tracks(full_run: tuple[Path, str], capsys: pytest.CaptureFixture[str]) -> None:
    code, out, err = run(["reproduce", str(full_run[0])], capsys)
    assert (code, err) == (0, "")
    lines = out.strip().splitlines()
    assert lines[0].startswith(f"{SCENE} (synthetic demo), keyframes 0:{N_FRAMES}, detections: simulated centerpoint")
    assert lines[1:] == [f"gnnpmb: identical ({N_FRAMES} frames)"]


def test_installed_script_with_a_detections_file_and_frame_range(demo_dataroot: Path, tmp_path: Path) -> None:
    """A real process through the console script: --detections (GT boxes as a submission), --frames,
    --classes."""
    from gnnpmb.data.nuscenes import load_scene, resolve_dataroot

    location = resolve_dataroot(demo_dataroot, None)
    scene = load_scene(location, SCENE)
    results = {}
    for k in scene.keyframes:
        g = k.gt
        results[k.sample_token] = [
            {
                "sample_token": k.sample_token,
                "translation": g.translation_m[i].tolist(),
                "size": g.size_wlh_m[i].tolist(),
                "rotation": g.quat_wxyz[i].tolist(),
                "velocity": g.velocity_mps[i].tolist(),
                "detection_name": str(g.class_name[i]),
                "detection_score": 0.8,
                "attribute_name": "",
            }
            for i in range(len(g))
        ]
    dets = tmp_path / "dets.json"
    dets.write_text(json.dumps({"meta": {"use_lidar": True}, "results": results}))
    out = tmp_path / "sub.rrd"
    argv = [SCENE, "--dataroot", str(demo_dataroot), "--detections", str(dets), "--frames", "2:6"]
    proc = subprocess.run(
        [str(SCRIPT), *argv, "--classes", "car,pedestrian", "--save", str(out)],
        capture_output=True,
        text=True,
        timeout=300,
        env={**os.environ, "NO_COLOR": "1"},
    )
    assert proc.returncode == 0, proc.stderr
    assert proc.stdout.strip().startswith(f"{SCENE}: 4 frames, gnnpmb ")
    assert "4/4" in proc.stderr  # the progress bar counted the frames
    rows = read_rows(out)
    assert [r["frame"] for r in rows[paths.EGO]] == [2, 3, 4, 5]
    assert {r["frame"] for r in rows[paths.decisions("gnnpmb")]} <= {2, 3, 4, 5}
    assert not any(p.startswith(paths.tracks("gnnpmb", "bus")) for p in rows)
    kept = at_frame(rows[paths.DETECTIONS_KEPT], 3)[0]
    assert kept["Boxes3D:labels"] and all(
        label.startswith("m") and label.endswith(" 0.80") for label in kept["Boxes3D:labels"]
    )


def _truncated_submission(path: Path) -> None:
    text = json.dumps({"meta": {}, "results": {"tok": [{"translation": [1.0, 2.0, 3.0], "size": [1, 2, 3]}]}})
    path.write_text(text[: len(text) // 2])


def _malformed_submission(path: Path) -> None:
    path.write_text(json.dumps({"meta": {}, "results": [1, 2, 3]}))


@pytest.mark.parametrize(
    ("argv", "expected"),
    [
        (["scene-9999"], "unknown scene 'scene-9999'; available: scene-0103, scene-0916"),
        ([SCENE, "--tracker", "kalman"], "unknown tracker 'kalman'; choose one of: gnnpmb, pmbm"),
        ([SCENE, "--classes", "car,tree"], "unknown class 'tree'; choose from: bicycle"),
        ([SCENE, "--detector", "yolo"], "unknown detector preset 'yolo'"),
        ([SCENE, "--frames", "abc"], "bad --frames 'abc': use START:END"),
        ([SCENE, "--frames", "5:2"], "END must be greater than START"),
        ([SCENE, "--frames", "30:50"], "--frames 30:50 is outside scene-0103, which has keyframes 0 to 39"),
        ([SCENE, "--frames", ":0"], "--frames 0:0 selects no keyframes"),
        ([SCENE, "--params", "missing.toml"], "parameter file not found"),
        ([SCENE, "--detections", "TRUNCATED"], "detections file"),
        ([SCENE, "--detections", "MALFORMED"], "detections file"),
        ([SCENE, "--detections", "missing.json"], "missing.json"),
    ],
)
def test_bad_input_is_one_line_and_leaves_no_recording(
    argv: list[str], expected: str, demo_dataroot: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    _truncated_submission(tmp_path / "truncated.json")
    _malformed_submission(tmp_path / "malformed.json")
    argv = [
        {"TRUNCATED": str(tmp_path / "truncated.json"), "MALFORMED": str(tmp_path / "malformed.json")}.get(a, a)
        for a in argv
    ]
    out = tmp_path / "out" / "x.rrd"
    out.parent.mkdir()
    code, stdout, stderr = run([*argv, "--dataroot", str(demo_dataroot), "--save", str(out)], capsys)
    assert code == 2
    assert stderr.count("\n") == 1 and stderr.startswith("error: ") and expected in stderr
    assert "Traceback" not in stderr and stdout == ""
    assert list(out.parent.iterdir()) == []


def test_missing_dataroot_and_bad_save_path(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    code, _, err = run([SCENE, "--dataroot", str(tmp_path / "nowhere"), "--save", str(tmp_path / "x.rrd")], capsys)
    assert code == 2 and "does not exist" in err and err.count("\n") == 1
    code, _, err = run([SCENE, "--save", str(tmp_path / "no" / "x.rrd")], capsys)
    assert code == 2 and "does not exist; create it first" in err
    assert list(tmp_path.iterdir()) == []


def test_a_real_process_prints_no_traceback(tmp_path: Path) -> None:
    proc = subprocess.run(
        [str(SCRIPT), SCENE, "--tracker", "nope", "--save", str(tmp_path / "x.rrd")],
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert proc.returncode == 2
    assert proc.stderr.strip().splitlines() == [
        f"error: unknown tracker 'nope'; choose one of: {', '.join(TRACKER_NAMES)}"
    ]
    assert list(tmp_path.iterdir()) == []


def test_parse_frames_and_classes() -> None:
    assert parse_frames(None) == (None, None)
    assert parse_frames("3:10") == (3, 10)
    assert parse_frames(":7") == (None, 7)
    assert parse_frames("4:") == (4, None)
    for bad in ["3", "a:b", "-1:4", "1:2:3", "4:4"]:
        with pytest.raises(GnnpmbError, match="--frames"):
            parse_frames(bad)
    assert parse_classes(None)[0] == "bicycle" and len(parse_classes(None)) == 7
    assert parse_classes(" car, bus ,car") == ("car", "bus")
    with pytest.raises(UnknownNameError):
        parse_classes(",")


def test_failures_are_skipped_with_a_notice_without_ground_truth(
    demo_dataroot: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    import dataclasses

    from gnnpmb.eval import failures
    from gnnpmb.types import Boxes

    request = prepare(SCENE, ["gnn"], dataroot=demo_dataroot, frames="0:3")
    unannotated = dataclasses.replace(
        request.scene,
        keyframes=tuple(dataclasses.replace(k, gt=Boxes.empty()) for k in request.scene.keyframes),
    )
    calls: list[None] = []
    reports, notices = find_reports(dataclasses.replace(request, scene=unannotated), [], lambda: calls.append(None))
    assert reports == {}
    assert notices == [unannotated.no_ground_truth()]
    assert notices[0].startswith(f"{SCENE} has no ground-truth boxes (no annotation of a tracked class")

    def not_in_a_split(*_args, **_kwargs):
        raise DataError(f"scene {SCENE} is in no nuScenes split, so the devkit cannot evaluate it")

    monkeypatch.setattr(failures, "find_failures", not_in_a_split)
    runs = [Run(run_tracker(request.scene, request.detections, "gnn", request.config, frame_range=request.frame_range))]
    reports, notices = find_reports(request, runs, lambda: calls.append(None))
    assert reports == {}
    assert notices == [
        f"failure markers skipped: scene {SCENE} is in no nuScenes split, so the devkit cannot evaluate it"
    ]
    assert calls == []
