"""``gnnpmb-viz``: track one nuScenes scene and watch every step of the tracker(s) in Rerun.

Everything the user typed is checked before a recording is opened (names, --frames, files, the dataset), so a
mistake costs one line on stderr and leaves no ``.rrd`` behind.
"""

from __future__ import annotations

import re
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Annotated

import numpy as np
import typer

from cli.errors import entry_point
from gnnpmb.config import TrackerConfig, load_config
from gnnpmb.data.scene import SceneData
from gnnpmb.errors import DataError, GnnpmbError
from gnnpmb.registry import TRACKER_NAMES, check_classes, check_tracker
from gnnpmb.types import TRACKING_CLASSES, Boxes, FrameDetections

DEFAULT_TRACKER = "gnnpmb"
DEFAULT_DETECTOR = "centerpoint"
_FRAMES_RE = re.compile(r"^\s*(\d*)\s*:\s*(\d*)\s*$")

app = typer.Typer(
    add_completion=False,
    help="Track a nuScenes scene and inspect every step of the tracker(s) in the Rerun viewer.",
    pretty_exceptions_enable=False,
)


@dataclass(frozen=True, slots=True)
class ViewRequest:
    """Everything one ``gnnpmb-viz`` run needs, checked: no recording is opened before this exists."""

    scene: SceneData
    trackers: tuple[str, ...]
    classes: tuple[str, ...]
    frame_range: range
    config: TrackerConfig
    detections: dict[str, Boxes]
    frame_detections: list[FrameDetections]
    save: Path | None


def parse_frames(text: str | None) -> tuple[int | None, int | None]:
    """``START:END`` (END exclusive, either side may be empty) -> (start, end); None -> (None, None)."""
    if text is None:
        return None, None
    match = _FRAMES_RE.match(text)
    if match is None:
        raise GnnpmbError(f"bad --frames '{text}': use START:END with keyframe indices, e.g. --frames 0:20")
    start, end = (int(g) if g else None for g in match.groups())
    if start is not None and end is not None and end <= start:
        raise GnnpmbError(f"bad --frames '{text}': END must be greater than START (END is exclusive)")
    return start, end


def frame_range_of(bounds: tuple[int | None, int | None], scene: SceneData) -> range:
    """The keyframes selected by parsed --frames bounds, checked against the scene's length."""
    n = len(scene.keyframes)
    start = 0 if bounds[0] is None else bounds[0]
    end = n if bounds[1] is None else bounds[1]
    if n == 0:
        raise DataError(f"{scene.name} has no keyframes")
    if start >= n or end > n:
        raise GnnpmbError(
            f"--frames {start}:{end} is outside {scene.name}, which has keyframes 0 to {n - 1} (use END <= {n})"
        )
    if end <= start:
        raise GnnpmbError(f"--frames {start}:{end} selects no keyframes; END must be greater than START")
    return range(start, end)


def parse_classes(text: str | None) -> tuple[str, ...]:
    """``car,bus`` -> ("car", "bus"), checked; None -> all seven tracking classes."""
    if text is None:
        return TRACKING_CLASSES
    names = [n.strip() for n in text.split(",") if n.strip()]
    return tuple(dict.fromkeys(check_classes(names)))


def prepare(
    scene_name: str,
    trackers: Sequence[str],
    dataroot: Path | None,
    version: str | None,
    detections_file: Path | None,
    detector: str,
    seed: int,
    params: Path | None,
    classes: str | None,
    frames: str | None,
    save: Path | None,
) -> ViewRequest:
    """Check every argument and load the scene and detections; raises GnnpmbError with a one-line message."""
    from gnnpmb.data.nuscenes import load_scene, open_nuscenes, resolve_dataroot
    from gnnpmb.data.simdet import get_preset
    from gnnpmb.pipeline import get_detections, preprocess_frames
    from viz.recording import check_save_path

    names = tuple(dict.fromkeys(check_tracker(t) for t in (trackers or [DEFAULT_TRACKER])))
    get_preset(detector)
    class_names = parse_classes(classes)
    bounds = parse_frames(frames)
    config = load_config(params)
    target = check_save_path(save) if save is not None else None
    location = resolve_dataroot(dataroot, version)
    scene = load_scene(open_nuscenes(location), location, scene_name)
    frame_range = frame_range_of(bounds, scene)
    detections = get_detections(scene, detections_file, detector, seed)
    frame_detections = preprocess_frames(scene, detections, config, class_names)
    return ViewRequest(scene, names, class_names, frame_range, config, detections, frame_detections, target)


