import dataclasses
from pathlib import Path

import numpy as np
import pytest

from gnnpmb.config import PreprocessParams
from gnnpmb.data.boxes3d import quat_wxyz_from_yaw, yaw_from_quat_wxyz
from gnnpmb.data.detections import load_detection_file, write_detection_file
from gnnpmb.data.preprocess import preprocess
from gnnpmb.data.scene import Keyframe, Pose, SceneData
from gnnpmb.data.simdet import (
    CONFUSABLE,
    PRESETS,
    DetectorPreset,
    scene_ghosts,
    simulate_detections,
    to_submission,
)
from gnnpmb.data.simdet_presets import CLASS_MODELS, VARIANTS
from gnnpmb.errors import UnknownNameError
from gnnpmb.types import TRACKING_CLASSES, Boxes

VARIANTS_RUNS = VARIANTS["runs"]

SIZES = {
    "car": (1.9, 4.5, 1.6),
    "pedestrian": (0.7, 0.7, 1.8),
    "bus": (2.9, 11.0, 3.4),
    "bicycle": (0.6, 1.7, 1.3),
}


def gt_boxes(objects) -> Boxes:
    """objects: (instance_id, class, x, y, yaw, vx, vy) per box."""
    n = len(objects)
    return Boxes(
        translation_m=np.array([(o[2], o[3], 1.0) for o in objects], dtype=float).reshape(n, 3),
        size_wlh_m=np.array([SIZES[o[1]] for o in objects], dtype=float).reshape(n, 3),
        quat_wxyz=quat_wxyz_from_yaw(np.array([o[4] for o in objects], dtype=float)).reshape(n, 4),
        velocity_mps=np.array([(o[5], o[6]) for o in objects], dtype=float).reshape(n, 2),
        score=np.ones(n),
        class_name=np.array([o[1] for o in objects], dtype=object),
        instance_id=np.array([o[0] for o in objects], dtype=object),
    )


def make_scene(frames, num_pts=None, token="scene-token-a", ego_xy=(100.0, 200.0)) -> SceneData:
    """frames: per keyframe, a list of objects as in ``gt_boxes``, positions relative to the ego."""
    keyframes = []
    for k, objects in enumerate(frames):
        shifted = [(o[0], o[1], o[2] + ego_xy[0], o[3] + ego_xy[1], *o[4:]) for o in objects]
        pts = np.full(len(objects), 200) if num_pts is None else np.asarray(num_pts[k])
        keyframes.append(
            Keyframe(
                index=k,
                sample_token=f"{token}-sample-{k}",
                timestamp_us=1_000_000 + 500_000 * k,
                ego_pose=Pose(np.array([ego_xy[0], ego_xy[1], 0.0]), np.array([1.0, 0.0, 0.0, 0.0])),
                lidar_calib=Pose(np.array([0.9, 0.0, 1.8]), np.array([1.0, 0.0, 0.0, 0.0])),
                lidar_path=Path(f"/nonexistent/{token}-{k}.pcd.bin"),
                gt=gt_boxes(shifted),
                gt_num_pts=pts,
            )
        )
    return SceneData(
        name="scene-test",
        token=token,
        description="hand-built test scene",
        dataroot=Path("/nonexistent"),
        version="v1.0-mini",
        synthetic=True,
        keyframes=tuple(keyframes),
    )


def street(n_frames: int = 6):
    objects = [
        ("car-1", "car", 8.0, 3.0, 0.2, 5.0, 1.0),
        ("car-2", "car", -15.0, -4.0, 3.0, 0.0, 0.0),
        ("ped-1", "pedestrian", 5.0, -6.0, 1.0, 1.0, 0.5),
        ("bus-1", "bus", 25.0, 10.0, 0.0, 3.0, 0.0),
        ("bike-1", "bicycle", -6.0, 12.0, -1.0, 2.0, 2.0),
    ]
    return [list(objects) for _ in range(n_frames)]


def quiet(preset: str = "centerpoint", **changes) -> DetectorPreset:
    """A preset without false positives (random or persistent) and duplicates, for tests of the true detections."""
    return dataclasses.replace(PRESETS[preset], **{"fp_rate": 0.0, "dup_prob": 0.0, "ghost_rate": 0.0, **changes})


