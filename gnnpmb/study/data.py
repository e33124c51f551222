"""What a study tracks: a checked dataset split and detection source, and the per-scene tracking step that
``track``, ``failures``, ``sweep`` and ``tune`` all run.

A scene's inputs (``SceneInputs``: the scene and its detections) are read from the persistent indexes by the
process that plans the work (``load_inputs``), and tracking them (``track_inputs``) needs nothing else, so a Ray
worker receives data, not paths to reload: ``track --workers`` sends each task its one scene, and a sweep or tune
puts the split's inputs once in Ray's object store (``StudyData.inputs``). A simulated detector runs where the
scene is tracked (it needs only the scene and the seed).
"""

from __future__ import annotations

import hashlib
import json
from collections.abc import Callable
from dataclasses import dataclass, replace
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
    inputs: Any = None
    """The split's ``SceneInputs`` by scene name, or a Ray ``ObjectRef`` to them (``for_scoring``); None: read
    each scene from the indexes when needed."""
    evaluation: DatasetLocation | None = None
    """The version folder holding only the split's evaluation tables (``gnnpmb.data.eval_subset``; ``for_scoring``)."""


@dataclass(frozen=True, slots=True)
class SceneInputs:
    """One scene and its detections per sample token (None: the simulated preset, generated when tracked)."""

    scene: SceneData
    detections: dict[str, Boxes] | None


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
    from gnnpmb.data.nuscenes import sample_tokens, split_scenes
    from gnnpmb.eval.nuscenes_eval import check_split_version

    if detections is not None:
        from gnnpmb.data.detections import check_detection_file

        check_detection_file(detections)
    check_split_version(split, location.version)
    scene_names = split_scenes(split, location)
    if not scene_names:
        raise GnnpmbError(f"split {split} has no scenes in {location.dataroot / location.version}")
    return StudyData(
        location=location,
        split=split,
        scene_names=tuple(scene_names),
        sample_tokens=tuple(sample_tokens(location, scene_names)),
        detections=None if detections is None else detections.resolve(),
        detector=detector,
        seed=seed,
    )


def load_inputs(data: StudyData, scene_name: str) -> SceneInputs:
    """The scene from the dataset index and its detections from the detection file's index (only its samples)."""
    from gnnpmb.data.detections import load_detection_file
    from gnnpmb.data.nuscenes import load_scene

    scene = load_scene(data.location, scene_name)
    if data.detections is None:
        return SceneInputs(scene, None)
    return SceneInputs(scene, load_detection_file(data.detections, scene.sample_tokens, scene.name))


def for_scoring(data: StudyData, on_ray: bool) -> StudyData:
    """``data`` with the split's evaluation folder built, and ``on_ray`` every scene's inputs in Ray's object
    store (one copy, shared by the workers of a node): the configurations scored in workers load nothing."""
    from gnnpmb.data.eval_subset import eval_location

    data = replace(data, evaluation=eval_location(data.location, data.scene_names))
    if not on_ray:
        return data
    import ray

    return replace(data, inputs=ray.put({name: load_inputs(data, name) for name in data.scene_names}))


def study_inputs(data: StudyData, scene_name: str) -> SceneInputs:
    """The inputs of one scene of ``data``: carried (``for_scoring``) or read from the indexes."""
    if data.inputs is None:
        return load_inputs(data, scene_name)
    inputs = data.inputs
    if not isinstance(inputs, dict):
        import ray

        inputs = ray.get(inputs)
    return inputs[scene_name]


def track_inputs(
    inputs: SceneInputs,
    tracker: str,
    config: TrackerConfig,
    detector: str,
    seed: int,
    on_frame: Callable[[], None] | None = None,
) -> SceneRun:
    """Track every keyframe of one scene (all 7 classes) into submission boxes."""
    from gnnpmb.eval.submission import run_results
    from gnnpmb.pipeline import get_detections, run_tracker

    detections = inputs.detections
    if detections is None:
        detections = get_detections(inputs.scene, None, detector, seed)
    run = run_tracker(inputs.scene, detections, tracker, config, on_frame=on_frame)
    return SceneRun(
        scene_name=inputs.scene.name,
        results=run_results(run),
        n_frames=len(run.frames),
        step_time_s=sum(f.step_time_s for f in run.frames),
    )


_PREPARED: dict[tuple, SceneInputs] = {}
"""Per-process memo of scene inputs with their detections (a sweep tracks the same scenes for every
configuration; a Ray worker keeps it between tasks)."""


def track_scene(data: StudyData, scene_name: str, tracker: str, config: TrackerConfig) -> SceneRun:
    """Track one scene of ``data``, its inputs (simulated detections included) prepared once per process."""
    from gnnpmb.pipeline import get_detections

    key = (data.location, scene_name, data.detections, data.detector, data.seed)
    if key not in _PREPARED:
        inputs = study_inputs(data, scene_name)
        if inputs.detections is None:
            inputs = SceneInputs(inputs.scene, get_detections(inputs.scene, None, data.detector, data.seed))
        _PREPARED[key] = inputs
    return track_inputs(_PREPARED[key], tracker, config, data.detector, data.seed)


def inputs_fingerprint(data: StudyData) -> str:
    """SHA-256 of what the results depend on apart from parameters and code: dataset path, version, tables,
    split scenes, and the detections (a file's bytes, or the simulated preset and seed)."""
    from gnnpmb.data.detections import detection_file_sha256
    from gnnpmb.provenance import tables_fingerprint

    detections: Any = (
        {"file_sha256": detection_file_sha256(data.detections)}
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
