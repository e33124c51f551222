"""``gnnpmb calibrate`` as a user runs it (in-process as the console script runs it, ``tests.inprocess``; the
script's own process start is checked in ``test_batch.py``): on the demo's two annotated scenes it writes one parameter
file that every tracker reads, with a comment on every learnt value; bad input is one ``error:`` line. Its check
by cross-validation is tested on smaller data in ``tests/gnnpmb/study/test_calibrate_check.py``."""

from __future__ import annotations

import re
import tomllib
from pathlib import Path

import pytest

from gnnpmb.config import load_config
from gnnpmb.types import TRACKING_CLASSES
from tests.inprocess import run_script, run_script_captured


@pytest.fixture(scope="module")
def calibrated(demo_dataroot: Path, tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, str]:
    out = tmp_path_factory.mktemp("calibrate") / "params.toml"
    argv = ["gnnpmb", "calibrate", "--dataroot", str(demo_dataroot), "--split", "mini_val", "--out", str(out)]
    argv.append("--no-check")  # everything learnt is written (the check: tests/gnnpmb/study/test_calibrate_check.py)
    done = run_script_captured(argv)
    assert done.returncode == 0, done.stderr
    return out, done.stdout


def test_the_file_is_read_by_the_parameter_reader_and_changes_each_class(calibrated: tuple[Path, str]) -> None:
    path, stdout = calibrated
    assert re.fullmatch(r"calibrate: \d+ per-class values from 2 scenes of mini_val -> .*params\.toml\n", stdout)
    config = load_config(path)
    for cls in TRACKING_CLASSES:
        own = config.for_class(cls)
        view = config.resolved(cls)
        assert 0.0 < own.r_x < 1.0 and 0.0 < own.r_vx < 5.0
        assert 0.0 < view.phd.p_detect < 1.0 and view.phd.p_detect == view.vector.p_detect
        assert view.pmb.miss_p_detect_max == view.phd.p_detect  # a PMB miss means what this detector's misses mean
        assert view.pmb.miss_p_detect_online == 0  # the learnt cap is kept, not learnt again from the tracks
        assert view.pmb.heading_std_rad > 0.0 and view.models.clutter_intensity > 0.0
    assert config.box_noise["car"].r_x != load_config(None).box_noise["car"].r_x


def test_every_learnt_value_says_what_it_was_learnt_from(calibrated: tuple[Path, str]) -> None:
    text = calibrated[0].read_text()
    data = tomllib.loads(text)
    assert set(data["classes"]) == set(TRACKING_CLASSES)
    values = [line for line in text.split("[box_noise.")[0].splitlines() if "=" in line and line[0] not in "#["]
    assert len(values) > 7 * 5
    for line in values:
        key, _, rest = line.partition("=")
        assert "  # " in rest, f"{key.strip()} has no comment"
    # the evaluation's matching distance is named where the values come from
    assert "2 m centre distance" in text


def test_each_class_says_how_many_objects_its_values_rest_on(calibrated: tuple[Path, str], demo_dataroot: Path) -> None:
    """The count the file states is the devkit's own: distinct annotated instances of the class with a box that
    its ``filter_eval_boxes`` keeps on the split."""
    from nuscenes.eval.common.loaders import add_center_dist, filter_eval_boxes, load_gt
    from nuscenes.eval.tracking.data_classes import TrackingBox

    from gnnpmb.data.nuscenes import open_nuscenes, resolve_dataroot
    from gnnpmb.eval.nuscenes_eval import quiet_devkit, tracking_config

    nusc = open_nuscenes(resolve_dataroot(demo_dataroot, None))
    cfg = tracking_config()  # it also tells the devkit's box class the tracking names
    with quiet_devkit():
        gt = load_gt(nusc, "mini_val", TrackingBox)
        gt = filter_eval_boxes(nusc, add_center_dist(nusc, gt), cfg.class_range, verbose=False)
    text = calibrated[0].read_text()
    for cls in TRACKING_CLASSES:
        ids = {b.tracking_id for b in gt.all if b.tracking_name == cls}
        boxes = sum(b.tracking_name == cls for b in gt.all)
        line = f"# {cls}: learnt from {len(ids)} annotated objects ({boxes} boxes the evaluation counts)"
        assert line in text.splitlines(), (cls, [x for x in text.splitlines() if x.startswith(f"# {cls}: learnt")])


def test_a_wrong_output_suffix_is_one_error_line(
    demo_dataroot: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    out = tmp_path / "params.json"
    argv = ["gnnpmb", "calibrate", "--dataroot", str(demo_dataroot), "--split", "mini_val", "--out", str(out)]
    done = run_script(argv, capsys)
    assert done.returncode == 2
    assert done.stderr.startswith("error: --out") and done.stderr.count("\n") == 1
    assert not out.exists()
