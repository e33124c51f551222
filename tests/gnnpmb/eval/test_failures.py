"""The failure finder on staged submissions built from the demo's ground truth, and on a real tracker run.

Staged failures: the ground truth as a perfect submission, then one deliberate change (an id relabelled from
frame k on, a neighbour's track ended, a false track walking onto an object). Submissions made of ground truth
have one score (1.0), so the devkit evaluates them at a single threshold and runs fast.
"""

from __future__ import annotations

import copy
import json
from collections import Counter
from pathlib import Path

import numpy as np
import pytest

from gnnpmb.config import TrackerConfig
from gnnpmb.data.nuscenes import check_dataroot, load_scene, open_nuscenes
from gnnpmb.data.scene import SceneData
from gnnpmb.eval.failures import FailureKind, FailureReport, find_failures
from gnnpmb.eval.submission import gt_results, run_results
from gnnpmb.pipeline import get_detections, run_tracker

SCENE = "scene-0103"
NEAR_EGO_M = 30.0


@pytest.fixture(scope="module")
def nusc(demo_dataroot: Path):
    return open_nuscenes(check_dataroot(demo_dataroot, "v1.0-mini"))


@pytest.fixture(scope="module")
def scene(nusc, demo_dataroot: Path) -> SceneData:
    return load_scene(check_dataroot(demo_dataroot, "v1.0-mini"), SCENE)


@pytest.fixture(scope="module")
def gt(scene: SceneData) -> dict[str, list[dict]]:
    return gt_results(scene)


def visible(scene: SceneData, frame: int) -> dict[str, tuple[str, np.ndarray]]:
    """Instance -> (class, BEV centre) of the ground truth the evaluation keeps for sure at ``frame``: with
    points, within NEAR_EGO_M of the ego."""
    kf = scene.keyframes[frame]
    ego = kf.ego_pose.translation_m[:2]
    out = {}
    for i, instance in enumerate(kf.gt.instance_id):
        xy = kf.gt.translation_m[i, :2]
        if kf.gt_num_pts[i] > 0 and np.hypot(*(xy - ego)) < NEAR_EGO_M:
            out[str(instance)] = (str(kf.gt.class_name[i]), xy)
    return out


def visible_throughout(scene: SceneData, frames: range) -> dict[str, tuple[str, np.ndarray]]:
    """Instances visible at every frame of ``frames`` (class and centre at the last one)."""
    common = visible(scene, frames[0])
    for f in frames[1:]:
        now = visible(scene, f)
        common = {k: now[k] for k in common if k in now}
    return common


def relabel(results: dict, frames: range, old_id: str, new_id: str) -> None:
    tokens = list(results)
    for f in frames:
        for b in results[tokens[f]]:
            if b["tracking_id"] == old_id:
                b["tracking_id"] = new_id


def drop(results: dict, frames: range, track_id: str) -> None:
    tokens = list(results)
    for f in frames:
        results[tokens[f]] = [b for b in results[tokens[f]] if b["tracking_id"] != track_id]


def kinds(report: FailureReport) -> Counter:
    return Counter(f.kind for f in report.failures)


def test_ground_truth_has_no_failures(nusc, gt: dict) -> None:
    report = find_failures(nusc, SCENE, gt, "ground-truth")
    assert report.failures == ()
    assert len(report.sample_tokens) == 40
    assert {"car", "pedestrian", "truck"} <= {c.class_name for c in report.classes}
    assert all(c.mota == 1.0 and c.ids == 0 and c.fn == 0 for c in report.classes)


def test_deliberate_id_switch_is_reported_at_its_frame_with_the_ids(nusc, scene: SceneData, gt: dict) -> None:
    k = 12
    instance, (class_name, _) = sorted(visible_throughout(scene, range(k - 1, k + 1)).items())[0]
    results = copy.deepcopy(gt)
    relabel(results, range(k, len(results)), instance, "switched")
    report = find_failures(nusc, SCENE, results, "staged")
    assert kinds(report) == {FailureKind.ID_SWITCH: 1}
    (switch,) = report.failures
    assert (switch.frame_index, switch.class_name) == (k, class_name)
    assert switch.sample_token == scene.keyframes[k].sample_token
    assert switch.gt_ids == (instance,) and switch.track_ids == (instance, "switched")
    # The lost track's box is where it was last reported (frame k - 1), so the marker shows both tracks.
    assert [b.role for b in switch.boxes] == ["gt", "new track", "old track"]
    last = next(b for b in results[scene.keyframes[k - 1].sample_token] if b["tracking_id"] == instance)
    np.testing.assert_allclose(switch.boxes[2].translation_m, last["translation"], atol=1e-6)
    devkit = {c.class_name: c for c in report.classes}[class_name]
    assert devkit.ids == 1 and devkit.mota < 1.0


