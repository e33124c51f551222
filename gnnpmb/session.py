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
from gnnpmb.registry import check_classes
from gnnpmb.runs import Capabilities, RunSpec, capabilities, parse_run, parse_runs, run_inputs
from gnnpmb.serve import ServeTarget, check_serve_ports

if TYPE_CHECKING:
    from gnnpmb.compare import Comparison
    from gnnpmb.config import TrackerConfig
    from gnnpmb.data.nuscenes import DatasetLocation
    from gnnpmb.data.scene import SceneData
    from gnnpmb.eval.failures import FailureReport
    from gnnpmb.events import EventSink
    from gnnpmb.focus import FocusTarget
    from gnnpmb.foreign import ForeignResults
    from gnnpmb.pipeline import TrackingRun
    from gnnpmb.provenance import DetectionsSource, Provenance, TrackDigest
    from gnnpmb.types import Boxes, FrameDetections
    from gnnpmb.why.facts import FactSink, TrackerFacts
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

    trackers: the names of the runs (``gnnpmb.runs``), in order; runs: each one's spec (built-in tracker or
    results file; empty: every name is a registry tracker with ``config``); foreign: the loaded results of each
    results run; configs: the parameters of each run with a file of its own; own_frames: the detections of a run
    whose parameters preprocess them otherwise; source: where the detections came from, with their hash; seed:
    the simulated detector's seed; argv: the command line, for the provenance; serve: the ports of the web viewer
    (None: save or spawn); notices: what the user should know (e.g. boxes of a results file left out).
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
    runs: tuple[RunSpec, ...] = ()
    foreign: Mapping[str, ForeignResults] = field(default_factory=dict)
    configs: Mapping[str, TrackerConfig] = field(default_factory=dict)
    own_frames: Mapping[str, list[FrameDetections]] = field(default_factory=dict)
    notices: tuple[str, ...] = ()

    def spec(self, name: str) -> RunSpec:
        """The spec of run ``name`` (a registry tracker of that name when ``runs`` does not list it)."""
        return next((s for s in self.runs if s.name == name), RunSpec(name, tracker=name))

    def capabilities(self, name: str) -> Capabilities:
        """What run ``name`` can show (``runs.capabilities``)."""
        return capabilities(self.spec(name))


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
    results: Sequence[str] = (),
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

    trackers: run spellings (``runs.parse_run``: ``gnnpmb``, ``gnnpmb:paper.toml``, ``NAME=FILE.json``);
    results: ``NAME=FILE.json`` runs, placed first (the default tracker runs when neither is given). The cheap
    checks (names, files, --frames, output path, ports, the --detections file) run before the dataset is loaded.
    detector None means the default preset; it cannot be combined with ``detections_file``.
    """
    if detections_file is not None and detector is not None:
        raise GnnpmbError("pass either --detections FILE.json or --detector PRESET, not both")
    if save is not None and serve is not None:
        raise GnnpmbError("pass either --save OUT.rrd or --serve, not both")
    detector = detector or DEFAULT_DETECTOR
    specs = parse_runs(trackers, results, default=DEFAULT_TRACKER)
    class_names = parse_classes(classes)
    bounds = parse_frames(frames)
    inputs = (("--detections", detections_file), ("--params", params), *run_inputs(specs))
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
    own = load_runs(specs, scene, location, config, detections, frame_detections, class_names)
    freeze_loaded()
    return ViewRequest(
        scene,
        location,
        tuple(s.name for s in specs),
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
        runs=specs,
        **own,
    )


def load_runs(
    specs: Sequence[RunSpec],
    scene: SceneData,
    location: DatasetLocation,
    config: TrackerConfig,
    detections: Mapping[str, Boxes],
    frames: list[FrameDetections],
    classes: Sequence[str],
) -> dict[str, Any]:
    """What the runs bring of their own (the ``ViewRequest`` fields ``foreign``, ``configs``, ``own_frames`` and
    ``notices``): each results file read and checked for ``scene`` (``gnnpmb.foreign``), each parameter file."""
    from gnnpmb.config import load_config
    from gnnpmb.data.nuscenes import all_sample_tokens
    from gnnpmb.foreign import read_results, scene_results
    from gnnpmb.pipeline import preprocess_frames

    foreign, configs, own_frames, notices = {}, {}, {}, []
    dataset_tokens: set[str] | None = None
    for spec in specs:
        if spec.results is not None:
            if dataset_tokens is None:
                dataset_tokens = all_sample_tokens(location)
            data = read_results(spec.results)
            foreign[spec.name] = scene_results(spec.name, spec.results, data, scene, frames, classes, dataset_tokens)
            notices += foreign[spec.name].notices
        elif spec.params is not None:
            own = configs[spec.name] = load_config(spec.params)
            if own.preprocess_by_class() != config.preprocess_by_class():
                own_frames[spec.name] = preprocess_frames(scene, detections, own, classes)
    return {"foreign": foreign, "configs": configs, "own_frames": own_frames, "notices": tuple(notices)}


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
    from gnnpmb.provenance import DetectionsSource, file_sha256

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
    specs = tuple(parse_run(t, "recorded run") for t in p.trackers)
    frame_range = frame_range_of((p.frame_start, p.frame_end), scene)
    recorded = p.detections
    if recorded.kind == "file":
        path = Path(detections_file) if detections_file is not None else Path(str(recorded.path))
        if not path.is_file():
            raise DataError(f"the recorded detections file {path} is missing; pass --detections FILE.json")
        source = DetectionsSource("file", file_sha256(path), path=str(Path(path).expanduser().absolute()))
        if source.sha256 != recorded.sha256:  # the file's bytes hashed now, never a digest kept by a cache
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
    own = load_runs(specs, scene, location, config, detections, frame_detections, classes)
    freeze_loaded()
    return ViewRequest(
        scene,
        location,
        tuple(s.name for s in specs),
        classes,
        frame_range,
        config,
        detections,
        frame_detections,
        target,
        source,
        p.seed,
        tuple(argv),
        runs=specs,
        **own,
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
    from gnnpmb.provenance import Provenance, recorded_versions

    return Provenance(
        argv=request.argv,
        versions=recorded_versions(),
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
        trackers=tuple(_recorded(request.spec(t)) for t in request.trackers),
        track_digests=digests,
    )


def _recorded(spec: RunSpec) -> str:
    """A run's spelling in the provenance, with absolute paths (``runs.parse_run`` reads it back)."""
    from dataclasses import replace

    absolute = {k: Path(v).absolute() for k in ("params", "results") if (v := getattr(spec, k)) is not None}
    return replace(spec, **absolute).text()


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
    missing = scene.no_ground_truth()
    if missing is not None:
        return {}, [missing]
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