def run_view(request: ViewRequest, *, progress: bool = True) -> dict[str, float]:
    """Log the scene and run every tracker into one recording; returns mean tracker ms per frame by tracker."""
    from rich.console import Console
    from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn, TimeElapsedColumn

    from gnnpmb.data.nuscenes import load_lidar_points
    from gnnpmb.pipeline import run_tracker
    from viz.blueprint import default_blueprint
    from viz.logger import TrackerLogger
    from viz.recording import recording
    from viz.scene import log_scene

    scene, frame_range = request.scene, request.frame_range
    n = len(frame_range)
    gate_z_m = float(np.median([k.ego_pose.translation_m[2] for k in scene.keyframes]))
    blueprint = default_blueprint(request.trackers, request.classes)
    bar = Progress(
        TextColumn("{task.description}"),
        BarColumn(),
        MofNCompleteColumn(),
        TimeElapsedColumn(),
        console=Console(stderr=True),
        disable=not progress,
    )
    ms_per_frame: dict[str, float] = {}
    name = f"{scene.name} {'+'.join(request.trackers)}"
    with recording(name, request.save, blueprint) as stream, bar:
        sensors = bar.add_task(f"{scene.name} sensors", total=n)
        log_scene(
            stream,
            scene,
            [request.frame_detections[i] for i in frame_range],
            frame_range,
            points_loader=load_lidar_points,
            on_frame=lambda: bar.advance(sensors),
        )
        for tracker in request.trackers:
            task = bar.add_task(f"{scene.name} {tracker}", total=n)
            logger = TrackerLogger(stream, tracker, gate_z_m=gate_z_m)
            run = run_tracker(
                scene,
                request.detections,
                tracker,
                request.config,
                sink=logger,
                classes=request.classes,
                frame_range=frame_range,
                on_frame=lambda task=task: bar.advance(task),
                frame_detections=request.frame_detections,
            )
            logger.finish()
            ms_per_frame[tracker] = 1000.0 * float(np.mean([f.step_time_s for f in run.frames]))
    return ms_per_frame


@app.command()
def view(
    scene: Annotated[str, typer.Argument(help="Scene name, e.g. scene-0103.")],
    tracker: Annotated[
        list[str] | None,
        typer.Option(
            "--tracker", "-t", metavar="NAME", help=f"Tracker to run; repeat for several ({', '.join(TRACKER_NAMES)})."
        ),
    ] = None,
    dataroot: Annotated[
        Path | None,
        typer.Option(metavar="DIR", help="nuScenes dataroot (default: $NUSCENES_DATAROOT, else the built-in demo)."),
    ] = None,
    version: Annotated[str | None, typer.Option(metavar="V", help="Dataset version folder, e.g. v1.0-mini.")] = None,
    detections: Annotated[
        Path | None,
        typer.Option(metavar="FILE.json", help="nuScenes detection results .json (default: a simulated detector)."),
    ] = None,
    detector: Annotated[
        str, typer.Option(metavar="PRESET", help="Simulated detector preset: centerpoint, megvii or pointpillars.")
    ] = DEFAULT_DETECTOR,
    seed: Annotated[int, typer.Option(metavar="N", help="Seed of the simulated detector.")] = 0,
    params: Annotated[
        Path | None, typer.Option(metavar="FILE.toml", help="Tracker parameter file (.toml) overriding the paper's.")
    ] = None,
    classes: Annotated[
        str | None,
        typer.Option(
            metavar="CLASS,...", help=f"Comma-separated classes to track (default all: {','.join(TRACKING_CLASSES)})."
        ),
    ] = None,
    frames: Annotated[
        str | None, typer.Option(metavar="START:END", help="Keyframes START:END (END exclusive), e.g. 0:20.")
    ] = None,
    save: Annotated[
        Path | None, typer.Option(metavar="OUT.rrd", help="Write the recording to this .rrd instead of a viewer.")
    ] = None,
    progress: Annotated[bool, typer.Option(help="Show a progress bar on stderr.")] = True,
) -> None:
    """Track SCENE and stream the recording to a Rerun viewer (or save it with --save)."""
    request = prepare(
        scene, tracker or [], dataroot, version, detections, detector, seed, params, classes, frames, save
    )
    ms = run_view(request, progress=progress)
    timing = ", ".join(f"{name} {value:.1f} ms/frame" for name, value in ms.items())
    output = f"saved {request.save}" if request.save is not None else "streamed to the Rerun viewer"
    typer.echo(f"{request.scene.name}: {len(request.frame_range)} frames, {timing}; {output}")


main = entry_point(app)