def _close_pair(scene: SceneData) -> tuple[int, str, str, str]:
    """(frame, A, B, class): two visible objects of one class with centres < 1.8 m apart."""
    for frame in range(1, len(scene.keyframes)):
        seen = sorted(visible(scene, frame).items())
        for i, (a, (ca, xa)) in enumerate(seen):
            for b, (cb, xb) in seen[i + 1 :]:
                if ca == cb and np.hypot(*(xa - xb)) < 1.8:
                    return frame, a, b, ca
    raise AssertionError("the demo scene has no two close objects of one class")


def test_staged_coalescence_is_reported(nusc, scene: SceneData, gt: dict) -> None:
    k, a, b, class_name = _close_pair(scene)
    results = copy.deepcopy(gt)
    drop(results, range(k, len(results)), b)  # from frame k on, track a stands for both
    report = find_failures(nusc, SCENE, results, "staged")
    at_k = [f for f in report.of_kind(FailureKind.COALESCENCE) if f.frame_index == k]
    assert len(at_k) == 1
    assert at_k[0].class_name == class_name
    assert at_k[0].gt_ids == (a, b) and at_k[0].track_ids == (a,)
    assert {(box.role, box.object_id) for box in at_k[0].boxes} == {
        ("track", a),
        ("matched gt", a),
        ("missed gt", b),
    }
    assert any(f.kind is FailureKind.MISS and f.gt_ids == (b,) and f.frame_index == k for f in report.failures)
    assert not report.of_kind(FailureKind.ID_SWITCH)


def _free_spot(scene: SceneData, frame: int, class_name: str, near: np.ndarray) -> np.ndarray:
    """A BEV point 6 m from ``near``, >= 3.5 m from every box of ``class_name`` and near the ego."""
    kf = scene.keyframes[frame]
    same = kf.gt.translation_m[kf.gt.class_name == class_name, :2]
    for angle in np.linspace(0.0, 2 * np.pi, 16, endpoint=False):
        spot = near + 6.0 * np.array([np.cos(angle), np.sin(angle)])
        if np.min(np.hypot(*(same - spot).T)) >= 3.5 and np.hypot(*(spot - kf.ego_pose.translation_m[:2])) < 35:
            return spot
    raise AssertionError("no free spot")


def _moved(box: dict, xy: np.ndarray, track_id: str) -> dict:
    return {
        **copy.deepcopy(box),
        "translation": [float(xy[0]), float(xy[1]), box["translation"][2]],
        "tracking_id": track_id,
    }


def test_staged_cascading_identity_theft(nusc, scene: SceneData, gt: dict) -> None:
    """A ghost track born on false boxes takes object O (frame k); O's old track, now without an object, takes
    object P (frame k + 1): identity theft, then a cascade step."""
    k = 14
    candidates = visible_throughout(scene, range(k - 2, k + 2))
    o, p, class_name = next(
        (o, p, co)
        for (o, (co, xo)), (p, (cp, xp)) in (
            (x, y) for x in sorted(candidates.items()) for y in sorted(candidates.items())
        )
        if o < p and co == cp and np.hypot(*(xo - xp)) > 8.0
    )
    results = copy.deepcopy(gt)
    tokens = list(results)
    box_of = {f: {b["tracking_id"]: b for b in results[tokens[f]]} for f in range(len(tokens))}
    for f in (k - 2, k - 1):  # the ghost: false boxes first
        spot = _free_spot(scene, f, class_name, np.array(box_of[f][o]["translation"][:2]))
        results[tokens[f]].append(_moved(box_of[f][o], spot, "ghost"))
    relabel(results, range(k, len(tokens)), o, "ghost")  # ... then it covers O
    spot = _free_spot(scene, k, class_name, np.array(box_of[k][o]["translation"][:2]))
    results[tokens[k]].append(_moved(box_of[k][o], spot, o))  # O's old track, off its object
    relabel(results, range(k + 1, len(tokens)), p, o)  # ... which then covers P

    report = find_failures(nusc, SCENE, results, "staged")
    thefts = report.of_kind(FailureKind.IDENTITY_THEFT)
    assert [(f.frame_index, f.gt_ids, f.track_ids, f.generation) for f in thefts] == [
        (k, (o,), ("ghost", o), 1),
        (k + 1, (p,), (o, p), 2),
    ]
    assert thefts[0].class_name == class_name
    switches = [(f.frame_index, f.gt_ids, f.track_ids) for f in report.of_kind(FailureKind.ID_SWITCH)]
    assert switches == [(k, (o,), (o, "ghost")), (k + 1, (p,), (p, o))]
    false_tracks = [(f.frame_index, f.track_ids) for f in report.of_kind(FailureKind.FALSE_TRACK)]
    assert false_tracks == [(k - 2, ("ghost",)), (k - 1, ("ghost",)), (k, (o,))]
    assert "ghost took GT" in thefts[0].describe() and "cascade step 2" in thefts[1].describe()


