"""A dataroot with the nuScenes tables and none (or some) of the LiDAR files, through ``gnnpmb-viz`` (in-process as
the console script runs it, ``tests.inprocess.run_script``, a process start less each; the script's own process
start is checked in ``tests/cli/test_app.py``): the recording holds boxes, tracks and failures, the terminal says
once which LiDAR files are missing (``gnnpmb.data.sensor_files``), and the keyframes without a file show no points
rather than the last sweep."""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest

from tests.inprocess import run_script
from tests.viz.rrd import read_rows
from viz import paths

SCENE = "scene-0103"
FRAMES = range(0, 6)


def _copy_tables(demo: Path, to: Path) -> Path:
    """A dataroot holding the demo's tables and maps only (a metadata-only download)."""
    to.mkdir()
    for name in ("v1.0-mini", "maps"):
        if (demo / name).exists():
            shutil.copytree(demo / name, to / name)
    return to


def _lidar_files(demo: Path, frames: range) -> list[Path]:
    """The demo's LIDAR_TOP files of scene-0103's keyframes ``frames``, in keyframe order."""
    from gnnpmb.data.nuscenes import DatasetLocation, load_scene

    scene = load_scene(DatasetLocation(demo, "v1.0-mini", synthetic=True), SCENE)
    return [scene.keyframes[i].lidar_path for i in frames]


def _argv(dataroot: Path, out: Path, progress: bool = False) -> list[str]:
    frames = f"{FRAMES.start}:{FRAMES.stop}"
    argv = ["gnnpmb-viz", SCENE, "--dataroot", str(dataroot), "--frames", frames, "--save", str(out)]
    return argv if progress else [*argv, "--no-progress"]


def _points_per_frame(rows: dict) -> dict[int, int]:
    return {r["frame"]: r["Points3D:positions.len"] for r in rows.get(paths.LIDAR, []) if not r["static"]}


def test_tables_without_lidar_files_still_draw_tracks_and_failures(
    demo_dataroot: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    root = _copy_tables(demo_dataroot, tmp_path / "meta")
    out = tmp_path / "meta.rrd"
    done = run_script(_argv(root, out, progress=True), capsys)
    assert done.returncode == 0, done.stderr
    notes = [line for line in done.stderr.splitlines() if line.startswith("note:") and "LiDAR" in line]
    assert len(notes) == 1 and notes[0].startswith(f"note: {SCENE}: no LiDAR files in this dataroot")
    assert f"{SCENE} boxes (no LiDAR files)" in done.stderr  # the progress row does not promise sensor data
    assert "Traceback" not in done.stderr
    rows = read_rows(out)
    assert _points_per_frame(rows) == {}  # nothing drawn where there is nothing to draw
    assert len([r for r in rows[paths.GT] if not r["static"]]) == len(FRAMES)
    assert any(p.startswith(paths.tracks("gnnpmb", "car") + "/") for p in rows)
    assert any(p.startswith(paths.failures_world("gnnpmb", "false_track")) for p in rows)
    doc = rows[paths.SCENE_INFO][0]["TextDocument:text"][0]
    assert "sensor files: no LiDAR files in this dataroot" in doc


def test_some_lidar_files_missing_are_named_and_shown_empty(
    demo_dataroot: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    root = _copy_tables(demo_dataroot, tmp_path / "partial")
    files = _lidar_files(demo_dataroot, FRAMES)
    present = [0, 1, 4, 5]
    for i in present:
        rel = files[i].relative_to(demo_dataroot)
        (root / rel).parent.mkdir(parents=True, exist_ok=True)
        shutil.copyfile(files[i], root / rel)
    out = tmp_path / "partial.rrd"
    done = run_script(_argv(root, out), capsys)
    assert done.returncode == 0, done.stderr
    notes = [line for line in done.stderr.splitlines() if "LiDAR" in line]
    assert len(notes) == 1, done.stderr
    assert f"the LiDAR files of 2 of {len(FRAMES)} keyframes are missing (frames 2, 3;" in notes[0]
    assert str(files[2].name) in notes[0]
    points = _points_per_frame(read_rows(out))
    assert sorted(points) == list(FRAMES)  # every keyframe has a row: the missing ones empty, not the last sweep
    assert all(points[i] > 1000 for i in present) and points[2] == points[3] == 0


@pytest.mark.parametrize("damage", ["truncated"])
def test_a_damaged_lidar_file_is_still_an_error(
    demo_dataroot: Path, tmp_path: Path, damage: str, capsys: pytest.CaptureFixture[str]
) -> None:
    root = _copy_tables(demo_dataroot, tmp_path / "damaged")
    files = _lidar_files(demo_dataroot, FRAMES)
    for i, f in enumerate(files):
        rel = f.relative_to(demo_dataroot)
        (root / rel).parent.mkdir(parents=True, exist_ok=True)
        data = f.read_bytes()
        (root / rel).write_bytes(data[:-3] if i == 2 else data)
    out = tmp_path / "damaged.rrd"
    done = run_script(_argv(root, out), capsys)
    assert done.returncode == 2
    assert done.stderr.strip().splitlines()[-1].startswith("error: LiDAR file ") and "truncated" in done.stderr
    assert not out.exists()
