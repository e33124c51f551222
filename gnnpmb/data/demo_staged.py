"""The demo's staged scene, ``scene-9001``: failures the two ``mini_val`` scenes do not show, staged so that the
trackers prone to them make them (a synthetic scene of the demo, in its own custom split ``staged``).

A straight two-lane road (ego at d = -1.75, 5 m/s):

* **coalescence**: two pedestrians walking shoulder to shoulder on the right sidewalk (0.7 m apart, 1.2 m/s,
  the ego's direction) and two cyclists riding side by side towards the ego on the far side (0.8 m apart, 4 m/s)
  who part at t = 12 s. Seen from the passing ego, the outer of each pair is hidden behind the inner one, so the
  detector often reports only one of them: a track on the inner one then lies within the match distance of both;
* **identity theft**: a pedestrian walking towards the ego on the left sidewalk passes a clutter hotspot of false
  pedestrians (``demo.CLUTTER_HOTSPOTS``) at t = 8 s, another walks 1.6 m ahead of it and 0.7 m aside, then waits
  for 7 s: a false track born at the hotspot in the seconds before can take the first walker's identity from its
  own track;
* a few other road users (a lead car, oncoming cars) so the scene is not empty.
"""

from __future__ import annotations

import math

from gnnpmb.data.demo_spec import SYNTHETIC_MARKER, Motion, ObjectSpec, SceneSpec, Segment

STAGED_SCENES: tuple[str, ...] = ("scene-9001",)
STAGED_SPLIT = "staged"
"""The custom split (``<dataroot>/v1.0-mini/splits.json``) the devkit evaluates the staged scene under."""
STAGED_SEED = 9001
"""The staged scene's LiDAR-noise stream (``demo._scene_seeds``)."""

_ADULT = "human.pedestrian.adult"
_PED_SIZE = (0.67, 0.73, 1.77)
_BIKE_SIZE = (0.6, 1.75, 1.3)
WALK_MPS = 1.3
THEFT_S_M = 52.0
"""Where (road s, on the left sidewalk at ``SIDEWALK_D_M``) the clutter hotspot of false pedestrians sits; the walker
passes it at ``THEFT_T_S``."""
SIDEWALK_D_M = 6.0
THEFT_T_S = 8.0
AHEAD_M = 1.6
"""The second walker walks this far ahead of the first, then waits (``WAIT_T_S`` to ``WAIT_T_S + WAIT_S``)."""
WAIT_T_S = 7.5
WAIT_S = 7.0
HOTSPOT_RADIUS_M = 1.2
HOTSPOT_FRAMES = tuple(range(int(2 * (THEFT_T_S - 3.5)), int(2 * THEFT_T_S) + 1))
"""False pedestrians at the hotspot from 3.5 s before the first walker passes it until it does."""


def _walker(s_at_t: float, t_s: float, segments: tuple[Segment, ...] = (), d_m: float = SIDEWALK_D_M) -> Motion:
    """A pedestrian walking towards -s at ``WALK_MPS`` (on the left sidewalk), at road s ``s_at_t`` at ``t_s``."""
    return Motion(s_at_t + WALK_MPS * t_s, d_m, math.pi, WALK_MPS, segments)


def staged_scene() -> SceneSpec:
    """The layout of ``scene-9001`` (module docstring)."""
    stop = WALK_MPS / 0.5
    wait = (Segment(WAIT_T_S), Segment(0.5, accel_mps2=-stop), Segment(WAIT_S), Segment(0.5, accel_mps2=stop))
    part = (Segment(12.0), Segment(2.0, yaw_rate_rps=0.45), Segment(6.0))
    objects = [
        ObjectSpec("pair_ped_inner", _ADULT, _PED_SIZE, Motion(28.0, -5.0, 0.0, 1.2), 18.0),
        ObjectSpec("pair_ped_outer", _ADULT, _PED_SIZE, Motion(28.0, -5.7, 0.0, 1.2), 18.0),
        ObjectSpec("pair_bike_inner", "vehicle.bicycle", _BIKE_SIZE, Motion(120.0, 3.6, math.pi, 4.0), 25.0),
        ObjectSpec("pair_bike_outer", "vehicle.bicycle", _BIKE_SIZE, Motion(120.0, 4.4, math.pi, 4.0, part), 25.0),
        ObjectSpec("walker_robbed", _ADULT, _PED_SIZE, _walker(THEFT_S_M, THEFT_T_S), 18.0),
        ObjectSpec(
            "walker_waiting", _ADULT, _PED_SIZE, _walker(THEFT_S_M - AHEAD_M, THEFT_T_S, wait, SIDEWALK_D_M + 0.7), 18.0
        ),
        ObjectSpec("lead_car", "vehicle.car", (1.9, 4.7, 1.6), Motion(20.0, -1.75, 0.0, 5.5), 42.0),
        ObjectSpec("oncoming_car", "vehicle.car", (1.85, 4.5, 1.55), Motion(160.0, 1.75, math.pi, 8.0), 42.0),
    ]
    return SceneSpec(
        name=STAGED_SCENES[0],
        description=(
            f"{SYNTHETIC_MARKER}: staged failures: pedestrians shoulder to shoulder and cyclists side by side "
            "(coalescence), a walker passing false detections beside another who waits (identity theft)"
        ),
        location="boston-seaport",
        start_us=1_533_112_000_000_000,
        road_origin_m=(612.5, 1480.0),
        road_heading_rad=-0.4,
        ego=Motion(0.0, -1.75, 0.0, 5.0),
        objects=tuple(objects),
    )


def hotspot_sd() -> tuple[float, float]:
    """The clutter hotspot's road coordinates (``THEFT_S_M`` on the left sidewalk)."""
    return THEFT_S_M, SIDEWALK_D_M
