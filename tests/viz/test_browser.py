"""The README's demo recording and a focus recording of two trackers in a real browser (Rerun's web viewer in
headless Chromium), and the pieces of ``tools.webcheck`` that decide whether a screenshot shows the rendered
scene. Both recordings open in one Chromium, one after the other: software WebGL compiles the viewer's shaders
in Chromium's GPU process, and the second recording reuses them (measured here: the focus check took 32 s of
Chromium's CPU after the demo in the same browser, 58 s in a browser of its own). Each page loads and first renders at
a small size, and is checked and shot at 1920x1080 (``tools.webcheck.LOADING_VIEWPORT``)."""

from __future__ import annotations

import os
import sys
import time
from collections.abc import Iterator
from pathlib import Path

import numpy as np
import pytest

from tools.webcheck import (
    CHROMIUM,
    DEFAULT_VIEWPORT,
    Chromium,
    Expected,
    ViewerState,
    backlog_region,
    backlog_shown,
    check_recording,
    decode_png,
    free_port,
    group_cpu_s,
    group_members,
    headless_chromium,
    process_group,
    protobuf_fields,
    read_viewer_state,
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
    assert all(70 <= y0 < y1 <= 360 for _, y0, _, y1 in boxes)
    assert backlog_region(1600) == (235, 6, 500, 30) and backlog_region(900)[2] == 230


def test_backlog_readout() -> None:
    img = _image(1600, 900)
    assert not backlog_shown(img)
    shown = img.copy()
    shown[12:24, 240:330] = (90, 90, 90)  # "123.4 s latency"
    assert backlog_shown(shown)


def test_process_group_is_killed_with_its_children(tmp_path: Path) -> None:
    script = "sleep 60 & sleep 60 & trap '' TERM; sleep 60"  # the leader ignores SIGTERM: SIGKILL follows
    with process_group(["sh", "-c", script], tmp_path / "log", grace_s=0.5) as proc:
        for _ in range(100):
            if len(group_members(proc.pid)) >= 3:
                break
            time.sleep(0.05)
        assert len(group_members(proc.pid)) >= 3
    assert group_members(proc.pid) == [] and proc.returncode is not None
    assert isinstance(free_port(), int)


def test_a_process_groups_cpu_seconds_include_its_children(tmp_path: Path) -> None:
    """A child busy for 1.5 s of CPU counts in its group's CPU seconds while it runs; an idle group counts next
    to nothing. (The child burns more than the 1.0 s awaited: ``/proc`` counts whole 10 ms ticks, so a child
    that stopped at exactly 1.0 s could read 0.99 for good.)"""
    busy = "import time\nend = time.process_time() + 1.5\nwhile time.process_time() < end: pass\ntime.sleep(60)"
    with process_group(["sh", "-c", f"{sys.executable} -c '{busy}'; sleep 60"], tmp_path / "log", grace_s=0.5) as proc:
        deadline = time.monotonic() + 60
        while group_cpu_s(proc.pid) < 1.0 and time.monotonic() < deadline:
            time.sleep(0.1)
        assert 1.0 <= group_cpu_s(proc.pid) < 3.0
    with process_group(["sleep", "60"], tmp_path / "idle.log", grace_s=0.5) as idle:
        assert group_cpu_s(idle.pid) < 0.5


def test_viewer_state_is_decoded_from_its_protobuf_bytes() -> None:
    """A hand-built ``viewer_state`` message: recording, two timelines with their loaded ranges, two views."""

    def varint(n: int) -> bytes:
        out = bytearray()
        while True:
            out.append((n & 0x7F) | (0x80 if n > 0x7F else 0))
            n >>= 7
            if not n:
                return bytes(out)

    def field(number: int, value: int | bytes) -> bytes:
        if isinstance(value, int):
            return varint(number << 3) + varint(value)
        return varint(number << 3 | 2) + varint(len(value)) + value

    def timeline(name: str, lo: int, hi: int) -> bytes:
        return field(1, field(1, name.encode())) + field(2, 1) + field(3, field(1, lo) + field(2, hi))

    recording = field(1, b"Recording:gnnpmb-viz:abc") + field(2, timeline("frame", 14, 26))
    recording += field(2, timeline("focus", 0, 22))
    views = field(5, field(1, b"id1") + field(2, b"3D") + field(3, b"gnnpmb 3D"))
    views += field(5, field(1, b"id2") + field(2, b"TextLog") + field(3, b"gnnpmb story"))
    state = read_viewer_state(field(1, b"about:recording") + field(3, recording) + views)
    assert state == ViewerState(
        "Recording:gnnpmb-viz:abc",
        frozenset({"gnnpmb 3D", "gnnpmb story"}),
        {
            "frame": 26,
            "focus": 22,
        },
    )
    expected = Expected("Recording:gnnpmb-viz:abc", frozenset({"gnnpmb 3D"}), {"frame": 26, "focus": 22})
    assert expected.met_by(state)
    assert not Expected("Recording:gnnpmb-viz:abc", frozenset({"gnnpmb 3D"}), {"frame": 39}).met_by(state)
    assert not Expected("Recording:gnnpmb-viz:abc", frozenset({"pmbm 3D"}), {}).met_by(state)
    # proto3 writes no field whose value is 0: a timeline loaded up to frame 0 has an empty range message
    at_zero = field(1, field(1, b"focus")) + field(2, 1) + field(3, b"")
    state = read_viewer_state(field(3, field(1, b"Recording:gnnpmb-viz:abc") + field(2, at_zero)) + views)
    assert state.timeline_max == {"focus": 0}
    assert Expected("Recording:gnnpmb-viz:abc", frozenset({"gnnpmb 3D"}), {"focus": 0}).met_by(state)
    with pytest.raises(ValueError):
        protobuf_fields(b"\x0a\x05ab")  # a 5-byte field with 2 bytes left


def require_chromium() -> None:
    """Skip without Chromium, or fail when the suite said it must run (GNNPMB_REQUIRE_BROWSER=1)."""
    if not CHROMIUM.is_file():
        if REQUIRE_BROWSER:
            pytest.fail(f"GNNPMB_REQUIRE_BROWSER=1 but there is no Chromium at {CHROMIUM}")
        pytest.skip(f"no Chromium at {CHROMIUM} (set GNNPMB_REQUIRE_BROWSER=1 to make this a failure)")


@pytest.fixture(scope="module")
def chromium(tmp_path_factory: pytest.TempPathFactory) -> Iterator[Chromium]:
    """One headless Chromium for the module's browser checks; once they are done, its whole process group is
    gone."""
    require_chromium()
    work = tmp_path_factory.mktemp("chromium")
    with headless_chromium(work) as browser:
        # Chromium's own temporary folders go under the work folder, not into /tmp, where a killed run leaves them
        assert list(work.glob("org.chromium.Chromium.*")), f"no Chromium temporary folder under {work}"
        yield browser
    assert group_members(browser.proc.pid) == [], f"Chromium's process group {browser.proc.pid} is still running"


@pytest.mark.slow
@pytest.mark.browser
def test_the_full_demo_recording_loads_and_renders_in_headless_chromium(
    demo_dataroot: Path,
    demo_recording: tuple[Path, str],
    chromium: Chromium,
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
) -> None:
    """The demo as the README makes it (one tracker, the whole scene, no --focus; ``tests/conftest.py``): ready by
    the viewer's own state with its sparse bird's-eye view, opened at the first failure worth a look."""
    from tests.pipeline import prepare, reports_of

    rrd = demo_recording[0]
    shot = tmp_path / "demo.png"
    result = check_recording(rrd, shot, n_views=1, timeout_s=420.0, work_dir=tmp_path / "web", browser=chromium)
    with capsys.disabled():
        print(f"\nbrowser check (full demo recording): {result.describe()}", file=sys.stderr)
    assert result.seconds_to_load is not None, f"the viewer never showed everything loaded; see {shot}"
    assert result.rendered, f"the views did not render; look at {shot} and the logs in {tmp_path / 'web'}"
    assert {"gnnpmb bird's-eye", "gnnpmb failures", "gnnpmb failures over time"} <= result.state.views
    request = prepare("scene-0103", ["gnnpmb"], dataroot=demo_dataroot)
    report = reports_of(request)[0]["gnnpmb"]
    assert result.state.timeline_max["focus"] == report.by_id(report.first_worth_opening()).frame_index
    for pgid in result.process_groups:
        assert group_members(pgid) == [], f"process group {pgid} still has processes"
    width, height = DEFAULT_VIEWPORT
    assert decode_png(shot.read_bytes()).shape == (height, width, 3)


@pytest.mark.slow
@pytest.mark.browser
def test_a_focus_recording_of_two_trackers_loads_and_renders_in_headless_chromium(
    demo_dataroot: Path,
    viz_recording,
    chromium: Chromium,
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
) -> None:
    """The bug-report workflow end to end: the first ID switch of GNN-PMB on the committed demo scene, as a focus
    recording of GNN-PMB beside PMBM without N-scan pruning, ready in the web viewer with every view present.

    One recording, with two trackers: its layout holds every view a one-tracker focus recording has (the browser
    load is 60-100 s on this 2-core machine); it is the recording ``tests/cli/test_focus.py`` reads (made once
    for both, ``tests.pipeline.focus_comparison_args``), which also checks focus recordings of other failure
    kinds and of one tracker without a browser. Without the camera views: with encoded images the web viewer's own
    state never reported "loaded" within 420 s under software WebGL here, though the screenshot showed every view
    drawn (issue 34's note)."""
    from tests.pipeline import PMBM_ALL, POSITION_ONLY, focus_comparison_args, prepare, reports_of

    request = prepare("scene-0103", ["gnnpmb"], dataroot=demo_dataroot, detector="pointpillars", params=POSITION_ONLY)
    reports, _ = reports_of(request)
    pick = next(i for i in reports["gnnpmb"].ids() if i.startswith("id_switch:"))
    trackers = ("gnnpmb", PMBM_ALL)
    rrd, _ = viz_recording(focus_comparison_args(pick))
    shot = tmp_path / "focus.png"
    result = check_recording(
        rrd, shot, n_views=len(trackers), timeout_s=420.0, work_dir=tmp_path / "web", browser=chromium
    )
    with capsys.disabled():
        print(f"\nbrowser check ({pick}, {' vs '.join(trackers)}): {result.describe()}", file=sys.stderr)
    assert result.seconds_to_load is not None, f"the viewer never showed everything loaded; see {shot}"
    assert result.rendered, f"the views did not render; look at {shot} and the logs in {tmp_path / 'web'}"
    assert {f"{t} bird's-eye" for t in trackers} | {"focus"} <= result.state.views
    assert result.state.timeline_max["focus"] == reports["gnnpmb"].by_id(pick).frame_index
    assert all(r.distinct_colors >= 200 for r in result.regions)
    for pgid in result.process_groups:
        assert group_members(pgid) == [], f"process group {pgid} still has processes"
    width, height = DEFAULT_VIEWPORT
    assert decode_png(shot.read_bytes()).shape == (height, width, 3)


def test_a_sparse_birds_eye_view_counts_as_rendered() -> None:
    """A full recording's bird's-eye view at frame 0 of the demo: a few boxes on a white ground, no LiDAR (1.9 %
    foreground, ~1,000 colours, 0.4 % coloured): rendered; a grid alone is not."""
    rng = np.random.default_rng(1)
    img = _image(800, 400)
    img[::40, :] = (238, 238, 238)  # the faint grid
    assert not region_stats(img, (0, 0, 800, 400)).rendered
    for _ in range(12):  # boxes: class-coloured outlines, anti-aliased
        x, y = rng.integers(20, 740), rng.integers(20, 360)
        shade = rng.integers(0, 256, 3)
        img[y : y + 30, x : x + 2] = shade
        img[y : y + 30, x + 40 : x + 42] = shade
        img[y, x : x + 42] = rng.integers(0, 256, (42, 3))
        img[y + 30, x : x + 42] = rng.integers(0, 256, (42, 3))
    stats = region_stats(img, (0, 0, 800, 400))
    assert 0.005 < stats.foreground_fraction < 0.02 and stats.rendered


@pytest.mark.parametrize("runs", [1, 2, 3])
def test_the_check_looks_at_as_many_views_as_the_recording_lays_side_by_side(tmp_path: Path, runs: int) -> None:
    """``python -m tools.webcheck FILE.rrd`` checked two views whatever the file: on a one-run recording the right
    half of its bird's-eye view counted as a second view, which on the dev set (no LiDAR) never looked rendered
    (dev set scene-0103 cphd ``--focus identity_theft:1``: 424 s, NOT ready). It now reads the blueprint's."""
    import rerun as rr

    from gnnpmb.focus import FocusTarget
    from tools.webcheck import runs_side_by_side
    from viz.blueprint import default_blueprint

    trackers = ["gnnpmb", "pmbm", "cphd"][:runs]
    for focus in (None, FocusTarget("t", 5, (0.0, 0.0), "car", {t: (1,) for t in trackers}, ("abc",))):
        path = tmp_path / f"bp-{focus is None}.rrd"
        stream = rr.RecordingStream("webcheck-views-test")
        stream.save(path, default_blueprint=default_blueprint(trackers, ["car"], focus))
        stream.disconnect()
        assert runs_side_by_side(path) == runs
