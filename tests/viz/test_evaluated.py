"""``viz.evaluated.devkit_gt``: where the evaluation has each ground-truth object, checked against the devkit's own
tracks (its filters and its interpolation, swapped weights included) on every object and frame of a demo scene."""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np

from gnnpmb.data.nuscenes import open_nuscenes
from gnnpmb.eval.failures import _prepared, _split_with_scene
from gnnpmb.eval.nuscenes_eval import quiet_devkit, scene_sample_tokens, tracking_config
from gnnpmb.session import prepare
from viz.evaluated import devkit_gt

SCENE = "scene-0103"


def devkit_boxes(demo_dataroot: Path) -> dict[tuple[int, str], np.ndarray]:
    """(frame, instance token) -> (2,) centre of every ground-truth box the devkit's tracking evaluation uses."""
    from nuscenes.eval.common.loaders import load_gt_of_sample_tokens
    from nuscenes.eval.tracking.data_classes import TrackingBox
    from nuscenes.eval.tracking.loaders import create_tracks

    request = prepare(SCENE, ["gnnpmb"], dataroot=demo_dataroot)
    nusc = open_nuscenes(request.location)
    tokens = scene_sample_tokens(nusc, SCENE)
    frame_of = {nusc.get("sample", t)["timestamp"]: i for i, t in enumerate(tokens)}
    cfg = tracking_config()  # also registers the tracking class names TrackingBox checks
    with quiet_devkit():
        gt = load_gt_of_sample_tokens(nusc, tokens, TrackingBox, verbose=False)
        tracks = create_tracks(_prepared(nusc, gt, cfg), nusc, _split_with_scene(nusc, SCENE), gt=True)
    (scene_tracks,) = tracks.values()
    return {
        (frame_of[ts], str(b.tracking_id)): np.array(b.translation[:2])
        for ts, boxes in scene_tracks.items()
        for b in boxes
    }


def test_devkit_gt_matches_the_devkits_tracks_on_every_object_and_frame(demo_dataroot: Path) -> None:
    expected = devkit_boxes(demo_dataroot)
    scene = prepare(SCENE, ["gnnpmb"], dataroot=demo_dataroot).scene
    kinds: set[str] = set()
    for keyframe in scene.keyframes:
        for gt_id in keyframe.gt.instance_id.astype(str).tolist():
            box = devkit_gt(scene, gt_id, keyframe.index)
            kinds.add(box.why)
            want = expected.get((keyframe.index, gt_id))
            if want is None:
                assert box.xy_m is None, (keyframe.index, gt_id, box)
            else:
                assert box.xy_m is not None, (keyframe.index, gt_id, box.why)
                np.testing.assert_allclose(box.xy_m, want, atol=1e-6)
    # The scene exercises every case: kept as annotated, interpolated, and dropped.
    assert {"annotated", "interpolated"} <= kinds and len(kinds) > 2
    # A box dropped for its range says how far it was and the class's range, which it exceeds.
    far = [
        re.fullmatch(
            r"it lies ([\d.]+) m from the ego vehicle, beyond the evaluation's (\d+) m range for \w+, and the "
            r"evaluation cannot interpolate it \(it keeps no box of it both before and after this frame\)",
            why,
        )
        for why in kinds
        if why.startswith("it lies")
    ]
    assert far and all(m and float(m.group(1)) >= float(m.group(2)) for m in far)
