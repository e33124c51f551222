"""``gnnpmb/params/turn.toml``: the coordinated-turn model for every class but bicycles (issue 32, Round 10), read
as a user's parameter file is, and what it changes: a turning car missed for a frame is predicted on its turn."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from gnnpmb.config import TrackerConfig, load_config
from gnnpmb.events import NullSink
from gnnpmb.pmb.core import PmbCore
from gnnpmb.pmb.gnnpmb import BestAssignment
from gnnpmb.types import IdAllocator
from tests.gnnpmb.pmb.helpers import make_measurements

TURN = load_config(Path(__file__).resolve().parents[3] / "gnnpmb" / "params" / "turn.toml")

RADIUS_M, SPEED_MPS, DT_S = 20.0, 8.0, 0.5
"""A car on a circle of 20 m at 8 m/s: turn rate 0.4 rad/s, 0.2 rad per keyframe."""


def on_circle(t_s: float) -> tuple[tuple[float, float], tuple[float, float]]:
    """Position and velocity of the car at time ``t_s`` (counter-clockwise about the origin, from (20, 0))."""
    a = SPEED_MPS / RADIUS_M * t_s
    xy = (RADIUS_M * math.cos(a), RADIUS_M * math.sin(a))
    v = (-SPEED_MPS * math.sin(a), SPEED_MPS * math.cos(a))
    return xy, v


def follow_the_circle(config: TrackerConfig, class_name: str = "car") -> tuple[list[int], float, int]:
    """Detected exactly on the circle (position and velocity) at keyframes 0-9 but missed at keyframe 8: the id of
    the track holding the detection at each detected keyframe, the distance (m) of the missed track's mean (its
    prediction) from the object at keyframe 8, and the filter's state dimension."""
    core = PmbCore(class_name, config.resolved(class_name), BestAssignment(), IdAllocator())
    holder, miss_error_m = [], math.nan
    for k in range(10):
        xy, v = on_circle(k * DT_S)
        meas = make_measurements([], cls=class_name) if k == 8 else make_measurements([xy], 0.9, class_name, [v])
        core.step(meas, DT_S if k else 0.0, NullSink())
        b = core.hypotheses[0].bernoullis
        if k == 8:
            oldest = int(np.argmin(b.track_id))
            miss_error_m = float(np.linalg.norm(b.mean[oldest, :2] - np.array(xy)))
        else:
            holder.append(int(b.track_id[b.misses == 0][0]))
    return holder, miss_error_m, b.mean.shape[1]


def test_turn_toml_sets_the_turn_model_for_every_class_but_bicycles():
    assert TURN.models.motion_model == 1
    assert TURN.models.turn_rate_std_rps == 0.05 and TURN.models.birth_turn_rate_std_rps == 0.05
    assert TURN.resolved("car").models.motion_model == 1
    assert TURN.resolved("motorcycle").models.motion_model == 1
    assert TURN.resolved("bicycle").models.motion_model == 0
    assert TrackerConfig().models.motion_model == 0  # not the default


def test_a_turning_car_keeps_its_track_and_is_predicted_on_its_turn_when_missed():
    """Constant velocity lags the rotating velocity: by keyframe 6 the car's prediction is so far off its turn that
    its own detection starts a new track (an ID switch with exact detections). The turn model learns the 0.4 rad/s
    from the measured velocity, keeps one track, and predicts the missed keyframe 8 within 0.2 m of the car."""
    cv_holder, _, cv_dim = follow_the_circle(TrackerConfig())
    ct_holder, ct_miss_error_m, ct_dim = follow_the_circle(TURN)
    assert (cv_dim, ct_dim) == (4, 5)
    assert len(set(cv_holder)) > 1
    assert set(ct_holder) == {1}
    assert ct_miss_error_m < 0.2


def test_bicycles_keep_constant_velocity():
    assert follow_the_circle(TURN, "bicycle") == follow_the_circle(TrackerConfig(), "bicycle")
    assert follow_the_circle(TURN, "bicycle")[2] == 4