def assert_boxes_equal(a: Boxes, b: Boxes) -> None:
    for field in dataclasses.fields(Boxes):
        np.testing.assert_array_equal(getattr(a, field.name), getattr(b, field.name))


def nearest_detection(dets: Boxes, xy: np.ndarray, max_dist: float) -> int | None:
    if not len(dets):
        return None
    d = np.hypot(*(dets.xy - xy).T)
    k = int(np.argmin(d))
    return k if d[k] <= max_dist else None


def test_output_shape_and_conventions():
    scene = make_scene(street())
    dets = simulate_detections(scene, "centerpoint", seed=1)
    assert list(dets) == list(scene.sample_tokens)
    for boxes in dets.values():
        assert len(boxes) > 5
        assert set(boxes.class_name) <= set(TRACKING_CLASSES)
        assert set(boxes.instance_id) == {""}
        assert np.all(np.diff(boxes.score) <= 0)  # sorted by score, highest first
        assert np.all((boxes.score > 0) & (boxes.score < 1))
        np.testing.assert_allclose(np.linalg.norm(boxes.quat_wxyz, axis=1), 1.0)
        assert np.all(boxes.size_wlh_m > 0)
        assert np.all(np.isfinite(boxes.translation_m)) and np.all(np.isfinite(boxes.velocity_mps))


def test_same_seed_same_output_other_seed_differs():
    scene = make_scene(street())
    a = simulate_detections(scene, "megvii", seed=3)
    b = simulate_detections(scene, "megvii", seed=3)
    c = simulate_detections(scene, "megvii", seed=4)
    for token in scene.sample_tokens:
        assert_boxes_equal(a[token], b[token])
    assert any(
        len(a[t]) != len(c[t]) or not np.array_equal(a[t].translation_m, c[t].translation_m)
        for t in scene.sample_tokens
    )


def test_frames_are_independent_of_each_other():
    frames = street(3)
    changed = [list(f) for f in frames]
    changed[1] = changed[1][:2] + [("truck-9", "car", 30.0, -20.0, 0.0, 0.0, 0.0)]
    a = simulate_detections(make_scene(frames), "pointpillars", seed=5)
    b = simulate_detections(make_scene(changed), "pointpillars", seed=5)
    tokens = make_scene(frames).sample_tokens
    assert_boxes_equal(a[tokens[0]], b[tokens[0]])
    assert_boxes_equal(a[tokens[2]], b[tokens[2]])
    assert len(a[tokens[1]]) != len(b[tokens[1]]) or not np.array_equal(
        a[tokens[1]].translation_m, b[tokens[1]].translation_m
    )


def test_unknown_preset_lists_the_presets():
    with pytest.raises(UnknownNameError, match="centerpoint, megvii, pointpillars"):
        simulate_detections(make_scene(street(1)), "second")


def detection_rate(preset: DetectorPreset, x: float, num_pts: int, class_name: str = "car", n: int = 400) -> float:
    frames = [[("obj", class_name, x, 0.0, 0.0, 0.0, 0.0)] for _ in range(n)]
    dets = simulate_detections(make_scene(frames, num_pts=[[num_pts]] * n), preset, seed=0)
    return float(np.mean([len(b) for b in dets.values()]))


def test_detection_probability_falls_with_distance_and_occlusion():
    p = quiet()
    near = detection_rate(p, 10.0, 200)
    far = detection_rate(p, 70.0, 200)
    few_points = detection_rate(p, 10.0, 2)
    no_points = detection_rate(p, 10.0, 0)
    assert near > 0.9
    assert far < 0.5 * near
    assert no_points < 0.05 < few_points < near
    assert detection_rate(p, 10.0, 200, class_name="bicycle") < near


