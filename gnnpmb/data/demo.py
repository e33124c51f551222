"""A synthetic dataset in the nuScenes format, for trying the viewer without the real data.

``generate_demo_dataset`` writes ``v1.0-mini`` tables and LIDAR_TOP keyframe sweeps that the unmodified devkit
(``nuscenes.nuscenes.NuScenes``) and the official tracking evaluation (``TrackingEval``, split ``mini_val``) accept.
It holds the two ``mini_val`` scene names and a staged scene, ``scene-9001``, in a custom split ``staged``
(``demo_staged``: coalescence and identity theft), 40 keyframes each at 2 Hz, and every scene description starts
with ``SYNTHETIC_MARKER`` so no one mistakes it for real data. It never substitutes for real data:
``gnnpmb.data.nuscenes.resolve_dataroot`` falls back to it only when no dataroot is given.

The layout is fixed (the seed only drives the LiDAR noise). Each scene is laid out in *road coordinates*
(s along the road, d to its left, metres), placed in the global frame by the scene's road origin and heading.
Objects move with piecewise constant acceleration and turn rate, integrated in 10 ms steps; boxes stand on the
ground (centre z = height / 2). LiDAR sweeps come from ``gnnpmb.data.raycast``, so occlusion is real and
``num_lidar_pts`` is the number of returns inside each box (0 when hidden or far).

scene-0103, a three-lane street (ego in the +s lane, d = -1.75, at 6 m/s; oncoming lanes at d = +1.75, +5.25):
    * an oncoming truck pulling a trailer (d = +5.25, 7 m/s, a car behind) that meets the ego around t = 8 s
      and hides the parked row and the left sidewalk for a few frames;
    * a tightly parked row of seven cars on the left (d = +8.4, s = 40..75, 0.5-1.0 m gaps: coalescence);
    * two pedestrians on the right sidewalk who walk behind a parked delivery truck (s = 50, d = -5; hidden for
      several frames, as is a cyclist) and pass each other 0.9 m apart at s = 57, t = 10 s;
    * two pedestrians passing each other head-on, 1.2 m apart, on a crosswalk at s = 108..109 around t = 13 s,
      and a child waiting beside it;
    * oncoming cars and a motorcycle; a car that waits in a side street (s = 118) until t = 13 s, then turns
      right into the ego's lane ahead of it.
scene-0916, a two-lane road (ego at d = -1.75, 5 m/s):
    * a rigid bus in the oncoming lane (d = +1.75, 8 m/s) that passes a roadworks zone of barriers, traffic
      cones and a construction worker on the left edge (s = 55..67) around t = 6..10 s: the clutter hotspot in
      ``CLUTTER_HOTSPOTS``, where a simulated detector should place false positives so that a false track can
      steal the bus's identity;
    * two pedestrians whose paths cross at right angles on a plaza (s = 52, d = +11.5) at t = 8.5 s and 9.9 s,
      hidden by the passing bus for a few frames; a pedestrian on each sidewalk, the right one hidden behind a
      parked trailer and parked cars at first;
    * a lead car, a car that slows down and turns left across the oncoming lane at s = 112 (t = 7.5..11 s),
      a cyclist the ego overtakes, an oncoming motorcycle and truck.

Files: ``<dataroot>/v1.0-mini/*.json``, ``samples/LIDAR_TOP/*.pcd.bin`` (float32 x 5: x, y, z, intensity, ring in
the LIDAR_TOP frame), ``samples/CAM_*/*.jpg`` (nuScenes' six cameras, ``demo_cameras``: their rows are written with
the tables, the images rendered on first use by ``ensure_scene_images``), ``maps/*.png`` (an empty semantic-prior
mask: the demo has no map) and ``gnnpmb-demo.json`` (generator version and seed, the mark of a demo dataroot that
may be regenerated in place). Built with ``sweeps`` (``gnnpmb demo-data --sweeps``, or ``GNNPMB_DEMO_SWEEPS=1`` for
the cached demo) it also holds nine LiDAR sweeps between keyframes in ``sweeps/LIDAR_TOP``, as nuScenes' 20 Hz
LiDAR does; the keyframes, annotations and detections stay the same.
"""

from __future__ import annotations

import io
import json
import math
import os
import shutil
import tempfile
import uuid
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from gnnpmb.atomic import sweep_leftovers, temp_prefix
from gnnpmb.cache_folder import CACHE_ENV, cache_root
from gnnpmb.data import demo_cameras
from gnnpmb.data.demo_spec import SYNTHETIC_MARKER, Motion, ObjectSpec, SceneSpec, Segment
from gnnpmb.data.demo_staged import (
    HOTSPOT_FRAMES,
    HOTSPOT_RADIUS_M,
    STAGED_SCENES,
    STAGED_SEED,
    STAGED_SPLIT,
    hotspot_sd,
    staged_scene,
)
from gnnpmb.data.demo_train import LAYOUT_SEEDS, TRAIN_SCENES, train_scene
from gnnpmb.data.raycast import LidarSpec, Scan, SceneBoxes, cast_scan
from gnnpmb.errors import DataError

DEMO_VERSION = "v1.0-mini"
DEMO_SCENES: tuple[str, ...] = ("scene-0103", "scene-0916")
DEMO_SEED = 0
GENERATOR_VERSION = 4
"""Bump when the generated data changes, so cached copies (``demo-v<N>``) are regenerated."""
MARKER_FILE = "gnnpmb-demo.json"

KEYFRAMES_PER_SCENE = 40
KEYFRAME_INTERVAL_US = 500_000
ANNOTATION_RANGE_M = 65.0
"""Objects are annotated over the contiguous span of keyframes in which they come within this distance of the ego."""
LIDAR_TRANSLATION_M = (0.943713, 0.0, 1.84023)
"""LIDAR_TOP mounting in the ego frame (close to the real nuScenes car); it is yawed by -90 degrees like there."""
LIDAR_YAW_RAD = -0.5 * math.pi
LIDAR = LidarSpec()
_INTEGRATION_STEP_S = 0.01
_MOVING_SPEED_MPS = 0.3
_TOKEN_NAMESPACE = uuid.uuid5(uuid.NAMESPACE_URL, "https://github.com/gnnpmb-viz/demo")


