"""The official tracking metrics of a set of scenes (one scene, or a split), computed in memory.

``TrackingEval`` scores a whole split named in the devkit (or in a ``splits.json`` beside the dataset); comparing two
runs on one scene, or on a split without writing files, needs the same numbers for any scenes. This module runs the
devkit's own steps on the scenes' samples, as ``TrackingEval.evaluate`` does: ground truth and predictions loaded
and filtered by its loaders (class ranges, boxes without points, bike racks), tracks built with averaged scores and
interpolation (``create_tracks``), each class accumulated by ``TrackingEvaluation`` over 40 recall thresholds, the
traditional metrics read at the best-MOTA threshold and AMOTA / AMOTP averaged with the worst value where a
threshold is not reached, then ``TrackingMetrics`` for the overall means and sums. On a whole split it gives what
``gnnpmb eval`` prints (tested).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import TYPE_CHECKING, Any

import numpy as np

from gnnpmb.errors import DataError
from gnnpmb.eval.nuscenes_eval import class_evaluation, quiet_devkit, scene_sample_tokens, tracking_config

if TYPE_CHECKING:
    from nuscenes import NuScenes


def scene_scores(
    nusc: NuScenes, scene_names: Sequence[str], results: Mapping[str, Sequence[Mapping[str, Any]]]
) -> tuple[dict[str, dict[str, float]], dict[str, float]]:
    """(per class {metric: value}, overall {metric: value}) of ``results`` (submission boxes by sample token; a
    sample without an entry counts as empty) on ``scene_names`` (all in one devkit or custom split), as named in
    the devkit's ``metrics_summary.json``; NaN where a class has no ground truth."""
    from nuscenes.eval.tracking.constants import AVG_METRIC_MAP, MOT_METRIC_MAP
    from nuscenes.eval.tracking.data_classes import TrackingMetrics

    from gnnpmb.eval.failures import _split_with_scene, devkit_tracks

    if not scene_names:
        raise DataError("no scenes to score")
    tokens = [t for name in scene_names for t in scene_sample_tokens(nusc, name)]
    splits = {_split_with_scene(nusc, name) for name in scene_names}
    split = max(splits, key=lambda s: sum(_split_with_scene(nusc, n) == s for n in scene_names))
    cfg = tracking_config()
    with quiet_devkit():
        *_, tracks_gt, tracks_pred = devkit_tracks(nusc, tokens, results, split, cfg)
        metrics = TrackingMetrics(cfg)
        for class_name in cfg.class_names:
            md = class_evaluation(tracks_gt, tracks_pred, class_name, cfg).accumulate()
            if not np.all(np.isnan(md.mota)):
                best = int(np.nanargmax(md.mota))
                for metric in MOT_METRIC_MAP.values():
                    if metric:
                        metrics.add_label_metric(metric, class_name, md.get_metric(metric)[best])
            for metric, source in AVG_METRIC_MAP.items():
                values = np.array(md.get_metric(source), dtype=np.float64)
                if np.all(np.isnan(values)):
                    value = np.nan
                else:
                    values[np.isnan(values)] = cfg.metric_worst[metric]
                    value = float(np.nanmean(values))
                metrics.add_label_metric(metric, class_name, value)
        metrics.add_runtime(0.0)
        summary = metrics.serialize()
    label_metrics: dict[str, dict[str, float]] = summary["label_metrics"]
    per_class = {c: {m: float(label_metrics[m].get(c, np.nan)) for m in label_metrics} for c in cfg.class_names}
    overall = {m: float(summary[m]) for m in label_metrics}
    return per_class, overall