def test_presets_are_ordered_by_quality():
    frames = [[("car-1", "car", 30.0, 5.0, 0.0, 0.0, 0.0), ("ped-1", "pedestrian", -25.0, 3.0, 0.0, 0.0, 0.0)]] * 150
    scene = make_scene(frames, num_pts=[[30, 8]] * 150)
    recall, error, separation = {}, {}, {}
    for name in PRESETS:
        dets = simulate_detections(scene, quiet(name), seed=2)
        hits, errs = 0, []
        for kf in scene.keyframes:
            for xy in kf.gt.xy:
                k = nearest_detection(dets[kf.sample_token], xy, 3.0)
                if k is not None:
                    hits += 1
                    errs.append(np.hypot(*(dets[kf.sample_token].xy[k] - xy)))
        recall[name] = hits / (2 * len(frames))
        error[name] = float(np.mean(errs))
        full = simulate_detections(make_scene([[]] * 150), name, seed=2)
        fp_scores = np.concatenate([b.score for b in full.values()])
        tp_scores = np.concatenate([b.score for b in dets.values()])
        separation[name] = tp_scores.mean() - fp_scores.mean()
    # Recall is not ordered: each preset's recall is fitted together with its noise and clutter to the
    # published mAP of its detector (benchmarks/detector_calibration.py).
    assert min(recall.values()) > 0.7
    assert error["centerpoint"] < error["megvii"] < error["pointpillars"]
    assert separation["centerpoint"] > separation["megvii"] > separation["pointpillars"] > 0.2


def test_position_offset_persists_per_instance():
    p = quiet(pos_noise_std_m=0.0, recall_near=1.0, range_p50_m=1e6)
    frames = [[("car-a", "car", 5.0, 0.0, 0.0, 0.0, 0.0), ("car-b", "car", -5.0, 0.0, 0.0, 0.0, 0.0)]] * 8
    scene = make_scene(frames)
    dets = simulate_detections(scene, p, seed=9)
    offsets = {"car-a": [], "car-b": []}
    for kf in scene.keyframes:
        boxes = dets[kf.sample_token]
        for inst, xy in zip(kf.gt.instance_id, kf.gt.xy, strict=True):
            k = nearest_detection(boxes, xy, 1.0)
            if k is not None:
                offsets[inst].append(boxes.xy[k] - xy)
    a, b = np.array(offsets["car-a"]), np.array(offsets["car-b"])
    assert len(a) >= 6 and len(b) >= 6
    np.testing.assert_allclose(a, np.broadcast_to(a[0], a.shape), atol=1e-9)
    np.testing.assert_allclose(b, np.broadcast_to(b[0], b.shape), atol=1e-9)
    assert np.hypot(*(a[0] - b[0])) > 1e-3 and np.hypot(*a[0]) > 1e-3


def test_velocity_is_truth_plus_noise_and_nan_safe():
    frames = [[("car-1", "car", 10.0, 0.0, 0.0, 4.0, -2.0), ("car-2", "car", -10.0, 0.0, 0.0, np.nan, np.nan)]]
    scene = make_scene(frames * 20)
    exact = simulate_detections(scene, quiet(vel_noise_std_mps=0.0), seed=1)
    noisy = simulate_detections(scene, quiet(), seed=1)
    moving = []
    for kf in scene.keyframes:
        for boxes in (exact[kf.sample_token], noisy[kf.sample_token]):
            assert np.all(np.isfinite(boxes.velocity_mps))
        k = nearest_detection(exact[kf.sample_token], kf.gt.xy[0], 2.0)
        if k is not None:
            np.testing.assert_allclose(exact[kf.sample_token].velocity_mps[k], [4.0, -2.0])
        k = nearest_detection(noisy[kf.sample_token], kf.gt.xy[0], 2.0)
        if k is not None:
            moving.append(noisy[kf.sample_token].velocity_mps[k])
    moving = np.array(moving)
    assert len(moving) > 10
    assert not np.allclose(moving, [4.0, -2.0])
    np.testing.assert_allclose(moving.mean(axis=0), [4.0, -2.0], atol=0.3)


def test_duplicates_are_removed_by_nms():
    p = quiet(dup_prob=1.0, recall_near=1.0)
    frames = [[("car-1", "car", 8.0, 3.0, 0.2, 0.0, 0.0), ("bus-1", "bus", 25.0, 10.0, 0.0, 0.0, 0.0)]] * 10
    scene = make_scene(frames)
    dets = simulate_detections(scene, p, seed=4)
    for kf in scene.keyframes:
        boxes = dets[kf.sample_token]
        assert len(boxes) % 2 == 0 and len(boxes) > 0
        frame = preprocess(boxes, PreprocessParams(score_threshold=0.0, nms_iou_3d=0.1))
        assert frame.kept.sum() == len(boxes) // 2
        assert frame.suppressed_by_nms.sum() == len(boxes) // 2


