"""The runs a command looks at, each under a name: a built-in tracker (with the command's parameters or a file of
its own) or the tracking results of any tracker (a nuScenes tracking submission, ``--results NAME=FILE.json``).

Spellings (``parse_run``), the same for ``--tracker``, ``gnnpmb diff A B`` and what the commands print back:

* ``gnnpmb``: a tracker of the registry, named after it;
* ``gnnpmb:paper.toml``: with its own parameter file, named ``gnnpmb-paper`` (tracker and file stem);
* ``NAME=gnnpmb:paper.toml``: the same, named NAME;
* ``NAME=FILE.json``: a results file, named NAME (``--results`` takes only this form).

A name is a plain word (letters, digits, ``_ . -``), unique among a command's runs; a results run may not take the
name of a registry tracker (its failures would be read as that tracker's). What a run can show the viewer is its
``Capabilities``: a built-in tracker's are declared in the registry; a results file has only its output.
"""

from __future__ import annotations

import re
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

from gnnpmb.errors import GnnpmbError, UnknownNameError
from gnnpmb.registry import TRACKER_NAMES, check_tracker, declared
from gnnpmb.symlinks import refuse_symlink_loop

if TYPE_CHECKING:
    from gnnpmb.events import Panel

_NAME = re.compile(r"^[A-Za-z0-9][A-Za-z0-9_.-]*$")
RESULTS_SUFFIX = ".json"
PARAMS_SUFFIX = ".toml"


@dataclass(frozen=True, slots=True)
class RunSpec:
    """One run: ``name`` (how every view, report and id names it) and either ``tracker`` (a registry name, with
    ``params``: its own parameter file, None: the command's) or ``results`` (a tracking results file)."""

    name: str
    tracker: str | None = None
    params: Path | None = None
    results: Path | None = None

    def text(self) -> str:
        """The spelling that gives this run back (``parse_run``), ``NAME=`` only where the name is not implied."""
        if self.results is not None:
            return f"{self.name}={self.results}"
        body = self.tracker if self.params is None else f"{self.tracker}:{self.params}"
        return body if self.name == default_name(str(self.tracker), self.params) else f"{self.name}={body}"

    def option(self) -> str:
        """The command-line option that adds this run, e.g. ``--tracker gnnpmb:paper.toml``."""
        return f"--tracker {self.text()}"


@dataclass(frozen=True, slots=True)
class Capabilities:
    """What a run can show: its tracker-specific panels, whether its tracks have existences, gates and a chosen
    assignment's costs (``skeleton.ClassFilter``), and whether only its output is known (a results file)."""

    panels: tuple[Panel, ...]
    has_existence: bool
    has_gates: bool
    has_costs: bool
    output_only: bool = False


OUTPUT_ONLY = Capabilities((), has_existence=False, has_gates=False, has_costs=False, output_only=True)
"""A results file: boxes, ids and scores, nothing of the update that made them."""


def default_name(tracker: str, params: Path | None) -> str:
    """``gnnpmb``, or ``gnnpmb-paper`` for ``gnnpmb`` with ``paper.toml``."""
    return tracker if params is None else f"{tracker}-{Path(params).stem}"


def capabilities(spec: RunSpec) -> Capabilities:
    """What ``spec`` can show (module docstring)."""
    if spec.tracker is None:
        return OUTPUT_ONLY
    t = spec.tracker
    panels, has_existence, has_gates, has_costs, _ = declared(t)
    return Capabilities(panels, has_existence, has_gates, has_costs)


def tracker_capabilities(name: str) -> Capabilities:
    """A registry tracker's capabilities (``capabilities`` of the run named after it)."""
    return capabilities(RunSpec(name, tracker=check_tracker(name)))


def _check_name(name: str, text: str) -> str:
    if not _NAME.match(name):
        raise GnnpmbError(
            f"bad run name '{name}' in '{text}': use letters, digits, '_', '.' or '-' (e.g. mine=results.json)"
        )
    return name


def parse_results(text: str) -> RunSpec:
    """``NAME=FILE.json`` (``--results``) -> its run; a name of a registry tracker is refused."""
    name, sep, file = text.partition("=")
    if not sep or not name or not file:
        raise GnnpmbError(f"bad --results '{text}': use NAME=FILE.json, e.g. --results mine=results.json")
    return _results(name.strip(), file.strip(), text)


