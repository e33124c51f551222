"""The comparison recording in a real browser (Rerun's web viewer in headless Chromium), and the pieces of
``viz.webcheck`` that decide whether a screenshot shows the rendered scene."""

from __future__ import annotations

import contextlib
import io
import os
import sys
import time
from pathlib import Path

import numpy as np
import pytest

from cli.app import main
from viz.webcheck import (
    CHROMIUM,
    DEFAULT_VIEWPORT,
    backlog_region,
    backlog_shown,
    changed_fraction,
    check_recording,
    decode_png,
    free_port,
    group_members,
    process_group,
    region_stats,
    view_regions,
)

REQUIRE_BROWSER = os.environ.get("GNNPMB_REQUIRE_BROWSER") == "1"
BACKGROUND = (245, 245, 245)


def _image(width: int = 400, height: int = 300) -> np.ndarray:
    return np.full((height, width, 3), BACKGROUND, dtype=np.uint8)


def test_a_uniform_or_text_only_region_is_not_rendered() -> None:
    img = _image()
    box = (0, 0, 400, 300)
    assert not region_stats(img, box).rendered
    img[100:110, 50:200] = (30, 30, 30)  # a line of dark "text": few colours, nothing coloured
    stats = region_stats(img, box)
    assert 0.0 < stats.foreground_fraction < 0.02 and stats.distinct_colors == 1 and not stats.rendered


def test_points_without_boxes_are_not_rendered_but_with_coloured_boxes_they_are() -> None:
    rng = np.random.default_rng(0)
    img = _image()
    ys, xs = rng.integers(0, 300, 6000), rng.integers(0, 400, 6000)
    img[ys, xs] = rng.integers(20, 120, (6000, 1)).repeat(3, axis=1)  # grey LiDAR points
    grey = region_stats(img, (0, 0, 400, 300))
    assert grey.foreground_fraction > 0.03 and grey.colored_fraction == 0.0 and not grey.rendered
    img[50:52, 100:300] = (0, 130, 200)  # a car box edge and a pedestrian box edge
    img[200:202, 20:90] = (60, 180, 75)
    img[150:180, 300:380] = rng.integers(0, 256, (30, 80, 3))  # a label / gate tangle
    assert region_stats(img, (0, 0, 400, 300)).rendered


def test_view_regions_tile_the_left_three_fifths() -> None:
    boxes = view_regions(1600, 900, 2)
    assert len(boxes) == 2 and boxes[0][2] < boxes[1][0] and boxes[1][2] <= 0.6 * 1600
    assert all(90 <= y0 < y1 <= 450 for _, y0, _, y1 in boxes)
    assert backlog_region(1600) == (235, 6, 500, 30) and backlog_region(900)[2] == 230


def test_backlog_readout_and_change_detection() -> None:
    img = _image(1600, 900)
    assert not backlog_shown(img)
    shown = img.copy()
    shown[12:24, 240:330] = (90, 90, 90)  # "123.4 s latency"
    assert backlog_shown(shown)
    assert changed_fraction(None, img) == 1.0 and changed_fraction(img, img) == 0.0
    assert changed_fraction(img, shown) == pytest.approx(12 * 90 / (1600 * 900))


def test_process_group_is_killed_with_its_children(tmp_path: Path) -> None:
    script = "sleep 60 & sleep 60 & trap '' TERM; sleep 60"  # the leader ignores SIGTERM: SIGKILL follows
    with process_group(["sh", "-c", script], tmp_path / "log") as proc:
        for _ in range(100):
            if len(group_members(proc.pid)) >= 3:
                break
            time.sleep(0.05)
        assert len(group_members(proc.pid)) >= 3
    assert group_members(proc.pid) == [] and proc.returncode is not None
    assert isinstance(free_port(), int)


@pytest.mark.slow
def test_comparison_recording_renders_in_headless_chromium(
    demo_dataroot: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    if not CHROMIUM.is_file():
        if REQUIRE_BROWSER:
            pytest.fail(f"GNNPMB_REQUIRE_BROWSER=1 but there is no Chromium at {CHROMIUM}")
        pytest.skip(f"no Chromium at {CHROMIUM} (set GNNPMB_REQUIRE_BROWSER=1 to make this a failure)")
    rrd = tmp_path / "comparison.rrd"
    with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(io.StringIO()):
        main(
            ["scene-0103", "-t", "gnnpmb", "-t", "pmbm", "--dataroot", str(demo_dataroot), "--save", str(rrd)]
        )
    assert rrd.is_file()
    shot = tmp_path / "comparison.png"
    result = check_recording(rrd, shot, n_views=2, timeout_s=420.0, work_dir=tmp_path / "web")
    with capsys.disabled():
        print(f"\nbrowser check: {result.describe()}", file=sys.stderr)
    assert shot.is_file() and shot.stat().st_size > 50_000
    assert result.rendered, f"the 3D views did not render; look at {shot} and the logs in {tmp_path / 'web'}"
    assert all(r.distinct_colors >= 1000 for r in result.regions)
    for pgid in result.process_groups:
        assert group_members(pgid) == [], f"process group {pgid} still has processes"
    width, height = DEFAULT_VIEWPORT
    assert decode_png(shot.read_bytes()).shape == (height, width, 3)
