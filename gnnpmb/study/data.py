"""What a study tracks: a checked dataset split and detection source, picklable so Ray workers can use it, and
the per-scene tracking step that ``track --workers``, ``sweep`` and ``tune`` all run.

Workers receive the resolved dataroot path, not the demo cache lookup, so on a cluster the dataroot (and a
detection file) must be readable at the same path on every node.
"""

from __future__ import annotations

import hashlib
import json
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from gnnpmb.config import TrackerConfig
from gnnpmb.data.nuscenes import DatasetLocation
from gnnpmb.data.scene import SceneData
from gnnpmb.errors import GnnpmbError
from gnnpmb.types import Boxes


@dataclass(frozen=True, slots=True)
class StudyData:
    """A split of a checked dataset and where its detections come from (a file, else a simulated preset)."""

    location: DatasetLocation
    split: str
    scene_names: tuple[str, ...]
    sample_tokens: tuple[str, ...]
    detections: Path | None
    detector: str
    seed: int


@dataclass(frozen=True, slots=True)
class SceneRun:
    """One scene tracked: submission boxes per sample token, keyframes tracked, and the tracker's step time."""

    scene_name: str
    results: dict[str, list[dict[str, Any]]]
    n_frames: int
    step_time_s: float


def resolve_study_data(
    location: DatasetLocation, split: str, detections: Path | None, detector: str, seed: int
) -> StudyData:
    """Check the split against the dataset (as ``gnnpmb track`` does) and list its scenes and sample tokens."""
    from gnnpmb.data.nuscenes import open_nuscenes, split_scenes
    from gnnpmb.eval.nuscenes_eval import check_split_version, split_sample_tokens

    if detections is not None and not detections.is_file():
        raise GnnpmbError(f"detections file not found: {detections}")
    check_split_version(split, location.version)
    scene_names = split_scenes(split, location)
    if not scene_names:
        raise GnnpmbError(f"split {split} has no scenes in {location.dataroot / location.version}")
    nusc = open_nuscenes(location)
    tokens = split_sample_tokens(nusc, scene_names)
    return StudyData(
        location=location,
        split=split,
        scene_names=tuple(scene_names),
        sample_tokens=tuple(tokens),
        detections=None if detections is None else detections.resolve(),
        detector=detector,
        seed=seed,
    )


_SCENES: dict[tuple, tuple[SceneData, dict[str, Boxes]]] = {}
"""Per-process cache of loaded scenes and their detections (a Ray worker keeps it between tasks)."""


def scene_inputs(data: StudyData, scene_name: str) -> tuple[SceneData, dict[str, Boxes]]:
    """The scene and its detections, loaded once per process."""
    from gnnpmb.data.nuscenes import load_scene, open_nuscenes
    from gnnpmb.pipeline import get_detections

    key = (data.location, scene_name, data.detections, data.detector, data.seed)
    if key not in _SCENES:
        scene = load_scene(open_nuscenes(data.location), data.location, scene_name)
        _SCENES[key] = (scene, get_detections(scene, data.detections, data.detector, data.seed))
    return _SCENES[key]


def track_scene(data: StudyData, scene_name: str, tracker: str, config: TrackerConfig) -> SceneRun:
    """Track every keyframe of one scene (all 7 classes) into submission boxes."""
    from gnnpmb.eval.submission import run_results
    from gnnpmb.pipeline import run_tracker

    scene, detections = scene_inputs(data, scene_name)
    run = run_tracker(scene, detections, tracker, config)
    return SceneRun(
        scene_name=scene_name,
        results=run_results(run),
        n_frames=len(run.frames),
        step_time_s=sum(f.step_time_s for f in run.frames),
    )


def inputs_fingerprint(data: StudyData) -> str:
    """SHA-256 of what the results depend on apart from parameters and code: dataset path, version, tables,
    split scenes, and the detections (a file's bytes, or the simulated preset and seed)."""
    from gnnpmb.provenance import file_sha256, tables_fingerprint

    detections: Any = (
        {"file_sha256": file_sha256(data.detections)}
        if data.detections is not None
        else {"preset": data.detector, "seed": data.seed}
    )
    blob = {
        "dataroot": str(data.location.dataroot),
        "version": data.location.version,
        "tables": tables_fingerprint(data.location),
        "split": data.split,
        "scenes": list(data.scene_names),
        "detections": detections,
    }
    return hashlib.sha256(json.dumps(blob, sort_keys=True).encode()).hexdigest()
