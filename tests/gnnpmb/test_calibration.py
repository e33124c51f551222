"""``gnnpmb.calibration``'s floors: a learnt process noise below the base configuration's is raised to it and says
so; one above it is written as learnt."""

from __future__ import annotations

import numpy as np
import pytest

from gnnpmb.calibration import ClassSamples, learn_class, process_noise
from gnnpmb.config import TrackerConfig


def test_process_noise_is_the_velocity_change_variance_never_below_the_base() -> None:
    rng = np.random.default_rng(0)
    base = TrackerConfig()
    dv = np.column_stack([rng.normal(0.0, 1.0, 400), rng.normal(0.0, 0.01, 400), np.zeros(400)])
    q_x, q_y = process_noise("car", dv, base)
    assert (q_x.key, q_y.key) == ("q_x", "q_y")
    assert q_x.value == pytest.approx(np.var(dv[:, 0])) and "raised" not in q_x.source
    assert q_y.value == base.classes["car"].q_y and "raised to the base's" in q_y.source


def test_too_few_velocity_changes_learn_nothing() -> None:
    assert process_noise("car", np.zeros((3, 3)), TrackerConfig()) == []


def _clutter_only(n_clutter: int, velocity_std_mps: float, frames: int = 100) -> ClassSamples:
    """A pedestrian class seen over ``frames`` keyframes with ``n_clutter`` unmatched detections (score 0.5) whose
    velocities have standard deviation ``velocity_std_mps`` per axis, and as many true ones (score 0.5, so the
    learnt score threshold keeps them all), nothing else."""
    rng = np.random.default_rng(1)
    v = rng.normal(0.0, velocity_std_mps, (n_clutter, 2))
    v = (v - v.mean(axis=0)) / v.std(axis=0) * velocity_std_mps
    empty2, empty = np.zeros((0, 2)), np.zeros(0)
    return ClassSamples(
        position_residual_m=empty2,
        velocity_residual_mps=empty2,
        heading_residual_rad=empty,
        log_size_ratio=empty2,
        matched_score=np.full(n_clutter, 0.5),
        gt_log_size=empty2,
        gt_range_m=empty,
        gt_best_score=empty,
        clutter_score=np.full(n_clutter, 0.5),
        clutter_velocity_mps=v,
        detection_score=np.full(2 * n_clutter, 0.5),
        birth_range_m=empty,
        later_keyframes=frames - 1,
        frames=frames,
        range_m=40.0,
    )


@pytest.mark.parametrize(
    ("n_clutter", "velocity_std_mps"),
    [(50, 0.5), (50, 3.0), (2000, 0.5)],
    ids=["intensity floored, concentrated velocities", "both below the base", "intensity above the base"],
)
def test_the_clutter_floor_holds_for_the_intensity_the_trackers_use(n_clutter: int, velocity_std_mps: float) -> None:
    """With the velocity measured the PMB trackers' clutter intensity is clutter_intensity x clutter_velocity_density;
    it is floored as a product: max(learnt kappa d, the base's), never the two factors each raised (50 clutter
    detections over 100 keyframes of pi 40^2 m^2 learn kappa 9.9e-5, below the base's 0.001; velocities of 0.5 m/s
    learn d = 1 / (4 pi 0.25) = 0.318, above the base's 0.02: the product is 3.2e-5, and raising both factors wrote
    3.2e-4)."""
    base = TrackerConfig()
    learnt = {v.key: v for v in learn_class("pedestrian", _clutter_only(n_clutter, velocity_std_mps), base)}
    kappa = n_clutter / 100 / (np.pi * 40.0**2)
    density = 1.0 / (4.0 * np.pi * velocity_std_mps**2)
    kappa_b, density_b = base.models.clutter_intensity, base.pmb.clutter_velocity_density
    written = learnt["clutter_intensity"].value * learnt["clutter_velocity_density"].value
    assert learnt["clutter_intensity"].value == pytest.approx(max(kappa, kappa_b))
    assert written == pytest.approx(max(kappa * density, kappa_b * density_b))
    assert f"{density:.3g}" in learnt["clutter_velocity_density"].source
