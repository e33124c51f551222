"""The official nuScenes tracking evaluation (the devkit's ``TrackingEval``), made quiet and safe.

Scores are the devkit's own: config ``tracking_nips_2019`` (2 m centre-distance matching, 40 recall
thresholds, class ranges 50 m for vehicles and 40 m for pedestrians and two-wheelers). AMOTA/AMOTP average
over the recall thresholds; MOTA, MOTP, MT, ML, TP, FP, FN, IDS and FRAG are read at the threshold with the
best MOTA (Weng et al. 2020, "AB3DMOT"; Caesar et al. 2020, "nuScenes"). This module checks the submission
first (``check_submission``) so a bad file fails with one clear line instead of an assert inside the devkit,
silences the devkit's printing, and writes its output files (``metrics_summary.json``,
``metrics_details.json``) atomically.
"""

from __future__ import annotations

import contextlib
import importlib.util
import io
import json
import math
import shutil
import tempfile
import warnings
from collections.abc import Callable, Collection, Iterator, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

from gnnpmb.atomic import finish, temp_prefix
from gnnpmb.errors import DataError, NotThisDatasetError
from gnnpmb.eval.submission import check_submission, read_submission

if TYPE_CHECKING:
    from nuscenes import NuScenes
    from nuscenes.eval.tracking.data_classes import TrackingConfig

    from gnnpmb.data.nuscenes import DatasetLocation

EVAL_CONFIG = "tracking_nips_2019"
"""The devkit config every score here is computed with."""

TABLE_METRICS: tuple[str, ...] = (
    "amota",
    "amotp",
    "mota",
    "motp",
    "recall",
    "mt",
    "ml",
    "tp",
    "fp",
    "fn",
    "ids",
    "frag",
)
"""The metrics shown in the results table, as named in the devkit's ``metrics_summary.json``."""

COUNT_METRICS = frozenset({"mt", "ml", "tp", "fp", "fn", "ids", "frag"})
"""Metrics that are counts (summed over classes in the overall row); the others are averaged."""

DEVKIT_FILES = ("metrics_summary.json", "metrics_details.json")


@contextlib.contextmanager
def quiet_devkit() -> Iterator[None]:
    """Silence the devkit: its prints (stdout), tqdm bars and pandas/motmetrics warnings (stderr)."""
    with (
        contextlib.redirect_stdout(io.StringIO()),
        contextlib.redirect_stderr(io.StringIO()),
        warnings.catch_warnings(),
    ):
        warnings.simplefilter("ignore")
        yield


def tracking_config() -> TrackingConfig:
    """The official ``tracking_nips_2019`` config. Creating it also registers the devkit's tracking class
    names, which ``TrackingBox`` checks against."""
    from nuscenes.eval.common.config import config_factory

    return config_factory(EVAL_CONFIG)


def tracking_config_file() -> dict[str, Any]:
    """The official ``tracking_nips_2019`` config as the devkit ships it (its JSON file), read without importing
    the devkit, whose package loads scikit-learn, matplotlib and OpenCV (1.4 s): for settings that need no
    evaluation, e.g. the class ranges (``tracking_config`` for the evaluation itself)."""
    spec = importlib.util.find_spec("nuscenes")
    if spec is None or not spec.submodule_search_locations:
        raise DataError("the nuScenes devkit is not installed (pip install nuscenes-devkit)")
    folder = Path(next(iter(spec.submodule_search_locations)))
    return json.loads((folder / "eval" / "tracking" / "configs" / f"{EVAL_CONFIG}.json").read_text(encoding="utf-8"))


def class_evaluation(tracks_gt: Any, tracks_pred: Any, class_name: str, cfg: TrackingConfig) -> Any:
    """The devkit's ``TrackingEvaluation`` of one class with the config's settings, exactly as ``TrackingEval``
    builds it (40 recall thresholds, the official distance function and thresholds), quiet."""
    from nuscenes.eval.tracking.algo import TrackingEvaluation
    from nuscenes.eval.tracking.data_classes import TrackingMetricData

    return TrackingEvaluation(
        tracks_gt,
        tracks_pred,
        class_name,
        cfg.dist_fcn_callable,
        cfg.dist_th_tp,
        cfg.min_recall,
        num_thresholds=TrackingMetricData.nelem,
        metric_worst=cfg.metric_worst,
        verbose=False,
    )