def test_false_positives_within_range_with_lower_scores():
    p = PRESETS["centerpoint"]
    scene = make_scene([[]] * 100)
    dets = simulate_detections(scene, "centerpoint", seed=6)
    counts = np.array([len(b) for b in dets.values()])
    assert abs(counts.mean() - p.fp_rate) < 3.0
    all_fp = Boxes.concatenate(list(dets.values()))
    ego = scene.keyframes[0].ego_pose.translation_m[:2]
    assert np.all(np.hypot(*(all_fp.xy - ego).T) <= p.fp_range_m + 1e-9)
    names, counts_by_class = np.unique(all_fp.class_name.astype(str), return_counts=True)
    by_class = dict(zip(names, counts_by_class, strict=True))
    assert by_class["car"] > by_class["bus"] and by_class["pedestrian"] > by_class["trailer"]
    assert np.mean(all_fp.score) < 0.3


def test_hotspot_clutter_near_bus_looks_like_a_large_vehicle():
    p = quiet(hotspot_rate=4.0)
    hotspot_xy = np.array([100.0 + 25.0, 200.0 + 14.0])
    far_hotspot = np.array([100.0 + 500.0, 200.0])
    frames = [[("bus-1", "bus", 25.0, 10.0, 0.0, 0.0, 0.0)]] * 40
    scene = make_scene(frames)
    plain = simulate_detections(scene, p, seed=8)
    cluttered = simulate_detections(scene, p, seed=8, hotspots=[(hotspot_xy, 3.0), (far_hotspot, 5.0)])
    extra = []
    for kf in scene.keyframes:
        boxes, before = cluttered[kf.sample_token], plain[kf.sample_token]
        in_spot = np.hypot(*(boxes.xy - hotspot_xy).T) <= 3.0 + 1e-9
        assert not np.any(np.hypot(*(before.xy - hotspot_xy).T) <= 3.0)
        assert len(boxes) - len(before) == in_spot.sum()  # all extra boxes are at the near hotspot
        extra.append(boxes.subset(in_spot))
    ghosts = Boxes.concatenate(extra)
    assert 100 < len(ghosts) < 220
    assert set(ghosts.class_name) <= set(CONFUSABLE["bus"])
    assert np.mean(ghosts.class_name == "bus") > 0.5

    # A spot limited to some keyframes adds clutter only there.
    timed = simulate_detections(scene, p, seed=8, hotspots=[(hotspot_xy, 3.0, (2, 5))])
    changed = [k for k, t in enumerate(scene.sample_tokens) if len(timed[t]) != len(plain[t])]
    assert set(changed) <= {2, 5} and changed


def test_confused_class_keeps_the_true_objects_box():
    exact = {"pos_noise_std_m": 0.0, "pos_bias_std_m": 0.0, "size_noise_rel": 0.0}
    p = quiet(confusion_scale=5.0, recall_near=1.0, class_recall=dict.fromkeys(TRACKING_CLASSES, 1.0), **exact)
    frames = [[("bike-1", "bicycle", 6.0, 2.0, 0.3, 1.0, 0.0), ("ped-1", "pedestrian", -5.0, 1.0, 0.0, 0.0, 0.0)]] * 60
    scene = make_scene(frames)
    dets = simulate_detections(scene, p, seed=3)
    labels = []
    for kf in scene.keyframes:
        boxes = dets[kf.sample_token]
        for k in range(len(kf.gt)):
            j = nearest_detection(boxes, kf.gt.xy[k], 1e-6)
            if j is None:
                continue
            np.testing.assert_allclose(boxes.size_wlh_m[j], kf.gt.size_wlh_m[k])
            labels.append((str(kf.gt.class_name[k]), str(boxes.class_name[j])))
    bike = [reported for true, reported in labels if true == "bicycle"]
    expected = 5.0 * CLASS_MODELS["bicycle"].confusion_prob
    assert len(bike) > 40 and set(bike) == {"bicycle", "motorcycle"}
    assert abs(np.mean(np.array(bike) == "motorcycle") - expected) < 0.2
    assert {reported for true, reported in labels if true == "pedestrian"} == {"pedestrian"}


