"""One ``gnnpmb-viz`` recording: the scene, every tracker's events drawn, their comparison, failures and focus.

``run_view`` is what ``gnnpmb-viz`` runs after ``gnnpmb.session.prepare`` checked the request. Each tracker's
events go through a ``TeeSink`` to its facts (``gnnpmb.why.facts.FactSink``) and then to its logger, which draws
from those facts; a focus recording then explains its failure from them (``gnnpmb.why.reason``).
"""

from __future__ import annotations

from gnnpmb.session import (
    ProgressBar,
    SilentProgress,
    ViewRequest,
    ViewResult,
    compare_runs,
    evidence_of,
    fact_sink,
    provenance_of,
    recording_name,
    resolve_opening,
    resolve_request_focus,
    run_digest,
    track_run,
)
from viz.opening import timeline_rows


def run_view(
    request: ViewRequest,
    *,
    progress: ProgressBar | None = None,
    failures: bool = True,
    cameras: bool = True,
    sweeps: bool = False,
) -> ViewResult:
    """Log the scene, run every tracker into one recording (sharing the preprocessed detections), compare them
    and log failures and provenance. With ``request.focus`` the trackers first run without logging to find the
    focus (``resolve_request_focus``); the recording then holds the keyframes around it, opens on it and explains
    it (``focus/summary``). ``progress``: a progress display (e.g. a rich ``Progress``; none by default).
    ``cameras``: the camera images with the boxes projected into them (``viz.cameras``; where the dataset has them,
    else a notice); ``sweeps``: also the LiDAR sweeps between keyframes (a notice when there are none)."""
    import numpy as np

    from gnnpmb.data.nuscenes import load_lidar_points
    from gnnpmb.events import TeeSink
    from gnnpmb.pipeline import TrackingRun
    from gnnpmb.why.reason import explain_failure
    from viz.blueprint import default_blueprint
    from viz.compare import log_comparison
    from viz.failures import log_failures
    from viz.focus import focus_legends, log_focus, tracker_views
    from viz.logger import FLUSH_FRAMES, TrackerLogger
    from viz.opening import (
        LabelNotes,
        drawn_tracks,
        log_failure_index,
        log_failure_timeline,
        log_lost_tracks,
        lost_ghosts,
    )
    from viz.provenance import log_provenance
    from viz.recording import recording
    from viz.scene import log_scene
    from viz.timeline import PLAIN_CLOCK, Clock

    scene, frame_range = request.scene, request.frame_range
    focus, opening, reports, notices = None, None, {}, []
    # The logged runs below give the same tracks (deterministic): the reports found first are reused.
    if request.focus is not None:
        focus, reports, notices = resolve_request_focus(request)
    elif failures:  # a full recording opens at its first failure worth a look (viz.opening)
        opening, reports, notices = resolve_opening(request)
    shown = focus.window(frame_range) if focus is not None else frame_range
    sensors, channels, sight = None, (), None
    if cameras or sweeps:
        from gnnpmb.data.sensors import load_scene_sensors
        from viz.cameras import absent_reason

        sensors = load_scene_sensors(scene, shown)
        absent = absent_reason(sensors, shown) if cameras else None
        if absent is not None:
            notices.append(absent)
        elif cameras:
            channels = sensors.channels
        if sweeps and not sensors.sweeps:
            notices.append("sweeps absent: the dataset has no LiDAR sweeps between this scene's keyframes")
    if focus is not None and channels:
        from gnnpmb.focus_cameras import focus_sight

        sight = focus_sight(focus, scene, sensors)
    start = focus or opening
    clock = Clock(focus_end=start.frame_index) if start is not None else PLAIN_CLOCK
    n = len(shown)
    # A focus recording gets its layout once its series are known, so their legends can be placed clear of them.
    caps = {t: request.capabilities(t) for t in request.trackers}
    blueprint = None
    if focus is None:
        blueprint = default_blueprint(
            request.trackers,
            request.classes,
            caps=caps,
            opening=opening,
            failure_index=bool(reports),
            frames=shown,
            timeline_rows={t: len(timeline_rows(r, shown)) for t, r in reports.items()},
            cameras=channels,
        )
    bar = progress if progress is not None else SilentProgress()
    runs: list[TrackingRun] = []
    loggers: dict[str, TrackerLogger] = {}
    facts = {}
    comparison = None
    if request.serve is not None:
        from viz.serving import serving

        opened = serving(recording_name(request, focus), request.serve, blueprint)
    else:
        opened = recording(recording_name(request, focus), request.save, blueprint)
    with opened as stream, bar:
        sensors_task = bar.add_task(f"{scene.name} sensors", total=n)
        log_scene(
            stream,
            scene,
            [request.frame_detections[i] for i in shown],
            shown,
            points_loader=load_lidar_points,
            on_frame=lambda: bar.advance(sensors_task),
            clock=clock,
        )
        if channels:
            from viz.cameras import log_cameras

            log_cameras(stream, scene, sensors, shown, clock)
        if sweeps and sensors is not None and sensors.sweeps:
            from viz.cameras import log_sweeps

            log_sweeps(stream, scene, sensors, shown)
        for tracker in request.trackers:
            task = bar.add_task(f"{scene.name} {tracker}", total=len(frame_range))
            sink = fact_sink(request, tracker)
            facts[tracker] = sink.facts
            logger = loggers[tracker] = TrackerLogger(
                stream,
                tracker,
                gate_z_m=scene.ground_z_m,
                clock=clock,
                log_frames=shown if focus is not None else None,
                focus_tracks=set(focus.track_ids.get(tracker, ())) if focus is not None else None,
                flush_frames=None if request.save is not None else FLUSH_FRAMES,
                has_existence=caps[tracker].has_existence,
                focus_class=focus.class_name if focus is not None else None,
                facts=sink.facts,
            )
            runs.append(track_run(request, tracker, TeeSink(sink, logger), lambda task=task: bar.advance(task)))
            logger.finish()
        notes = None
        if focus is None and reports:  # a full recording: one label per box, the lost tracks drawn (viz.opening)
            ghosts = {run.tracker: lost_ghosts(reports[run.tracker], run, facts[run.tracker], shown) for run in runs}
            notes = LabelNotes({run.tracker: drawn_tracks(run) for run in runs}, ghosts)
        if len(runs) > 1:
            comparison = compare_runs(runs)
            log_comparison(
                stream,
                comparison.within(shown),
                scene,
                clock,
                show_labels=focus is None,
                focus_class=focus.class_name if focus is not None else None,
                notes=notes,
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
                    opened = opening.failure_id if opening is not None else None
                    log_failure_index(stream, name, report, opened, k == 0, shown)
                    log_lost_tracks(stream, name, ghosts[name], notes, scene, clock, shown)
                    log_failure_timeline(stream, name, report, scene, clock, shown, opened if k == 0 else None)
        if notes is not None:
            notes.send(stream, clock, scene)
        if focus is not None:
            evidence = {
                run.tracker: evidence_of(request, reports[run.tracker], facts[run.tracker], run) for run in runs
            }
            finding = None
            if focus.failure_id is not None and focus.failure_tracker in evidence:
                owner = evidence[focus.failure_tracker]
                others = [ev for t, ev in evidence.items() if t != focus.failure_tracker]
                finding = explain_failure(focus.failure_id, owner, scene, others, first_frame=shown.start)
            log_focus(stream, focus, scene, tracker_views(evidence, loggers), loggers, clock, shown, finding, sight)
            legends = focus_legends(focus, loggers, comparison.within(shown) if comparison is not None else None)
            stream.send_blueprint(
                default_blueprint(
                    request.trackers,
                    request.classes,
                    focus,
                    legends,
                    caps,
                    cameras=channels,
                    focus_camera=sight.best_channel if sight is not None else None,
                ),
                make_active=True,
                make_default=True,
            )
        digests = {run.tracker: run_digest(run) for run in runs}
        log_provenance(stream, provenance_of(request, digests))
    ms = {run.tracker: 1000.0 * float(np.mean([f.step_time_s for f in run.frames])) for run in runs}
    return ViewResult(ms, digests, comparison, (*request.notices, *notices), focus, reports)
