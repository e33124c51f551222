"""The eight ``mini_train`` scenes of the synthetic demo: varied street layouts drawn from a seeded generator.

Parameters are chosen on ``mini_train`` and reported on the hand-built ``mini_val`` scenes (``gnnpmb.data.demo``),
so the train scenes must not copy the val layouts: each train scene draws its own road (2-4 lanes), ego speed
(0-10 m/s), traffic density, parked rows (0.4-2.5 m gaps), convoys of a truck with a trailer, buses,
pedestrians walking along, crossing or standing in groups, cyclists, motorcycles, a car that brakes and turns,
and sometimes a roadworks zone that is a clutter hotspot for the simulated detector. Cars of one lane share one
speed and keep >= 8 m gaps, so no two boxes of one lane overlap. The layout of scene i depends only on its name
(``LAYOUT_SEEDS``), never on the LiDAR noise seed.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from gnnpmb.data.demo_spec import SYNTHETIC_MARKER, Motion, ObjectSpec, SceneSpec, Segment

TRAIN_SCENES: tuple[str, ...] = (
    "scene-0061",
    "scene-0553",
    "scene-0655",
    "scene-0757",
    "scene-0796",
    "scene-1077",
    "scene-1094",
    "scene-1100",
)
"""The devkit's ``mini_train`` scene names."""

LAYOUT_SEEDS: dict[str, int] = {name: 9000 + i for i, name in enumerate(TRAIN_SCENES)}
DENSITY: dict[str, float] = dict(zip(TRAIN_SCENES, (0.6, 1.0, 1.4, 0.8, 1.2, 1.6, 0.7, 1.1), strict=True))
"""Traffic density factor per train scene (sparse suburb to dense city)."""

LANE_WIDTH_M = 3.5
_CAR = "vehicle.car"
_ADULT = "human.pedestrian.adult"
_PED_SIZE = (0.67, 0.73, 1.77)
_CAR_SIZES = ((1.85, 4.6, 1.55), (1.9, 4.8, 1.62), (1.78, 4.3, 1.5), (1.95, 4.9, 1.7), (1.75, 4.1, 1.47))
_LOCATIONS = ("boston-seaport", "singapore-onenorth", "singapore-queenstown", "singapore-hollandvillage")


@dataclass(frozen=True, slots=True)
class Roadworks:
    """A roadworks zone of a train scene: centre in road coordinates (s, d) and radius, metres."""

    scene_name: str
    centre_sd_m: tuple[float, float]
    radius_m: float


def _lane_traffic(
    rng: np.random.Generator, prefix: str, d_m: float, heading_rad: float, n: int, speed_mps: float
) -> list[ObjectSpec]:
    """``n`` vehicles in one lane at one speed, spaced >= 8 m apart over s in [-40, 220]."""
    objects, s = [], float(rng.uniform(-40.0, 0.0))
    for i in range(n):
        kind = rng.choice(4, p=(0.8, 0.08, 0.06, 0.06))
        if kind == 0:
            size, cat, inten = _CAR_SIZES[int(rng.integers(len(_CAR_SIZES)))], _CAR, 40.0
        elif kind == 1:
            size, cat, inten = (2.5, float(rng.uniform(6.0, 8.0)), 3.2), "vehicle.truck", 55.0
        elif kind == 2:
            size, cat, inten = (2.9, 11.5, 3.5), "vehicle.bus.rigid", 50.0
        else:
            size, cat, inten = (0.8, 2.1, 1.5), "vehicle.motorcycle", 30.0
        s += 0.5 * size[1]
        objects.append(ObjectSpec(f"{prefix}{i}", cat, size, Motion(s, d_m, heading_rad, speed_mps), inten))
        s += 0.5 * size[1] + float(rng.uniform(8.0, 35.0))
        if s > 220.0:
            break
    return objects


def _parked_row(rng: np.random.Generator, prefix: str, s0: float, d_m: float, n: int) -> list[ObjectSpec]:
    cars, s = [], s0
    heading = 0.0 if d_m < 0 else math.pi
    for i in range(n):
        size = _CAR_SIZES[int(rng.integers(len(_CAR_SIZES)))]
        cars.append(ObjectSpec(f"{prefix}{i}", _CAR, size, Motion(s + 0.5 * size[1], d_m, heading, 0.0), 40.0))
        s += size[1] + float(rng.uniform(0.4, 2.5))
    return cars


