"""One viewer session, callable from Python: check a request, track, log the recording, reproduce a recording.

``gnnpmb-viz`` (``cli.app``) only parses its command line into ``prepare`` and prints what ``viz.view.run_view``
returns; a notebook does the same::

    from gnnpmb.session import prepare
    from viz.view import run_view

    request = prepare("scene-0103", ["gnnpmb", "pmbm"], frames="0:20", save=Path("demo.rrd"))
    result = run_view(request)
    result.ms_per_frame, result.comparison

``prepare`` checks every argument (names, frames, output path, ports, the detections file) before loading the
scene, so a mistake raises a one-line ``GnnpmbError`` and no recording is opened. ``run_view`` (in ``viz``: it
draws) logs the scene, runs every tracker into one recording (sharing the preprocessed detections), compares them,
marks their failures and explains the focus; this module finds the failures (``find_reports``), the focus
(``resolve_request_focus``) and the evidence of a failure's finding (``focus_evidence``); ``prepare_reproduction``
and ``rerun_digests`` re-run a recorded run from its provenance.
"""

from __future__ import annotations

import gc
import re
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from types import TracebackType
from typing import TYPE_CHECKING, Any, Protocol

from gnnpmb.classes import TRACKING_CLASSES
from gnnpmb.errors import DataError, GnnpmbError
from gnnpmb.outputs import check_output_file
from gnnpmb.registry import check_classes, check_tracker, tracker_has_existence
from gnnpmb.serve import ServeTarget, check_serve_ports

if TYPE_CHECKING:
    from gnnpmb.compare import Comparison
    from gnnpmb.config import TrackerConfig
    from gnnpmb.data.nuscenes import DatasetLocation
    from gnnpmb.data.scene import SceneData
    from gnnpmb.eval.failures import FailureReport
    from gnnpmb.focus import FocusTarget
    from gnnpmb.pipeline import TrackingRun
    from gnnpmb.provenance import DetectionsSource, Provenance, TrackDigest
    from gnnpmb.types import Boxes, FrameDetections
    from gnnpmb.why.findings import Finding
    from gnnpmb.why.reason import Evidence

DEFAULT_TRACKER = "gnnpmb"
DEFAULT_DETECTOR = "centerpoint"
_FRAMES_RE = re.compile(r"^\s*(\d*)\s*:\s*(\d*)\s*$")


class ProgressBar(Protocol):
    """What ``run_view`` needs of a progress display (a rich ``Progress`` has it): a context manager with
    tasks that advance."""

    def __enter__(self) -> Any: ...

    def __exit__(
        self, kind: type[BaseException] | None, value: BaseException | None, traceback: TracebackType | None
    ) -> Any: ...

    def add_task(self, description: str, total: float | None = ...) -> Any: ...

    def advance(self, task_id: Any, advance: float = ...) -> None: ...


class SilentProgress:
    """A progress display that shows nothing."""

    def __enter__(self) -> SilentProgress:
        return self

    def __exit__(
        self, kind: type[BaseException] | None, value: BaseException | None, traceback: TracebackType | None
    ) -> None:
        return None

    def add_task(self, description: str, total: float | None = None) -> int:
        return 0

    def advance(self, task_id: Any, advance: float = 1) -> None:
        return None


@dataclass(frozen=True, slots=True)
class ViewRequest:
    """Everything one ``gnnpmb-viz`` run needs, checked: no recording is opened before this exists.

    source: where the detections came from, with their hash; seed: the simulated detector's seed;
    argv: the command line, for the provenance; serve: the ports of the web viewer (None: save or spawn).
    """

    scene: SceneData
    location: DatasetLocation
    trackers: tuple[str, ...]
    classes: tuple[str, ...]
    frame_range: range
    config: TrackerConfig
    detections: dict[str, Boxes]
    frame_detections: list[FrameDetections]
    save: Path | None
    source: DetectionsSource
    seed: int
    argv: tuple[str, ...]
    focus: str | None = None
    serve: ServeTarget | None = None


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
    reports: Mapping[str, FailureReport] = field(default_factory=dict)


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


def evaluated_keyframes(frame_range: range, scene: SceneData) -> range | None:
    """The keyframes failures are found in: those tracked (``--frames``), None when that is the whole scene."""
    return None if len(frame_range) == len(scene.keyframes) else frame_range


def parse_classes(text: str | None) -> tuple[str, ...]:
    """``car,bus`` -> ("car", "bus"), checked; None -> all seven tracking classes."""
    if text is None:
        return TRACKING_CLASSES
    names = [n.strip() for n in text.split(",") if n.strip()]
    return tuple(dict.fromkeys(check_classes(names)))