def resolve_opening(request: ViewRequest) -> tuple[FocusTarget | None, dict[str, FailureReport], list[str]]:
    """Where a full recording opens: run every tracker without logging, find their failures and take the first
    failure worth a look of the first run (``FailureReport.first_worth_opening``) as a focus target (None: no
    failure, or no ground truth); returns it, the failure reports and notices."""
    from gnnpmb.focus import resolve_focus

    runs = rerun_runs(request)
    reports, notices = find_reports(request, runs)
    report = reports.get(request.trackers[0])
    first = report.first_worth_opening(request.frame_range) if report is not None else None
    if first is None:
        return None, reports, notices
    estimates = {run.tracker: [f.estimates for f in run.frames] for run in runs}
    return resolve_focus(first, request.scene, reports, estimates, request.frame_range), reports, notices


def rerun_runs(request: ViewRequest) -> list[TrackingRun]:
    """Run every tracker of ``request`` without logging."""
    return [track_run(request, name) for name in request.trackers]


def track_run(
    request: ViewRequest, name: str, sink: EventSink | None = None, on_frame: Callable[[], None] | None = None
) -> TrackingRun:
    """Run ``name`` of ``request`` over its frames, its events to ``sink``: a built-in tracker tracks (with its own
    parameters and detections when it has them), a results file is replayed (``gnnpmb.foreign.replay``); the run
    is named ``name``."""
    from dataclasses import replace

    from gnnpmb.foreign import replay
    from gnnpmb.pipeline import run_tracker

    foreign = request.foreign.get(name)
    if foreign is not None:
        return replay(
            foreign, request.scene, request.frame_detections, request.classes, request.frame_range, sink, on_frame
        )
    spec = request.spec(name)
    run = run_tracker(
        request.scene,
        request.own_frames.get(name, request.frame_detections),
        str(spec.tracker),
        request.configs.get(name, request.config),
        sink=sink,
        classes=request.classes,
        frame_range=request.frame_range,
        on_frame=on_frame,
    )
    return run if run.tracker == name else replace(run, tracker=name)


def fact_sink(request: ViewRequest, name: str) -> FactSink:
    """A ``why.facts.FactSink`` for run ``name`` (output only for a results file)."""
    from gnnpmb.why.facts import FactSink

    caps = request.capabilities(name)
    return FactSink(name, has_existence=caps.has_existence, output_only=caps.output_only)


def evidence_of(request: ViewRequest, report: FailureReport, facts: TrackerFacts, run: TrackingRun) -> Evidence:
    """The ``why.reason.Evidence`` of one run: with a results file, how each box was placed on a detection."""
    from gnnpmb.why.reason import Evidence

    foreign = request.foreign.get(run.tracker)
    return Evidence(report, facts, run, foreign.boxes_on if foreign is not None else {})


def gather_evidence(request: ViewRequest) -> tuple[dict[str, Evidence], list[str]]:
    """Every tracker of ``request`` run with a ``why.facts.FactSink``, its failures found: the evidence a finding
    is explained from (``why.reason.explain_failure``), per tracker, and notices (as ``find_reports``)."""
    from gnnpmb.events import TeeSink

    runs, facts = [], {}
    for name in request.trackers:
        sink = fact_sink(request, name)
        facts[name] = sink.facts
        runs.append(track_run(request, name, TeeSink(sink)))
    reports, notices = find_reports(request, runs)
    return {
        run.tracker: evidence_of(request, reports[run.tracker], facts[run.tracker], run)
        for run in runs
        if run.tracker in reports
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
    """A note for each package whose version differs from the recorded one, and one when the ``gnnpmb`` source
    files differ (``provenance.SOURCE_KEY``), whatever the version says."""
    from gnnpmb.provenance import SOURCE_KEY, code_differs, package_versions, source_digest

    packages = {k: v for k, v in recorded.items() if k != SOURCE_KEY}
    now = package_versions(tuple(packages))
    notes = [f"note: recorded with {k} {v}, now {now[k]}" for k, v in packages.items() if now.get(k) != v]
    if code_differs(recorded):
        notes.append(
            f"note: recorded with other gnnpmb code (source digest {recorded[SOURCE_KEY]}, now {source_digest()}): "
            "tracks may differ because the code differs"
        )
    return notes