def default_split(version: str) -> str:
    """The evaluation split of a version: mini_val for *mini, test for *test, else val."""
    if version.endswith("mini"):
        return "mini_val"
    if version.endswith("test"):
        return "test"
    return "val"


def resolve_split(dataroot: Path | None, version: str | None, split: str | None) -> tuple[DatasetLocation, str]:
    """The dataset (``data.nuscenes.resolve_dataroot``, asked for ``split`` when one is named) and the split:
    ``split``, else the version's evaluation split (``default_split``)."""
    from gnnpmb.data.nuscenes import resolve_dataroot

    location = resolve_dataroot(dataroot, version, (split,) if split else ())
    return location, split or default_split(location.version)


def check_split_version(split: str, version: str) -> None:
    """The devkit evaluates mini splits only on a ``*mini`` version, train/val on ``*trainval``, test on
    ``*test``; custom splits (``splits.json``) on any version."""
    from gnnpmb.data.nuscenes import SPLIT_VERSION_SUFFIX, split_fits_version

    if not split_fits_version(split, version):
        suffix = SPLIT_VERSION_SUFFIX[split]
        raise DataError(
            f"split {split} cannot be evaluated on dataset version {version}; use a version ending in "
            f"'{suffix}' (e.g. v1.0-{suffix}) or a split of {version}"
        )


def scene_sample_tokens(nusc: NuScenes, scene_name: str) -> list[str]:
    """The sample tokens of one scene in time order (following the devkit's ``next`` links)."""
    for scene in nusc.scene:
        if scene["name"] == scene_name:
            tokens = []
            token = scene["first_sample_token"]
            while token:
                tokens.append(token)
                token = nusc.get("sample", token)["next"]
            return tokens
    raise DataError(f"scene {scene_name} is not in dataset {nusc.version} at {nusc.dataroot}")


def split_sample_tokens(nusc: NuScenes, scene_names: Sequence[str]) -> list[str]:
    """Every sample token of the given scenes, scene by scene in time order."""
    tokens: list[str] = []
    for name in scene_names:
        tokens.extend(scene_sample_tokens(nusc, name))
    return tokens


def default_eval_dir(results_path: Path) -> Path:
    """Where ``gnnpmb eval`` writes the devkit's files by default: ``<stem>_eval/`` next to the results."""
    results_path = Path(results_path)
    return results_path.with_name(f"{results_path.stem}_eval")


@dataclass(frozen=True, slots=True)
class TrackingScores:
    """The devkit's metrics: per_class[class][metric] and overall[metric] (NaN where a class has no ground
    truth), with the evaluation time and where ``metrics_summary.json`` was written."""

    per_class: dict[str, dict[str, float]]
    overall: dict[str, float]
    eval_time_s: float
    summary_path: Path

    @staticmethod
    def from_summary(summary: dict[str, Any], summary_path: Path) -> TrackingScores:
        """Read the devkit's ``metrics_summary.json`` content."""
        label_metrics: dict[str, dict[str, float]] = summary["label_metrics"]
        classes = sorted(next(iter(label_metrics.values())))
        per_class = {c: {m: float(label_metrics[m][c]) for m in label_metrics} for c in classes}
        overall = {m: float(summary[m]) for m in label_metrics}
        return TrackingScores(per_class, overall, float(summary["eval_time"]), summary_path)


