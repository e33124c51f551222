"""The synthetic demo: accepted by the unmodified devkit and its tracking eval, consistent, physical, deterministic."""

from __future__ import annotations

import hashlib
import json
import re
import shutil
from collections import defaultdict
from pathlib import Path

import numpy as np
import pytest
from nuscenes.eval.tracking.utils import category_to_tracking_name
from nuscenes.nuscenes import NuScenes
from nuscenes.utils.data_classes import LidarPointCloud
from nuscenes.utils.geometry_utils import points_in_box
from pyquaternion import Quaternion
from shapely.geometry import Polygon

from gnnpmb.cache_folder import CACHE_ENV
from gnnpmb.data import demo
from gnnpmb.data.demo import (
    CLUTTER_HOTSPOTS,
    DEMO_SCENES,
    DEMO_SEED,
    DEMO_VERSION,
    KEYFRAME_INTERVAL_US,
    SYNTHETIC_MARKER,
    ensure_demo_dataset,
    generate_demo_dataset,
)
from gnnpmb.data.demo_staged import STAGED_SCENES
from gnnpmb.errors import DataError
from gnnpmb.types import TRACKING_CLASSES

EGO_SIZE_WL_M = (1.73, 4.08)


@pytest.fixture(scope="module")
def nusc(demo_dataroot: Path) -> NuScenes:
    return NuScenes(version=DEMO_VERSION, dataroot=str(demo_dataroot), verbose=False)


def _scene_samples(nusc: NuScenes, scene_name: str) -> list[dict]:
    scene = next(s for s in nusc.scene if s["name"] == scene_name)
    samples, token = [], scene["first_sample_token"]
    while token:
        samples.append(nusc.get("sample", token))
        token = samples[-1]["next"]
    return samples


def _tracks(nusc: NuScenes, scene_name: str) -> dict[str, dict[int, dict]]:
    """instance token -> {keyframe index: annotation}."""
    tracks: dict[str, dict[int, dict]] = defaultdict(dict)
    for k, sample in enumerate(_scene_samples(nusc, scene_name)):
        for ann_token in sample["anns"]:
            ann = nusc.get("sample_annotation", ann_token)
            tracks[ann["instance_token"]][k] = ann
    return tracks


def _footprint(xy: np.ndarray, wl: tuple[float, float], yaw: float) -> Polygon:
    c, s = np.cos(yaw), np.sin(yaw)
    half_w, half_l = 0.5 * wl[0], 0.5 * wl[1]
    local = np.array([[half_l, half_w], [-half_l, half_w], [-half_l, -half_w], [half_l, -half_w]])
    return Polygon(xy + local @ np.array([[c, s], [-s, c]]))


def _yaw(quat_wxyz: list[float]) -> float:
    return Quaternion(quat_wxyz).yaw_pitch_roll[0]


def test_scenes_and_descriptions(nusc: NuScenes) -> None:
    assert sorted(s["name"] for s in nusc.scene) == sorted(DEMO_SCENES + STAGED_SCENES)
    for scene in nusc.scene:
        assert scene["description"].startswith(SYNTHETIC_MARKER)
        samples = _scene_samples(nusc, scene["name"])
        assert len(samples) == scene["nbr_samples"] == 40
        assert samples[0]["token"] == scene["first_sample_token"]
        assert samples[-1]["token"] == scene["last_sample_token"]
        assert np.all(np.diff([s["timestamp"] for s in samples]) == KEYFRAME_INTERVAL_US)
        assert all(s["scene_token"] == scene["token"] for s in samples)


def test_tokens_are_unique_32_hex(nusc: NuScenes) -> None:
    for table in nusc.table_names:
        tokens = [r["token"] for r in getattr(nusc, table)]
        assert len(set(tokens)) == len(tokens), table
        if table != "visibility":  # the devkit's visibility tokens are "1".."4"
            assert all(re.fullmatch(r"[0-9a-f]{32}", t) for t in tokens), table


def test_chains_and_instances_consistent(nusc: NuScenes) -> None:
    for table in ("sample", "sample_data", "sample_annotation"):
        for row in getattr(nusc, table):
            if row["next"]:
                assert nusc.get(table, row["next"])["prev"] == row["token"]
            if row["prev"]:
                assert nusc.get(table, row["prev"])["next"] == row["token"]
    for inst in nusc.instance:
        chain, token = [], inst["first_annotation_token"]
        while token:
            ann = nusc.get("sample_annotation", token)
            assert ann["instance_token"] == inst["token"]
            chain.append(ann)
            token = ann["next"]
        assert len(chain) == inst["nbr_annotations"]
        assert chain[-1]["token"] == inst["last_annotation_token"]
        times = [nusc.get("sample", a["sample_token"])["timestamp"] for a in chain]
        assert np.all(np.diff(times) == KEYFRAME_INTERVAL_US), "annotations must be on consecutive keyframes"
    n_by_instance = defaultdict(int)
    for ann in nusc.sample_annotation:
        n_by_instance[ann["instance_token"]] += 1
        assert len(ann["attribute_tokens"]) <= 1
        for tok in ann["attribute_tokens"]:
            nusc.get("attribute", tok)
        nusc.get("visibility", ann["visibility_token"])
    assert all(n_by_instance[i["token"]] == i["nbr_annotations"] for i in nusc.instance)