def detections_source(
    scene: SceneData, detections: dict[str, Boxes], detections_file: Path | None, detector: str, seed: int
) -> DetectionsSource:
    """Where ``detections`` came from, with the SHA-256 of the file, or of the simulated boxes."""
    from gnnpmb.data.detections import detection_file_sha256
    from gnnpmb.provenance import DetectionsSource, boxes_sha256

    if detections_file is not None:
        path = Path(detections_file).expanduser().absolute()
        return DetectionsSource("file", detection_file_sha256(path), path=str(path))
    return DetectionsSource("simulated", boxes_sha256(detections, scene.sample_tokens), preset=detector, seed=int(seed))


def prepare(
    scene_name: str,
    trackers: Sequence[str],
    *,
    dataroot: Path | None = None,
    version: str | None = None,
    detections_file: Path | None = None,
    detector: str | None = None,
    seed: int = 0,
    params: Path | None = None,
    classes: str | None = None,
    frames: str | None = None,
    save: Path | None = None,
    serve: ServeTarget | None = None,
    argv: Sequence[str] = (),
    focus: str | None = None,
) -> ViewRequest:
    """Check every argument and load the scene and detections; raises GnnpmbError with a one-line message.

    The cheap checks (names, --frames, output path, ports, the --detections file) run before the dataset is
    loaded. detector None means the default preset; it cannot be combined with ``detections_file``.
    """
    if detections_file is not None and detector is not None:
        raise GnnpmbError("pass either --detections FILE.json or --detector PRESET, not both")
    if save is not None and serve is not None:
        raise GnnpmbError("pass either --save OUT.rrd or --serve, not both")
    detector = detector or DEFAULT_DETECTOR
    names = tuple(dict.fromkeys(check_tracker(t) for t in (trackers or [DEFAULT_TRACKER])))
    class_names = parse_classes(classes)
    bounds = parse_frames(frames)
    inputs = (("--detections", detections_file), ("--params", params))
    target = check_output_file(save, "--save", ".rrd", inputs=inputs) if save is not None else None
    if serve is not None:
        check_serve_ports(serve)
    if focus is not None:
        from gnnpmb.focus import parse_focus

        parse_focus(focus)

    from gnnpmb.config import load_config
    from gnnpmb.data.detections import check_detection_file
    from gnnpmb.data.nuscenes import load_scene, resolve_dataroot
    from gnnpmb.data.simdet import get_preset
    from gnnpmb.pipeline import get_detections, preprocess_frames

    get_preset(detector)
    config = load_config(params)
    if detections_file is not None:
        check_detection_file(detections_file)
    location = resolve_dataroot(dataroot, version, (scene_name,))
    scene = load_scene(location, scene_name)
    frame_range = frame_range_of(bounds, scene)
    detections = get_detections(scene, detections_file, detector, seed)
    source = detections_source(scene, detections, detections_file, detector, seed)
    frame_detections = preprocess_frames(scene, detections, config, class_names)
    freeze_loaded()
    return ViewRequest(
        scene,
        location,
        names,
        class_names,
        frame_range,
        config,
        detections,
        frame_detections,
        target,
        source,
        int(seed),
        tuple(argv),
        focus=focus,
        serve=serve,
    )


def freeze_loaded() -> None:
    """Collect garbage, then move every object alive (the devkit's tables, the scene, the frames) out of the
    garbage collector's reach (``gc.freeze``): they live as long as the process, and a full collection walking
    them cost ~130 ms in the middle of tracking. Objects frozen are still freed by reference counting; only
    reference cycles among them would outlive their use."""
    gc.collect()
    gc.freeze()


