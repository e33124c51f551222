"""Stage 1, the request: every argument of a command checked before anything is loaded.

``check_request`` is what ``gnnpmb-viz`` and ``gnnpmb failures`` build from their options and what a notebook
builds from Python arguments: names, --frames, --classes, the output path, ports, the focus spelling, the
parameter file and the detections file are checked here, so a mistake raises a one-line ``GnnpmbError`` and
nothing is loaded or written.
"""

from __future__ import annotations

import re
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

from gnnpmb.classes import TRACKING_CLASSES
from gnnpmb.errors import GnnpmbError
from gnnpmb.outputs import check_output_file
from gnnpmb.registry import check_classes
from gnnpmb.runs import RunSpec, parse_runs, run_inputs
from gnnpmb.serve import ServeTarget, check_serve_ports

if TYPE_CHECKING:
    from gnnpmb.config import TrackerConfig

DEFAULT_TRACKER = "gnnpmb"
DEFAULT_DETECTOR = "centerpoint"
_FRAMES_RE = re.compile(r"^\s*(\d*)\s*:\s*(\d*)\s*$")


@dataclass(frozen=True, slots=True)
class Request:
    """One command's checked arguments; nothing of the dataset is loaded yet.

    runs: each run's spec (``gnnpmb.runs``), in command-line order; frame_bounds: --frames as (start, end), either
    None; config: the parameters of --params (the defaults without it); detector: the simulated preset (used when
    ``detections_file`` is None); save: the checked absolute output path; serve: the web viewer's ports (None: save
    or spawn); focus: the --focus spelling, checked by ``gnnpmb.focus.parse_focus``; argv: the command line, for the
    provenance.
    """

    scene_name: str
    runs: tuple[RunSpec, ...]
    classes: tuple[str, ...]
    frame_bounds: tuple[int | None, int | None]
    config: TrackerConfig
    dataroot: Path | None = None
    version: str | None = None
    detections_file: Path | None = None
    detector: str = DEFAULT_DETECTOR
    seed: int = 0
    save: Path | None = None
    serve: ServeTarget | None = None
    focus: str | None = None
    argv: tuple[str, ...] = ()


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


def parse_classes(text: str | None) -> tuple[str, ...]:
    """``car,bus`` -> ("car", "bus"), checked; None -> all seven tracking classes."""
    if text is None:
        return TRACKING_CLASSES
    names = [n.strip() for n in text.split(",") if n.strip()]
    return tuple(dict.fromkeys(check_classes(names)))


def check_request(
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
) -> Request:
    """Check every argument; raises GnnpmbError with a one-line message.

    trackers: run spellings (``runs.parse_run``: ``gnnpmb``, ``gnnpmb:paper.toml``, ``NAME=FILE.json``);
    results: ``NAME=FILE.json`` runs, placed first (the default tracker runs when neither is given). detector None
    means the default preset; it cannot be combined with ``detections_file``.
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
    from gnnpmb.data.simdet import get_preset

    get_preset(detector)
    config = load_config(params)
    if detections_file is not None:
        check_detection_file(detections_file)
    return Request(
        scene_name,
        specs,
        class_names,
        bounds,
        config,
        dataroot=dataroot,
        version=version,
        detections_file=detections_file,
        detector=detector,
        seed=int(seed),
        save=target,
        serve=serve,
        focus=focus,
        argv=tuple(argv),
    )