def run_tracking_eval(results_path: Path, dataroot: Path, version: str, split: str, out_dir: Path) -> TrackingScores:
    """Run ``TrackingEval`` quietly (no curves) and move its files into ``out_dir`` atomically.

    The devkit writes into a temporary folder beside ``out_dir``; each file then replaces its old version with
    ``os.replace``, so a failed run leaves ``out_dir`` as it was. Check the submission first
    (``check_submission``): the devkit's own checks are bare asserts, turned into ``DataError`` here.
    """
    from nuscenes.eval.tracking.evaluate import TrackingEval

    out_dir = Path(out_dir)
    out_dir.parent.mkdir(parents=True, exist_ok=True)
    tmp = Path(tempfile.mkdtemp(prefix=temp_prefix(out_dir, "build"), dir=out_dir.parent))
    try:
        with quiet_devkit():
            cfg = tracking_config()
            try:
                evaluation = TrackingEval(
                    config=cfg,
                    result_path=str(results_path),
                    eval_set=split,
                    output_dir=str(tmp),
                    nusc_version=version,
                    nusc_dataroot=str(dataroot),
                    verbose=False,
                )
                summary = evaluation.main(render_curves=False)
            except (AssertionError, ValueError, KeyError) as exc:
                raise DataError(f"the nuScenes evaluation rejected {Path(results_path).name}: {exc}") from None
        out_dir.mkdir(parents=True, exist_ok=True)
        for name in DEVKIT_FILES:
            finish(tmp / name, out_dir / name)  # the one output file mode (gnnpmb.atomic)
    finally:
        shutil.rmtree(tmp, ignore_errors=True)
    return TrackingScores.from_summary(summary, out_dir / DEVKIT_FILES[0])


def evaluate_submission(
    results_path: Path, location: DatasetLocation, split: str, out_dir: Path | None = None
) -> TrackingScores:
    """Check ``results_path`` against ``split`` of the dataset at ``location``, then score it with the
    official evaluation, on a version folder holding only the split's evaluation tables
    (``gnnpmb.data.eval_subset``); the devkit's files go to ``out_dir`` (default ``default_eval_dir(results_path)``)."""
    from gnnpmb.data.eval_subset import eval_location
    from gnnpmb.data.nuscenes import all_sample_tokens, dataset_index, sample_tokens, split_scenes

    results_path = Path(results_path)
    check_split_version(split, location.version)
    data = read_submission(results_path)  # a broken file fails before the devkit's slow import
    scene_names = split_scenes(split, location)
    if not scene_names:
        raise DataError(f"split {split} has no scenes in {location.dataroot / location.version}; pick another split")
    index = dataset_index(location)
    if not any(index.tracked_annotations(name) for name in scene_names):
        raise DataError(
            f"split {split} of {location.dataroot} has no ground truth: {location.version}/sample_annotation.json "
            f"holds no annotation of a tracked class in its {len(scene_names)} scenes (as in a test split); the "
            "official evaluation needs ground truth to score against"
        )
    try:
        check_submission(
            data,
            results_path.name,
            split,
            sample_tokens(location, scene_names),
            _LazyTokens(lambda: all_sample_tokens(location)),
        )
    except NotThisDatasetError as exc:
        raise NotThisDatasetError(f"{exc}{split_hint(location, data.get('results', {}), split)}") from None
    del data
    evaluated = eval_location(location, scene_names)
    return run_tracking_eval(
        results_path, evaluated.dataroot, evaluated.version, split, out_dir or default_eval_dir(results_path)
    )


def split_hint(location: DatasetLocation, results: Any, split: str) -> str:
    """`` It holds the N samples of split X: pass --split X`` when ``results`` (a submission's samples) are exactly
    those of another split X of the dataset than ``split``; else empty."""
    from gnnpmb.data.nuscenes import sample_tokens, split_names, split_scenes

    if not isinstance(results, Mapping) or not results:
        return ""
    for name in split_names(location):
        scenes = split_scenes(name, location) if name != split else []
        if scenes and set(sample_tokens(location, scenes)) == set(results):
            return f" It holds the {len(results)} samples of split {name}: pass --split {name}"
    return ""


class _LazyTokens(Collection[str]):
    """Every sample token of the dataset, read only when asked (a submission with samples of other splits)."""

    def __init__(self, load: Callable[[], set[str]]) -> None:
        self._load = load
        self._tokens: set[str] | None = None

    def _get(self) -> set[str]:
        if self._tokens is None:
            self._tokens = self._load()
        return self._tokens

    def __contains__(self, token: object) -> bool:
        return token in self._get()

    def __iter__(self) -> Iterator[str]:
        return iter(self._get())

    def __len__(self) -> int:
        return len(self._get())


def format_metric(metric: str, value: float) -> str:
    """A metric as the devkit prints it: 3 decimals for ratios and distances, integers for counts."""
    if value is None or (isinstance(value, float) and math.isnan(value)):
        return "-"
    return f"{int(round(value))}" if metric in COUNT_METRICS else f"{value:.3f}"