def test_only_the_tracked_classes_are_evaluated(nusc, gt: dict) -> None:
    """A run of one class (``--classes car``): the other classes' objects are no one's misses."""
    cars = {token: [b for b in boxes if b["tracking_name"] == "car"] for token, boxes in gt.items()}
    report = find_failures(nusc, SCENE, cars, "cars", classes=("car",))
    assert report.failures == ()
    assert [c.class_name for c in report.classes] == ["car"]
    every = find_failures(nusc, SCENE, cars, "cars")
    assert {f.class_name for f in every.failures} == {c.class_name for c in every.classes} - {"car"}


def test_failures_of_a_tracker_run_add_up_to_the_devkits_counts(nusc, scene: SceneData) -> None:
    run = run_tracker(scene, get_detections(scene, None, "pointpillars", 0), "gnnpmb", TrackerConfig())
    report = find_failures(nusc, SCENE, run_results(run), "gnnpmb")
    assert report.failures
    for c in report.classes:
        mine = Counter(f.kind for f in report.failures if f.class_name == c.class_name)
        counts = (mine[FailureKind.ID_SWITCH], mine[FailureKind.FALSE_TRACK], mine[FailureKind.MISS])
        assert counts == (c.ids, c.fp, c.fn), c.class_name
        assert mine[FailureKind.FRAGMENTATION] == c.frag, c.class_name
    frames = [f.frame_index for f in report.failures]
    assert frames == sorted(frames)
    data = json.loads(json.dumps(report.to_json(), allow_nan=False))
    assert data["totals"]["miss"] == len(report.of_kind(FailureKind.MISS))
    assert data["failures"][0]["boxes"][0]["translation"]
    assert report.counts(FailureKind.MISS).sum() == len(report.of_kind(FailureKind.MISS))


def test_a_robbed_track_taking_its_own_object_back_is_no_theft() -> None:
    """Hand-made accumulator events: ghost (born false) takes O from track 1; track 1 takes O back later."""
    from nuscenes.eval.tracking.data_classes import TrackingBox

    from gnnpmb.eval.failures import _class_failures, _Frame
    from gnnpmb.eval.nuscenes_eval import tracking_config

    tracking_config()

    def tb(track_id: str, x: float) -> TrackingBox:
        return TrackingBox(
            "s",
            (x, 0.0, 1.0),
            (2.0, 4.0, 1.5),
            (1.0, 0.0, 0.0, 0.0),
            tracking_id=track_id,
            tracking_name="car",
        )

    o, ghost, own = {"O": tb("O", 0.0)}, tb("ghost", 0.0), tb("1", 0.0)
    frames = [
        _Frame(0, o, {"1": own, "ghost": tb("ghost", 9.0)}, [("MATCH", "O", "1"), ("FP", None, "ghost")]),
        _Frame(1, o, {"1": tb("1", 9.0), "ghost": ghost}, [("SWITCH", "O", "ghost"), ("FP", None, "1")]),
        _Frame(2, o, {"1": own, "ghost": tb("ghost", 9.0)}, [("SWITCH", "O", "1"), ("FP", None, "ghost")]),
    ]
    failures = _class_failures(frames, "car", ["s0", "s1", "s2"], 2.0, 2.0)
    thefts = [(f.frame_index, f.track_ids, f.generation) for f in failures if f.kind is FailureKind.IDENTITY_THEFT]
    assert thefts == [(1, ("ghost", "1"), 1)]
    switches = [(f.frame_index, f.track_ids) for f in failures if f.kind is FailureKind.ID_SWITCH]
    assert switches == [(1, ("1", "ghost")), (2, ("ghost", "1"))]
