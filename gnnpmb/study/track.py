"""Tracking a split, in this process or as Ray tasks: the one entry point of ``gnnpmb track`` (``track_to_file``);
``sweep`` and ``tune`` track through the same ``gnnpmb.study.data`` steps. (One scene's failures go through the
stages of ``gnnpmb.stages``.)

In this process each scene is read from the indexes and tracked in turn. On Ray this process reads each scene's
inputs (the scene and its detections, from the indexes) and sends them with the task, a few consecutive scenes
per task (``TASKS_PER_WORKER`` tasks per worker: fewer tasks, less of Ray's per-task cost on a small machine), so
a worker holds only its scenes and loads nothing. Every scene is tracked by the same deterministic code either
way and the runs are put back in split order, so the submission equals a one-worker run's byte for byte.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

from gnnpmb.config import TrackerConfig
from gnnpmb.study.data import SceneInputs, SceneRun, StudyData, load_inputs, track_inputs
from gnnpmb.study.runner import Execution, run_tasks, session

IN_PROCESS = Execution(workers=1)
TASKS_PER_WORKER = 4
"""Ray tasks per worker when the scenes are split among ``workers`` (one scene per task without a cap)."""


@dataclass(frozen=True, slots=True)
class ScenesTask:
    """Consecutive scenes of the split to track, with their inputs."""

    inputs: tuple[SceneInputs, ...]
    tracker: str
    config: TrackerConfig
    detector: str
    seed: int


def _track(task: ScenesTask) -> list[SceneRun]:
    return [track_inputs(i, task.tracker, task.config, task.detector, task.seed) for i in task.inputs]


def track_split(
    data: StudyData,
    tracker: str,
    config: TrackerConfig,
    run: Execution = IN_PROCESS,
    on_scene: Callable[[SceneRun], None] | None = None,
    on_frame: Callable[[], None] | None = None,
) -> list[SceneRun]:
    """Track every scene of ``data`` on ``run`` (Ray unless one worker); runs in split order. ``on_frame`` is
    called after each keyframe tracked in this process (not on Ray), ``on_scene`` after each scene."""
    if not run.uses_ray:
        runs = []
        for name in data.scene_names:
            runs.append(track_inputs(load_inputs(data, name), tracker, config, data.detector, data.seed, on_frame))
            if on_scene is not None:
                on_scene(runs[-1])
        return runs
    names = data.scene_names
    size = 1 if run.workers is None else -(-len(names) // (run.workers * TASKS_PER_WORKER))
    chunks = [names[i : i + size] for i in range(0, len(names), size)]
    tasks = (
        ScenesTask(tuple(load_inputs(data, n) for n in chunk), tracker, config, data.detector, data.seed)
        for chunk in chunks
    )
    done: dict[int, list[SceneRun]] = {}
    with session(run):
        for i, scene_runs in run_tasks(_track, tasks, run):
            done[i] = scene_runs
            if on_scene is not None:
                for scene_run in scene_runs:
                    on_scene(scene_run)
    return [r for i in range(len(chunks)) for r in done[i]]


@dataclass(frozen=True, slots=True)
class TrackSummary:
    """What ``track_to_file`` did: scenes, keyframes and boxes written, and the trackers' mean ms per frame."""

    scenes: int
    frames: int
    boxes: int
    ms_per_frame: float


def track_to_file(
    data: StudyData,
    tracker: str,
    config: TrackerConfig,
    out: Path,
    run: Execution = IN_PROCESS,
    on_scene: Callable[[SceneRun], None] | None = None,
    on_frame: Callable[[], None] | None = None,
) -> TrackSummary:
    """Track the split of ``data`` and write its nuScenes tracking submission to ``out`` (atomically)."""
    from gnnpmb.eval.submission import build_submission, write_submission

    runs = track_split(data, tracker, config, run, on_scene, on_frame)
    write_submission(out, build_submission([r.results for r in runs], data.sample_tokens))
    frames = sum(r.n_frames for r in runs)
    boxes = sum(len(b) for r in runs for b in r.results.values())
    step_s = sum(r.step_time_s for r in runs)
    return TrackSummary(len(runs), frames, boxes, 1e3 * step_s / max(frames, 1))
