"""A box whose points are radar returns only, as `gnnpmb failures --why` prints it.

Real nuScenes annotations often have ``num_lidar_pts = 0`` and ``num_radar_pts > 0`` (a far or low object only the
radars hit); the devkit keeps them (it drops only boxes with no point of either kind). Neither the demo nor the dev
set has a radar point, so "the detector gave no detection ... (3 LiDAR and radar points in its box): the detector
missed it" read as three LiDAR returns a LiDAR detector overlooked, where it had none (world3, /tmp/truth47: the dev
set with radar-only boxes; 645 of the 1,813 counts printed over nine scenes x three trackers). The counts are now
printed apart where a box had radar returns.
"""

from __future__ import annotations

import json
import re
import shutil
from pathlib import Path

import pytest

from tests.inprocess import run_script

SCENE = "scene-0103"
SUMMED = re.compile(r"\b[1-9][\d,]*(?:–[\d,]+)? LiDAR and radar points")
SPLIT = re.compile(r"\b0 LiDAR and [1-9][\d,]*(?:–[\d,]+)? radar points")


def _radar_only(demo: Path, to: Path) -> Path:
    """The demo's tables with every box's LiDAR points moved to radar (same total: the devkit and the simulated
    detector see the same boxes)."""
    to.mkdir()
    for name in ("v1.0-mini", "maps"):
        if (demo / name).exists():
            shutil.copytree(demo / name, to / name)
    table = to / "v1.0-mini" / "sample_annotation.json"
    rows = json.loads(table.read_text(encoding="utf-8"))
    for r in rows:
        r["num_radar_pts"], r["num_lidar_pts"] = r["num_lidar_pts"] + r["num_radar_pts"], 0
    table.write_text(json.dumps(rows), encoding="utf-8")
    return to


def test_a_box_with_radar_returns_only_is_not_said_to_have_lidar_points(
    demo_dataroot: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    root = _radar_only(demo_dataroot, tmp_path / "radar")
    proc = run_script(["gnnpmb", "failures", SCENE, "--dataroot", str(root), "--frames", "0:12", "--why"], capsys)
    assert proc.returncode == 0, proc.stderr
    assert SUMMED.findall(proc.stdout) == []
    said = re.findall(r"\(0 LiDAR and \d+ radar points in its box\): the detector missed it", proc.stdout)
    assert said, proc.stdout[-2000:]
    assert SPLIT.search(proc.stdout)


def test_without_radar_the_count_reads_as_before(demo_dataroot: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """The demo (no radar point anywhere): one count, as every earlier report printed it."""
    argv = ["gnnpmb", "failures", SCENE, "--dataroot", str(demo_dataroot), "--frames", "0:12", "--why"]
    proc = run_script(argv, capsys)
    assert proc.returncode == 0, proc.stderr
    assert re.search(r"\(\d+ LiDAR and radar points in its box\): the detector missed it", proc.stdout)
    assert " radar points in its box" not in proc.stdout.replace("LiDAR and radar points in its box", "")
