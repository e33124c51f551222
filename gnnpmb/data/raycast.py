"""A small spinning-LiDAR simulator: rays against a flat ground and oriented boxes, nearest hit wins.

The sensor has ``n_beams`` beams at evenly spaced elevations and fires every beam at ``n_azimuth`` evenly spaced
azimuths per revolution (one keyframe = one revolution, no motion during the sweep). A ray from the sensor
origin o along the unit direction u hits

* the ground plane z = 0 (global) at t = -o_z / u_z when u_z < 0;
* a box with centre c, rotation R and half extents (l/2, w/2, h/2) where the slab test in the box frame
  (o' = R^T (o - c), u' = R^T u) gives t_near = max_k min(t_k^-, t_k^+) <= t_far = min_k max(t_k^-, t_k^+),
  with t_k^± = (±half_k - o'_k) / u'_k (Kay & Kajiya, "Ray tracing complex scenes", SIGGRAPH 1986).

Only the rays inside a box's azimuth and elevation window (from its 8 corners) are tested, so a frame costs
about the angular area of its boxes rather than rays x boxes. Rays are cast against the *physical* box, the
annotated box shrunk by ``surface_inset_m`` on every side but the bottom, and the range noise is clipped below
that inset, so each return of an object lies inside its annotated box like in real annotations (whose boxes are
a little larger than the object). Returns beyond ``max_range_m`` are dropped.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

GROUND = -1
"""``Scan.target`` of a return from the ground plane."""


@dataclass(frozen=True, slots=True)
class LidarSpec:
    """Beam layout and noise of the simulated LIDAR_TOP (roughly a 32-beam spinning sensor)."""

    n_beams: int = 32
    elevation_min_deg: float = -30.0
    elevation_max_deg: float = 10.0
    n_azimuth: int = 1200
    max_range_m: float = 70.0
    range_noise_m: float = 0.01
    """Standard deviation of the Gaussian range noise, clipped to +-``range_noise_clip_m``."""
    range_noise_clip_m: float = 0.03
    surface_inset_m: float = 0.04
    ground_intensity: float = 6.0
    intensity_noise: float = 3.0

    def __post_init__(self) -> None:
        if self.range_noise_clip_m >= self.surface_inset_m:
            raise ValueError("range_noise_clip_m must be below surface_inset_m so returns stay inside their box")

    def elevations_rad(self) -> np.ndarray:
        """(n_beams,) beam elevations, lowest first (the ring index is the position in this array)."""
        return np.deg2rad(np.linspace(self.elevation_min_deg, self.elevation_max_deg, self.n_beams))

    def azimuths_rad(self) -> np.ndarray:
        """(n_azimuth,) azimuths in [-pi, pi), the centres of equal bins."""
        return -np.pi + (np.arange(self.n_azimuth) + 0.5) * (2.0 * np.pi / self.n_azimuth)

    def directions(self) -> np.ndarray:
        """(n_beams, n_azimuth, 3) unit ray directions in the sensor frame."""
        el = self.elevations_rad()[:, None]
        az = self.azimuths_rad()[None, :]
        return np.stack(np.broadcast_arrays(np.cos(el) * np.cos(az), np.cos(el) * np.sin(az), np.sin(el)), axis=-1)


@dataclass(frozen=True, slots=True)
class SceneBoxes:
    """M oriented boxes in the global frame, standing on the ground (yaw-only rotation).

    centre_m: (M, 3); size_wlh_m: (M, 3); yaw_rad: (M,); intensity: (M,) mean return intensity of each surface.
    """

    centre_m: np.ndarray
    size_wlh_m: np.ndarray
    yaw_rad: np.ndarray
    intensity: np.ndarray

    def __len__(self) -> int:
        return int(self.centre_m.shape[0])


@dataclass(frozen=True, slots=True)
class Scan:
    """One simulated sweep.

    points: (N, 5) float32 x, y, z, intensity, ring in the sensor frame (the ``.pcd.bin`` layout);
    target: (N,) index of the box each return came from, or ``GROUND``;
    num_pts: (M,) returns whose point lies inside each annotated box (the devkit's ``points_in_box`` count);
    visible_fraction: (M,) returns from each box over the returns it would give with nothing in front of it
    (0 where it would give none).
    """

    points: np.ndarray
    target: np.ndarray
    num_pts: np.ndarray
    visible_fraction: np.ndarray


def _yaw_matrices(yaw_rad: np.ndarray) -> np.ndarray:
    """(M, 3, 3) rotations about z."""
    c, s = np.cos(yaw_rad), np.sin(yaw_rad)
    out = np.zeros((yaw_rad.shape[0], 3, 3))
    out[:, 0, 0], out[:, 0, 1], out[:, 1, 0], out[:, 1, 1], out[:, 2, 2] = c, -s, s, c, 1.0
    return out


def _corner_offsets(size_wlh_m: np.ndarray) -> np.ndarray:
    """(M, 8, 3) corner offsets in each box's frame (x along the length, y along the width)."""
    signs = np.array([[sx, sy, sz] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)], dtype=float)
    half_lwh = 0.5 * size_wlh_m[:, [1, 0, 2]]
    return signs[None, :, :] * half_lwh[:, None, :]


