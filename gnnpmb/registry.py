"""Tracker names (the ``--tracker`` values) and how each is built, one instance per class; wiring only.

Every tracker is a ``skeleton.ClassFilter``, whose ``step(measurements, dt_s, sink) -> list[TrackEstimate]`` is
the one frame loop; a family writes its hooks. The PMB family shares ``pmb.core.PmbCore`` and differs only in
the hypothesis strategy (paper sec. III-IV). Adding a tracker: its ``ClassFilter`` subclass (or strategy), one
factory here, one line in ``TRACKER_DESCRIPTIONS``.
"""

from __future__ import annotations

import functools
from collections.abc import Callable
from typing import TYPE_CHECKING

from gnnpmb.classes import TRACKING_CLASSES
from gnnpmb.errors import UnknownNameError

if TYPE_CHECKING:  # numpy-heavy; the CLI imports this module for its help text
    from gnnpmb.config import TrackerConfig
    from gnnpmb.events import Panel
    from gnnpmb.skeleton import ClassFilter
    from gnnpmb.types import IdAllocator


def _gnnpmb(class_name: str, config: TrackerConfig, ids: IdAllocator) -> ClassFilter:
    from gnnpmb.pmb.core import PmbCore
    from gnnpmb.pmb.gnnpmb import BestAssignment

    return PmbCore(class_name, config, BestAssignment(), ids)


def _pmbm(class_name: str, config: TrackerConfig, ids: IdAllocator) -> ClassFilter:
    from gnnpmb.pmb.core import PmbCore
    from gnnpmb.pmb.pmbm import KBest

    return PmbCore(class_name, config, KBest(config.pmbm), ids)


def _topmb(class_name: str, config: TrackerConfig, ids: IdAllocator) -> ClassFilter:
    from gnnpmb.pmb.core import PmbCore
    from gnnpmb.pmb.topmb import MarginalMerge

    return PmbCore(class_name, config, MarginalMerge(config.lbp), ids)


def _phd(class_name: str, config: TrackerConfig, ids: IdAllocator) -> ClassFilter:
    from gnnpmb.phd.gmphd import GmPhdTracker

    return GmPhdTracker(class_name, config, ids)


def _cphd(class_name: str, config: TrackerConfig, ids: IdAllocator) -> ClassFilter:
    from gnnpmb.phd.cphd import CphdTracker

    return CphdTracker(class_name, config, ids)


def _jpda(class_name: str, config: TrackerConfig, ids: IdAllocator) -> ClassFilter:
    from gnnpmb.vector.jpda import JpdaTracker

    return JpdaTracker(class_name, config, ids)


def _gnn(class_name: str, config: TrackerConfig, ids: IdAllocator) -> ClassFilter:
    from gnnpmb.vector.gnn import GnnTracker

    return GnnTracker(class_name, config, ids)


def _greedy(class_name: str, config: TrackerConfig, ids: IdAllocator) -> ClassFilter:
    from gnnpmb.greedy import GreedyTracker

    return GreedyTracker(class_name, config, ids)


def _ab3dmot(class_name: str, config: TrackerConfig, ids: IdAllocator) -> ClassFilter:
    from gnnpmb.box.ab3dmot import make

    return make(class_name, config, ids)


def _prob3dmot(class_name: str, config: TrackerConfig, ids: IdAllocator) -> ClassFilter:
    from gnnpmb.box.prob3dmot import make

    return make(class_name, config, ids)


def _simpletrack(class_name: str, config: TrackerConfig, ids: IdAllocator) -> ClassFilter:
    from gnnpmb.box.simpletrack import make_simpletrack

    return make_simpletrack(class_name, config, ids)


def _immortal(class_name: str, config: TrackerConfig, ids: IdAllocator) -> ClassFilter:
    from gnnpmb.box.simpletrack import make_immortal

    return make_immortal(class_name, config, ids)


def _cbmot(class_name: str, config: TrackerConfig, ids: IdAllocator) -> ClassFilter:
    from gnnpmb.cbmot import CbmotTracker

    return CbmotTracker(class_name, config, ids)


