"""The evaluation's facts from the devkit's own per-frame bookkeeping, with no code of ``gnnpmb.eval``.

Steps, as ``nuscenes.eval.tracking.evaluate.TrackingEval.__init__`` takes them for the scene's samples: load the
ground truth, add ego distances, ``filter_eval_boxes`` (class range, zero points, bike racks), ``create_tracks``
(which interpolates gaps inside a track); then per class ``TrackingEvaluation.accumulate`` (all recall thresholds,
as ``compute_metrics`` scores them), the best-MOTA threshold, and ``accumulate_threshold`` at it, whose
``acc.events`` (MATCH / SWITCH / MISS / FP per devkit frame id, OId, HId) are read back onto keyframe indices by
replaying the accumulator's frame numbering (a frame with neither ground truth nor a kept track has no id), and
onto the scene's object and track ids through the devkit's own merge mappings (the merge renumbers them).
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from tools.truth.scene import NEAR_M

MATCHED = ("MATCH", "SWITCH")


@dataclass
class EvalFacts:
    """Per class: threshold (None: every box counts), and at each keyframe index who the accumulator matched.

    gt_to_track[(class, frame)][gt id] = track id (str) or None (a MISS); track_to_gt likewise (None: an FP);
    counted[(class)] = track ids whose averaged score passes the threshold; evaluated_gt[(frame, gt id)] = the
    BEV centre of the box the devkit scored (an annotation or an interpolation)."""

    thresholds: dict[str, float | None] = field(default_factory=dict)
    gt_to_track: dict[tuple[str, int], dict[str, str | None]] = field(default_factory=dict)
    track_to_gt: dict[tuple[str, int], dict[str, str | None]] = field(default_factory=dict)
    counted: dict[str, set[str]] = field(default_factory=dict)
    evaluated_gt: dict[tuple[int, str], tuple[float, float]] = field(default_factory=dict)
    switches: dict[tuple[str, int], set[str]] = field(default_factory=dict)
    submitted: dict[int, set[str]] = field(default_factory=dict)
    """frame -> the track ids the submission has a box of there (before any filter)."""
    boxes: dict[int, list[tuple[str, str, tuple[float, float]]]] = field(default_factory=dict)
    """frame -> the submission's boxes there: (track id, class, ground-plane centre)."""
    pred_xy: dict[tuple[str, int], dict[str, tuple[float, float]]] = field(default_factory=dict)
    """(class, frame) -> the centre of each track box the accumulator scored there (interpolations included)."""
    scores: dict[tuple[int, str], float] = field(default_factory=dict)
    geometry: dict[tuple[int, str], tuple[float, ...]] = field(default_factory=dict)
    """(frame, track id) -> the submission box's size, rotation and centre height (``scene.Detection.box``)."""
    averaged: dict[str, tuple[int, float]] = field(default_factory=dict)
    """track id -> (frames the devkit's filters kept its box, the score ``create_tracks`` averaged over them)."""
    kept_frames: dict[str, tuple[int, ...]] = field(default_factory=dict)
    """track id -> the frames at which the devkit's filters kept its box (those ``averaged`` is over)."""
    pred_ego_m: dict[tuple[int, str], float] = field(default_factory=dict)
    """(frame, track id) -> the devkit's distance (``add_center_dist``) of the submission's box to the ego vehicle."""
    kept_gt: set[tuple[int, str]] = field(default_factory=set)
    """(frame, object id) of each annotated box the devkit's filters kept (the ends its interpolation joins)."""
    stamps: dict[int, int] = field(default_factory=dict)
    """frame -> its sample's timestamp (µs), the time the devkit interpolates over."""
    """(frame, track id) -> the submission box's tracking score."""
    """(class, frame) -> the object ids of the frame's SWITCH events."""

    def matched_track(self, class_name: str, frame: int, gt_id: str) -> str | None:
        return self.gt_to_track.get((class_name, frame), {}).get(gt_id)

    def matched_gt(self, class_name: str, frame: int, track_id: str) -> str | None:
        return self.track_to_gt.get((class_name, frame), {}).get(track_id)

    def false_near(self, frame: int, place_xy_m, class_name: str) -> list[str]:
        """The track ids of ``class_name`` the accumulator counted as false positives at ``frame`` with a scored box
        within ``NEAR_M`` of ``place_xy_m`` (a false track of another class is another failure)."""
        return sorted(
            t
            for (k, y), tracks in self.track_to_gt.items()
            if y == frame and k == class_name
            for t, g in tracks.items()
            if g is None
            and (xy := self.pred_xy.get((k, y), {}).get(t)) is not None
            and math.dist(xy, place_xy_m) < NEAR_M
        )


