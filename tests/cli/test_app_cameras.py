"""gnnpmb-viz with and without cameras, and on a dataset without camera images: what the user sees."""

from __future__ import annotations

from pathlib import Path

import pytest

from cli.app import main
from gnnpmb.data.sensors import CAMERA_ORDER, SceneSensors
from tests.inprocess import run_main
from tests.viz.rrd import read_rows
from viz import paths

ARGS = ["scene-0103", "--frames", "0:2", "--no-failures", "--no-progress"]


def _cameras_in(path: Path) -> dict[str, int]:
    rows = read_rows(path)
    return {
        c: sum(1 for r in rows.get(paths.camera(c), []) if r.get("EncodedImage:blob") is not None) for c in CAMERA_ORDER
    }


def test_cameras_by_default_and_none_with_no_cameras(
    demo_dataroot: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    with_cams, without = tmp_path / "with.rrd", tmp_path / "without.rrd"
    code, _, err = run_main(main, [*ARGS, "--dataroot", str(demo_dataroot), "--save", str(with_cams)], capsys)
    assert code == 0, err
    assert _cameras_in(with_cams) == dict.fromkeys(CAMERA_ORDER, 2)
    argv = [*ARGS, "--dataroot", str(demo_dataroot), "--save", str(without), "--no-cameras"]
    code, _, err = run_main(main, argv, capsys)
    assert code == 0, err
    assert _cameras_in(without) == dict.fromkeys(CAMERA_ORDER, 0) and "cameras" not in err


def test_a_dataset_without_camera_images_says_so_in_one_line(
    demo_dataroot: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    import gnnpmb.data.sensors as sensors

    monkeypatch.setattr(
        sensors, "load_scene_sensors", lambda scene, frames=None: SceneSensors(tuple(() for _ in scene.keyframes), ())
    )
    out = tmp_path / "x.rrd"
    code, _, err = run_main(main, [*ARGS, "--dataroot", str(demo_dataroot), "--save", str(out), "--sweeps"], capsys)
    assert code == 0, err
    notes = [line for line in err.splitlines() if line.startswith("note: ")]
    assert notes == [
        "note: cameras absent: the dataset has no camera images for this scene",
        "note: sweeps absent: the dataset has no LiDAR sweeps between this scene's keyframes",
    ]
    assert _cameras_in(out) == dict.fromkeys(CAMERA_ORDER, 0)