def test_persistent_false_positives_stay_at_fixed_places_with_stable_scores():
    p = quiet(ghost_rate=3.0, ghost_presence=0.8)
    scene = make_scene([[]] * 12)
    ghosts = scene_ghosts(scene, p, seed=5)
    dets = simulate_detections(scene, p, seed=5)
    ego = scene.keyframes[0].ego_pose.translation_m[:2]
    in_range = np.flatnonzero(np.hypot(*(ghosts.xy_global - ego).T) <= p.fp_range_m)
    assert len(in_range) >= 1
    for g in in_range:
        seen = [nearest_detection(dets[t], ghosts.xy_global[g], 0.5) for t in scene.sample_tokens]
        hits = [k for k, j in enumerate(seen) if j is not None]
        assert len(hits) >= 6  # present in most frames, at the same place
        assert any(b - a == 1 for a, b in zip(hits, hits[1:], strict=False))  # in consecutive frames
        scores = [dets[scene.sample_tokens[k]].score[seen[k]] for k in hits]
        assert np.std(scores) < 0.06 and abs(np.mean(scores) - ghosts.score[g]) < 0.05
        assert {str(dets[scene.sample_tokens[k]].class_name[seen[k]]) for k in hits} == {str(ghosts.class_name[g])}
    # Every reported box is a ghost within range; other seeds put the ghosts elsewhere.
    for token in scene.sample_tokens:
        d = np.hypot(*(dets[token].xy[:, None, :] - ghosts.xy_global[None, in_range, :]).transpose(2, 0, 1))
        assert np.all(d.min(axis=1) < 0.6)
    other = scene_ghosts(scene, p, seed=6)
    assert len(other) != len(ghosts) or not np.allclose(other.xy_global, ghosts.xy_global)


def test_heading_flips_are_rarer_for_cars_than_for_bicycles():
    p = quiet(yaw_noise_std_rad=0.0, yaw_flip_prob=0.02, recall_near=1.0, confusion_scale=0.0)
    frames = [[("car-1", "car", 8.0, 0.0, 0.4, 0.0, 0.0), ("bike-1", "bicycle", -6.0, 3.0, 0.4, 0.0, 0.0)]] * 300
    dets = simulate_detections(make_scene(frames), p, seed=2)
    flipped: dict[str, list[bool]] = {"car": [], "bicycle": []}
    for boxes in dets.values():
        for k in range(len(boxes)):
            yaw = float(yaw_from_quat_wxyz(boxes.quat_wxyz[k : k + 1])[0])
            flipped[str(boxes.class_name[k])].append(abs(np.angle(np.exp(1j * (yaw - 0.4)))) > 3.0)
    expected = {c: 0.02 * CLASS_MODELS[c].flip_scale for c in flipped}
    assert len(flipped["car"]) > 250 and len(flipped["bicycle"]) > 50
    assert np.mean(flipped["car"]) < 0.06 < np.mean(flipped["bicycle"])
    assert abs(np.mean(flipped["bicycle"]) - expected["bicycle"]) < 0.1


def test_some_false_positive_scores_overlap_true_ones():
    p = dataclasses.replace(PRESETS["pointpillars"], ghost_rate=0.0, fp_high_score_frac=0.1)
    dets = simulate_detections(make_scene([[]] * 40), p, seed=1)
    fp_scores = np.concatenate([b.score for b in dets.values()])
    assert np.mean(fp_scores > 0.5) > 0.03
    assert np.median(fp_scores) < 0.25


