"""``gnnpmb calibrate``'s check (``gnnpmb/calibration_check.py``): its rule on hand-made scores, the premise that
each class may choose apart (classes are tracked apart), and the command on the demo's two ``mini_val`` scenes cut
to 6 keyframes: the file holds what the printed check chose, and what it left out is said, not lost."""

from __future__ import annotations

import functools
import json
import re
import tomllib
from pathlib import Path

import pytest

from cli.batch import app
from cli.errors import run_app
from gnnpmb.calibration import Learnt
from gnnpmb.calibration_check import (
    CHECK_TRACKER,
    GROUPS,
    MARGIN_AMOTA,
    CheckResult,
    candidate_values,
    candidates,
    choose,
    fold_scenes,
)
from gnnpmb.config import TrackerConfig, config_from_dict
from gnnpmb.eval.nuscenes_eval import resolve_split
from gnnpmb.study.data import resolve_study_data, track_scene
from gnnpmb.types import TRACKING_CLASSES
from tests.inprocess import run_main


def run(argv: list[str], capsys: pytest.CaptureFixture[str]) -> tuple[int, str, str]:
    """The command in-process: (exit code, stdout, stderr)."""
    return run_main(functools.partial(run_app, app), argv, capsys)


def test_a_class_keeps_the_defaults_unless_a_candidate_beats_them_by_the_margin() -> None:
    amota: dict[str, dict[str, float | None]] = {n: dict.fromkeys(TRACKING_CLASSES, 0.5) for n in candidates()}
    amota["learnt"]["car"] = 0.5 + MARGIN_AMOTA  # by the margin exactly
    amota["without clutter"]["car"] = 0.5 + MARGIN_AMOTA  # a tie goes to the earlier candidate
    amota["learnt"]["truck"] = 0.5 + MARGIN_AMOTA / 2  # best, but not by the margin
    amota["without P_D cap"]["bus"] = 0.7
    amota["learnt"]["bus"] = 0.6
    amota["defaults"]["trailer"] = 0.9  # the defaults best
    for name in candidates():
        amota[name]["bicycle"] = None  # no annotations of the class in any fold
    chosen = choose(amota)
    assert chosen["car"] == "learnt"
    assert chosen["truck"] == "defaults"
    assert chosen["bus"] == "without P_D cap"
    assert chosen["trailer"] == "defaults"
    assert chosen["bicycle"] == "defaults"
    assert chosen["pedestrian"] == chosen["motorcycle"] == "defaults"  # all equal
    result = CheckResult(amota=amota, chosen=chosen, folds=(("a",), ("b",)))
    assert result.reason("car") == "everything learnt written: 2-fold AMOTA 0.510 against the defaults' 0.500"
    assert (
        result.reason("bus")
        == "everything learnt but the P_D cap written: 2-fold AMOTA 0.700 against the defaults' 0.500"
    )
    assert result.reason("truck") == (
        "the defaults kept: no candidate beat them by 0.01 (2-fold AMOTA 0.500; best, learnt, 0.505)"
    )
    assert result.reason("trailer") == "the defaults kept: they scored highest (2-fold AMOTA 0.900)"
    assert result.reason("bicycle") == "the defaults kept: no annotations of the class in any fold"


def _item(table: str, key: str) -> Learnt:
    return Learnt(table, key, 1.0, "test")


def test_a_candidate_leaves_out_only_values_the_check_tracker_reads() -> None:
    learnt = [
        _item("classes.car", "r_x"),
        _item("classes.car", "r_vx"),
        _item("classes.car", "clutter_intensity"),
        _item("classes.car.pmb", "heading_std_rad"),
        _item("classes.car.pmb", "miss_p_detect_max"),
        _item("classes.car.phd", "p_detect"),
        _item("classes.car.vector", "p_detect"),
    ]
    keys = {name: [(v.table, v.key) for v in candidate_values(name, learnt)] for name in candidates()}
    assert keys["learnt"] == [(v.table, v.key) for v in learnt]
    assert keys["defaults"] == [("classes.car.phd", "p_detect"), ("classes.car.vector", "p_detect")]
    assert ("classes.car", "r_vx") not in keys["without velocity noise"]
    assert len(keys["without velocity noise"]) == len(learnt) - 1
    assert ("classes.car.pmb", "heading_std_rad") not in keys["without box likelihood"]
    assert ("classes.car.pmb", "miss_p_detect_max") not in keys["without P_D cap"]
    assert ("classes.car", "clutter_intensity") not in keys["without clutter"]


def test_folds_take_every_kth_scene_in_sorted_order() -> None:
    assert fold_scenes(["s3", "s1", "s5", "s2", "s4"], 2) == [("s1", "s3", "s5"), ("s2", "s4")]
    assert fold_scenes(["b", "a"], 2) == [("a",), ("b",)]