@dataclass(frozen=True, slots=True)
class ClutterHotspot:
    """A place where a simulated detector should produce false positives: within ``radius_m`` of ``xy_global``
    (global frame, metres) during the keyframes ``frames`` (indices into the scene's keyframes)."""

    scene_name: str
    xy_global: tuple[float, float]
    radius_m: float
    frames: tuple[int, ...]

    @staticmethod
    def at(
        spec: SceneSpec, centre_sd_m: tuple[float, float], radius_m: float, frames: tuple[int, ...]
    ) -> ClutterHotspot:
        """The hotspot of scene ``spec`` around road point ``centre_sd_m`` (s, d), its global x, y to the millimetre."""
        x, y = spec.to_global(np.array(centre_sd_m[0]), np.array(centre_sd_m[1]))
        return ClutterHotspot(spec.name, (round(float(x), 3), round(float(y), 3)), radius_m, frames)


CATEGORIES: tuple[tuple[str, str], ...] = (
    ("human.pedestrian.adult", "Adult subcategory."),
    ("human.pedestrian.child", "Child subcategory."),
    ("human.pedestrian.wheelchair", "Wheelchairs."),
    ("human.pedestrian.stroller", "Strollers."),
    ("human.pedestrian.personal_mobility", "Small electric or self-propelled vehicles."),
    ("human.pedestrian.police_officer", "Police officer."),
    ("human.pedestrian.construction_worker", "Construction worker."),
    ("animal", "All animals."),
    ("vehicle.car", "Vehicle designed primarily for personal use."),
    ("vehicle.motorcycle", "Gasoline or electric powered 2-wheeled vehicle."),
    ("vehicle.bicycle", "Human or electric powered 2-wheeled vehicle."),
    ("vehicle.bus.bendy", "Bendy bus subcategory."),
    ("vehicle.bus.rigid", "Rigid bus subcategory."),
    ("vehicle.truck", "Vehicles primarily designed to haul cargo."),
    ("vehicle.construction", "Vehicles primarily designed for construction."),
    ("vehicle.emergency.ambulance", "All types of ambulances."),
    ("vehicle.emergency.police", "All types of police vehicles."),
    ("vehicle.trailer", "Any vehicle trailer."),
    ("movable_object.barrier", "Temporary road barrier."),
    ("movable_object.trafficcone", "All types of traffic cones."),
    ("movable_object.pushable_pullable", "Objects that a pedestrian may push or pull."),
    ("movable_object.debris", "Movable object that is left on the driveable surface."),
    ("static_object.bicycle_rack", "Area or device intended to park or secure the bicycles in a row."),
)
ATTRIBUTES: tuple[tuple[str, str], ...] = (
    ("vehicle.moving", "Vehicle is moving."),
    ("vehicle.stopped", "Vehicle, with a driver, is stationary but may move at any time."),
    ("vehicle.parked", "Vehicle is stationary with no intent to move."),
    ("cycle.with_rider", "There is someone riding the bicycle or motorcycle."),
    ("cycle.without_rider", "There is no one riding the bicycle or motorcycle."),
    ("pedestrian.sitting_lying_down", "The pedestrian is sitting or lying down."),
    ("pedestrian.standing", "The pedestrian is standing."),
    ("pedestrian.moving", "The pedestrian is moving."),
)
VISIBILITY_LEVELS: tuple[tuple[str, str, float], ...] = (
    ("1", "v0-40", 0.4),
    ("2", "v40-60", 0.6),
    ("3", "v60-80", 0.8),
    ("4", "v80-100", math.inf),
)
"""(token, level, upper bound of the visible fraction) of the devkit's four visibility bins."""


def token(*parts: object) -> str:
    """Deterministic 32-hex-character token of a name (uuid5)."""
    return uuid.uuid5(_TOKEN_NAMESPACE, "/".join(str(p) for p in parts)).hex


def _through(s_m: float, d_m: float, t_s: float, heading_rad: float, speed_mps: float) -> Motion:
    """Constant-velocity motion that passes road point (s_m, d_m) at time t_s."""
    return Motion(
        s_m=s_m - speed_mps * t_s * math.cos(heading_rad),
        d_m=d_m - speed_mps * t_s * math.sin(heading_rad),
        heading_rad=heading_rad,
        speed_mps=speed_mps,
    )


def _parked(s_m: float, d_m: float, heading_rad: float = 0.0) -> Motion:
    return Motion(s_m=s_m, d_m=d_m, heading_rad=heading_rad, speed_mps=0.0)


_CAR = "vehicle.car"
_ADULT = "human.pedestrian.adult"
_PED_SIZE = (0.67, 0.73, 1.77)
_CAR_SIZES = ((1.85, 4.6, 1.55), (1.9, 4.8, 1.62), (1.78, 4.3, 1.5), (1.95, 4.9, 1.7), (1.75, 4.1, 1.47))


def _parked_row(
    prefix: str, s_start_m: float, d_m: float, heading_rad: float, gaps_m: tuple[float, ...]
) -> list[ObjectSpec]:
    """Cars parked bumper to bumper along +s from ``s_start_m`` (rear of the first), with the given gaps."""
    cars = []
    s = s_start_m
    for i in range(len(gaps_m) + 1):
        size = _CAR_SIZES[i % len(_CAR_SIZES)]
        cars.append(ObjectSpec(f"{prefix}{i}", _CAR, size, _parked(s + 0.5 * size[1], d_m, heading_rad), 40.0))
        if i < len(gaps_m):
            s += size[1] + gaps_m[i]
    return cars


