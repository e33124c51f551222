"""Score a tracker and a config on a demo split with the official evaluation: the loop shared by
``table1.py`` and ``tune_mini_train.py``."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from gnnpmb.config import TrackerConfig
from gnnpmb.data.nuscenes import DatasetLocation, load_scene, open_nuscenes, resolve_dataroot, split_scenes
from gnnpmb.data.scene import SceneData
from gnnpmb.eval.nuscenes_eval import TrackingScores, evaluate_submission, split_sample_tokens
from gnnpmb.eval.submission import build_submission, run_results, write_submission
from gnnpmb.pipeline import get_detections, run_tracker
from gnnpmb.types import Boxes


@dataclass(frozen=True, slots=True)
class DemoSplit:
    """A split of the demo dataset, loaded once: its scenes and sample tokens."""

    split: str
    location: DatasetLocation
    scenes: tuple[SceneData, ...]
    tokens: tuple[str, ...]

    @staticmethod
    def load(split: str, dataroot: Path | None = None, version: str | None = None) -> DemoSplit:
        """The demo's ``split``, or the split of the dataset at ``dataroot`` (e.g. the dev set)."""
        location = resolve_dataroot(dataroot, version, (split,))
        nusc = open_nuscenes(location)
        names = split_scenes(split, location)
        scenes = tuple(load_scene(location, n) for n in names)
        return DemoSplit(split, location, scenes, tuple(split_sample_tokens(nusc, names)))

    def detections(self, preset: str, seed: int, detections_file: Path | None = None) -> list[dict[str, Boxes]]:
        """Per scene: the detections of ``detections_file``, else the simulated detector ``preset``."""
        return [get_detections(s, detections_file, preset, seed) for s in self.scenes]


@dataclass(frozen=True, slots=True)
class RunScores:
    """Overall scores of one run and its per-frame tracker times (ms)."""

    scores: TrackingScores
    step_ms: np.ndarray


def score(
    split: DemoSplit, detections: Sequence[dict[str, Boxes]], tracker: str, config: TrackerConfig, out: Path
) -> RunScores:
    """Track every scene of ``split`` and score the submission (files under ``out``)."""
    runs = [run_tracker(s, d, tracker, config) for s, d in zip(split.scenes, detections, strict=True)]
    out.parent.mkdir(parents=True, exist_ok=True)
    path = out.with_suffix(".json")
    write_submission(path, build_submission([run_results(r) for r in runs], list(split.tokens)))
    scores = evaluate_submission(path, split.location, split.split, out.with_name(out.name + "_eval"))
    return RunScores(scores, np.array([f.step_time_s for r in runs for f in r.frames]) * 1e3)