_FACTORIES: dict[str, Callable[[str, TrackerConfig, IdAllocator], ClassFilter]] = {
    "gnnpmb": _gnnpmb,
    "pmbm": _pmbm,
    "topmb": _topmb,
    "phd": _phd,
    "cphd": _cphd,
    "jpda": _jpda,
    "gnn": _gnn,
    "greedy": _greedy,
    "ab3dmot": _ab3dmot,
    "prob3dmot": _prob3dmot,
    "simpletrack": _simpletrack,
    "immortal": _immortal,
    "cbmot": _cbmot,
}

TRACKER_NAMES: tuple[str, ...] = tuple(_FACTORIES)

TRACKER_DESCRIPTIONS: dict[str, str] = {
    "gnnpmb": "GNN-PMB: PMB keeping the single best global hypothesis (Hungarian)",
    "pmbm": "PMBM: up to N_h global hypotheses from Murty's k-best assignments",
    "topmb": "TO-PMB: track-oriented PMB, marginals by loopy belief propagation",
    "phd": "GM-PHD: Gaussian-mixture probability hypothesis density filter",
    "cphd": "GM-CPHD: cardinalised PHD filter",
    "jpda": "JPDA: joint probabilistic data association with M/N track logic",
    "gnn": "GNN: global nearest neighbour Kalman trackers with M/N track logic",
    "greedy": "greedy: CenterPoint's closest-pair matching of velocity-projected detection centres",
    "ab3dmot": "AB3DMOT: 3D IoU, Hungarian, 10-D box Kalman filter, birth and death by hits and misses",
    "prob3dmot": "Probabilistic 3D MOT: Mahalanobis distance, greedy matching, noise learned per class",
    "simpletrack": "SimpleTrack: 3D GIoU, Hungarian, NMS, detector-velocity motion model, score decay",
    "immortal": "ImmortalTracker: SimpleTrack whose tracks are never deleted, predicted while unseen",
    "cbmot": "CBMOT: CenterPoint's greedy tracker with confidence-based score refinement",
}


def check_tracker(name: str) -> str:
    if name not in _FACTORIES:
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
    return _declared(name)[0]


def tracker_has_existence(name: str) -> bool:
    """Whether tracker ``name``'s tracks have an existence probability (``skeleton.ClassFilter.has_existence``)."""
    return _declared(name)[1]


def tracker_has_gates(name: str) -> bool:
    """Whether tracker ``name`` gates with the innovation covariance (``skeleton.ClassFilter.has_gates``)."""
    return _declared(name)[2]


def tracker_has_costs(name: str) -> bool:
    """Whether tracker ``name``'s update follows a chosen assignment (``skeleton.ClassFilter.has_costs``)."""
    return _declared(name)[3]


def tracker_keeps_detection_box(name: str) -> bool:
    """Whether tracker ``name``'s output boxes carry their detections' size and heading
    (``skeleton.ClassFilter.keeps_detection_box``)."""
    return _declared(name)[4]


@functools.cache
def _declared(name: str) -> tuple[tuple[Panel, ...], bool, bool, bool, bool]:
    """What tracker ``name`` declares (panels, has_existence, has_gates, has_costs, keeps_detection_box), read
    once from an instance for the first class with the default configuration (building one costs a couple of
    milliseconds, and the blueprint asks several times per tracker)."""
    from gnnpmb.config import TrackerConfig
    from gnnpmb.types import IdAllocator

    sample = make_class_tracker(name, TRACKING_CLASSES[0], TrackerConfig(), IdAllocator())
    return sample.panels, sample.has_existence, sample.has_gates, sample.has_costs, sample.keeps_detection_box


def make_class_tracker(name: str, class_name: str, config: TrackerConfig, ids: IdAllocator) -> ClassFilter:
    """Tracker ``name`` for class ``class_name``; it sees ``config`` with that class's overrides applied."""
    return _FACTORIES[check_tracker(name)](class_name, config.resolved(class_name), ids)