def prepare_reproduction(
    provenance: Provenance,
    *,
    dataroot: Path | None = None,
    detections_file: Path | None = None,
    save: Path | None = None,
    argv: Sequence[str] = (),
) -> ViewRequest:
    """The request that re-runs a recorded run: same dataset (checked by scene token), same detections
    (checked by hash), parameters, classes, frames and trackers. dataroot / detections_file replace the
    recorded paths (e.g. on another machine). Raises a DataError naming the input that is missing or
    changed."""
    from gnnpmb.config import config_from_dict
    from gnnpmb.data.nuscenes import check_dataroot, load_scene
    from gnnpmb.pipeline import get_detections, preprocess_frames

    p = provenance
    target = check_output_file(save, "--save", ".rrd") if save is not None else None
    root = Path(dataroot) if dataroot is not None else Path(p.dataroot)
    if not root.exists():
        raise DataError(f"the recorded dataroot {root} does not exist; pass --dataroot DIR with a copy of it")
    location = check_dataroot(root, p.version, "--dataroot" if dataroot is not None else "the recording")
    scene = load_scene(location, p.scene_name)
    if scene.token != p.scene_token:
        raise DataError(
            f"{p.scene_name} in {location.dataroot} has token {scene.token}, the recorded one "
            f"{p.scene_token}: not the same dataset"
        )
    config = config_from_dict(p.config)
    classes = tuple(check_classes(list(p.classes)))
    trackers = tuple(check_tracker(t) for t in p.trackers)
    frame_range = frame_range_of((p.frame_start, p.frame_end), scene)
    recorded = p.detections
    if recorded.kind == "file":
        path = Path(detections_file) if detections_file is not None else Path(str(recorded.path))
        if not path.is_file():
            raise DataError(f"the recorded detections file {path} is missing; pass --detections FILE.json")
        source = detections_source(scene, {}, path, DEFAULT_DETECTOR, p.seed)
        if source.sha256 != recorded.sha256:
            raise DataError(
                f"detections file {path} has changed since the recording (sha256 {source.sha256[:12]}, "
                f"recorded {recorded.sha256[:12]})"
            )
        detections = get_detections(scene, path, DEFAULT_DETECTOR, p.seed)
    else:
        preset = str(recorded.preset)
        seed = int(recorded.seed if recorded.seed is not None else p.seed)
        detections = get_detections(scene, None, preset, seed)
        source = detections_source(scene, detections, None, preset, seed)
        if source.sha256 != recorded.sha256:
            raise DataError(
                f"the simulated {preset} detector (seed {seed}) now gives other detections than when "
                f"recorded (sha256 {source.sha256[:12]}, recorded {recorded.sha256[:12]})"
            )
    frame_detections = preprocess_frames(scene, detections, config, classes)
    freeze_loaded()
    return ViewRequest(
        scene,
        location,
        trackers,
        classes,
        frame_range,
        config,
        detections,
        frame_detections,
        target,
        source,
        p.seed,
        tuple(argv),
    )


def recording_name(request: ViewRequest, focus: FocusTarget | None = None) -> str:
    """E.g. "scene-0103 · gnnpmb vs pmbm · synthetic demo", with "· focus id_switch:1" for a focus."""
    data = "synthetic demo" if request.scene.synthetic else f"nuScenes {request.location.version}"
    name = f"{request.scene.name} · {' vs '.join(request.trackers)} · {data}"
    if focus is not None:
        name += f" · focus {focus.failure_id or request.focus}"
    return name


def provenance_of(request: ViewRequest, digests: dict[str, TrackDigest]) -> Provenance:
    """The provenance of a run of ``request`` whose tracks have ``digests``."""
    from gnnpmb.provenance import Provenance, package_versions

    return Provenance(
        argv=request.argv,
        versions=package_versions(),
        config=request.config.as_dict(),
        dataroot=str(request.location.dataroot),
        version=request.location.version,
        synthetic=request.scene.synthetic,
        scene_name=request.scene.name,
        scene_token=request.scene.token,
        detections=request.source,
        seed=request.seed,
        frame_start=request.frame_range.start,
        frame_end=request.frame_range.stop,
        classes=request.classes,
        trackers=request.trackers,
        track_digests=digests,
    )


def run_digest(run: TrackingRun) -> TrackDigest:
    """The track digest of one tracker run."""
    from gnnpmb.provenance import track_digest

    return track_digest([f.keyframe.index for f in run.frames], [f.estimates for f in run.frames])


def compare_runs(runs: Sequence[TrackingRun]) -> Comparison:
    """Per-frame disagreements between tracker runs over the same keyframes (``gnnpmb.compare``), between the
    tracks the viewer draws (existence at least ``why.words.SHOW_MIN_EXISTENCE``)."""
    from gnnpmb.compare import compare_trackers
    from gnnpmb.why.words import SHOW_MIN_EXISTENCE

    frames = runs[0].frames
    return compare_trackers(
        [f.keyframe.gt for f in frames],
        {
            run.tracker: [tuple(e for e in f.estimates if e.existence >= SHOW_MIN_EXISTENCE) for f in run.frames]
            for run in runs
        },
        frame_indices=[f.keyframe.index for f in frames],
    )


def find_reports(
    request: ViewRequest, runs: Sequence[TrackingRun], on_done: Callable[[], None] = lambda: None
) -> tuple[dict[str, FailureReport], list[str]]:
    """Each run's failures found with the devkit's matching in the tracked keyframes (or stored from an earlier
    run of the same tracks, ``eval.failure_cache``), and notices: a scene without ground truth, or one the
    devkit cannot evaluate, gives no reports."""
    from gnnpmb.eval.failure_cache import scene_report
    from gnnpmb.eval.submission import run_results

    scene = request.scene
    if not any(len(k.gt) for k in scene.keyframes):
        return {}, [f"{scene.name} has no ground-truth boxes (no annotations): failure markers skipped"]
    reports = {}
    keyframes = evaluated_keyframes(request.frame_range, scene)
    for run in runs:
        try:
            reports[run.tracker] = scene_report(request.location, scene.name, run.tracker, run_results(run), keyframes)
        except DataError as exc:
            return {}, [f"failure markers skipped: {exc}"]
        on_done()
    return reports, []


