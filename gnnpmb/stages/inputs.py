"""Stage 2, the inputs: the scene slice, its detections (preprocessed once, shared by every run), each results
file read for the scene and each run's own parameters.

``load_inputs`` loads what a checked ``request.Request`` names; ``reproduction_inputs`` loads what a recording's
provenance names, checking that the dataset and the detections are the recorded ones.
"""

from __future__ import annotations

import gc
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import TYPE_CHECKING, Any

from gnnpmb.errors import DataError, GnnpmbError
from gnnpmb.outputs import check_output_file
from gnnpmb.registry import check_classes
from gnnpmb.runs import Capabilities, RunSpec, capabilities, parse_run
from gnnpmb.stages.request import DEFAULT_DETECTOR, Request

if TYPE_CHECKING:
    from gnnpmb.config import TrackerConfig
    from gnnpmb.data.nuscenes import DatasetLocation
    from gnnpmb.data.scene import SceneData
    from gnnpmb.foreign import ForeignResults
    from gnnpmb.provenance import DetectionsSource, Provenance
    from gnnpmb.serve import ServeTarget
    from gnnpmb.types import Boxes, FrameDetections


@dataclass(frozen=True, slots=True)
class Inputs:
    """Everything the runs of one command read, loaded and checked.

    trackers: the names of the runs (``gnnpmb.runs``), in order; runs: each one's spec (built-in tracker or
    results file; empty: every name is a registry tracker with ``config``); foreign: the loaded results of each
    results run; configs: the parameters of each run with a file of its own; own_frames: the detections of a run
    whose parameters preprocess them otherwise; caps: what each run can show (``runs.capabilities``, found once
    here); source: where the detections came from, with their hash; seed:
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
    caps: Mapping[str, Capabilities] = field(default_factory=dict)
    notices: tuple[str, ...] = ()

    def spec(self, name: str) -> RunSpec:
        """The spec of run ``name`` (a registry tracker of that name when ``runs`` does not list it)."""
        return next((s for s in self.runs if s.name == name), RunSpec(name, tracker=name))

    def capabilities(self, name: str) -> Capabilities:
        """What run ``name`` can show (``runs.capabilities``)."""
        return self.caps[name] if name in self.caps else capabilities(self.spec(name))

    @property
    def evaluated_keyframes(self) -> range | None:
        """The keyframes failures are found in: those tracked (``--frames``), None when that is the whole scene."""
        return None if len(self.frame_range) == len(self.scene.keyframes) else self.frame_range


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


def simulated_note(location: DatasetLocation, preset: str | None, seed: int) -> str | None:
    """The note for detections simulated (``preset``; None: a file was given) on a dataset that is not the built-in
    demo: a user's own data, tracked on a made-up detector because --detections was left out. None otherwise."""
    if preset is None or location.synthetic:
        return None
    return (
        f"no --detections: the detections are simulated from the dataset's annotations (--detector {preset}, "
        f"seed {seed}); pass --detections FILE.json to track your detector's"
    )


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


def load_inputs(request: Request) -> Inputs:
    """Load the scene, its detections and every run's own inputs named by ``request``; raises a one-line
    ``GnnpmbError`` when the dataset, the scene or a results file does not fit."""
    from gnnpmb.data.nuscenes import load_scene, resolve_dataroot
    from gnnpmb.pipeline import get_detections, preprocess_frames

    location = resolve_dataroot(request.dataroot, request.version, (request.scene_name,))
    scene = load_scene(location, request.scene_name)
    frame_range = frame_range_of(request.frame_bounds, scene)
    detections = get_detections(scene, request.detections_file, request.detector, request.seed)
    source = detections_source(scene, detections, request.detections_file, request.detector, request.seed)
    frame_detections = preprocess_frames(scene, detections, request.config, request.classes)
    own = _run_inputs(request.runs, scene, location, request.config, detections, frame_detections, request.classes)
    note = simulated_note(location, None if request.detections_file else request.detector, request.seed)
    own["notices"] = (note, *own["notices"]) if note else own["notices"]
    freeze_loaded()
    return Inputs(
        scene,
        location,
        tuple(s.name for s in request.runs),
        request.classes,
        frame_range,
        request.config,
        detections,
        frame_detections,
        request.save,
        source,
        request.seed,
        request.argv,
        focus=request.focus,
        serve=request.serve,
        runs=request.runs,
        **own,
    )


