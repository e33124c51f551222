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