def _walkers(rng: np.random.Generator, prefix: str, d_m: float, n: int) -> list[ObjectSpec]:
    """Pedestrians along a sidewalk: the two directions keep 1 m apart; some walk in pairs 0.8 m apart."""
    peds = []
    for i in range(n):
        forward = bool(rng.random() < 0.5)
        d = d_m + (0.5 if forward else -0.5)
        speed = float(rng.uniform(0.8, 1.6))
        s = float(rng.uniform(-10.0, 150.0))
        peds.append(
            ObjectSpec(f"{prefix}{i}", _ADULT, _PED_SIZE, Motion(s, d, 0.0 if forward else math.pi, speed), 18.0)
        )
        if rng.random() < 0.3:
            peds.append(
                ObjectSpec(
                    f"{prefix}{i}b", _ADULT, _PED_SIZE, Motion(s + 0.8, d, 0.0 if forward else math.pi, speed), 18.0
                )
            )
    return peds


def _crossers(rng: np.random.Generator, prefix: str, n: int) -> list[ObjectSpec]:
    """Pedestrians crossing the road at right angles, on the centre line at a random time in [3, 17] s."""
    peds = []
    for i in range(n):
        heading = 0.5 * math.pi if rng.random() < 0.5 else -0.5 * math.pi
        speed = float(rng.uniform(1.0, 1.6))
        t_mid = float(rng.uniform(3.0, 17.0))
        s_cross = float(rng.uniform(20.0, 120.0))
        start = Motion(s_cross, -math.sin(heading) * speed * t_mid, heading, speed)
        peds.append(ObjectSpec(f"{prefix}{i}", _ADULT, _PED_SIZE, start, 18.0))
    return peds