def _run_inputs(
    specs: Sequence[RunSpec],
    scene: SceneData,
    location: DatasetLocation,
    config: TrackerConfig,
    detections: Mapping[str, Boxes],
    frames: list[FrameDetections],
    classes: Sequence[str],
) -> dict[str, Any]:
    """What the runs bring of their own (the ``Inputs`` fields ``foreign``, ``configs``, ``own_frames``, ``caps``
    and ``notices``): each results file read and checked for ``scene`` (``gnnpmb.foreign``), each parameter file,
    what each run can show."""
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
    caps = {spec.name: capabilities(spec) for spec in specs}
    return {"foreign": foreign, "configs": configs, "own_frames": own_frames, "caps": caps, "notices": tuple(notices)}


YOUNG_COLLECTION_THRESHOLD = 20_000
"""``gnnpmb-viz``'s threshold of the garbage collector's first generation (CPython's: 700). Loading, tracking
and drawing make many short-lived containers: on the warm demo 700 gave 336 collections (65-80 ms of CPU), 20,000
gives 21 (25 ms), with the same peak memory."""


def collect_rarely() -> None:
    """The ``gnnpmb-viz`` script's collector while it imports and loads (``cli.app.main``): only the young
    generation, every ``YOUNG_COLLECTION_THRESHOLD`` allocations, until ``freeze_loaded``. Young collections free
    what a cold run's load leaves in reference cycles: the devkit's first import (matplotlib, pyparsing) catches
    exceptions whose tracebacks keep their frames, and the frames their callers' locals (the index build's tables);
    with the collector off they stayed to the end (1.83 against 1.53 GB of peak memory on a full-size cold
    ``gnnpmb-viz``, ``benchmarks/full_scale.py``). The older generations, which a warm run's load would walk whole
    (~140,000 objects), are left to the freeze."""
    gc.set_threshold(YOUNG_COLLECTION_THRESHOLD, LOADING_NEVER, LOADING_NEVER)


LOADING_NEVER = 1_000_000_000
"""An older generation's threshold that is never reached while loading (``collect_rarely``)."""


def freeze_loaded() -> None:
    """Move every object alive (the devkit's tables, the scene, the frames) out of the garbage collector's reach
    (``gc.freeze``): they live as long as the process, and a full collection walking them cost ~130 ms in the
    middle of tracking. Objects frozen are still freed by reference counting; only reference cycles among them
    would outlive their use. With the script's loading collector (``collect_rarely``) nothing is collected first
    (a full collection walked all 140,000 objects of the warm demo for ~85 ms) and the older generations are
    collected again from here (CPython's thresholds, the young one kept); otherwise (the Python API, tests)
    garbage is collected first."""
    young, older, oldest = gc.get_threshold()
    if older == LOADING_NEVER:
        gc.set_threshold(young, 10, 10)
    else:
        gc.collect()
    gc.freeze()


def reproduction_inputs(
    provenance: Provenance,
    *,
    dataroot: Path | None = None,
    detections_file: Path | None = None,
    save: Path | None = None,
    argv: Sequence[str] = (),
) -> Inputs:
    """The inputs that re-run a recorded run: same dataset (checked by scene token), same detections (checked by
    hash), parameters, classes, frames and trackers. dataroot / detections_file replace the recorded paths (e.g.
    on another machine). Raises a DataError naming the input that is missing or changed."""
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
    own = _run_inputs(specs, scene, location, config, detections, frame_detections, classes)
    freeze_loaded()
    return Inputs(
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


def recorded_spelling(spec: RunSpec) -> str:
    """A run's spelling in the provenance, with absolute paths (``runs.parse_run`` reads it back)."""
    absolute = {k: Path(v).absolute() for k in ("params", "results") if (v := getattr(spec, k)) is not None}
    return replace(spec, **absolute).text()
