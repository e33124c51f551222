from __future__ import annotations

import numpy as np
import pytest

from viz.pointcloud import intensity_colors, prepare_sweep, voxel_downsample


def test_voxel_downsample_averages_points_per_voxel() -> None:
    # Two clusters of 3 points, each inside one 1 m voxel; intensities average too.
    pts = np.array(
        [[0.1, 0.1, 0.1, 10], [0.2, 0.2, 0.2, 20], [0.3, 0.3, 0.3, 30], [5.1, 5.1, 5.1, 0], [5.2, 5.2, 5.2, 0],
         [5.3, 5.3, 5.3, 3]],
        dtype=np.float32,
    )  # fmt: skip
    out = voxel_downsample(pts, 1.0)
    out = out[np.argsort(out[:, 0])]
    np.testing.assert_allclose(out, [[0.2, 0.2, 0.2, 20.0], [5.2, 5.2, 5.2, 1.0]], rtol=1e-5)
    assert out.dtype == np.float32


def test_prepare_sweep_only_downsamples_large_sweeps_and_is_deterministic() -> None:
    rng = np.random.default_rng(3)
    pts = np.concatenate([rng.normal(0, 20, (5000, 3)), rng.uniform(0, 255, (5000, 2))], axis=1)
    small = prepare_sweep(pts, max_points=10_000)
    assert small.shape == (5000, 4)
    np.testing.assert_array_equal(small, pts[:, :4].astype(np.float32))
    down = prepare_sweep(pts, max_points=1000, voxel_m=5.0)
    assert 0 < len(down) < 5000 and down.shape[1] == 4
    np.testing.assert_array_equal(down, prepare_sweep(pts, max_points=1000, voxel_m=5.0))
    with pytest.raises(ValueError, match="positive"):
        voxel_downsample(pts, 0.0)


def test_intensity_colours_are_monotone() -> None:
    c = intensity_colors(np.array([0.0, 10.0, 100.0, 255.0, 1000.0]))
    assert c.dtype == np.uint8 and c.shape == (5, 3)
    assert np.all(np.diff(c[:4].astype(int).sum(axis=1)) > 0)
    np.testing.assert_array_equal(c[3], c[4])