def _results(name: str, file: str, text: str) -> RunSpec:
    _check_name(name, text)
    if name in TRACKER_NAMES:
        raise GnnpmbError(
            f"results name '{name}' is a built-in tracker's; name the results otherwise, e.g. mine-{name}={file}"
        )
    path = Path(file).expanduser()
    if path.suffix.lower() != RESULTS_SUFFIX:
        raise GnnpmbError(f"results file {file} must be a .json tracking submission (in '{text}')")
    if path.is_dir():
        raise GnnpmbError(f"results path {file} is a folder; pass the tracking results .json (in '{text}')")
    refuse_symlink_loop(path, "results file")
    if not path.is_file():
        raise GnnpmbError(f"results file not found: {file} (in '{text}')")
    return RunSpec(name, results=path)


def parse_run(text: str, option: str = "--tracker") -> RunSpec:
    """One run spelling (module docstring) -> its ``RunSpec``; raises a one-line error naming ``option``."""
    text = text.strip()
    name, sep, body = text.partition("=")
    if not sep:
        name, body = "", text
    elif not name or not body:
        raise GnnpmbError(f"bad {option} '{text}': use TRACKER, TRACKER:PARAMS.toml or NAME=FILE.json")
    if body.lower().endswith(RESULTS_SUFFIX):
        if not name:
            raise GnnpmbError(f"bad {option} '{text}': a results file needs a name, e.g. mine={body}")
        return _results(name, body, text)
    tracker, colon, params = body.partition(":")
    try:
        check_tracker(tracker)
    except UnknownNameError as exc:
        if tracker == text:
            raise
        raise UnknownNameError(f"{exc} (in {option} '{text}'; a results file is NAME=FILE.json)") from None
    params_path = None
    if colon:
        params_path = Path(params).expanduser()
        if params_path.suffix.lower() != PARAMS_SUFFIX:
            raise GnnpmbError(f"bad {option} '{text}': the parameters after ':' must be a .toml file")
        refuse_symlink_loop(params_path, "parameter file")
        if not params_path.is_file():
            raise GnnpmbError(f"parameter file not found: {params} (in {option} '{text}')")
    own = default_name(tracker, params_path)
    if name and name in TRACKER_NAMES and (name != tracker or params_path is not None):
        raise GnnpmbError(f"run name '{name}' is a built-in tracker's; name the run otherwise, e.g. my-{name}={body}")
    return RunSpec(_check_name(name or own, text), tracker=tracker, params=params_path)


def check_runs(specs: Sequence[RunSpec]) -> tuple[RunSpec, ...]:
    """The runs in order, each name once (the same spelling twice is dropped; two runs under one name are
    refused)."""
    out: dict[str, RunSpec] = {}
    for spec in specs:
        seen = out.get(spec.name)
        if seen is None:
            out[spec.name] = spec
        elif seen != spec:
            raise GnnpmbError(
                f"two runs are named '{spec.name}' ({seen.text()} and {spec.text()}); name one otherwise, "
                f"e.g. other={spec.text().split('=')[-1]}"
            )
    return tuple(out.values())


def parse_runs(trackers: Sequence[str], results: Sequence[str] = (), default: str | None = None) -> tuple[RunSpec, ...]:
    """The runs of a command: every ``--results`` first, then every ``--tracker`` (``default`` when neither is
    given)."""
    specs = [parse_results(r) for r in results] + [parse_run(t) for t in trackers]
    if not specs and default is not None:
        specs = [parse_run(default)]
    if not specs:
        raise GnnpmbError("no run given: pass --tracker NAME or --results NAME=FILE.json")
    return check_runs(specs)


def run_inputs(specs: Sequence[RunSpec]) -> tuple[tuple[str, Path], ...]:
    """The files the runs read (results files, per-run parameter files), named by the option that gave each, for
    ``outputs.check_output_file``'s ``inputs``: no output may overwrite one."""
    out: list[tuple[str, Path]] = []
    for spec in specs:
        if spec.results is not None:
            out.append((f"--results {spec.name}", spec.results))
        if spec.params is not None:
            out.append((f"--tracker {spec.name} parameters", spec.params))
    return tuple(out)