def _scene_0103() -> SceneSpec:
    truck_len, trailer_len, hitch_gap = 6.8, 10.5, 0.7
    convoy_speed = 7.0
    truck_s0 = 113.2
    trailer_s0 = truck_s0 + 0.5 * truck_len + hitch_gap + 0.5 * trailer_len
    turn_radius, turn_speed = 6.0, 4.0
    objects = [
        ObjectSpec(
            "truck", "vehicle.truck", (2.5, truck_len, 3.2), Motion(truck_s0, 5.25, math.pi, convoy_speed), 55.0
        ),
        ObjectSpec(
            "trailer", "vehicle.trailer", (2.5, trailer_len, 3.8), Motion(trailer_s0, 5.25, math.pi, convoy_speed), 50.0
        ),
        ObjectSpec(
            "convoy_car",
            _CAR,
            (1.8, 4.4, 1.5),
            Motion(trailer_s0 + 0.5 * trailer_len + 8.0 + 2.2, 5.25, math.pi, convoy_speed),
            38.0,
        ),
        ObjectSpec("oncoming_car_a", _CAR, (1.9, 4.7, 1.6), Motion(135.0, 1.75, math.pi, 9.0), 42.0),
        ObjectSpec("oncoming_car_c", _CAR, (1.85, 4.5, 1.55), Motion(236.0, 1.75, math.pi, 8.0), 42.0),
        ObjectSpec("motorcycle", "vehicle.motorcycle", (0.8, 2.1, 1.5), Motion(168.0, 1.75, math.pi, 10.0), 30.0),
        *_parked_row("parked", 40.0, 8.4, math.pi, (0.55, 0.9, 0.7, 0.5, 0.95, 0.65)),
        ObjectSpec("left_sidewalk_ped", _ADULT, _PED_SIZE, Motion(75.0, 11.0, math.pi, 1.3), 18.0),
        ObjectSpec("delivery_truck", "vehicle.truck", (2.4, 6.5, 3.0), _parked(50.0, -5.0), 55.0),
        ObjectSpec("bicycle", "vehicle.bicycle", (0.6, 1.75, 1.3), Motion(20.0, -7.2, 0.0, 4.0), 25.0),
        ObjectSpec("sidewalk_ped_a", _ADULT, _PED_SIZE, Motion(70.0, -9.6, math.pi, 1.3), 18.0),
        ObjectSpec("sidewalk_ped_b", _ADULT, _PED_SIZE, Motion(45.0, -10.5, 0.0, 1.2), 18.0),
        ObjectSpec("crosswalk_ped_c", _ADULT, _PED_SIZE, _through(108.0, 0.0, 13.0, 0.5 * math.pi, 1.4), 18.0),
        ObjectSpec("crosswalk_ped_d", _ADULT, _PED_SIZE, _through(109.2, 0.0, 13.3, -0.5 * math.pi, 1.4), 18.0),
        ObjectSpec("child", "human.pedestrian.child", (0.5, 0.5, 1.3), _parked(106.5, -10.2, 0.5 * math.pi), 15.0),
        ObjectSpec(
            "turning_car",
            _CAR,
            (1.85, 4.5, 1.55),
            Motion(
                118.0,
                -1.75 - turn_radius - 4.0,
                0.5 * math.pi,
                0.0,
                (
                    Segment(13.0),
                    Segment(2.0, accel_mps2=turn_speed / 2.0),
                    Segment(0.5 * math.pi * turn_radius / turn_speed, yaw_rate_rps=-turn_speed / turn_radius),
                    Segment(4.0, accel_mps2=0.5),
                ),
            ),
            40.0,
        ),
    ]
    return SceneSpec(
        name="scene-0103",
        description=(
            f"{SYNTHETIC_MARKER}: three-lane street; an oncoming truck with a trailer hides the left sidewalk, "
            "tightly parked cars, pedestrians passing each other behind a parked truck and on a crosswalk, "
            "a car turning in"
        ),
        location="boston-seaport",
        start_us=1_533_110_400_000_000,
        road_origin_m=(412.5, 1180.0),
        road_heading_rad=0.35,
        ego=Motion(0.0, -1.75, 0.0, 6.0),
        objects=tuple(objects),
    )


_ROADWORKS_S_M = (55.0, 67.0)
_ROADWORKS_CENTRE_SD = (61.0, 4.1)
_BUS_SPEED_MPS = 8.0
_BUS_S0_M = 125.0


def _plaza_ped_2() -> Motion:
    """Crosses plaza_ped_1's path at right angles 1.4 s after it (heading -70 degrees), then stops at the curb."""
    walk = _through(52.0, 11.5, 9.9, math.radians(-70.0), 1.2)
    return Motion(walk.s_m, walk.d_m, walk.heading_rad, walk.speed_mps, (Segment(13.0), Segment(1.0, accel_mps2=-1.2)))


def _scene_0916() -> SceneSpec:
    s_lo, s_hi = _ROADWORKS_S_M
    barriers = [
        ObjectSpec(f"barrier{i}", "movable_object.barrier", (2.5, 0.5, 0.98), _parked(s, 4.5, 0.5 * math.pi), 90.0)
        for i, s in enumerate(np.linspace(s_lo + 1.5, s_hi - 1.5, 4))
    ]
    cones = [
        ObjectSpec(f"cone{i}", "movable_object.trafficcone", (0.41, 0.41, 1.07), _parked(s, 3.7), 110.0)
        for i, s in enumerate(np.linspace(s_lo, s_hi, 4))
    ]
    turn_radius = 9.0
    objects = [
        ObjectSpec(
            "bus", "vehicle.bus.rigid", (2.9, 11.5, 3.5), Motion(_BUS_S0_M, 1.75, math.pi, _BUS_SPEED_MPS), 50.0
        ),
        *barriers,
        *cones,
        ObjectSpec(
            "construction_worker",
            "human.pedestrian.construction_worker",
            (0.7, 0.75, 1.8),
            Motion(58.0, 5.4, 0.0, 0.4),
            20.0,
        ),
        ObjectSpec("plaza_ped_1", _ADULT, _PED_SIZE, _through(52.0, 11.5, 8.5, math.radians(20.0), 1.3), 18.0),
        ObjectSpec("plaza_ped_2", _ADULT, _PED_SIZE, _plaza_ped_2(), 18.0),
        ObjectSpec("left_sidewalk_ped", _ADULT, _PED_SIZE, Motion(30.0, 6.6, 0.0, 1.3), 18.0),
        ObjectSpec("right_sidewalk_ped", _ADULT, _PED_SIZE, Motion(60.0, -7.0, math.pi, 1.3), 18.0),
        ObjectSpec("parked_trailer", "vehicle.trailer", (2.45, 8.0, 3.4), _parked(30.0, -4.8), 45.0),
        *_parked_row("parked", 39.7, -4.8, 0.0, (1.0,)),
        ObjectSpec("lead_car", _CAR, (1.9, 4.7, 1.6), Motion(22.0, -1.75, 0.0, 5.6), 42.0),
        ObjectSpec(
            "turning_car",
            _CAR,
            (1.85, 4.5, 1.55),
            Motion(
                70.0,
                -1.75,
                0.0,
                6.0,
                (
                    Segment(5.0),
                    Segment(2.5, accel_mps2=-0.8),
                    Segment(0.5 * math.pi * turn_radius / 4.0, yaw_rate_rps=4.0 / turn_radius),
                    Segment(3.0, accel_mps2=0.5),
                ),
            ),
            40.0,
        ),
        ObjectSpec("bicycle", "vehicle.bicycle", (0.6, 1.75, 1.3), Motion(10.0, -3.1, 0.0, 4.0), 25.0),
        ObjectSpec("motorcycle", "vehicle.motorcycle", (0.8, 2.1, 1.5), Motion(190.0, 1.75, math.pi, 10.0), 30.0),
        ObjectSpec("oncoming_truck", "vehicle.truck", (2.5, 7.2, 3.3), Motion(200.0, 1.75, math.pi, 7.0), 55.0),
    ]
    return SceneSpec(
        name="scene-0916",
        description=(
            f"{SYNTHETIC_MARKER}: two-lane road; a bus passes roadworks (barriers, cones: clutter hotspot), "
            "pedestrians cross paths behind it, a car turns left across the oncoming lane"
        ),
        location="singapore-onenorth",
        start_us=1_533_111_000_000_000,
        road_origin_m=(1205.3, 1010.7),
        road_heading_rad=2.2,
        ego=Motion(0.0, -1.75, 0.0, 5.0),
        objects=tuple(objects),
    )


