"""Stage 6, the recording: the scene, every run's events drawn, their comparison, failures and focus.

``run_view`` takes the loaded inputs (``gnnpmb.stages.inputs``), runs every tracker once with its events recorded
(``gnnpmb.stages.runs``), finds their failures (``stages.evaluation``), the focus or the opening failure and the
comparison (``stages.findings``), and only then opens the recording: each run's recorded events are replayed into
its logger, which draws from the run's facts (``gnnpmb.why.facts``); a focus recording explains its failure.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import TYPE_CHECKING

from gnnpmb.stages.evaluation import find_reports
from gnnpmb.stages.findings import (
    all_evidence,
    compare_runs,
    explain_focus,
    where_to_open,
)
from gnnpmb.stages.inputs import Inputs
from gnnpmb.stages.runs import provenance_of, run_all, run_digests
from viz.opening import timeline_rows

if TYPE_CHECKING:
    from rich.progress import Progress

    from gnnpmb.compare import Comparison
    from gnnpmb.eval.failures import FailureReport
    from gnnpmb.focus import FocusTarget
    from gnnpmb.provenance import TrackDigest


@dataclass(frozen=True, slots=True)
class ViewResult:
    """What ``run_view`` did: mean tracker ms per frame and track digest per tracker, the comparison (None
    with one tracker), notices for the user (e.g. failures skipped), the focus and each tracker's failures
    (empty when not looked for)."""

    ms_per_frame: dict[str, float]
    digests: dict[str, TrackDigest]
    comparison: Comparison | None
    notices: tuple[str, ...]
    focus: FocusTarget | None = None
    reports: dict[str, FailureReport] = field(default_factory=dict)


def recording_name(inputs: Inputs, focus: FocusTarget | None = None) -> str:
    """E.g. "scene-0103 · gnnpmb vs pmbm · synthetic demo", with "· focus id_switch:1" for a focus."""
    data = "synthetic demo" if inputs.scene.synthetic else f"nuScenes {inputs.location.version}"
    name = f"{inputs.scene.name} · {' vs '.join(inputs.trackers)} · {data}"
    if focus is not None:
        name += f" · focus {focus.failure_id or inputs.focus}"
    return name


def run_view(
    inputs: Inputs,
    *,
    progress: Progress | None = None,
    failures: bool = True,
    cameras: bool = True,
    sweeps: bool = False,
) -> ViewResult:
    """Run every tracker once with its events recorded, find the failures (with ``failures``, or for a focus), the
    focus or the opening failure and the comparison, then log the scene, replay each run's events into its logger
    and log failures and provenance. With ``inputs.focus`` the recording holds the keyframes around the focus,
    opens on it and explains it (``focus/summary``). ``progress``: a rich ``Progress`` (none by default).
    ``cameras``: the camera images with the boxes projected into them (``viz.cameras``; where the dataset has them,
    else a notice); ``sweeps``: also the LiDAR sweeps between keyframes (a notice when there are none)."""
    import numpy as np
    from rich.progress import Progress

    from gnnpmb.data.nuscenes import load_lidar_points
    from gnnpmb.data.sensor_files import lidar_presence
    from viz.blueprint import default_blueprint, existence_word
    from viz.compare import log_comparison
    from viz.failures import log_failures
    from viz.logger import FLUSH_FRAMES, TrackerLogger
    from viz.opening import (
        LabelNotes,
        drawn_tracks,
        log_failure_index,
        log_failure_timeline,
        log_lost_tracks,
        lost_ghosts,
        view_eyes,
    )
    from viz.provenance import log_provenance
    from viz.recording import recording
    from viz.scene import lidar_notice, log_scene
    from viz.timeline import PLAIN_CLOCK, Clock

    scene, frame_range = inputs.scene, inputs.frame_range
    bar = progress if progress is not None else Progress(disable=True)
    with bar:
        tasks = {t: bar.add_task(f"{scene.name} {t}", total=len(frame_range)) for t in inputs.trackers}
        runs = run_all(inputs, record=True, on_frame=lambda t: lambda: bar.advance(tasks[t]))
        start, reports, notices = None, {}, []
        if inputs.focus is not None or failures:  # a full recording opens at its first failure worth a look
            reports, notices = find_reports(inputs, runs)
            start = where_to_open(inputs, runs, reports, notices)
        focus, opening = (start, None) if inputs.focus is not None else (None, start)
        shown = focus.window(frame_range) if focus is not None else frame_range
        # Missing LiDAR files are drawn around, said once (gnnpmb.data.sensor_files); damaged ones stay an error.
        lidar = lidar_presence(scene, shown)
        points_loader = None
        if not lidar.absent:
            points_loader = (
                load_lidar_points if lidar.complete else lambda k: load_lidar_points(k) if lidar.has(k.index) else None
            )
        sensors, channels, camera_notices = None, (), []
        if cameras or sweeps:
            from gnnpmb.data.sensors import absent_reason, load_scene_sensors

            sensors = load_scene_sensors(scene, shown)
            absent = absent_reason(sensors, shown) if cameras else None
            if absent is not None:
                camera_notices.append(absent)
            elif cameras:
                channels = sensors.channels
            if sweeps and not sensors.sweeps:
                camera_notices.append("sweeps absent: the dataset has no LiDAR sweeps between this scene's keyframes")
        sensor_note = lidar_notice(lidar)  # the sensor data first, then what is said of it
        notices = [*notices, *([sensor_note] if sensor_note is not None else []), *camera_notices]
        clock = Clock(focus_end=start.frame_index) if start is not None else PLAIN_CLOCK
        # A focus recording gets its layout once its series are known, so their legends can be placed clear of them.
        blueprint = None
        if focus is None:
            blueprint = default_blueprint(
                inputs.trackers,
                inputs.classes,
                caps=inputs.caps,
                opening=opening,
                failure_index=bool(reports),
                frames=shown,
                timeline_rows={t: len(timeline_rows(r, shown)) for t, r in reports.items()},
                cameras=channels,
            )
        loggers: dict[str, TrackerLogger] = {}
        comparison = None
        if inputs.serve is not None:
            from viz.serving import serving

            opened = serving(recording_name(inputs, focus), inputs.serve, blueprint)
        else:
            opened = recording(recording_name(inputs, focus), inputs.save, blueprint)
        with opened as stream:
            logged = "boxes and LiDAR" if points_loader is not None else "boxes (no LiDAR files)"
            sensors_task = bar.add_task(f"{scene.name} {logged}", total=len(shown))
            log_scene(
                stream,
                scene,
                [inputs.frame_detections[i] for i in shown],
                shown,
                points_loader=points_loader,
                on_frame=lambda: bar.advance(sensors_task),
                clock=clock,
                sensor_note=sensor_note,
            )
            if channels:
                from viz.camera_boxes import log_camera_boxes, scene_boxes
                from viz.cameras import log_cameras
                from viz.opening import drawn_tracks

                log_cameras(stream, scene, sensors, shown, clock)
                involved = {r.name: focus.object_ids(r.name) for r in runs} if focus is not None else None
                tracks = {run.name: drawn_tracks(run.tracking) for run in runs}
                boxes = scene_boxes(
                    scene, shown, [inputs.frame_detections[i] for i in shown], tracks, reports, involved
                )
                log_camera_boxes(stream, scene, sensors, shown, clock, boxes)
            if sweeps and sensors is not None and sensors.sweeps:
                from viz.cameras import log_sweeps

                log_sweeps(stream, scene, sensors, shown)
            for run in runs:
                logger = loggers[run.name] = TrackerLogger(
                    stream,
                    run.name,
                    gate_z_m=scene.ground_z_m,
                    clock=clock,
                    log_frames=shown if focus is not None else None,
                    focus_tracks=set(focus.track_ids.get(run.name, ())) if focus is not None else None,
                    flush_frames=None if inputs.save is not None else FLUSH_FRAMES,
                    has_existence=inputs.caps[run.name].has_existence,
                    existence_word=existence_word(inputs.caps[run.name]),
                    focus_class=focus.class_name if focus is not None else None,
                    facts=run.facts,
                    label_tracks=focus is not None,  # a full recording labels only what its failures note
                )
                run.replay(logger)
                logger.finish()
            notes = None
            if focus is None and reports:  # a full recording: one label per box, the lost tracks drawn (viz.opening)
                ghosts = {run.name: lost_ghosts(reports[run.name], run.tracking, run.facts, shown) for run in runs}
                strip_rows = max(len(timeline_rows(r, shown)) for r in reports.values())
                eyes = view_eyes(strip_rows, bool(channels), len(runs))
                notes = LabelNotes({run.name: drawn_tracks(run.tracking) for run in runs}, ghosts, eyes)
            if len(runs) > 1:
                comparison = compare_runs(runs)
                log_comparison(
                    stream,
                    comparison.within(shown),
                    scene,
                    clock,
                    show_labels=False,  # "only in one run" is the marker's colour; its words are a click away
                    focus_class=focus.class_name if focus is not None else None,
                )
            if failures or focus is not None:
                for k, (name, report) in enumerate(reports.items()):
                    log_failures(
                        stream,
                        name,
                        report,
                        scene,
                        shown,
                        clock,
                        show_labels=focus is None,
                        involved=focus.object_ids(name) if focus is not None else None,
                        focus_kind=focus.failure_kind if focus is not None else None,
                        notes=notes,
                    )
                    if notes is not None:
                        opened_id = opening.failure_id if opening is not None else None
                        log_failure_index(stream, name, report, opened_id, k == 0, shown)
                        log_lost_tracks(stream, name, ghosts[name], notes, scene, clock, shown)
                        log_failure_timeline(
                            stream, name, report, scene, clock, shown, opened_id if k == 0 else None, len(runs)
                        )
            if notes is not None:
                notes.send(stream, clock, scene)
            if focus is not None:
                from gnnpmb.focus_cameras import focus_sight
                from viz.focus import focus_legends, log_focus, tracker_views

                sight = focus_sight(focus, scene, sensors) if channels and sensors is not None else None
                evidence = all_evidence(inputs, runs, reports)
                finding = explain_focus(inputs, focus, evidence, first_frame=shown.start)
                log_focus(stream, focus, scene, tracker_views(evidence, loggers), loggers, clock, shown, finding, sight)
                legends = focus_legends(focus, loggers, comparison.within(shown) if comparison is not None else None)
                quiet = comparison is not None and not any(
                    d.class_name == focus.class_name and d.frame_index <= focus.frame_index
                    for d in comparison.within(shown).disagreements
                )
                stream.send_blueprint(
                    default_blueprint(
                        inputs.trackers,
                        inputs.classes,
                        focus,
                        legends,
                        inputs.caps,
                        cameras=channels,
                        focus_camera=sight.best_channel if sight is not None else None,
                        focus_class_quiet=quiet,
                    ),
                    make_active=True,
                    make_default=True,
                )
            digests = run_digests(runs)
            log_provenance(stream, provenance_of(inputs, digests))
    ms = {run.name: 1000.0 * float(np.mean([f.step_time_s for f in run.tracking.frames])) for run in runs}
    return ViewResult(ms, digests, comparison, (*inputs.notices, *notices), focus, reports)
