"""``gnnpmb track --workers N``: the scenes of a split tracked as parallel Ray tasks, one scene per task.

Every scene is tracked by the same deterministic code as in one process, and the runs are put back in split
order, so the submission equals a one-worker run's byte for byte.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

from gnnpmb.config import TrackerConfig
from gnnpmb.study.data import SceneRun, StudyData, track_scene
from gnnpmb.study.runner import Execution, run_tasks, session


@dataclass(frozen=True, slots=True)
class SceneTask:
    """One scene of the split to track."""

    data: StudyData
    scene_name: str
    tracker: str
    config: TrackerConfig


def _track(task: SceneTask) -> SceneRun:
    return track_scene(task.data, task.scene_name, task.tracker, task.config)


def track_scenes(
    data: StudyData,
    tracker: str,
    config: TrackerConfig,
    run: Execution,
    on_scene: Callable[[SceneRun], None] | None = None,
) -> list[SceneRun]:
    """Track every scene of ``data`` on ``run`` (Ray unless one worker); runs in split order."""
    tasks = [SceneTask(data, name, tracker, config) for name in data.scene_names]
    runs: dict[int, SceneRun] = {}
    with session(run):
        for i, scene_run in run_tasks(_track, tasks, run):
            runs[i] = scene_run
            if on_scene is not None:
                on_scene(scene_run)
    return [runs[i] for i in range(len(tasks))]
