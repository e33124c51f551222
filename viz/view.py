"""One ``gnnpmb-viz`` recording: the scene, every tracker's events drawn, their comparison, failures and focus.

``run_view`` is what ``gnnpmb-viz`` runs after ``gnnpmb.session.prepare`` checked the request. Each tracker's
events go through a ``TeeSink`` to its facts (``gnnpmb.why.facts.FactSink``) and then to its logger, which draws
from those facts; a focus recording then explains its failure from them (``gnnpmb.why.reason``).
"""

from __future__ import annotations

from gnnpmb.registry import tracker_has_existence
from gnnpmb.session import (
    ProgressBar,
    SilentProgress,
    ViewRequest,
    ViewResult,
    compare_runs,
    find_reports,
    provenance_of,
    recording_name,
    resolve_request_focus,
    run_digest,
)


def run_view(request: ViewRequest, *, progress: ProgressBar | None = None, failures: bool = True) -> ViewResult:
    """Log the scene, run every tracker into one recording (sharing the preprocessed detections), compare them
    and log failures and provenance. With ``request.focus`` the trackers first run without logging to find the
    focus (``resolve_request_focus``); the recording then holds the keyframes around it, opens on it and explains
    it (``focus/summary``). ``progress``: a progress display (e.g. a rich ``Progress``; none by default)."""
    import numpy as np

    from gnnpmb.data.nuscenes import load_lidar_points
    from gnnpmb.events import TeeSink
    from gnnpmb.pipeline import TrackingRun, run_tracker
    from gnnpmb.why.facts import FactSink
    from gnnpmb.why.reason import Evidence, explain_failure
    from viz.blueprint import default_blueprint
    from viz.compare import log_comparison
    from viz.failures import log_failures
    from viz.focus import focus_legends, log_focus, tracker_views
    from viz.logger import FLUSH_FRAMES, TrackerLogger
    from viz.provenance import log_provenance
    from viz.recording import recording
    from viz.scene import log_scene
    from viz.timeline import PLAIN_CLOCK, Clock

    scene, frame_range = request.scene, request.frame_range
    focus, reports, notices = None, {}, []
    if request.focus is not None:  # the logged runs below give the same tracks (deterministic): reuse the reports
        focus, reports, notices = resolve_request_focus(request)
    shown = focus.window(frame_range) if focus is not None else frame_range
    clock = Clock(focus_end=focus.frame_index) if focus is not None else PLAIN_CLOCK
    n = len(shown)
    # A focus recording gets its layout once its series are known, so their legends can be placed clear of them.
    blueprint = default_blueprint(request.trackers, request.classes) if focus is None else None
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
        sensors = bar.add_task(f"{scene.name} sensors", total=n)
        log_scene(
            stream,
            scene,
            [request.frame_detections[i] for i in shown],
            shown,
            points_loader=load_lidar_points,
            on_frame=lambda: bar.advance(sensors),
            clock=clock,
        )
        for tracker in request.trackers:
            task = bar.add_task(f"{scene.name} {tracker}", total=len(frame_range))
            fact_sink = FactSink(tracker, has_existence=tracker_has_existence(tracker))
            facts[tracker] = fact_sink.facts
            logger = loggers[tracker] = TrackerLogger(
                stream,
                tracker,
                gate_z_m=scene.ground_z_m,
                clock=clock,
                log_frames=shown if focus is not None else None,
                focus_tracks=set(focus.track_ids.get(tracker, ())) if focus is not None else None,
                flush_frames=None if request.save is not None else FLUSH_FRAMES,
                has_existence=tracker_has_existence(tracker),
                focus_class=focus.class_name if focus is not None else None,
                facts=fact_sink.facts,
            )
            runs.append(
                run_tracker(
                    scene,
                    request.frame_detections,
                    tracker,
                    request.config,
                    sink=TeeSink(fact_sink, logger),
                    classes=request.classes,
                    frame_range=frame_range,
                    on_frame=lambda task=task: bar.advance(task),
                )
            )
            logger.finish()
        if len(runs) > 1:
            comparison = compare_runs(runs)
            log_comparison(
                stream,
                comparison.within(shown),
                scene,
                clock,
                show_labels=focus is None,
                focus_class=focus.class_name if focus is not None else None,
            )
        if failures and focus is None:
            task = bar.add_task(f"{scene.name} failures", total=len(runs))
            reports, notices = find_reports(request, runs, lambda: bar.advance(task))
        if failures or focus is not None:
            for name, report in reports.items():
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
                )
        if focus is not None:
            evidence = {run.tracker: Evidence(reports[run.tracker], facts[run.tracker], run) for run in runs}
            finding = None
            if focus.failure_id is not None and focus.failure_tracker in evidence:
                owner = evidence[focus.failure_tracker]
                others = [ev for t, ev in evidence.items() if t != focus.failure_tracker]
                finding = explain_failure(focus.failure_id, owner, scene, others, first_frame=shown.start)
            log_focus(stream, focus, scene, tracker_views(evidence, loggers), loggers, clock, shown, finding)
            legends = focus_legends(focus, loggers, comparison.within(shown) if comparison is not None else None)
            stream.send_blueprint(
                default_blueprint(request.trackers, request.classes, focus, legends),
                make_active=True,
                make_default=True,
            )
        digests = {run.tracker: run_digest(run) for run in runs}
        log_provenance(stream, provenance_of(request, digests))
    ms = {run.tracker: 1000.0 * float(np.mean([f.step_time_s for f in run.frames])) for run in runs}
    return ViewResult(ms, digests, comparison, tuple(notices), focus, reports)