def test_every_tracking_class_with_plausible_sizes(nusc: NuScenes) -> None:
    sizes = defaultdict(list)
    for ann in nusc.sample_annotation:
        name = category_to_tracking_name(ann["category_name"])
        if name is not None:
            sizes[name].append(ann["size"])
    assert sorted(sizes) == sorted(TRACKING_CLASSES)
    longest = {"car": (3.5, 5.5), "truck": (5.0, 10.0), "bus": (9.0, 14.0), "trailer": (6.0, 14.0)}
    for name, (lo, hi) in longest.items():
        lengths = np.array(sizes[name])[:, 1]
        assert np.all((lengths >= lo) & (lengths <= hi)), name
    peds = np.array(sizes["pedestrian"])
    assert np.all((peds[:, 2] > 1.0) & (peds[:, 2] < 2.0))


def test_get_sample_data_returns_boxes_in_the_sensor_frame(nusc: NuScenes) -> None:
    sample = _scene_samples(nusc, "scene-0916")[20]
    path, boxes, _ = nusc.get_sample_data(sample["data"]["LIDAR_TOP"])
    assert Path(path).is_file()
    assert len(boxes) == len(sample["anns"]) > 10
    # The sensor sits 1.84 m above the ground, so every box's bottom is at z = -1.84 in the sensor frame.
    bottoms = np.array([b.center[2] - 0.5 * b.wlh[2] for b in boxes])
    assert np.allclose(bottoms, -1.84023, atol=1e-6)


def test_lidar_files_and_num_lidar_pts_match_points_in_box(nusc: NuScenes) -> None:
    checked = 0
    for scene_name in DEMO_SCENES:
        samples = _scene_samples(nusc, scene_name)
        for k in (0, 17, 39):
            sweep = nusc.get("sample_data", samples[k]["data"]["LIDAR_TOP"])
            raw = np.fromfile(nusc.get_sample_data_path(sweep["token"]), dtype=np.float32)
            assert raw.size % 5 == 0
            raw = raw.reshape(-1, 5)
            assert 20_000 < raw.shape[0] < 60_000
            assert np.all(np.isfinite(raw))
            assert set(np.unique(raw[:, 4])) <= set(range(32))
            assert np.all(np.linalg.norm(raw[:, :3], axis=1) <= 70.1)
            pc = LidarPointCloud.from_file(nusc.get_sample_data_path(sweep["token"]))
            calib = nusc.get("calibrated_sensor", sweep["calibrated_sensor_token"])
            pose = nusc.get("ego_pose", sweep["ego_pose_token"])
            pc.rotate(Quaternion(calib["rotation"]).rotation_matrix)
            pc.translate(np.array(calib["translation"]))
            pc.rotate(Quaternion(pose["rotation"]).rotation_matrix)
            pc.translate(np.array(pose["translation"]))
            on_ground = np.abs(pc.points[2]) < 0.05
            assert on_ground.mean() > 0.3 and pc.points[2].min() > -0.05, "the ground plane is z = 0 (global)"
            for ann_token in samples[k]["anns"]:
                ann = nusc.get("sample_annotation", ann_token)
                inside = int(points_in_box(nusc.get_box(ann_token), pc.points[:3]).sum())
                assert inside == ann["num_lidar_pts"], ann["category_name"]
                checked += 1
    assert checked > 80


def test_boxes_stand_on_the_ground_and_do_not_overlap(nusc: NuScenes) -> None:
    for scene_name in DEMO_SCENES:
        for sample in _scene_samples(nusc, scene_name):
            anns = [nusc.get("sample_annotation", t) for t in sample["anns"]]
            for ann in anns:
                assert ann["translation"][2] == pytest.approx(0.5 * ann["size"][2])
            pose = nusc.get("ego_pose", nusc.get("sample_data", sample["data"]["LIDAR_TOP"])["ego_pose_token"])
            shapes = [
                _footprint(np.array(a["translation"][:2]), (a["size"][0], a["size"][1]), _yaw(a["rotation"]))
                for a in anns
            ]
            shapes.append(_footprint(np.array(pose["translation"][:2]), EGO_SIZE_WL_M, _yaw(pose["rotation"])))
            for i in range(len(shapes)):
                for j in range(i + 1, len(shapes)):
                    assert shapes[i].intersection(shapes[j]).area < 1e-6, (scene_name, i, j)


