"""The pipeline: one detection argument, scene facts (ground height, clutter hotspots) on the scene."""

from __future__ import annotations

import numpy as np
import pytest

from gnnpmb.config import TrackerConfig
from gnnpmb.data.demo import CLUTTER_HOTSPOTS
from gnnpmb.data.nuscenes import load_scene, resolve_dataroot
from gnnpmb.pipeline import get_detections, preprocess_frames, run_tracker
from gnnpmb.types import TRACKING_CLASSES


@pytest.fixture(scope="module")
def scene(demo_dataroot):
    location = resolve_dataroot(demo_dataroot, "v1.0-mini")
    return load_scene(location, "scene-0103")


def test_the_demo_scene_carries_its_hotspots_and_ground_height(scene):
    assert scene.clutter_hotspots == tuple(h for h in CLUTTER_HOTSPOTS if h.scene_name == "scene-0103")
    assert scene.ground_z_m == float(np.median([k.ego_pose.translation_m[2] for k in scene.keyframes]))


def test_raw_and_preprocessed_detections_give_the_same_run(scene):
    config = TrackerConfig()
    detections = get_detections(scene, None, "megvii", seed=0)
    frames = preprocess_frames(scene, detections, config, TRACKING_CLASSES)
    a = run_tracker(scene, detections, "gnn", config, frame_range=range(0, 8))
    b = run_tracker(scene, frames, "gnn", config, frame_range=range(0, 8))
    assert [f.estimates for f in a.frames] == [f.estimates for f in b.frames]
    with pytest.raises(ValueError, match="preprocessed frames for the"):
        run_tracker(scene, frames[:3], "gnn", config)
