"""The README's demo recording in a real browser (Rerun's web viewer in headless Chromium): a module of its own so
that it runs beside ``test_browser.py``'s focus-recording check on the other worker."""

from __future__ import annotations

import sys
from pathlib import Path

import pytest

from tests.viz.test_browser import require_chromium
from tools.webcheck import check_recording, group_members


@pytest.mark.slow
@pytest.mark.browser
def test_the_full_demo_recording_loads_and_renders_in_headless_chromium(
    demo_dataroot: Path, demo_recording: tuple[Path, str], tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """The demo as the README makes it (one tracker, the whole scene, no --focus; ``tests/conftest.py``): ready by
    the viewer's own state with its sparse bird's-eye view, opened at the first failure worth a look."""
    from tests.pipeline import prepare, reports_of

    require_chromium()
    rrd = demo_recording[0]
    shot = tmp_path / "demo.png"
    result = check_recording(rrd, shot, n_views=1, timeout_s=420.0, work_dir=tmp_path / "web")
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