def test_failure_situations_are_present(nusc: NuScenes, demo_dataroot: Path) -> None:
    tracks = {name: _tracks(nusc, name) for name in DEMO_SCENES}

    # Coalescence: a row of parked cars 0.5-1 m apart.
    parked = [
        next(iter(t.values()))
        for t in tracks["scene-0103"].values()
        if next(iter(t.values()))["category_name"] == "vehicle.car"
        and nusc.get("attribute", next(iter(t.values()))["attribute_tokens"][0])["name"] == "vehicle.parked"
    ]
    heading = next(spec for spec in demo.SCENES if spec.name == "scene-0103").road_heading_rad
    parked.sort(key=lambda a: np.dot(a["translation"][:2], [np.cos(heading), np.sin(heading)]))
    assert len(parked) >= 6
    gaps = [
        np.linalg.norm(np.subtract(b["translation"][:2], a["translation"][:2])) - 0.5 * (a["size"][1] + b["size"][1])
        for a, b in zip(parked, parked[1:], strict=False)
    ]
    assert all(0.45 <= g <= 1.05 for g in gaps), gaps

    # Occlusion: some tracked object within 40 m has points, then none for 2-8 keyframes, then points again.
    def hidden_runs(track: dict[int, dict], ego_xy: np.ndarray) -> list[int]:
        seen = [
            (k, a["num_lidar_pts"] > 0)
            for k, a in sorted(track.items())
            if np.linalg.norm(np.subtract(a["translation"][:2], ego_xy[k])) < 40.0
        ]
        runs, run, started = [], 0, False
        for _, visible in seen:
            if visible:
                if started and run:
                    runs.append(run)
                started, run = True, 0
            elif started:
                run += 1
        return runs

    occluded = 0
    for name in DEMO_SCENES:
        ego_xy = np.array(
            [
                nusc.get("ego_pose", nusc.get("sample_data", s["data"]["LIDAR_TOP"])["ego_pose_token"])["translation"][
                    :2
                ]
                for s in _scene_samples(nusc, name)
            ]
        )
        for track in tracks[name].values():
            if category_to_tracking_name(next(iter(track.values()))["category_name"]) is not None:
                occluded += any(2 <= r <= 8 for r in hidden_runs(track, ego_xy))
    assert occluded >= 3

    # Pedestrians crossing each other: two pedestrian tracks come within 1.5 m of each other.
    closest = np.inf
    for name in DEMO_SCENES:
        peds = [t for t in tracks[name].values() if next(iter(t.values()))["category_name"].startswith("human")]
        for i, a in enumerate(peds):
            for b in peds[i + 1 :]:
                for k in set(a) & set(b):
                    closest = min(
                        closest, np.linalg.norm(np.subtract(a[k]["translation"][:2], b[k]["translation"][:2]))
                    )
    assert closest < 1.5

    # The bus passes within a few metres of the clutter hotspot during the hotspot's frames.
    (hotspot,) = [h for h in CLUTTER_HOTSPOTS if h.scene_name in DEMO_SCENES]
    assert hotspot.scene_name in DEMO_SCENES and len(hotspot.frames) >= 3
    bus = next(
        t for t in tracks[hotspot.scene_name].values() if next(iter(t.values()))["category_name"] == "vehicle.bus.rigid"
    )
    distances = [np.linalg.norm(np.subtract(bus[k]["translation"][:2], hotspot.xy_global)) for k in hotspot.frames]
    assert min(distances) < 4.0
    assert all(k in bus and bus[k]["num_lidar_pts"] > 0 for k in hotspot.frames)


def _hashes(root: Path) -> dict[str, str]:
    return {
        str(p.relative_to(root)): hashlib.sha256(p.read_bytes()).hexdigest()
        for p in sorted(root.rglob("*"))
        if p.is_file()
    }


def test_same_seed_gives_byte_identical_files(demo_dataroot: Path, tmp_path: Path) -> None:
    again = generate_demo_dataset(tmp_path / "again", seed=DEMO_SEED)
    ours, shared = _hashes(again), _hashes(demo_dataroot)
    # camera images are rendered when a scene is first shown: the shared dataset may hold some the new one lacks
    rendered = {k for k in shared.keys() - ours.keys() if k.startswith("samples/CAM_")}
    assert {k: v for k, v in shared.items() if k not in rendered} == ours
    json.loads((again / demo.MARKER_FILE).read_text())


