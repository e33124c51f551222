"""The official tracking metrics from the devkit's per-class accumulation, as ``TrackingEval.evaluate`` reads them.

Per class, ``TrackingEvaluation.accumulate`` gives each metric at 40 recall thresholds; the traditional metrics
(``MOT_METRIC_MAP``: MOTA, MOTP, TP, FP, FN, IDS, FRAG...) are read at the best-MOTA threshold and AMOTA / AMOTP
(``AVG_METRIC_MAP``) averaged over the thresholds with the config's worst value where one is not reached; then
``TrackingMetrics`` gives the overall means and sums (Caesar et al. 2020, "nuScenes"). One accumulation of a run
gives both these figures and its failures (``eval.failures.find_failures``).
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

if TYPE_CHECKING:
    from nuscenes.eval.tracking.data_classes import TrackingConfig, TrackingMetricData

PerClass = dict[str, dict[str, float]]
Overall = dict[str, float]


@dataclass(frozen=True, slots=True)
class OfficialScores:
    """The official metrics of some keyframes, named as in the devkit's ``metrics_summary.json``.

    per_class: (class name, {metric: value}) in the config's class order; overall: {metric: value}; None stands for
    the devkit's NaN (a class without ground truth), so that scores read back from JSON compare equal."""

    per_class: tuple[tuple[str, Mapping[str, float | None]], ...]
    overall: Mapping[str, float | None]

    def as_floats(self) -> tuple[PerClass, Overall]:
        """(per class {metric: value}, overall {metric: value}) with NaN for None (``eval.scene_scores``' form)."""

        def floats(values: Mapping[str, float | None]) -> dict[str, float]:
            return {m: math.nan if v is None else v for m, v in values.items()}

        return {c: floats(v) for c, v in self.per_class}, floats(self.overall)

    def to_json(self) -> dict[str, Any]:
        return {"per_class": [[c, dict(v)] for c, v in self.per_class], "overall": dict(self.overall)}

    @staticmethod
    def from_json(data: Mapping[str, Any]) -> OfficialScores:
        def numbers(values: Mapping[str, Any]) -> dict[str, float | None]:
            return {str(m): None if v is None else float(v) for m, v in values.items()}

        return OfficialScores(tuple((str(c), numbers(v)) for c, v in data["per_class"]), numbers(data["overall"]))


def official_scores(class_data: Sequence[tuple[str, TrackingMetricData]], cfg: TrackingConfig) -> OfficialScores:
    """The official metrics from each class's accumulated metric data (``TrackingEvaluation.accumulate``, one per
    class of ``cfg``, in its order); call it inside ``nuscenes_eval.quiet_devkit``."""
    from nuscenes.eval.tracking.constants import AVG_METRIC_MAP, MOT_METRIC_MAP
    from nuscenes.eval.tracking.data_classes import TrackingMetrics

    metrics = TrackingMetrics(cfg)
    for class_name, md in class_data:
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
    per_class = tuple(
        (c, {m: json_number(label_metrics[m].get(c, np.nan)) for m in label_metrics}) for c in cfg.class_names
    )
    return OfficialScores(per_class, {m: json_number(summary[m]) for m in label_metrics})


def json_number(value: Any) -> float | None:
    """``value`` as a float, None for NaN (what JSON and the tables show as undefined)."""
    return None if np.isnan(value) else float(value)
