"""Every tracker at the declared overflow limits (``gnnpmb.param``): legal values run with finite output and no
floating-point overflow or invalid operation; the CPHD refuses a birth count its cardinality support cannot hold."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

from gnnpmb.config import ConfigError, TrackerConfig, with_params
from gnnpmb.data.nuscenes import load_scene, resolve_dataroot
from gnnpmb.param import FACTOR_LIMIT, SQUARED_LIMIT, STD_LIMIT, VARIANCE_LIMIT
from gnnpmb.phd.cphd import check_birth_fits, predict_cardinality
from gnnpmb.pipeline import get_detections, run_tracker
from gnnpmb.registry import TRACKER_NAMES

V, S, D, F = VARIANCE_LIMIT.hi, STD_LIMIT.hi, SQUARED_LIMIT.hi, FACTOR_LIMIT.hi
AT_THE_LIMITS = {
    "q_x": V,
    "q_y": V,
    "r_x": V,
    "r_y": V,
    "r_vx": V,
    "match_distance_m": D,
    "cbmot_distance_m": D,
    "birth_pos_std_m": S,
    "birth_vel_std_mps": S,
    "clutter_intensity": F,
}


@pytest.fixture(scope="module")
def frames(demo_dataroot):
    scene = load_scene(resolve_dataroot(demo_dataroot, "v1.0-mini"), "scene-0103")
    return scene, get_detections(scene, None, "centerpoint", seed=0)


@pytest.mark.parametrize("velocity", [0, 1])
def test_every_tracker_runs_finite_at_the_limits(frames, velocity):
    scene, detections = frames
    values = {f"classes.car.{k}": v for k, v in AT_THE_LIMITS.items()} | {"pmb.measure_velocity": velocity}
    values |= {"pmb.clutter_velocity_density": F, "prob3dmot.distance_threshold": D, "box_noise.car.q_vx": V}
    config = with_params(TrackerConfig(), values)
    with np.errstate(over="raise", invalid="raise"), warnings.catch_warnings():
        warnings.simplefilter("error")
        for tracker in TRACKER_NAMES:
            run = run_tracker(scene, detections, tracker, config, classes=("car",))
            out = [v for f in run.frames for e in f.estimates for v in (*e.translation_m, e.score, e.existence)]
            assert np.isfinite(out).all(), tracker


def test_the_cphd_refuses_a_birth_count_beyond_its_cardinality_support():
    check_birth_fits(900.0, 100)  # its pmf on 0..100 is small but representable
    predict_cardinality(np.array([1.0]), 0.9, 900.0, 100)
    with pytest.raises(ConfigError, match=r"birth count \(mean 1100: .*\[phd\] max_cardinality = 100"):
        predict_cardinality(np.array([1.0]), 0.9, 1100.0, 100)
    with pytest.raises(ConfigError, match="max_cardinality"):
        check_birth_fits(1e300, 100)