def test_refuses_a_foreign_folder_and_regenerates_a_demo(demo_dataroot: Path, tmp_path: Path) -> None:
    foreign = tmp_path / "mine"
    foreign.mkdir()
    (foreign / "notes.txt").write_text("keep me")
    with pytest.raises(DataError, match="not empty and not a gnnpmb-viz demo"):
        generate_demo_dataset(foreign)
    assert (foreign / "notes.txt").read_text() == "keep me"
    assert not [p for p in tmp_path.iterdir() if p.name.startswith(".")], "no temp folder may be left behind"

    target = tmp_path / "demo"
    shutil.copytree(demo_dataroot, target)
    stale = target / "samples" / "LIDAR_TOP" / "stale.pcd.bin"
    stale.write_bytes(b"")
    assert generate_demo_dataset(target) == target.absolute()
    assert not stale.exists()
    assert not [p for p in tmp_path.iterdir() if p.name.startswith(".")]


def test_ensure_demo_dataset_generates_once_into_the_cache(
    demo_dataroot: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setenv(CACHE_ENV, str(tmp_path / "cache"))
    expected = tmp_path / "cache" / f"demo-v{demo.GENERATOR_VERSION}"
    shutil.copytree(demo_dataroot, expected)

    def no_generation(*args: object, **kwargs: object) -> Path:
        raise AssertionError("the cached demo should have been reused")

    monkeypatch.setattr(demo, "generate_demo_dataset", no_generation)
    assert ensure_demo_dataset() == expected

    (expected / demo.MARKER_FILE).unlink()  # an incomplete or foreign-looking cache is rebuilt
    calls: list[Path] = []
    monkeypatch.setattr(demo, "generate_demo_dataset", lambda out, seed, scenes, sweeps=False: calls.append(out) or out)
    ensure_demo_dataset()
    assert calls == [expected]
    ensure_demo_dataset(("mini_val", "scene-0103"))  # val needs alone never build the train scenes
    ensure_demo_dataset(("mini_train",))
    assert calls == [expected, expected, expected.with_name(expected.name + "-all")]


def _submission(nusc: NuScenes, fresh_ids: bool) -> dict:
    results: dict[str, list[dict]] = {}
    for name in DEMO_SCENES:
        for k, sample in enumerate(_scene_samples(nusc, name)):
            boxes = []
            for ann_token in sample["anns"]:
                ann = nusc.get("sample_annotation", ann_token)
                tracking_name = category_to_tracking_name(ann["category_name"])
                if tracking_name is None or ann["num_lidar_pts"] == 0:
                    continue
                velocity = np.nan_to_num(nusc.box_velocity(ann_token)[:2])
                boxes.append(
                    {
                        "sample_token": sample["token"],
                        "translation": ann["translation"],
                        "size": ann["size"],
                        "rotation": ann["rotation"],
                        "velocity": velocity.tolist(),
                        "tracking_id": f"{ann['instance_token']}-{k}" if fresh_ids else ann["instance_token"],
                        "tracking_name": tracking_name,
                        "tracking_score": 1.0,
                    }
                )
            results[sample["token"]] = boxes
    meta = {"use_camera": False, "use_lidar": True, "use_radar": False, "use_map": False, "use_external": False}
    return {"meta": meta, "results": results}


@pytest.mark.parametrize(("fresh_ids", "amota_range"), [(False, (0.999, 1.0)), (True, (0.0, 0.1))])
def test_official_tracking_eval(
    nusc: NuScenes, demo_dataroot: Path, tmp_path: Path, fresh_ids: bool, amota_range: tuple[float, float]
) -> None:
    from nuscenes.eval.common.config import config_factory
    from nuscenes.eval.tracking.evaluate import TrackingEval

    result_path = tmp_path / "submission.json"
    result_path.write_text(json.dumps(_submission(nusc, fresh_ids)))
    evaluation = TrackingEval(
        config=config_factory("tracking_nips_2019"),
        result_path=str(result_path),
        eval_set="mini_val",
        output_dir=str(tmp_path / "eval"),
        nusc_version=DEMO_VERSION,
        nusc_dataroot=str(demo_dataroot),
        verbose=False,
        render_classes=[],
    )
    metrics, _ = evaluation.evaluate()
    summary = metrics.serialize()
    assert amota_range[0] <= summary["amota"] <= amota_range[1]
    for name in TRACKING_CLASSES:
        amota = summary["label_metrics"]["amota"][name]
        assert not np.isnan(amota), f"{name} has no ground truth left after the eval's filters"