def train_scene(name: str) -> tuple[SceneSpec, Roadworks | None]:
    """The layout of train scene ``name`` (one of ``TRAIN_SCENES``) and its roadworks zone, if any."""
    index = TRAIN_SCENES.index(name)
    rng = np.random.default_rng(LAYOUT_SEEDS[name])
    density = DENSITY[name]
    n_same = int(rng.integers(1, 3))
    n_onc = int(rng.integers(1, 3))
    half_width = LANE_WIDTH_M * max(n_same, n_onc)
    turns = bool(rng.random() < 0.6)
    ego_speed = 0.0 if rng.random() < 0.2 else float(rng.uniform(2.0, 4.0 if turns else 10.0))
    objects: list[ObjectSpec] = []
    for lane in range(n_same):
        d = -0.5 * LANE_WIDTH_M - LANE_WIDTH_M * lane
        if lane == 0 and turns:
            continue
        speed = ego_speed if lane == 0 else float(rng.uniform(3.0, 12.0))
        n = int(rng.poisson(4.0 * density)) + 1
        lane_objects = _lane_traffic(rng, f"same{lane}_", d, 0.0, n, speed)
        if lane == 0:  # the ego's own lane moves at the ego's speed; keep 12 m around the ego clear
            lane_objects = [o for o in lane_objects if o.motion.s_m > 12.0]
        objects.extend(lane_objects)
    for lane in range(n_onc):
        d = 0.5 * LANE_WIDTH_M + LANE_WIDTH_M * lane
        speed = float(rng.uniform(4.0, 13.0))
        n = int(rng.poisson(5.0 * density))
        objects.extend(
            ObjectSpec(o.name, o.category, o.size_wlh_m, Motion(o.motion.s_m + 60.0, d, math.pi, speed), o.intensity)
            for o in _lane_traffic(rng, f"onc{lane}_", d, math.pi, n, speed)
        )
    if rng.random() < 0.6:  # an oncoming truck pulling a trailer in the outer oncoming lane
        d = 0.5 * LANE_WIDTH_M + LANE_WIDTH_M * (n_onc - 1)
        s0, speed = float(rng.uniform(90.0, 160.0)), float(rng.uniform(5.0, 9.0))
        objects.append(
            ObjectSpec("convoy_truck", "vehicle.truck", (2.5, 6.8, 3.2), Motion(s0, d, math.pi, speed), 55.0)
        )
        objects.append(
            ObjectSpec(
                "convoy_trailer", "vehicle.trailer", (2.5, 10.5, 3.8), Motion(s0 + 9.35, d, math.pi, speed), 50.0
            )
        )
        objects = [o for o in objects if not (o.motion.d_m == d and o.name.startswith("onc"))]
    for side, sign in (("left", 1.0), ("right", -1.0)):
        if rng.random() < 0.7:
            n = int(rng.integers(2, 3 + int(6 * density)))
            objects.extend(
                _parked_row(rng, f"parked_{side}_", float(rng.uniform(5.0, 60.0)), sign * (half_width + 1.2), n)
            )
        if rng.random() < 0.3:
            objects.append(
                ObjectSpec(
                    f"parked_trailer_{side}",
                    "vehicle.trailer",
                    (2.45, 8.0, 3.4),
                    Motion(float(rng.uniform(80.0, 140.0)), sign * (half_width + 1.4), 0.0, 0.0),
                    45.0,
                )
            )
        objects.extend(_walkers(rng, f"walk_{side}_", sign * (half_width + 4.5), int(rng.poisson(3.0 * density))))
        if rng.random() < 0.5:
            objects.append(
                ObjectSpec(
                    f"bicycle_{side}",
                    "vehicle.bicycle",
                    (0.6, 1.75, 1.3),
                    Motion(
                        float(rng.uniform(0.0, 80.0)),
                        sign * (half_width + 2.6),
                        0.0 if sign < 0 else math.pi,
                        float(rng.uniform(3.0, 6.0)),
                    ),
                    25.0,
                )
            )
    objects.extend(_crossers(rng, "cross_", int(rng.poisson(2.0 * density))))
    if rng.random() < 0.4:
        objects.append(
            ObjectSpec(
                "waiting_group_0",
                _ADULT,
                _PED_SIZE,
                Motion(float(rng.uniform(30, 90)), -(half_width + 3.0), 0.5 * math.pi, 0.0),
                18.0,
            )
        )
        g = objects[-1].motion
        objects.append(
            ObjectSpec(
                "waiting_group_1",
                "human.pedestrian.child",
                (0.5, 0.5, 1.3),
                Motion(g.s_m + 0.9, g.d_m, g.heading_rad, 0.0),
                15.0,
            )
        )
    if turns:  # a car ahead in the ego's lane that brakes and turns off the road
        turn_r, s0, v0 = float(rng.uniform(6.0, 10.0)), float(rng.uniform(30.0, 60.0)), float(rng.uniform(5.0, 9.0))
        turn_sign = float(rng.choice((-1.0, 1.0)))
        objects.append(
            ObjectSpec(
                "turning_car",
                _CAR,
                (1.85, 4.5, 1.55),
                Motion(
                    s0,
                    -0.5 * LANE_WIDTH_M,
                    0.0,
                    v0,
                    (
                        Segment(float(rng.uniform(2.0, 8.0))),
                        Segment(2.0, accel_mps2=-(v0 - 4.0) / 2.0),
                        Segment(0.5 * math.pi * turn_r / 4.0, yaw_rate_rps=turn_sign * 4.0 / turn_r),
                        Segment(3.0, accel_mps2=0.5),
                    ),
                ),
                40.0,
            )
        )
    roadworks = None
    if rng.random() < 0.5:
        s_rw, d_rw = float(rng.uniform(40.0, 110.0)), half_width + 0.8
        for i, s in enumerate(np.linspace(s_rw - 5.0, s_rw + 5.0, 3)):
            objects.append(
                ObjectSpec(
                    f"barrier{i}",
                    "movable_object.barrier",
                    (2.5, 0.5, 0.98),
                    Motion(float(s), d_rw, 0.5 * math.pi, 0.0),
                    90.0,
                )
            )
        roadworks = Roadworks(name, (s_rw, d_rw), 7.0)
    location = _LOCATIONS[index % len(_LOCATIONS)]
    spec = SceneSpec(
        name=name,
        description=(
            f"{SYNTHETIC_MARKER}: generated training street (layout seed {LAYOUT_SEEDS[name]}, density {density})"
        ),
        location=location,
        start_us=1_532_400_000_000_000 + index * 3_600_000_000,
        road_origin_m=(float(rng.uniform(300.0, 1800.0)), float(rng.uniform(300.0, 1800.0))),
        road_heading_rad=float(rng.uniform(-math.pi, math.pi)),
        ego=Motion(0.0, -0.5 * LANE_WIDTH_M, 0.0, ego_speed),
        objects=tuple(objects),
    )
    return spec, roadworks