def test_a_class_boxes_do_not_depend_on_another_class_parameters(tiny_dataroot: Path) -> None:
    """The premise of choosing per class: the check's tracker with only the car's values changed (every group the
    check leaves out, and the noise) outputs every other class's boxes exactly as before."""
    location, split = resolve_split(tiny_dataroot, None, "mini_val")
    data = resolve_study_data(location, split, None, "pointpillars", 0)
    car = {"r_x": 2.0, "r_y": 2.0, "r_vx": 3.0, "r_vy": 3.0, "clutter_intensity": 0.01, "score_threshold": 0.3}
    pmb = {"heading_std_rad": 0.2, "size_log_std": 0.1, "box_outlier_prob": 0.1, "size_log_spread": 0.3}
    pmb |= {"miss_p_detect_max": 0.9, "miss_p_detect_online": 0, "clutter_velocity_density": 0.5}
    changed = config_from_dict({"classes": {"car": {**car, "pmb": pmb}}})
    assert set().union(*GROUPS.values()) <= set(car) | set(pmb)

    def boxes(config: TrackerConfig, cars: bool) -> list[str]:
        runs = [track_scene(data, n, CHECK_TRACKER, config).results for n in data.scene_names]
        kept = [
            {k: v for k, v in box.items() if k != "tracking_id"}  # ids come from one counter shared by the classes
            for part in runs
            for frame in part.values()
            for box in frame
            if (box["tracking_name"] == "car") == cars
        ]
        return sorted(json.dumps(b, sort_keys=True) for b in kept)

    assert boxes(TrackerConfig(), cars=False) == boxes(changed, cars=False)
    assert boxes(TrackerConfig(), cars=True) != boxes(changed, cars=True)  # the change did change the cars


def _values(data: dict, prefix: str = "") -> dict[tuple[str, str], float]:
    """(table, key) -> value of a parameter file's per-class tables."""
    out = {}
    for key, value in data.items():
        name = f"{prefix}.{key}" if prefix else key
        if isinstance(value, dict):
            out |= _values(value, name)
        else:
            out[(prefix, key)] = value
    return out


NOT_WRITTEN = re.compile(r"^# not written: \[(?P<table>[\w.]+)\] (?P<key>\w+) = (?P<value>\S+)  \(", re.M)


def test_the_file_holds_what_the_printed_check_chose_and_says_what_it_left_out(
    two_scene_dataroot: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    common = ["calibrate", "--dataroot", str(two_scene_dataroot), "--split", "mini_val", "--no-progress"]
    code, stdout, stderr = run([*common, "--out", str(tmp_path / "all.toml"), "--no-check"], capsys)
    assert code == 0, stderr
    code, stdout, stderr = run([*common, "--out", str(tmp_path / "checked.toml"), "--workers", "1"], capsys)
    assert code == 0, stderr
    everything = tomllib.loads((tmp_path / "all.toml").read_text())
    text = (tmp_path / "checked.toml").read_text()
    checked = tomllib.loads(text)
    assert checked["box_noise"] == everything["box_noise"]
    learnt = _values(everything["classes"], "classes")
    written = _values(checked["classes"], "classes")
    left_out = {(m["table"], m["key"]): float(m["value"]) for m in NOT_WRITTEN.finditer(text)}
    assert not written.keys() & left_out.keys()
    assert written | left_out == pytest.approx(learnt)  # nothing learnt is lost: written, or said not written
    rows = {line.split("│")[1].strip(): line.split("│")[-2].strip() for line in stdout.splitlines() if "│" in line}
    for cls in TRACKING_CLASSES:
        chosen = rows[cls]
        mine = [Learnt(t, k, v, "") for (t, k), v in learnt.items() if t.split(".")[1] == cls]
        expected = {(v.table, v.key) for v in candidate_values(chosen, mine)}
        assert {k for k in written if k[0].split(".")[1] == cls} == expected, cls
        assert re.search(rf"^# {cls}: check of gnnpmb's values: ", text, re.M), cls
        unchecked = sorted({t.rsplit(".", 1)[-1] for (t, _) in written if t.split(".")[1] == cls} & {"phd", "vector"})
        said = re.search(rf"^# {cls}: (.*) written as learnt: read by the PHD/CPHD and JPDA/GNN trackers", text, re.M)
        # a class whose gnnpmb values the check left at the defaults still gets the other families' values: said so
        assert (said.group(1) if said else None) == (" and ".join(f"[{t}]" for t in unchecked) or None), cls
    summary = stdout.strip().splitlines()[-1]
    assert summary.startswith(f"calibrate: {len(written)} per-class values from 2 scenes of mini_val, ")
    assert f", {len(left_out)} left out by the check -> " in summary


@pytest.mark.parametrize("folds", ["1", "3"])
def test_folds_the_split_cannot_hold_are_one_error_line(
    folds: str, two_scene_dataroot: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    out = tmp_path / "p.toml"
    argv = ["calibrate", "--dataroot", str(two_scene_dataroot), "--split", "mini_val", "--out", str(out)]
    code, stdout, stderr = run([*argv, "--folds", folds], capsys)
    assert code == 2
    expected = f"--folds {folds}: the check cuts the 2 scenes of split mini_val into 2 folds (or use --no-check"
    assert stderr.startswith(f"error: {expected}") and stderr.count("\n") == 1
    assert not out.exists()
