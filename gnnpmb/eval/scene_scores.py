"""The official tracking metrics of a set of scenes (one scene, or a split), computed in memory.

``TrackingEval`` scores a whole split named in the devkit (or in a ``splits.json`` beside the dataset); comparing two
runs on one scene, or on a split without writing files, needs the same numbers for any scenes. This module runs the
devkit's own steps on the scenes' samples, as ``TrackingEval.evaluate`` does: ground truth and predictions loaded
and filtered by its loaders (class ranges, boxes without points, bike racks), tracks built with averaged scores and
interpolation (``create_tracks``), each class accumulated by ``TrackingEvaluation`` over 40 recall thresholds and
read as the devkit reads it (``eval.official_scores``). On a whole split it gives what
``gnnpmb eval`` prints (tested).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import TYPE_CHECKING, Any

from gnnpmb.errors import DataError
from gnnpmb.eval.nuscenes_eval import class_evaluation, quiet_devkit, scene_sample_tokens, tracking_config
from gnnpmb.eval.official_scores import Overall, PerClass, official_scores

if TYPE_CHECKING:
    from nuscenes import NuScenes


def scene_scores(
    nusc: NuScenes, scene_names: Sequence[str], results: Mapping[str, Sequence[Mapping[str, Any]]]
) -> tuple[PerClass, Overall]:
    """(per class {metric: value}, overall {metric: value}) of ``results`` (submission boxes by sample token; a
    sample without an entry counts as empty) on ``scene_names`` (all in one devkit or custom split), as named in
    the devkit's ``metrics_summary.json``; NaN where a class has no ground truth. One scene's figures come with
    its failure report too (``FailureReport.scores``), from the same accumulation."""
    from gnnpmb.eval.failures import _split_with_scene, devkit_tracks

    if not scene_names:
        raise DataError("no scenes to score")
    tokens = [t for name in scene_names for t in scene_sample_tokens(nusc, name)]
    splits = {_split_with_scene(nusc, name) for name in scene_names}
    split = max(splits, key=lambda s: sum(_split_with_scene(nusc, n) == s for n in scene_names))
    cfg = tracking_config()
    with quiet_devkit():
        *_, tracks_gt, tracks_pred = devkit_tracks(nusc, tokens, results, split, cfg)
        class_data = [(c, class_evaluation(tracks_gt, tracks_pred, c, cfg).accumulate()) for c in cfg.class_names]
        return official_scores(class_data, cfg).as_floats()
