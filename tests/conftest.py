"""Shared fixtures: the synthetic demo dataset, generated once per test session."""

from __future__ import annotations

from pathlib import Path

import pytest


@pytest.fixture(scope="session")
def demo_dataroot(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """Dataroot of the synthetic nuScenes-format demo (``v1.0-mini``, scenes scene-0103 and scene-0916).

    Generated with the default seed into a session temp dir; treat it as read-only.
    """
    from gnnpmb.data.demo import DEMO_SEED, generate_demo_dataset

    return generate_demo_dataset(tmp_path_factory.mktemp("demo") / "nuscenes", seed=DEMO_SEED)


@pytest.fixture(scope="session")
def cv_results(demo_dataroot: Path, tmp_path_factory: pytest.TempPathFactory) -> Path:
    """Another tracker's results on the demo's ``mini_val`` scenes (a tracking submission written by
    ``examples/cv_tracker.py``, a constant-velocity tracker outside the registry, on the centerpoint preset)."""
    from examples.cv_tracker import track_scenes
    from gnnpmb.data.demo import DEMO_SCENES
    from gnnpmb.eval.submission import SUBMISSION_META, write_json

    path = tmp_path_factory.mktemp("cv") / "cv.json"
    results = track_scenes(list(DEMO_SCENES), demo_dataroot, None, "centerpoint")
    write_json(path, {"meta": dict(SUBMISSION_META), "results": results})
    return path


@pytest.fixture(scope="session")
def swept_dataroot(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The demo's scene-0103 built with one LiDAR sweep between keyframes (nuScenes has nine; one keeps the
    tests quick)."""
    from gnnpmb.data import demo

    patch = pytest.MonkeyPatch()
    patch.setattr(demo, "SWEEPS_PER_INTERVAL", 1)
    try:
        return demo.generate_demo_dataset(
            tmp_path_factory.mktemp("swept") / "data", scenes=("scene-0103",), sweeps=True
        )
    finally:
        patch.undo()
