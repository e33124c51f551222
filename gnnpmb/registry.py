"""Tracker names (the ``--tracker`` values) and how each is built, one instance per class; wiring only.

Every tracker is a ``skeleton.ClassFilter``, whose ``step(measurements, dt_s, sink) -> list[TrackEstimate]`` is
the one frame loop; a family writes its hooks. The PMB family shares ``pmb.core.PmbCore`` and differs only in
the hypothesis strategy (paper sec. III-IV). Adding a tracker: its ``ClassFilter`` subclass (or strategy) and
one entry in ``_TRACKERS``.
"""

from __future__ import annotations

import functools
import importlib
from typing import TYPE_CHECKING

from gnnpmb.classes import TRACKING_CLASSES
from gnnpmb.errors import UnknownNameError

if TYPE_CHECKING:  # numpy-heavy; the CLI imports this module for its help text
    from gnnpmb.config import TrackerConfig
    from gnnpmb.events import Panel
    from gnnpmb.skeleton import ClassFilter
    from gnnpmb.types import IdAllocator


_TRACKERS: dict[str, tuple[str, str]] = {
    "gnnpmb": (
        "gnnpmb.pmb.gnnpmb:BestAssignment",
        "GNN-PMB: PMB keeping the single best global hypothesis (Hungarian)",
    ),
    "pmbm": ("gnnpmb.pmb.pmbm:KBest", "PMBM: up to N_h global hypotheses from Murty's k-best assignments"),
    "topmb": ("gnnpmb.pmb.topmb:MarginalMerge", "TO-PMB: track-oriented PMB, marginals by loopy belief propagation"),
    "phd": ("gnnpmb.phd.gmphd:GmPhdTracker", "GM-PHD: Gaussian-mixture probability hypothesis density filter"),
    "cphd": ("gnnpmb.phd.cphd:CphdTracker", "GM-CPHD: cardinalised PHD filter"),
    "jpda": ("gnnpmb.vector.jpda:JpdaTracker", "JPDA: joint probabilistic data association with M/N track logic"),
    "gnn": ("gnnpmb.vector.gnn:GnnTracker", "GNN: global nearest neighbour Kalman trackers with M/N track logic"),
    "greedy": (
        "gnnpmb.greedy:GreedyTracker",
        "greedy: CenterPoint's closest-pair matching of velocity-projected detection centres",
    ),
    "ab3dmot": (
        "gnnpmb.box.ab3dmot:make",
        "AB3DMOT: 3D IoU, Hungarian, 10-D box Kalman filter, birth and death by hits and misses",
    ),
    "prob3dmot": (
        "gnnpmb.box.prob3dmot:make",
        "Probabilistic 3D MOT: Mahalanobis distance, greedy matching, noise learned per class",
    ),
    "simpletrack": (
        "gnnpmb.box.simpletrack:make_simpletrack",
        "SimpleTrack: 3D GIoU, Hungarian, NMS, detector-velocity motion model, score decay",
    ),
    "immortal": (
        "gnnpmb.box.simpletrack:make_immortal",
        "ImmortalTracker: SimpleTrack whose tracks are never deleted, predicted while unseen",
    ),
    "cbmot": (
        "gnnpmb.cbmot:CbmotTracker",
        "CBMOT: CenterPoint's greedy tracker with confidence-based score refinement",
    ),
}
"""Tracker name -> (``module:callable`` building its ``ClassFilter`` from (class name, config, ids), or for the
PMB family its hypothesis strategy, ``_PMB_STRATEGY_SECTION``; one-line description). Modules are imported on
first use: the CLI imports this module for its help text."""

_PMB_STRATEGY_SECTION: dict[str, str | None] = {"gnnpmb": None, "pmbm": "pmbm", "topmb": "lbp"}
"""The PMB family (``pmb.core.PmbCore`` with a strategy): the config section its strategy is built from."""

TRACKER_NAMES: tuple[str, ...] = tuple(_TRACKERS)


def _build(name: str, class_name: str, config: TrackerConfig, ids: IdAllocator) -> ClassFilter:
    module, _, attribute = _TRACKERS[name][0].partition(":")
    make = getattr(importlib.import_module(module), attribute)
    if name not in _PMB_STRATEGY_SECTION:
        return make(class_name, config, ids)
    from gnnpmb.pmb.core import PmbCore

    section = _PMB_STRATEGY_SECTION[name]
    return PmbCore(class_name, config, make() if section is None else make(getattr(config, section)), ids)


def check_tracker(name: str) -> str:
    if name not in _TRACKERS:
        raise UnknownNameError(f"unknown tracker '{name}'; choose one of: {', '.join(TRACKER_NAMES)}")
    return name


def check_classes(names: list[str]) -> list[str]:
    bad = [n for n in names if n not in TRACKING_CLASSES]
    if bad:
        raise UnknownNameError(f"unknown class '{bad[0]}'; choose from: {', '.join(TRACKING_CLASSES)}")
    if not names:
        raise UnknownNameError(f"no classes given; choose from: {', '.join(TRACKING_CLASSES)}")
    return names


def tracker_panels(name: str) -> tuple[Panel, ...]:
    """The tracker-specific viewer panels tracker ``name`` declares (the same for every class)."""
    return declared(name)[0]


def tracker_has_existence(name: str) -> bool:
    """Whether tracker ``name``'s tracks have an existence probability (``skeleton.ClassFilter.has_existence``)."""
    return declared(name)[1]


def tracker_has_gates(name: str) -> bool:
    """Whether tracker ``name`` gates with the innovation covariance (``skeleton.ClassFilter.has_gates``)."""
    return declared(name)[2]


def tracker_keeps_detection_box(name: str) -> bool:
    """Whether tracker ``name``'s output boxes carry their detections' size and heading
    (``skeleton.ClassFilter.keeps_detection_box``)."""
    return declared(name)[4]


@functools.cache
def declared(name: str) -> tuple[tuple[Panel, ...], bool, bool, bool, bool]:
    """What tracker ``name`` declares (panels, has_existence, has_gates, has_costs, keeps_detection_box), read
    once from an instance for the first class with the default configuration (building one costs a couple of
    milliseconds, and the blueprint asks several times per tracker)."""
    from gnnpmb.config import TrackerConfig
    from gnnpmb.types import IdAllocator

    sample = make_class_tracker(name, TRACKING_CLASSES[0], TrackerConfig(), IdAllocator())
    return sample.panels, sample.has_existence, sample.has_gates, sample.has_costs, sample.keeps_detection_box


def make_class_tracker(name: str, class_name: str, config: TrackerConfig, ids: IdAllocator) -> ClassFilter:
    """Tracker ``name`` for class ``class_name``; it sees ``config`` with that class's overrides applied."""
    check_tracker(name)
    return _build(name, class_name, config.resolved(class_name), ids)