def test_to_submission_format():
    scene = make_scene(street(2))
    dets = simulate_detections(scene, "centerpoint", seed=0)
    sub = to_submission(dets)
    assert sub["meta"]["use_lidar"] is True and sub["meta"]["use_camera"] is False
    assert list(sub["results"]) == list(scene.sample_tokens)
    token = scene.sample_tokens[0]
    entries = sub["results"][token]
    assert len(entries) == len(dets[token])
    fields = {
        "sample_token",
        "translation",
        "size",
        "rotation",
        "velocity",
        "detection_name",
        "detection_score",
        "attribute_name",
    }
    attrs = {
        "vehicle.moving",
        "vehicle.parked",
        "pedestrian.moving",
        "pedestrian.standing",
        "cycle.with_rider",
        "cycle.without_rider",
    }
    for e in entries:
        assert set(e) == fields and e["sample_token"] == token
        assert (len(e["translation"]), len(e["size"]), len(e["rotation"]), len(e["velocity"])) == (3, 3, 4, 2)
        assert all(type(v) is float for v in e["translation"] + e["size"] + e["rotation"] + e["velocity"])
        assert isinstance(e["detection_score"], float) and e["attribute_name"] in attrs
    np.testing.assert_allclose([e["detection_score"] for e in entries], dets[token].score)


def test_submission_round_trips_through_the_loader(tmp_path):
    scene = make_scene(street(3))
    dets = simulate_detections(scene, "pointpillars", seed=12)
    path = tmp_path / "sim.json"
    write_detection_file(path, to_submission(dets))
    loaded = load_detection_file(path, scene.sample_tokens)
    for token in scene.sample_tokens:
        for field in ("translation_m", "size_wlh_m", "quat_wxyz", "velocity_mps", "score"):
            np.testing.assert_allclose(getattr(loaded[token], field), getattr(dets[token], field), rtol=1e-15)
        np.testing.assert_array_equal(loaded[token].class_name, dets[token].class_name)


def test_variant_names_and_realism_off_leaves_the_preset_unchanged():
    from gnnpmb.data.simdet_presets import get_preset

    assert get_preset("megvii+runs").realism == VARIANTS["runs"] and get_preset("megvii").realism.near_fp_prob == 0
    with pytest.raises(UnknownNameError, match=r"\+runs"):
        get_preset("megvii+sunny")
    scene = make_scene(street())
    off = dataclasses.replace(PRESETS["pointpillars"], realism=dataclasses.replace(VARIANTS["real"], **OFF))
    a, b = simulate_detections(scene, "pointpillars", seed=2), simulate_detections(scene, off, seed=2)
    for token in scene.sample_tokens:
        assert_boxes_equal(a[token], b[token])


OFF = {"hardness_std_logit": 0.0, "score_hardness": 0.0, "near_fp_prob": 0.0, "velocity_outlier_prob": 0.0}


def test_hardness_makes_misses_come_in_runs():
    """With the latent hardness, a missed object is missed again next frame more often than its miss rate."""
    objects = [(f"car-{i}", "car", 5.0 + 3 * (i % 10), -20.0 + 4 * (i // 10), 0.0, 0.0, 0.0) for i in range(40)]
    frames = [list(objects) for _ in range(40)]
    scene = make_scene(frames, num_pts=[np.full(40, 10)] * 40)  # few points: some misses
    runs = dataclasses.replace(quiet("pointpillars"), realism=dataclasses.replace(VARIANTS_RUNS, score_hardness=0.0))
    hits = []
    for preset in (quiet("pointpillars"), runs):
        dets = simulate_detections(scene, preset, seed=7)
        seen = np.array(
            [
                [nearest_detection(dets[k.sample_token], k.gt.xy[i], 0.8) is not None for i in range(40)]
                for k in scene.keyframes
            ]
        )
        miss = ~seen
        hits.append((miss[1:] & miss[:-1]).sum() / max(miss[:-1].sum(), 1) / max(miss.mean(), 1e-9))
    assert hits[1] > 1.5 * hits[0]


def test_near_object_false_boxes_sit_beside_objects():
    scene = make_scene(street(20))
    near = dataclasses.replace(quiet(), realism=dataclasses.replace(VARIANTS_RUNS, **{**OFF, "near_fp_prob": 1.0}))
    dets = simulate_detections(scene, near, seed=1)
    first = dets[scene.sample_tokens[0]]
    assert len(first) >= 2 * len(scene.keyframes[0].gt) - 1
