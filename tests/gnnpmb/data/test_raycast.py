"""The LiDAR simulator: exact hits on boxes and the ground, occlusion, and the per-box point counts."""

from __future__ import annotations

import numpy as np
import pytest

from gnnpmb.data.raycast import GROUND, LidarSpec, SceneBoxes, cast_scan

SPEC = LidarSpec(n_beams=16, n_azimuth=720, range_noise_m=0.0, range_noise_clip_m=0.0)
SENSOR_HEIGHT_M = 1.8


def _boxes(centres_xy: list[tuple[float, float]], sizes_wlh: list[tuple[float, float, float]], yaw=None) -> SceneBoxes:
    sizes = np.array(sizes_wlh, dtype=float)
    centres = np.column_stack([np.array(centres_xy, dtype=float), 0.5 * sizes[:, 2]])
    n = len(centres_xy)
    return SceneBoxes(centres, sizes, np.zeros(n) if yaw is None else np.asarray(yaw, float), np.full(n, 50.0))


def _cast(boxes: SceneBoxes, yaw_rad: float = 0.0, spec: LidarSpec = SPEC):
    c, s = np.cos(yaw_rad), np.sin(yaw_rad)
    rotation = np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])
    origin = np.array([100.0, -50.0, SENSOR_HEIGHT_M])
    return cast_scan(spec, origin, rotation, boxes, np.random.default_rng(0)), origin, rotation


def test_ground_returns_lie_on_the_plane_at_the_expected_range() -> None:
    scan, origin, rotation = _cast(_boxes([(0.0, 0.0)], [(1.0, 1.0, 1.0)]))  # far away: nothing but ground
    assert np.all(scan.target == GROUND)
    global_z = (scan.points[:, :3].astype(float) @ rotation.T + origin)[:, 2]
    assert np.allclose(global_z, 0.0, atol=1e-5)
    elevations = SPEC.elevations_rad()
    expected_beams = np.flatnonzero(SENSOR_HEIGHT_M / np.tan(-np.minimum(elevations, -1e-9)) <= SPEC.max_range_m)
    assert set(np.unique(scan.points[:, 4]).astype(int)) == set(expected_beams)
    assert scan.points.shape[0] == expected_beams.size * SPEC.n_azimuth


def _box_frame(points_global: np.ndarray, centre: np.ndarray, yaw: float) -> np.ndarray:
    c, s = np.cos(yaw), np.sin(yaw)
    return (points_global - centre) @ np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


@pytest.mark.parametrize("sensor_yaw", [0.0, 2.5])
def test_box_hits_are_on_its_surface_and_counted(sensor_yaw: float) -> None:
    boxes = _boxes([(110.0, -50.0)], [(2.0, 4.0, 1.5)], yaw=[0.3])
    scan, origin, rotation = _cast(boxes, sensor_yaw)
    local = _box_frame(scan.points[:, :3].astype(float) @ rotation.T + origin, boxes.centre_m[0], 0.3)
    hits = local[scan.target == 0]
    assert hits.shape[0] > 50
    half = np.array([2.0, 1.0, 0.75])
    inset = SPEC.surface_inset_m
    # every hit lies on the physical box (the annotated box shrunk by the inset, except at the bottom)
    on_side = np.isclose(np.abs(hits[:, :2]), half[:2] - inset, atol=1e-4).any(axis=1)
    on_top = np.isclose(hits[:, 2], half[2] - inset, atol=1e-4)
    assert np.all(on_side | on_top)
    # the count is of all returns inside the annotated box: its hits plus ground returns in the inset margin
    inside = np.all(np.abs(local) <= half, axis=1)
    assert scan.num_pts[0] == np.count_nonzero(inside)
    assert np.all(inside[scan.target == 0]) and scan.num_pts[0] <= 1.05 * hits.shape[0]
    assert scan.visible_fraction[0] == pytest.approx(1.0)


def test_a_box_hidden_behind_a_taller_one_gets_no_points() -> None:
    boxes = _boxes([(106.0, -50.0), (115.0, -50.0)], [(6.0, 2.0, 4.0), (1.0, 1.0, 1.5)])
    scan, _, _ = _cast(boxes)
    assert scan.num_pts[0] > 100
    assert scan.num_pts[1] == 0 and scan.visible_fraction[1] == 0.0
    alone, _, _ = _cast(_boxes([(115.0, -50.0)], [(1.0, 1.0, 1.5)]))
    assert alone.num_pts[0] > 0


def test_partly_hidden_box_has_a_visible_fraction_between_0_and_1() -> None:
    boxes = _boxes([(106.0, -51.0), (115.0, -50.0)], [(2.0, 1.0, 4.0), (4.0, 1.0, 1.5)])
    scan, _, _ = _cast(boxes)
    assert 0.05 < scan.visible_fraction[1] < 0.95


def test_returns_beyond_max_range_are_dropped() -> None:
    spec = LidarSpec(n_beams=16, n_azimuth=720, max_range_m=20.0)
    scan, _, _ = _cast(_boxes([(125.0, -50.0)], [(4.0, 2.0, 3.0)]), spec=spec)
    assert scan.num_pts[0] == 0
    assert np.linalg.norm(scan.points[:, :3], axis=1).max() <= 20.0 + spec.range_noise_clip_m


def test_noisy_returns_stay_inside_their_box() -> None:
    boxes = _boxes([(108.0, -47.0)], [(1.9, 4.5, 1.6)], yaw=[1.0])
    origin = np.array([100.0, -50.0, 1.8])
    scan = cast_scan(LidarSpec(), origin, np.eye(3), boxes, np.random.default_rng(3))
    local = _box_frame(scan.points[scan.target == 0, :3].astype(float) + origin, boxes.centre_m[0], 1.0)
    assert local.shape[0] > 100
    assert np.all(np.abs(local) <= np.array([2.25, 0.95, 0.8]))