def _split_of(nusc, scene_name: str) -> str:
    """The smallest devkit split (or custom split of the dataroot) that holds the scene."""
    import json
    from pathlib import Path

    from nuscenes.utils.splits import create_splits_scenes

    splits = create_splits_scenes()
    custom = Path(nusc.dataroot) / nusc.version / "splits.json"
    if custom.is_file():
        splits.update(json.loads(custom.read_text(encoding="utf-8")))
    return min((n for n, s in splits.items() if scene_name in s), key=lambda n: len(splits[n]))


def eval_facts(nusc, scene_name: str, results: Mapping[str, Sequence[Mapping[str, Any]]]) -> EvalFacts:
    """The devkit's matching of ``results`` (sample token -> submission boxes) on one scene (module docstring)."""
    import contextlib
    import io

    from nuscenes.eval.common.config import config_factory
    from nuscenes.eval.common.data_classes import EvalBoxes
    from nuscenes.eval.common.loaders import add_center_dist, filter_eval_boxes, load_gt_of_sample_tokens
    from nuscenes.eval.tracking.data_classes import TrackingBox
    from nuscenes.eval.tracking.loaders import create_tracks

    from gnnpmb.eval.nuscenes_eval import class_evaluation

    cfg = config_factory("tracking_nips_2019")
    scene = next(s for s in nusc.scene if s["name"] == scene_name)
    tokens, token = [], scene["first_sample_token"]
    while token:
        tokens.append(token)
        token = nusc.get("sample", token)["next"]
    frame_of_stamp = {nusc.get("sample", t)["timestamp"]: i for i, t in enumerate(tokens)}
    split = _split_of(nusc, scene_name)
    with contextlib.redirect_stdout(io.StringIO()):
        gt = load_gt_of_sample_tokens(nusc, tokens, TrackingBox, verbose=False)
        pred = EvalBoxes.deserialize({t: list(results.get(t, [])) for t in tokens}, TrackingBox)
        gt = filter_eval_boxes(nusc, add_center_dist(nusc, gt), cfg.class_range, verbose=False)
        kept_gt = [(t, str(b.tracking_id)) for t in tokens for b in gt[t]]  # create_tracks adds its interpolations
        pred = add_center_dist(nusc, pred)
        pred_ego = {(t, str(b.tracking_id)): float(b.ego_dist) for t in tokens for b in pred[t]}
        pred = filter_eval_boxes(nusc, pred, cfg.class_range, verbose=False)
        kept_pred = [str(b.tracking_id) for t in tokens for b in pred[t]]
        kept_at = [(t, str(b.tracking_id)) for t in tokens for b in pred[t]]
        tracks_gt = create_tracks(gt, nusc, split, gt=True)
        tracks_pred = create_tracks(pred, nusc, split, gt=False)
    out = EvalFacts()
    out.pred_ego_m = {(frame_of_stamp[nusc.get("sample", t)["timestamp"]], k): d for (t, k), d in pred_ego.items()}
    for t, track in kept_at:
        out.kept_frames.setdefault(track, ())
        out.kept_frames[track] += (frame_of_stamp[nusc.get("sample", t)["timestamp"]],)
    out.kept_gt = {(frame_of_stamp[nusc.get("sample", t)["timestamp"]], g) for t, g in kept_gt}
    for token in tokens:
        frame = frame_of_stamp[nusc.get("sample", token)["timestamp"]]
        out.boxes[frame] = [
            (str(b["tracking_id"]), b["tracking_name"], (float(b["translation"][0]), float(b["translation"][1])))
            for b in results.get(token, [])
        ]
        out.submitted[frame] = {b[0] for b in out.boxes[frame]}
        out.stamps[frame] = int(nusc.get("sample", token)["timestamp"])
        for b in results.get(token, []):
            out.scores[(frame, str(b["tracking_id"]))] = float(b["tracking_score"])
            out.geometry[(frame, str(b["tracking_id"]))] = (*b["size"], *b["rotation"], b["translation"][2])
    scene_gt = tracks_gt[scene["token"]]
    scene_pred = tracks_pred[scene["token"]]
    average = {str(b.tracking_id): float(b.tracking_score) for boxes in scene_pred.values() for b in boxes}
    out.averaged = {t: (kept_pred.count(t), average[t]) for t in set(kept_pred) if t in average}
    for stamp, boxes in scene_gt.items():
        for b in boxes:
            out.evaluated_gt[(frame_of_stamp[stamp], str(b.tracking_id))] = (
                float(b.translation[0]),
                float(b.translation[1]),
            )
    for class_name in cfg.class_names:
        ev = class_evaluation(
            tracks_gt, tracks_pred, class_name, cfg
        )  # the devkit's own object, as TrackingEval builds it
        best = _best_mota_threshold(ev)
        if best is None:
            continue
        threshold = best[0]
        out.thresholds[class_name] = threshold
        events, oid_of, hid_of = _accumulate_threshold(ev, threshold)
        frame_of_id = []  # devkit frame id -> keyframe index, numbered as accumulate_threshold numbers them
        counted: set[str] = set()
        for stamp in scene_gt:
            g = [b for b in scene_gt[stamp] if b.tracking_name == class_name]
            p = [b for b in scene_pred[stamp] if b.tracking_name == class_name]
            if threshold is not None:
                p = [b for b in p if b.tracking_score >= threshold]
            counted.update(str(b.tracking_id) for b in p)
            if g or p:
                frame_of_id.append(frame_of_stamp[stamp])
                out.gt_to_track[(class_name, frame_of_stamp[stamp])] = {str(b.tracking_id): None for b in g}
                out.track_to_gt[(class_name, frame_of_stamp[stamp])] = {str(b.tracking_id): None for b in p}
                out.pred_xy[(class_name, frame_of_stamp[stamp])] = {
                    str(b.tracking_id): (float(b.translation[0]), float(b.translation[1])) for b in p
                }
        out.counted[class_name] = counted
        events = events.reset_index()
        for frame_id, kind, oid, hid in zip(
            events["FrameId"], events["Type"], events["OId"], events["HId"], strict=True
        ):
            if str(kind) in MATCHED:
                frame = frame_of_id[int(frame_id)]
                gt_id, track_id = str(oid_of[oid]), str(hid_of[hid])
                out.gt_to_track[(class_name, frame)][gt_id] = track_id
                out.track_to_gt[(class_name, frame)][track_id] = gt_id
                if str(kind) == "SWITCH":
                    out.switches.setdefault((class_name, frame), set()).add(gt_id)
    return out