def resolve_request_focus(request: ViewRequest) -> tuple[FocusTarget, dict[str, FailureReport], list[str]]:
    """Run the trackers without logging, find their failures and resolve ``request.focus``; returns the focus,
    the failure reports and notices. Raises GnnpmbError (one line) when the focus names nothing in this run."""
    from gnnpmb.focus import resolve_focus

    if request.focus is None:
        raise ValueError("the request has no focus")
    runs = rerun_runs(request)
    reports, notices = find_reports(request, runs)
    if not reports and not request.focus.startswith("track:"):
        raise GnnpmbError(f"--focus {request.focus} needs ground truth: {'; '.join(notices)}")
    estimates = {run.tracker: [f.estimates for f in run.frames] for run in runs}
    return resolve_focus(request.focus, request.scene, reports, estimates, request.frame_range), reports, notices


def rerun_runs(request: ViewRequest) -> list[TrackingRun]:
    """Run every tracker of ``request`` without logging."""
    from gnnpmb.pipeline import run_tracker

    return [
        run_tracker(
            request.scene,
            request.frame_detections,
            tracker,
            request.config,
            classes=request.classes,
            frame_range=request.frame_range,
        )
        for tracker in request.trackers
    ]


def gather_evidence(request: ViewRequest) -> tuple[dict[str, Evidence], list[str]]:
    """Every tracker of ``request`` run with a ``why.facts.FactSink``, its failures found: the evidence a finding
    is explained from (``why.reason.explain_failure``), per tracker, and notices (as ``find_reports``)."""
    from gnnpmb.events import TeeSink
    from gnnpmb.pipeline import run_tracker
    from gnnpmb.why.facts import FactSink
    from gnnpmb.why.reason import Evidence

    runs, facts = [], {}
    for tracker in request.trackers:
        sink = FactSink(tracker, has_existence=tracker_has_existence(tracker))
        facts[tracker] = sink.facts
        runs.append(
            run_tracker(
                request.scene,
                request.frame_detections,
                tracker,
                request.config,
                sink=TeeSink(sink),
                classes=request.classes,
                frame_range=request.frame_range,
            )
        )
    reports, notices = find_reports(request, runs)
    return {
        run.tracker: Evidence(reports[run.tracker], facts[run.tracker], run) for run in runs if run.tracker in reports
    }, notices


def explain_all(request: ViewRequest, evidence: Mapping[str, Evidence]) -> dict[str, list[Finding]]:
    """Per tracker, the finding of each of its failures (in ``FailureReport.ids`` order), the other trackers'
    evidence beside it."""
    from gnnpmb.focus import FRAMES_BEFORE
    from gnnpmb.why.reason import explain_failure

    out = {}
    for tracker, ev in evidence.items():
        others = [o for t, o in evidence.items() if t != tracker]
        start = request.frame_range.start
        out[tracker] = [
            explain_failure(fid, ev, request.scene, others, first_frame=max(start, f.frame_index - FRAMES_BEFORE))
            for fid, f in zip(ev.report.ids(), ev.report.failures, strict=True)
        ]
    return out


def rerun_digests(request: ViewRequest) -> dict[str, TrackDigest]:
    """Run every tracker of ``request`` without logging; their track digests."""
    return {run.tracker: run_digest(run) for run in rerun_runs(request)}


def digest_report(recorded: dict[str, TrackDigest], now: dict[str, TrackDigest]) -> tuple[list[str], bool]:
    """One line per tracker ("identical" or its first differing keyframe) and whether all are identical."""
    lines, same = [], True
    for tracker, digest in now.items():
        before = recorded.get(tracker)
        if before is None:
            lines.append(f"{tracker}: no recorded track digest to compare with")
            same = False
            continue
        first = before.first_difference(digest)
        if first is None:
            lines.append(f"{tracker}: identical ({len(digest.frames)} frames)")
        else:
            lines.append(
                f"{tracker}: DIFFERENT from keyframe {first} on "
                f"({before.differing_frames(digest)} of {len(digest.frames)} frames differ)"
            )
            same = False
    return lines, same


def version_notes(recorded: dict[str, str]) -> list[str]:
    """A note for each package whose version differs from the recorded one."""
    from gnnpmb.provenance import package_versions

    now = package_versions(tuple(recorded))
    return [f"note: recorded with {k} {v}, now {now[k]}" for k, v in recorded.items() if now.get(k) != v]