def _index_window(angles: np.ndarray, start: float, step: float, count: int, wrap: bool) -> np.ndarray:
    """Indices of the bins (centres start + (i + 0.5) step) whose centre lies within [min, max] of ``angles``.

    For azimuths (``wrap``) the corner angles are unwrapped around their circular mean first, so a box behind
    the sensor (across +-pi) gets one contiguous window taken modulo ``count``.
    """
    if wrap:
        ref = np.angle(np.mean(np.exp(1j * angles)))
        rel = np.angle(np.exp(1j * (angles - ref)))
        lo, hi = ref + rel.min(), ref + rel.max()
    else:
        lo, hi = float(angles.min()), float(angles.max())
    first = int(np.ceil((lo - start) / step - 0.5))
    last = int(np.floor((hi - start) / step - 0.5))
    idx = np.arange(first, last + 1)
    if wrap:
        return np.unique(idx % count)
    return idx[(idx >= 0) & (idx < count)]


def _elevation_window(rel_z_m: tuple[float, float], range_m: tuple[float, float], elevations: np.ndarray) -> np.ndarray:
    """Indices of the beams that can meet a box spanning heights ``rel_z_m`` = (bottom, top) above the sensor
    and horizontal distances ``range_m`` = (nearest, farthest) from it.

    The steepest ray to the box leaves towards its nearest footprint point (which may lie mid-edge), the
    shallowest towards its farthest, so the window is [atan2(bottom, r), atan2(top, r')] with r, r' chosen
    by the signs of bottom and top.
    """
    bottom, top = rel_z_m
    near, far = range_m
    lo = np.arctan2(bottom, near if bottom < 0.0 else far)
    hi = np.arctan2(top, far if top < 0.0 else near)
    return np.flatnonzero((elevations >= lo) & (elevations <= hi))