def _best_mota_threshold(ev) -> tuple[float | None] | None:
    """(threshold,) at which ``ev.accumulate()`` would have its best MOTA, as ``TrackingEval`` picks it
    (``np.nanargmax(md.mota)``, None: the confidence there is NaN); None when the class has no ground truth.
    The same devkit steps as ``accumulate`` (``compute_thresholds``, ``accumulate_threshold`` per distinct
    threshold, the devkit's ``mota_custom``, NaN for unachieved recalls, duplicates repeated), computing MOTA only:
    the other metrics ``accumulate`` computes take most of its time and do not choose the threshold."""
    import contextlib
    import io

    from nuscenes.eval.tracking.utils import create_motmetrics

    count = sum(
        b.tracking_name == ev.class_name for scene in ev.tracks_gt.values() for frame in scene.values() for b in frame
    )
    if count == 0:
        return None
    mh = create_motmetrics()
    with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(io.StringIO()):
        thresholds, _ = ev.compute_thresholds(count)
        mota: list[float] = []
        for t, threshold in enumerate(thresholds):
            if np.isnan(threshold):
                mota.append(math.nan)
            elif threshold in thresholds[:t]:
                mota.append(mota[list(thresholds).index(threshold)])
            else:
                acc, _ = ev.accumulate_threshold(threshold)
                mota.append(float(mh.compute(acc, metrics=["mota_custom"], name="t")["mota_custom"].iloc[0]))
    if all(math.isnan(v) for v in mota):
        return (None,)  # no recall reached: the devkit fills the worst MOTA and its confidence is NaN
    best = int(np.nanargmax(mota))
    return (None if np.isnan(thresholds[best]) else float(thresholds[best]),)


def _accumulate_threshold(ev, threshold: float | None):
    """``ev.accumulate_threshold(threshold)``'s events with the ids the scene gave them: the devkit merges the
    per-scene accumulators with ``MOTAccumulatorCustom.merge_event_dataframes``, which renumbers object and
    hypothesis ids; its own mappings (``return_mappings``) are read back here. Returns (events, new OId ->
    object id, new HId -> track id)."""
    import contextlib
    import io

    from nuscenes.eval.tracking.mot import MOTAccumulatorCustom

    original = MOTAccumulatorCustom.merge_event_dataframes
    mappings: list[dict] = []

    def merge(dfs, *args, **kwargs):
        merged, infos = original(dfs, *args, return_mappings=True, **kwargs)
        mappings.extend(infos)
        return merged

    MOTAccumulatorCustom.merge_event_dataframes = staticmethod(merge)
    try:
        with contextlib.redirect_stderr(io.StringIO()):
            events, _ = ev.accumulate_threshold(threshold)
    finally:
        MOTAccumulatorCustom.merge_event_dataframes = staticmethod(original)
    (info,) = mappings  # one scene
    assert info.get("frame_offset", 0) == 0
    oid_of = {new: old for old, new in info.get("oid_map", {}).items()}
    hid_of = {new: old for old, new in info.get("hid_map", {}).items()}
    return events, oid_of, hid_of
