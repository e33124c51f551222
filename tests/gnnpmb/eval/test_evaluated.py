"""``eval.evaluated``: how the evaluation saw every object and track of a demo scene, checked against the devkit's
own output computed here apart (its filters, its interpolation, its averaged scores) and against the annotations."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from gnnpmb.data.nuscenes import open_nuscenes
from gnnpmb.eval.evaluated import Dropped, GtStatus
from gnnpmb.eval.failure_cache import scene_report
from gnnpmb.eval.failures import _split_with_scene
from gnnpmb.eval.nuscenes_eval import quiet_devkit, scene_sample_tokens, tracking_config
from gnnpmb.eval.submission import run_results
from gnnpmb.pipeline import run_tracker
from tests.pipeline import prepare

SCENE = "scene-0103"


@pytest.fixture(scope="module")
def evaluated(demo_dataroot: Path):
    """The report of gnnpmb on the scene, the submission, and the devkit's prepared tracks computed apart. The report
    is the one ``gnnpmb-viz`` and ``gnnpmb failures`` use (``scene_report``): read from the session's cache when an
    earlier test evaluated the same run (the README's demo command does), else found now."""
    from nuscenes.eval.common.loaders import add_center_dist, filter_eval_boxes, load_gt_of_sample_tokens
    from nuscenes.eval.tracking.data_classes import TrackingBox
    from nuscenes.eval.tracking.loaders import create_tracks

    request = prepare(SCENE, ["gnnpmb"], dataroot=demo_dataroot)
    nusc = open_nuscenes(request.location)
    run = run_tracker(request.scene, request.frame_detections, "gnnpmb", request.config)
    results = run_results(run)
    report = scene_report(request.location, SCENE, "gnnpmb", results)
    tokens = scene_sample_tokens(nusc, SCENE)
    frame_of = {nusc.get("sample", t)["timestamp"]: i for i, t in enumerate(tokens)}
    cfg = tracking_config()
    with quiet_devkit():
        gt = load_gt_of_sample_tokens(nusc, tokens, TrackingBox, verbose=False)
        kept = {
            (i, str(b.tracking_id))
            for i, t in enumerate(tokens)
            for b in filter_eval_boxes(nusc, add_center_dist(nusc, gt), cfg.class_range)[t]
        }
        gt = load_gt_of_sample_tokens(nusc, tokens, TrackingBox, verbose=False)
        tracks = create_tracks(
            filter_eval_boxes(nusc, add_center_dist(nusc, gt), cfg.class_range),
            nusc,
            _split_with_scene(nusc, SCENE),
            True,
        )
    (scene_tracks,) = tracks.values()
    boxes = {(frame_of[ts], str(b.tracking_id)): b for ts, bs in scene_tracks.items() for b in bs}
    return request.scene, report, results, kept, boxes, cfg


def test_each_object_frame_has_the_status_the_devkits_own_filters_and_tracks_give(evaluated) -> None:
    scene, report, _results, kept, boxes, cfg = evaluated
    statuses = set()
    for keyframe in scene.keyframes:
        gt = keyframe.gt
        for k, gt_id in enumerate(gt.instance_id.astype(str).tolist()):
            g = report.gt_frame(gt_id, keyframe.index)
            assert g is not None, (keyframe.index, gt_id)
            statuses.add(g.status)
            np.testing.assert_allclose(g.annotated_xy_m, gt.translation_m[k, :2], atol=1e-9)
            assert g.points == int(keyframe.gt_num_pts[k])
            ego_m = float(np.hypot(*(gt.translation_m[k, :2] - keyframe.ego_pose.translation_m[:2])))
            assert g.ego_distance_m == pytest.approx(ego_m, abs=1e-6)
            assert g.range_m == cfg.class_range[str(gt.class_name[k])]
            box = boxes.get((keyframe.index, gt_id))
            if (keyframe.index, gt_id) in kept:
                assert g.status is GtStatus.SCORED and g.dropped is None
            else:
                expected = Dropped.BEYOND_RANGE if ego_m >= g.range_m else Dropped.NO_POINTS
                assert g.dropped is expected, (keyframe.index, gt_id)
                if box is not None:
                    assert g.status is GtStatus.INTERPOLATED
                else:
                    assert g.status is (GtStatus.BEYOND_RANGE if expected is Dropped.BEYOND_RANGE else GtStatus.NO_BOX)
            if box is None:
                assert g.evaluated_xy_m is None
            else:
                np.testing.assert_allclose(g.evaluated_xy_m, box.translation[:2], atol=1e-9)
    assert statuses == set(GtStatus)  # the scene has every case


def test_an_interpolated_box_names_its_ends_and_where_the_right_weights_would_put_it(evaluated) -> None:
    scene, report, *_ = evaluated
    checked = 0
    for frames in report.gt_frames.values():
        for f, g in frames.items():
            if g.status is not GtStatus.INTERPOLATED or g.between is None:
                continue
            left, right = g.between
            assert frames[left].status is GtStatus.SCORED and frames[right].status is GtStatus.SCORED
            assert all(frames[x].status is not GtStatus.SCORED for x in range(left + 1, right))
            t = [scene.keyframes[x].timestamp_us for x in (left, f, right)]
            share = (t[1] - t[0]) / (t[2] - t[0])
            a, b = np.asarray(frames[left].annotated_xy_m), np.asarray(frames[right].annotated_xy_m)
            np.testing.assert_allclose(g.unswapped_xy_m, (1 - share) * a + share * b, atol=1e-9)
            # the devkit's own box is the interpolation with the weights swapped (nuscenes-devkit issue #1141)
            np.testing.assert_allclose(g.evaluated_xy_m, share * a + (1 - share) * b, atol=1e-6)
            checked += 1
    assert checked > 0


def test_a_tracks_score_is_averaged_over_the_frames_the_range_filter_kept(evaluated) -> None:
    scene, report, results, *_ = evaluated
    cfg = evaluated[-1]
    differing = 0
    for t, ev in report.track_evals.items():
        scores, kept = [], []
        for f, keyframe in enumerate(scene.keyframes):
            for box in results[keyframe.sample_token]:
                if box["tracking_id"] != t:
                    continue
                scores.append(box["tracking_score"])
                ego = np.hypot(*(np.asarray(box["translation"][:2]) - keyframe.ego_pose.translation_m[:2]))
                if ego < cfg.class_range[box["tracking_name"]]:
                    kept.append((f, box["tracking_score"]))
        assert ev.submitted_mean == pytest.approx(np.mean(scores))
        assert ev.kept == tuple(f for f, _ in kept)
        if kept:
            assert ev.averaged_score == pytest.approx(np.mean([s for _, s in kept]), rel=1e-12)
            assert report.track_scores[t] == ev.averaged_score
        else:
            assert ev.averaged_score is None
        differing += len(kept) != len(scores)
    assert differing > 0  # some tracks leave the range: the two averages differ there


def test_a_tracks_matches_are_the_devkits_match_and_switch_events_at_the_best_mota_threshold(evaluated) -> None:
    _scene, report, *_ = evaluated
    from gnnpmb.eval.failures import FailureKind

    by_frame: dict[tuple[int, str], list[str]] = {}
    for t, ev in report.track_evals.items():
        assert list(ev.matches) == sorted(ev.matches) and len({x for x, _ in ev.matches}) == len(ev.matches)
        for x, g in ev.matches:
            assert x in ev.submitted or x in ev.interpolated  # the evaluation scored a box of the track there
            assert ev.matched_at(x) == g
            by_frame.setdefault((x, g), []).append(t)
    assert by_frame and all(len(ts) == 1 for ts in by_frame.values())  # one track per object and frame
    for f in report.failures:
        x = f.frame_index
        if f.kind is FailureKind.ID_SWITCH:  # the new track took the object
            assert report.track_evals[f.track_ids[1]].matched_at(x) == f.gt_ids[0]
        elif f.kind is FailureKind.FALSE_TRACK:  # matched to nothing
            assert report.track_evals[f.track_ids[0]].matched_at(x) is None
        elif f.kind in (FailureKind.MISS, FailureKind.FRAGMENTATION):  # nothing matched to it
            assert (x, f.gt_ids[0]) not in by_frame
    assert {FailureKind.FALSE_TRACK, FailureKind.MISS} <= {f.kind for f in report.failures}  # both cases seen


def test_a_track_read_back_keeps_its_matches_and_one_written_without_them_is_not_read() -> None:
    from gnnpmb.eval.evaluated import TrackEval

    ev = TrackEval((1, 2, 3), (1, 2, 3), (), 0.5, 0.5, ((1, "a" * 32), (2, "b" * 32), (3, "a" * 32)))
    data = ev.to_json()
    assert data["matches"] == {"a" * 32: [1, 3], "b" * 32: [2]}  # each object's id once
    assert TrackEval.from_json(data) == ev
    del data["matches"]  # a cached report of the version before: evaluated again, not read as matched nowhere
    with pytest.raises(KeyError):
        TrackEval.from_json(data)