SCENES: tuple[SceneSpec, ...] = (_scene_0103(), _scene_0916(), staged_scene())


def keyframe_times_s() -> np.ndarray:
    """(K,) keyframe times since the scene start."""
    return np.arange(KEYFRAMES_PER_SCENE) * (KEYFRAME_INTERVAL_US * 1e-6)


def integrate_motion(motion: Motion, times_s: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Road-frame trajectory sampled at ``times_s`` (K,): (K, 2) position (s, d), (K,) heading, (K,) speed.

    Between segment changes the acceleration a and turn rate w are constant; the state is integrated with
    steps of 10 ms (speed and heading exactly, position by the midpoint rule).
    """
    n_steps = int(round(float(np.max(times_s)) / _INTEGRATION_STEP_S))
    step_start = np.arange(n_steps) * _INTEGRATION_STEP_S
    accel = np.zeros(n_steps)
    yaw_rate = np.zeros(n_steps)
    begin = 0.0
    for seg in motion.segments:
        inside = (step_start >= begin - 1e-9) & (step_start < begin + seg.duration_s - 1e-9)
        accel[inside] = seg.accel_mps2
        yaw_rate[inside] = seg.yaw_rate_rps
        begin += seg.duration_s
    speed = motion.speed_mps + np.concatenate([[0.0], np.cumsum(accel * _INTEGRATION_STEP_S)])
    heading = motion.heading_rad + np.concatenate([[0.0], np.cumsum(yaw_rate * _INTEGRATION_STEP_S)])
    if np.any(speed < -1e-9):
        raise ValueError("a motion's speed must not become negative")
    speed = np.maximum(speed, 0.0)
    mid_speed = 0.5 * (speed[1:] + speed[:-1])
    mid_heading = 0.5 * (heading[1:] + heading[:-1])
    step = mid_speed[:, None] * _INTEGRATION_STEP_S * np.stack([np.cos(mid_heading), np.sin(mid_heading)], axis=1)
    position = np.array([motion.s_m, motion.d_m]) + np.concatenate([np.zeros((1, 2)), np.cumsum(step, axis=0)])
    index = np.rint(np.asarray(times_s) / _INTEGRATION_STEP_S).astype(int)
    return position[index], heading[index], speed[index]


@dataclass(frozen=True, slots=True)
class Trajectories:
    """Global-frame states of a scene's objects over its K keyframes: xy (M, K, 2), yaw (M, K), speed (M, K);
    ego_xy (K, 2), ego_yaw (K,)."""

    xy: np.ndarray
    yaw: np.ndarray
    speed: np.ndarray
    ego_xy: np.ndarray
    ego_yaw: np.ndarray


def scene_trajectories(spec: SceneSpec, times_s: np.ndarray | None = None) -> Trajectories:
    """Integrate every object's and the ego's motion at the keyframe times (or at ``times_s`` since the scene
    start, multiples of 10 ms) and place them in the global frame."""
    times = keyframe_times_s() if times_s is None else times_s
    xy, yaw, speed = [], [], []
    for obj in spec.objects:
        pos, heading, v = integrate_motion(obj.motion, times)
        xy.append(spec.to_global(pos[:, 0], pos[:, 1]))
        yaw.append(heading + spec.road_heading_rad)
        speed.append(v)
    ego_pos, ego_heading, _ = integrate_motion(spec.ego, times)
    return Trajectories(
        xy=np.round(np.array(xy), 4),
        yaw=np.array(yaw),
        speed=np.array(speed),
        ego_xy=np.round(spec.to_global(ego_pos[:, 0], ego_pos[:, 1]), 4),
        ego_yaw=ego_heading + spec.road_heading_rad,
    )


def _train_hotspots() -> tuple[ClutterHotspot, ...]:
    """The roadworks zones of the generated ``mini_train`` scenes, active in every keyframe."""
    out = []
    for name in TRAIN_SCENES:
        spec, roadworks = train_scene(name)
        if roadworks is None:
            continue
        out.append(
            ClutterHotspot.at(spec, roadworks.centre_sd_m, roadworks.radius_m, tuple(range(KEYFRAMES_PER_SCENE)))
        )
    return tuple(out)


def scene_spec(name: str) -> SceneSpec:
    """The layout of demo scene ``name``: a hand-built ``mini_val`` scene or a generated ``mini_train`` one."""
    for spec in SCENES:
        if spec.name == name:
            return spec
    return train_scene(name)[0]


def _clutter_hotspots() -> tuple[ClutterHotspot, ...]:
    spec = next(s for s in SCENES if s.name == "scene-0916")
    traj = scene_trajectories(spec)
    bus = next(i for i, o in enumerate(spec.objects) if o.name == "bus")
    centre = spec.to_global(np.array(_ROADWORKS_CENTRE_SD[0]), np.array(_ROADWORKS_CENTRE_SD[1]))
    near = np.linalg.norm(traj.xy[bus] - centre, axis=1) <= 15.0
    return (ClutterHotspot.at(spec, _ROADWORKS_CENTRE_SD, 7.0, tuple(int(k) for k in np.flatnonzero(near))),)


def _staged_hotspots() -> tuple[ClutterHotspot, ...]:
    """The false pedestrians just ahead of the staged scene's file of pedestrians (``demo_staged``)."""
    return (ClutterHotspot.at(staged_scene(), hotspot_sd(), HOTSPOT_RADIUS_M, HOTSPOT_FRAMES),)


CLUTTER_HOTSPOTS: tuple[ClutterHotspot, ...] = _clutter_hotspots() + _train_hotspots() + _staged_hotspots()
"""Where and when the demo's bus passes the roadworks of scene-0916 (see the module docstring), and the roadworks
of the generated train scenes (``demo_train``)."""


def _yaw_quat_wxyz(yaw_rad: float) -> list[float]:
    return [math.cos(0.5 * yaw_rad), 0.0, 0.0, math.sin(0.5 * yaw_rad)]


def _yaw_matrix(yaw_rad: float) -> np.ndarray:
    c, s = math.cos(yaw_rad), math.sin(yaw_rad)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def _attribute(category: str, speed_mps: float, ever_moves: bool) -> str | None:
    """The nuScenes attribute name of an annotation, from its category and speed."""
    moving = speed_mps > _MOVING_SPEED_MPS
    if category.startswith("human.pedestrian"):
        return "pedestrian.moving" if moving else "pedestrian.standing"
    if category in ("vehicle.bicycle", "vehicle.motorcycle"):
        return "cycle.with_rider"
    if category.startswith("vehicle."):
        if moving:
            return "vehicle.moving"
        return "vehicle.stopped" if ever_moves else "vehicle.parked"
    return None


def _visibility_token(visible_fraction: float) -> str:
    return next(tok for tok, _, upper in VISIBILITY_LEVELS if visible_fraction < upper)


def _annotated_span(distance_m: np.ndarray) -> np.ndarray:
    """(K,) bool: the contiguous keyframes from the first to the last within ``ANNOTATION_RANGE_M``."""
    inside = np.flatnonzero(distance_m <= ANNOTATION_RANGE_M)
    span = np.zeros(distance_m.shape, dtype=bool)
    if inside.size:
        span[inside[0] : inside[-1] + 1] = True
    return span


TABLE_NAMES: tuple[str, ...] = (
    "category",
    "attribute",
    "visibility",
    "instance",
    "sensor",
    "calibrated_sensor",
    "ego_pose",
    "log",
    "scene",
    "sample",
    "sample_data",
    "sample_annotation",
    "map",
)
"""The tables ``nuscenes.NuScenes`` 1.2.0 loads (``<dataroot>/<version>/<table>.json``)."""


def _link(rows: list[dict]) -> None:
    """Fill the prev/next tokens of rows that form one chain, in order."""
    for i, row in enumerate(rows):
        row["prev"] = rows[i - 1]["token"] if i > 0 else ""
        row["next"] = rows[i + 1]["token"] if i + 1 < len(rows) else ""


def _sweep(
    spec: SceneSpec,
    traj: Trajectories,
    j: int,
    timestamp: int,
    out: tuple[Path, str, dict[str, list[dict]]],
    tokens: tuple[str, str, str],
    rng: np.random.Generator,
) -> tuple[np.ndarray, Scan, dict]:
    """One LIDAR_TOP sweep at state ``j`` of ``traj``: the indices of the objects in reach (C,), their scan, its
    ``.pcd.bin`` in ``out`` = (dataroot, folder, tables), its ``ego_pose`` row added to the tables and its
    ``sample_data`` row returned; tokens: (its ego pose's, its own, its sample's)."""
    dataroot, folder, tables = out
    sizes = np.array([o.size_wlh_m for o in spec.objects], dtype=float)
    calib_t = np.array(LIDAR_TRANSLATION_M)
    reach = LIDAR.max_range_m + 0.5 * np.linalg.norm(sizes, axis=1) + np.linalg.norm(calib_t[:2])
    ego_t = np.array([traj.ego_xy[j, 0], traj.ego_xy[j, 1], 0.0])
    ego_r = _yaw_matrix(float(traj.ego_yaw[j]))
    cast = np.flatnonzero(np.linalg.norm(traj.xy[:, j] - traj.ego_xy[j], axis=1) <= reach)
    boxes = SceneBoxes(
        centre_m=np.column_stack([traj.xy[cast, j], 0.5 * sizes[cast, 2:]]),
        size_wlh_m=sizes[cast],
        yaw_rad=traj.yaw[cast, j],
        intensity=np.array([o.intensity for o in spec.objects])[cast],
    )
    scan = cast_scan(LIDAR, ego_t + ego_r @ calib_t, ego_r @ _yaw_matrix(LIDAR_YAW_RAD), boxes, rng)
    filename = f"{folder}/LIDAR_TOP/gnnpmb-demo-{spec.name}__LIDAR_TOP__{timestamp}.pcd.bin"
    (dataroot / filename).write_bytes(scan.points.astype("<f4").tobytes())
    pose_token, row_token, sample_token = tokens
    rotation = _yaw_quat_wxyz(float(traj.ego_yaw[j]))
    pose = {
        "token": pose_token,
        "timestamp": timestamp,
        "rotation": rotation,
        "translation": [*map(float, ego_t[:2]), 0.0],
    }
    tables["ego_pose"].append(pose)
    row = {
        "token": row_token,
        "sample_token": sample_token,
        "ego_pose_token": pose_token,
        "calibrated_sensor_token": token("calibrated_sensor", spec.name, "LIDAR_TOP"),
        "timestamp": timestamp,
        "fileformat": "pcd",
        "is_key_frame": folder == "samples",
        "height": 0,
        "width": 0,
        "filename": filename,
    }
    return cast, scan, row


def _write_scene(
    spec: SceneSpec,
    tables: dict[str, list[dict]],
    dataroot: Path,
    rng: np.random.Generator,
    sweep_rng: np.random.Generator | None = None,
) -> None:
    """Simulate one scene: its log, samples, LiDAR keyframe sweeps and annotations; with ``sweep_rng`` also the
    LiDAR sweeps between keyframes (``_intermediate_sweeps``, their noise from that generator, so the keyframes
    stay the same)."""
    traj = scene_trajectories(spec)
    times_us = spec.start_us + np.arange(KEYFRAMES_PER_SCENE) * KEYFRAME_INTERVAL_US
    log_name = f"gnnpmb-demo-{spec.name}"
    log_token = token("log", spec.name)
    tables["log"].append(
        {
            "token": log_token,
            "logfile": log_name,
            "vehicle": "gnnpmb-demo",
            "date_captured": "2018-08-01",
            "location": spec.location,
        },
    )
    calib_token = token("calibrated_sensor", spec.name, "LIDAR_TOP")
    tables["calibrated_sensor"].append(
        {
            "token": calib_token,
            "sensor_token": token("sensor", "LIDAR_TOP"),
            "translation": list(LIDAR_TRANSLATION_M),
            "rotation": _yaw_quat_wxyz(LIDAR_YAW_RAD),
            "camera_intrinsic": [],
        },
    )
    sizes = np.array([o.size_wlh_m for o in spec.objects], dtype=float)
    centres = np.concatenate([traj.xy, np.broadcast_to(0.5 * sizes[:, None, 2:], traj.xy.shape[:2] + (1,))], axis=2)
    annotated = np.array([_annotated_span(d) for d in np.linalg.norm(traj.xy - traj.ego_xy[None], axis=2)])
    num_pts = np.zeros(annotated.shape, dtype=np.int64)
    visible = np.zeros(annotated.shape)

    samples, sweeps = [], []
    for k in range(KEYFRAMES_PER_SCENE):
        timestamp = int(times_us[k])
        sample_token = token("sample", spec.name, k)
        lidar_tokens = (token("ego_pose", spec.name, k), token("sample_data", spec.name, "LIDAR_TOP", k), sample_token)
        cast, scan, row = _sweep(spec, traj, k, timestamp, (dataroot, "samples", tables), lidar_tokens, rng)
        num_pts[cast, k] = scan.num_pts
        visible[cast, k] = scan.visible_fraction
        samples.append({"token": sample_token, "timestamp": timestamp, "scene_token": token("scene", spec.name)})
        sweeps.append(row)
    _link(samples)
    if sweep_rng is not None:
        sweeps = sorted(
            sweeps + _intermediate_sweeps(spec, tables, dataroot, sweep_rng, samples),
            key=lambda r: r["timestamp"],
        )
    _link(sweeps)
    for row in samples:
        tables["sample"].append(row)
    for row in sweeps:
        tables["sample_data"].append(row)
    _camera_rows(spec, tables, samples)
    tables["scene"].append(
        {
            "token": token("scene", spec.name),
            "log_token": log_token,
            "nbr_samples": len(samples),
            "first_sample_token": samples[0]["token"],
            "last_sample_token": samples[-1]["token"],
            "name": spec.name,
            "description": spec.description,
        },
    )

    attribute_tokens = {name: token("attribute", name) for name, _ in ATTRIBUTES}
    for m, obj in enumerate(spec.objects):
        frames = np.flatnonzero(annotated[m])
        if frames.size == 0:
            continue
        instance_token = token("instance", spec.name, obj.name)
        ever_moves = bool(np.any(traj.speed[m] > _MOVING_SPEED_MPS))
        anns = []
        for k in frames:
            attribute = _attribute(obj.category, float(traj.speed[m, k]), ever_moves)
            anns.append(
                {
                    "token": token("sample_annotation", spec.name, obj.name, int(k)),
                    "sample_token": samples[k]["token"],
                    "instance_token": instance_token,
                    "visibility_token": _visibility_token(float(visible[m, k])),
                    "attribute_tokens": [] if attribute is None else [attribute_tokens[attribute]],
                    "translation": [float(v) for v in centres[m, k]],
                    "size": list(obj.size_wlh_m),
                    "rotation": _yaw_quat_wxyz(float(traj.yaw[m, k])),
                    "num_lidar_pts": int(num_pts[m, k]),
                    "num_radar_pts": 0,
                }
            )
        _link(anns)
        for row in anns:
            tables["sample_annotation"].append(row)
        tables["instance"].append(
            {
                "token": instance_token,
                "category_token": token("category", obj.category),
                "nbr_annotations": len(anns),
                "first_annotation_token": anns[0]["token"],
                "last_annotation_token": anns[-1]["token"],
            },
        )


SWEEPS_PER_INTERVAL = 9
"""LiDAR sweeps between two keyframes when the demo is built with sweeps (nuScenes: a 20 Hz LiDAR, 2 Hz
keyframes)."""
SWEEPS_ENV = "GNNPMB_DEMO_SWEEPS"
"""Set to 1 to give the cached demo the sweeps between keyframes (a separate cache folder)."""


def _intermediate_sweeps(
    spec: SceneSpec, tables: dict[str, list[dict]], dataroot: Path, rng: np.random.Generator, samples: list[dict]
) -> list[dict]:
    """The non-keyframe LIDAR_TOP sweeps between consecutive keyframes (``SWEEPS_PER_INTERVAL`` each, evenly
    spaced), each with its ego pose; a sweep belongs to the next keyframe's sample, as in nuScenes."""
    step_s = KEYFRAME_INTERVAL_US * 1e-6 / (SWEEPS_PER_INTERVAL + 1)
    offsets = np.arange(1, SWEEPS_PER_INTERVAL + 1) * step_s
    times_s = (keyframe_times_s()[:-1, None] + offsets[None]).reshape(-1)
    traj = scene_trajectories(spec, times_s)
    rows = []
    for j, t_s in enumerate(times_s):
        timestamp = spec.start_us + int(round(t_s * 1e6))
        tokens = (
            token("ego_pose", spec.name, "LIDAR_TOP", "sweep", j),
            token("sample_data", spec.name, "LIDAR_TOP", "sweep", j),
            samples[j // SWEEPS_PER_INTERVAL + 1]["token"],
        )
        rows.append(_sweep(spec, traj, j, timestamp, (dataroot, "sweeps", tables), tokens, rng)[2])
    return rows


def _camera_rows(spec: SceneSpec, tables: dict[str, list[dict]], samples: list[dict]) -> None:
    """Each camera's calibration and, per keyframe, its keyframe ``sample_data`` row taken at the LiDAR time with
    its own ``ego_pose`` row (the keyframe's pose); the images themselves are rendered on first use
    (``ensure_scene_images``)."""
    log_name = f"gnnpmb-demo-{spec.name}"
    keyframe_poses = {token("ego_pose", spec.name, k) for k in range(len(samples))}
    lidar_poses = {row["timestamp"]: row for row in tables["ego_pose"] if row["token"] in keyframe_poses}
    for cam in demo_cameras.CAMERAS:
        calib_token = token("calibrated_sensor", spec.name, cam.channel)
        tables["calibrated_sensor"].append(
            {
                "token": calib_token,
                "sensor_token": token("sensor", cam.channel),
                "translation": list(cam.translation_m),
                "rotation": list(cam.quat_wxyz),
                "camera_intrinsic": [list(r) for r in cam.intrinsic],
            },
        )
        rows = []
        for k, sample in enumerate(samples):
            timestamp = sample["timestamp"]
            pose_token = token("ego_pose", spec.name, cam.channel, k)
            tables["ego_pose"].append({**lidar_poses[timestamp], "token": pose_token})
            rows.append(
                {
                    "token": token("sample_data", spec.name, cam.channel, k),
                    "sample_token": sample["token"],
                    "ego_pose_token": pose_token,
                    "calibrated_sensor_token": calib_token,
                    "timestamp": timestamp,
                    "fileformat": "jpg",
                    "is_key_frame": True,
                    "height": demo_cameras.IMAGE_HEIGHT_PX,
                    "width": demo_cameras.IMAGE_WIDTH_PX,
                    "filename": demo_cameras.image_filename(log_name, cam.channel, timestamp),
                }
            )
        _link(rows)
        tables["sample_data"].extend(rows)


def _road_left_m(spec: SceneSpec) -> float:
    """The road's left edge (road d, metres): wider when vehicles drive in a second oncoming lane."""
    wide = any(
        o.category.startswith("vehicle.") and o.motion.speed_mps > 0 and o.motion.d_m >= 5.0 for o in spec.objects
    )
    return demo_cameras.WIDE_ROAD_LEFT_M if wide else demo_cameras.ROAD_HALF_WIDTH_M


def ensure_scene_images(dataroot: Path, scene_name: str, frames: range | None = None) -> int:
    """Render the missing camera images of demo scene ``scene_name`` at the keyframes ``frames`` (default: all)
    into ``dataroot`` (a demo dataroot of the current generator version); the number written. Each keyframe shows
    every object of the scene (annotated or not) at its keyframe pose."""
    spec = scene_spec(scene_name)
    times_us = spec.start_us + np.arange(KEYFRAMES_PER_SCENE) * KEYFRAME_INTERVAL_US
    log_name = f"gnnpmb-demo-{spec.name}"
    missing = [
        k
        for k in (frames if frames is not None else range(KEYFRAMES_PER_SCENE))
        if not all(
            (dataroot / demo_cameras.image_filename(log_name, cam.channel, int(times_us[k]))).is_file()
            for cam in demo_cameras.CAMERAS
        )
    ]
    if not missing:
        return 0
    traj = scene_trajectories(spec)
    ego_s = integrate_motion(spec.ego, keyframe_times_s())[0][:, 0]
    sizes = np.array([o.size_wlh_m for o in spec.objects], dtype=float).reshape(-1, 3)
    rgb = demo_cameras.category_rgb([o.category for o in spec.objects])
    jobs = []
    for k in missing:
        centres = np.column_stack([traj.xy[:, k], 0.5 * sizes[:, 2]]) if len(sizes) else np.zeros((0, 3))
        view = demo_cameras.WorldView(
            road_origin_m=spec.road_origin_m,
            road_heading_rad=spec.road_heading_rad,
            road_left_m=_road_left_m(spec),
            ego_s_m=float(ego_s[k]),
            centre_m=centres,
            size_wlh_m=sizes,
            yaw_rad=traj.yaw[:, k] if len(sizes) else np.zeros(0),
            rgb=rgb,
        )
        for cam in demo_cameras.CAMERAS:
            pose = demo_cameras.CameraPose.of(cam, traj.ego_xy[k], float(traj.ego_yaw[k]))
            jobs.append((demo_cameras.image_filename(log_name, cam.channel, int(times_us[k])), view, pose))
    return demo_cameras.render_views(dataroot, jobs)


def _empty_mask_png() -> bytes:
    """A small all-background semantic-prior mask (8-bit grey PNG), so the devkit's map table resolves."""
    from PIL import Image

    buffer = io.BytesIO()
    Image.fromarray(np.zeros((16, 16), dtype=np.uint8), mode="L").save(buffer, format="PNG")
    return buffer.getvalue()


def _scene_seeds(seed: int, names: tuple[str, ...]) -> list[np.random.SeedSequence]:
    """LiDAR-noise seed of each scene: the val scenes keep their original streams, a train scene gets its own."""
    val = dict(zip(DEMO_SCENES, np.random.SeedSequence(seed).spawn(len(DEMO_SCENES)), strict=True))
    layout = {**LAYOUT_SEEDS, **dict.fromkeys(STAGED_SCENES, STAGED_SEED)}
    return [val[n] if n in val else np.random.SeedSequence([seed, layout[n]]) for n in names]


def _write_dataset(dataroot: Path, seed: int, names: tuple[str, ...], sweeps: bool = False) -> None:
    """Write the demo scenes ``names`` into the (empty) folder ``dataroot`` (with the LiDAR sweeps between
    keyframes when ``sweeps``)."""
    specs = [scene_spec(n) for n in names]
    (dataroot / DEMO_VERSION).mkdir(parents=True)
    (dataroot / "samples" / "LIDAR_TOP").mkdir(parents=True)
    if sweeps:
        (dataroot / "sweeps" / "LIDAR_TOP").mkdir(parents=True)
    (dataroot / "maps").mkdir()
    tables: dict[str, list[dict]] = {name: [] for name in TABLE_NAMES}
    for name, description in CATEGORIES:
        tables["category"].append({"token": token("category", name), "name": name, "description": description})
    for name, description in ATTRIBUTES:
        tables["attribute"].append({"token": token("attribute", name), "name": name, "description": description})
    for tok, level, upper in VISIBILITY_LEVELS:
        lower = max((u for _, _, u in VISIBILITY_LEVELS if u < upper), default=0.0)
        tables["visibility"].append(
            {
                "token": tok,
                "level": level,
                "description": f"visibility of the whole object is between {lower:.0%} and {min(upper, 1.0):.0%}",
            },
        )
    tables["sensor"].append({"token": token("sensor", "LIDAR_TOP"), "channel": "LIDAR_TOP", "modality": "lidar"})
    for cam in demo_cameras.CAMERAS:
        tables["sensor"].append({"token": token("sensor", cam.channel), "channel": cam.channel, "modality": "camera"})
    for spec, scene_seed in zip(specs, _scene_seeds(seed, names), strict=True):
        sweep_rng = np.random.default_rng(scene_seed.spawn(1)[0]) if sweeps else None
        _write_scene(spec, tables, dataroot, np.random.default_rng(scene_seed), sweep_rng)

    mask = _empty_mask_png()
    for location in sorted({s.location for s in specs}):
        map_token = token("map", location)
        filename = f"maps/{map_token}.png"
        (dataroot / filename).write_bytes(mask)
        logs = [token("log", s.name) for s in specs if s.location == location]
        tables["map"].append(
            {"token": map_token, "log_tokens": logs, "category": "semantic_prior", "filename": filename}
        )
    for name, rows in tables.items():
        (dataroot / DEMO_VERSION / f"{name}.json").write_text(json.dumps(rows, indent=1) + "\n", encoding="utf-8")
    staged = [n for n in names if n in STAGED_SCENES]
    if staged:  # a custom split of the devkit (nuscenes-devkit 1.2.0 reads splits.json beside the tables)
        splits = json.dumps({STAGED_SPLIT: staged}, indent=1) + "\n"
        (dataroot / DEMO_VERSION / "splits.json").write_text(splits, encoding="utf-8")
    marker = {
        "generator": "gnnpmb-viz demo",
        "generator_version": GENERATOR_VERSION,
        "seed": seed,
        "scenes": list(names),
        **({"sweeps": SWEEPS_PER_INTERVAL} if sweeps else {}),
    }
    (dataroot / MARKER_FILE).write_text(json.dumps(marker, indent=1) + "\n", encoding="utf-8")


def is_demo_dataroot(
    path: Path, seed: int | None = None, scenes: tuple[str, ...] = (), sweeps: bool | None = None
) -> bool:
    """Whether ``path`` holds a complete demo of the current generator version (and of ``seed`` if given, with at
    least the scenes ``scenes``, with or without the sweeps between keyframes as ``sweeps`` says if given)."""
    try:
        marker = json.loads((path / MARKER_FILE).read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return False
    if not isinstance(marker, dict) or marker.get("generator_version") != GENERATOR_VERSION:
        return False
    if not set(scenes) <= set(marker.get("scenes", ())):
        return False
    if sweeps is not None and bool(marker.get("sweeps")) != sweeps:
        return False
    return seed is None or marker.get("seed") == seed


def check_demo_scenes(names: tuple[str, ...]) -> tuple[str, ...]:
    """``names`` if every one is a demo scene (the ten ``v1.0-mini`` names), else a ``DataError`` naming the first
    unknown one."""
    known = DEMO_SCENES + STAGED_SCENES + TRAIN_SCENES
    for n in names:
        if n not in known:
            raise DataError(f"unknown demo scene '{n}'; the demo has: {', '.join(sorted(known))}")
    if not names:
        raise DataError(f"no demo scenes given; the demo has: {', '.join(sorted(known))}")
    return tuple(n for n in sorted(known) if n in names)


def generate_demo_dataset(
    out_dir: Path,
    seed: int = DEMO_SEED,
    scenes: tuple[str, ...] = DEMO_SCENES + STAGED_SCENES,
    *,
    sweeps: bool = False,
) -> Path:
    """Write the demo scenes ``scenes`` (default: the two mini_val ones and the staged one) into ``out_dir`` (the
    dataroot) and return it; ``sweeps``: also the LiDAR sweeps between keyframes (``SWEEPS_PER_INTERVAL`` per
    interval, ``sweeps/LIDAR_TOP``; the build then takes about ten times as long).

    The data is built in a sibling temp folder and renamed into place, so a reader never sees half a dataset.
    ``out_dir`` may be missing, empty or an earlier demo; anything else is refused with a ``DataError``.
    """
    out_dir = Path(out_dir).expanduser().absolute()
    if out_dir.exists() and not out_dir.is_dir():
        raise DataError(f"cannot write the demo dataset to {out_dir}: it is a file; choose a folder")
    replaces_demo = (out_dir / MARKER_FILE).is_file()
    if not replaces_demo and out_dir.is_dir() and any(out_dir.iterdir()):
        raise DataError(
            f"refusing to write the demo dataset into {out_dir}: the folder is not empty and not a gnnpmb-viz "
            "demo; choose a new or empty folder"
        )
    out_dir.parent.mkdir(parents=True, exist_ok=True)
    sweep_leftovers(out_dir.parent)  # builds of killed runs
    build = Path(tempfile.mkdtemp(prefix=temp_prefix(out_dir, "build"), dir=out_dir.parent))
    try:
        _write_dataset(build / "data", seed, check_demo_scenes(tuple(scenes)), sweeps)
        if out_dir.exists():
            old = Path(tempfile.mkdtemp(prefix=temp_prefix(out_dir, "old"), dir=out_dir.parent))
            os.replace(out_dir, old / "data")
            os.replace(build / "data", out_dir)
            shutil.rmtree(old, ignore_errors=True)
        else:
            os.replace(build / "data", out_dir)
    finally:
        shutil.rmtree(build, ignore_errors=True)
    return out_dir


def demo_cache_dir(full: bool = False) -> Path:
    """Where ``ensure_demo_dataset`` keeps the demo: a ``demo-v<GENERATOR_VERSION>`` subfolder of ``cache_root``
    (the two mini_val scenes and the staged one) or ``demo-v<GENERATOR_VERSION>-all`` (with the eight mini_train
    scenes, when ``full``); ``-sweeps`` is appended when ``$GNNPMB_DEMO_SWEEPS`` is 1 (``demo_sweeps``)."""
    return cache_root() / f"demo-v{GENERATOR_VERSION}{'-all' if full else ''}{'-sweeps' if demo_sweeps() else ''}"


def demo_sweeps() -> bool:
    """Whether the cached demo has the LiDAR sweeps between keyframes: ``$GNNPMB_DEMO_SWEEPS`` set to 1."""
    value = os.environ.get(SWEEPS_ENV, "").strip()
    if value not in ("", "0", "1"):
        raise DataError(f"{SWEEPS_ENV}={value!r} is not valid; set it to 1 (demo with LiDAR sweeps) or 0")
    return value == "1"


TRAIN_NEEDS = ("mini_train", "train")
"""Split names that need the generated train scenes."""


def demo_layout(needs: tuple[str, ...] = ()) -> tuple[Path, tuple[str, ...]]:
    """The cached demo's dataroot and scenes for ``needs`` (split or scene names about to be used): the two
    ``mini_val`` scenes and the staged one (``demo_staged``); the eight train scenes are included (in a separate
    cached dataroot) only when one of them is a train split or scene."""
    full = any(n in TRAIN_NEEDS or n in TRAIN_SCENES for n in needs)
    scenes = DEMO_SCENES + STAGED_SCENES
    return demo_cache_dir(full), (scenes + TRAIN_SCENES if full else scenes)


def ensure_demo_dataset(needs: tuple[str, ...] = (), *, rebuild: bool = False) -> Path:
    """The dataroot of the cached demo (seed ``DEMO_SEED``) for ``needs`` (``demo_layout``), generated on first
    use, so the default val demo stays quick to build; ``rebuild`` generates it again (a damaged cache). With
    ``$GNNPMB_DEMO_SWEEPS=1`` the demo (in its own folder) also holds the LiDAR sweeps between keyframes."""
    dataroot, scenes = demo_layout(needs)
    sweeps = demo_sweeps()
    sweep_leftovers(dataroot.parent)  # builds of killed runs
    if not rebuild and is_demo_dataroot(dataroot, DEMO_SEED, scenes, sweeps):
        return dataroot
    try:
        return generate_demo_dataset(dataroot, DEMO_SEED, scenes, sweeps=sweeps)
    except OSError as exc:
        if is_demo_dataroot(dataroot, DEMO_SEED, scenes, sweeps):
            return dataroot
        raise DataError(
            f"cannot create the demo dataset in {dataroot}: {exc.strerror or exc}; set {CACHE_ENV} to a writable folder"
        ) from exc