def _slab_hits(origin_box: np.ndarray, dirs_box: np.ndarray, lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
    """Entry distance of rays into an axis-aligned box [lo, hi] (box frame), inf where a ray misses.

    origin_box: (3,) ray origin (outside the box); dirs_box: (..., 3) unit directions; lo, hi: (3,).
    """
    with np.errstate(divide="ignore", invalid="ignore"):
        inv = 1.0 / dirs_box
        t_lo = (lo - origin_box) * inv
        t_hi = (hi - origin_box) * inv
    t_near = np.nanmax(np.minimum(t_lo, t_hi), axis=-1)
    t_far = np.nanmin(np.maximum(t_lo, t_hi), axis=-1)
    hit = (t_near <= t_far) & (t_near > 0.0)
    return np.where(hit, t_near, np.inf)


def cast_scan(
    spec: LidarSpec,
    sensor_translation_m: np.ndarray,
    sensor_rotation: np.ndarray,
    boxes: SceneBoxes,
    rng: np.random.Generator,
) -> Scan:
    """Simulate one sweep of a level sensor at ``sensor_translation_m`` (3,) with rotation matrix (3, 3)
    (sensor to global, a rotation about z) among ``boxes`` standing on the ground plane z = 0.
    Returns points in the sensor frame.
    """
    if not np.allclose(sensor_rotation[:, 2], (0.0, 0.0, 1.0), atol=1e-9):
        raise ValueError("the simulated sensor must be level (its z axis vertical)")
    dirs_sensor = spec.directions()
    n_beams, n_az = dirs_sensor.shape[:2]
    elevations = spec.elevations_rad()
    az_step = 2.0 * np.pi / spec.n_azimuth
    dirs_global = dirs_sensor @ sensor_rotation.T
    origin = np.asarray(sensor_translation_m, dtype=float)

    with np.errstate(divide="ignore"):
        t_ground = np.where(dirs_global[..., 2] < 0.0, -origin[2] / dirs_global[..., 2], np.inf)
    t_best = t_ground
    target = np.full((n_beams, n_az), GROUND, dtype=np.int64)

    m = len(boxes)
    rotations = _yaw_matrices(boxes.yaw_rad)
    half_lwh = 0.5 * boxes.size_wlh_m[:, [1, 0, 2]]
    corners_global = boxes.centre_m[:, None, :] + np.einsum(
        "mij,mkj->mki", rotations, _corner_offsets(boxes.size_wlh_m)
    )
    corners_sensor = (corners_global - origin) @ sensor_rotation
    origin_in_box = np.einsum("mji,mj->mi", rotations, origin - boxes.centre_m)
    nearest_m = np.linalg.norm(np.maximum(np.abs(origin_in_box[:, :2]) - half_lwh[:, :2], 0.0), axis=1)
    farthest_m = np.linalg.norm(corners_sensor[..., :2], axis=-1).max(axis=1)
    windows: list[tuple[np.ndarray, np.ndarray]] = []
    alone_hits = np.zeros(m, dtype=np.int64)
    for k in range(m):
        cs = corners_sensor[k]
        if nearest_m[k] > 0.0:
            az_idx = _index_window(np.arctan2(cs[:, 1], cs[:, 0]), -np.pi, az_step, n_az, wrap=True)
        else:
            az_idx = np.arange(n_az)
        rel_z = (float(cs[:, 2].min()), float(cs[:, 2].max()))
        el_idx = _elevation_window(rel_z, (float(nearest_m[k]), float(farthest_m[k])), elevations)
        windows.append((el_idx, az_idx))
        if az_idx.size == 0 or el_idx.size == 0:
            continue
        sub = np.ix_(el_idx, az_idx)
        origin_box = origin_in_box[k]
        dirs_box = dirs_global[sub] @ rotations[k]
        inset = spec.surface_inset_m
        lo = -half_lwh[k] + np.array([inset, inset, 0.0])
        hi = half_lwh[k] - inset
        t_box = _slab_hits(origin_box, dirs_box, lo, hi)
        alone_hits[k] = int(np.count_nonzero(t_box <= spec.max_range_m))
        closer = t_box < t_best[sub]
        t_best[sub] = np.where(closer, t_box, t_best[sub])
        target[sub] = np.where(closer, k, target[sub])

    valid = t_best <= spec.max_range_m
    noise = np.clip(
        rng.normal(0.0, spec.range_noise_m, size=t_best.shape), -spec.range_noise_clip_m, spec.range_noise_clip_m
    )
    intensity_mean = np.append(boxes.intensity, spec.ground_intensity)[target]  # GROUND = -1 picks the last
    intensity = np.clip(np.rint(intensity_mean + rng.normal(0.0, spec.intensity_noise, size=t_best.shape)), 0.0, 255.0)
    ranges = np.where(valid, t_best + noise, 0.0)
    xyz = dirs_sensor * ranges[..., None]
    ring = np.broadcast_to(np.arange(n_beams, dtype=float)[:, None], (n_beams, n_az))
    grid = np.concatenate([xyz, intensity[..., None], ring[..., None]], axis=-1).astype(np.float32)
    points = grid[valid]
    point_target = target[valid]

    index_grid = np.full((n_beams, n_az), -1, dtype=np.int64)
    index_grid[valid] = np.arange(points.shape[0])
    num_pts = np.zeros(m, dtype=np.int64)
    direct_hits = np.bincount(point_target[point_target >= 0], minlength=m)
    for k, (el_idx, az_idx) in enumerate(windows):
        cand = index_grid[np.ix_(el_idx, az_idx)].ravel()
        cand = cand[cand >= 0]
        if cand.size == 0:
            continue
        p_global = points[cand, :3].astype(np.float64) @ sensor_rotation.T + origin
        p_box = (p_global - boxes.centre_m[k]) @ rotations[k]
        num_pts[k] = int(np.count_nonzero(np.all(np.abs(p_box) <= half_lwh[k], axis=1)))
    visible = np.where(alone_hits > 0, direct_hits / np.maximum(alone_hits, 1), 0.0)
    return Scan(points=points, target=point_target, num_pts=num_pts, visible_fraction=np.clip(visible, 0.0, 1.0))
