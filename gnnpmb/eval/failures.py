"""The failure finder: the frames and ids the official metrics blame, and two failure patterns of the paper.

One scene of a tracking submission is prepared exactly as ``TrackingEval`` prepares it (the devkit's loaders:
class ranges, boxes without points, bike racks, track-averaged scores, interpolation inside tracks). Per
class, the devkit's ``TrackingEvaluation.accumulate`` picks the recall threshold with the best MOTA, as the
official MOTA, IDS, FP and FN do; the frames are then fed again through the devkit's own accumulator
(``MOTAccumulatorCustom.update``: CLEAR-MOT matching, Bernardin & Stiefelhagen 2008, with a 2 m centre
distance) at that threshold, so every reported event is one the official counts include. The devkit merges its
per-scene accumulators with renamed ids, hence this replay, which keeps the real ids and frames.

Kinds (one ``Failure`` per event):

* ``id_switch``: a SWITCH event; gt_ids = (object,), track_ids = (old track, new track).
* ``fragmentation``: an object tracked before and after this frame becomes missed here (the devkit's FRAG);
  track_ids = (the track it had,).
* ``false_track``: an FP event (a track box matched to no object); track_ids = (track,).
* ``miss``: a MISS event (an object no track box covers); gt_ids = (object,).
* ``coalescence`` (paper sec. I and V-C): one track stands for several close objects of one class: an object
  is missed while a track matched to another object whose centre is < ``coalescence_radius_m`` away lies
  within the match distance of it as well; gt_ids = (matched object, missed objects...), track_ids = (track,).
* ``identity_theft`` (cascading identity theft, paper sec. V-C): a track born on false detections (its first
  frames are FPs) takes over a real object that another track held, causing the object's ID switch;
  gt_ids = (object,), track_ids = (thief, victim). The victim, left without its object, may steal the next
  object in turn: a cascade (``generation`` 2, 3, ...).
"""

from __future__ import annotations

import enum
import json
import math
from collections import defaultdict
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from gnnpmb.errors import DataError
from gnnpmb.eval.evaluated import Dropped, GtFrame, TrackEval, gt_frames, track_evals
from gnnpmb.eval.nuscenes_eval import class_evaluation, quiet_devkit, scene_sample_tokens, tracking_config
from gnnpmb.eval.official_scores import OfficialScores, json_number, official_scores

if TYPE_CHECKING:
    from nuscenes import NuScenes
    from nuscenes.eval.common.data_classes import EvalBoxes
    from nuscenes.eval.tracking.data_classes import TrackingBox, TrackingConfig

COALESCENCE_RADIUS_M = 2.0
"""Objects with BEV centres closer than this may be covered by one track (the devkit's match distance)."""

_NOT_EVENTS = frozenset({"RAW", "ASCEND", "TRANSFER", "MIGRATE"})
"""Bookkeeping rows of the accumulator; the metrics count only MATCH, SWITCH, MISS and FP ("noraw")."""


class FailureKind(enum.Enum):
    ID_SWITCH = "id_switch"
    FRAGMENTATION = "fragmentation"
    FALSE_TRACK = "false_track"
    MISS = "miss"
    COALESCENCE = "coalescence"
    IDENTITY_THEFT = "identity_theft"


def short_id(object_id: str) -> str:
    """A short, still distinctive form of an id for tables and labels (first 6 characters of long tokens)."""
    return object_id if len(object_id) <= 8 else object_id[:6]


OPEN_FIRST = (
    FailureKind.ID_SWITCH,
    FailureKind.IDENTITY_THEFT,
    FailureKind.COALESCENCE,
    FailureKind.FRAGMENTATION,
    FailureKind.FALSE_TRACK,
    FailureKind.MISS,
)
"""The order in which failure kinds are suggested for a first look (``FailureReport.first_worth_opening``): the
association errors a tracker debugger is for come before misses and false tracks, which the detector often causes."""


@dataclass(frozen=True, slots=True)
class FailureBox:
    """A box involved in a failure, as the evaluation saw it (ground truth or track, possibly interpolated).

    role: "gt" or "track" plus what it did (e.g. "missed gt", "old track"); object_id: instance token or
    tracking id; translation_m (3,), size_wlh_m (3,), quat_wxyz (4,) in the global frame; interpolated: a
    ground-truth box the evaluation made up between annotated frames because the object had no LiDAR or radar
    points at this one (the devkit drops such boxes, then interpolates its tracks over the gap); annotated: False
    where the object had no annotation at all at this keyframe (it left view and came back: the gap is in the
    annotations, not in the points).
    """

    role: str
    object_id: str
    translation_m: tuple[float, float, float]
    size_wlh_m: tuple[float, float, float]
    quat_wxyz: tuple[float, float, float, float]
    interpolated: bool = False
    annotated: bool = True
    dropped: str | None = None
    """Why the evaluation dropped an interpolated ground-truth box's annotation (``Dropped``'s value; None: no
    points, as before it was recorded): beyond the class range too (audit truth53, world9: a pedestrian with 12
    LiDAR points crossing the 40 m range was noted "no points")."""

    @property
    def is_gt(self) -> bool:
        return self.role.endswith("gt")


@dataclass(frozen=True, slots=True)
class Failure:
    """One failure event at one keyframe (``frame_index`` into the scene's keyframes); see the module
    docstring for what gt_ids and track_ids hold per kind. generation counts cascade steps of identity theft
    (else 0)."""

    kind: FailureKind
    frame_index: int
    sample_token: str
    class_name: str
    gt_ids: tuple[str, ...]
    track_ids: tuple[str, ...]
    boxes: tuple[FailureBox, ...]
    generation: int = 0

    def describe(self) -> str:
        """One readable line naming the ids (and saying when a ground-truth box was interpolated)."""
        made_up = {b.object_id: _dropped_note(b) for b in self.boxes if b.is_gt and b.interpolated}
        if not made_up:
            return self._what()
        if len(self.gt_ids) == 1:
            return self._what() + f" (GT box interpolated by the evaluation: {next(iter(made_up.values()))})"
        parts = []  # of several objects, the one(s) it concerns
        for why in dict.fromkeys(made_up.values()):
            named = ", ".join(f"GT {short_id(g)}" for g, a in made_up.items() if a == why)
            parts.append(f"{named}: box interpolated by the evaluation, {why}")
        return self._what() + f" ({'; '.join(parts)})"

    @property
    def gt_interpolated(self) -> bool:
        """Whether a ground-truth box of this failure is one the evaluation interpolated (``FailureBox``)."""
        return any(b.interpolated for b in self.boxes if b.is_gt)

    def _what(self) -> str:
        gt = ", ".join(f"GT {short_id(g)}" for g in self.gt_ids)
        tracks = [f"track {t}" for t in self.track_ids]
        match self.kind:
            case FailureKind.ID_SWITCH:
                return f"{self.class_name} {gt}: {tracks[0]} -> {tracks[1]}"
            case FailureKind.FRAGMENTATION:
                return f"{self.class_name} {gt} lost by {tracks[0]}"
            case FailureKind.FALSE_TRACK:
                return f"{self.class_name} {tracks[0]}"
            case FailureKind.MISS:
                return f"{self.class_name} {gt}"
            case FailureKind.COALESCENCE:
                missed = ", ".join(f"GT {short_id(g)}" for g in self.gt_ids[1:])
                return f"{self.class_name} {tracks[0]} covers GT {short_id(self.gt_ids[0])} and missed {missed}"
            case FailureKind.IDENTITY_THEFT:
                cascade = f" (cascade step {self.generation})" if self.generation > 1 else ""
                return f"{self.class_name} {tracks[0]} took {gt} from {tracks[1]}{cascade}"
        raise AssertionError(self.kind)

    def to_json(self) -> dict[str, Any]:
        return {
            "kind": self.kind.value,
            "frame_index": self.frame_index,
            "sample_token": self.sample_token,
            "class_name": self.class_name,
            "gt_ids": list(self.gt_ids),
            "track_ids": list(self.track_ids),
            "generation": self.generation,
            "description": self.describe(),
            "boxes": [
                {
                    "role": b.role,
                    "id": b.object_id,
                    "translation": list(b.translation_m),
                    "size": list(b.size_wlh_m),
                    "rotation": list(b.quat_wxyz),
                    "interpolated": b.interpolated,
                    "annotated": b.annotated,
                    "dropped": b.dropped,
                }
                for b in self.boxes
            ],
        }

    @staticmethod
    def from_json(data: Mapping[str, Any]) -> Failure:
        """The failure ``to_json`` wrote (its description is derived, so not read)."""
        return Failure(
            kind=FailureKind(data["kind"]),
            frame_index=int(data["frame_index"]),
            sample_token=str(data["sample_token"]),
            class_name=str(data["class_name"]),
            gt_ids=tuple(data["gt_ids"]),
            track_ids=tuple(data["track_ids"]),
            boxes=tuple(
                FailureBox(
                    role=b["role"],
                    object_id=b["id"],
                    translation_m=tuple(b["translation"]),
                    size_wlh_m=tuple(b["size"]),
                    quat_wxyz=tuple(b["rotation"]),
                    interpolated=bool(b.get("interpolated", False)),
                    annotated=bool(b.get("annotated", True)),
                    dropped=b.get("dropped"),
                )
                for b in data["boxes"]
            ),
            generation=int(data["generation"]),
        )


@dataclass(frozen=True, slots=True)
class ClassEvaluation:
    """The devkit's numbers for one class at the best-MOTA recall threshold (score threshold None: no recall
    level was reached, every box counts). tp, fp, fn, ids, frag are the devkit's own counts (NaN if
    unknown)."""

    class_name: str
    threshold: float | None
    mota: float
    tp: float
    fp: float
    fn: float
    ids: float
    frag: float


@dataclass(frozen=True, slots=True)
class FailureReport:
    """Every failure of one tracker on one scene; sample_tokens (F,) in keyframe order; classes: the evaluated
    classes (those with ground truth in the scene after the devkit's filters); track_scores: tracking id -> the
    score the evaluation compared with its class's threshold, the devkit's average of the track's box scores
    (after its range filter), the same at every frame of the track; gt_frames: instance token -> frame -> how the
    evaluation saw the object there, track_evals: tracking id -> how it saw the track (``eval.evaluated``);
    frames: the keyframes (start, end exclusive) evaluated when only those were tracked (``--frames``), None for
    the whole scene; failure frame indices are always the scene's keyframe indices, and ids number the failures
    of the evaluated keyframes; scores: the official metrics of the evaluated keyframes, read from the same
    accumulation as the failures (None: not kept)."""

    scene_name: str
    tracker: str
    sample_tokens: tuple[str, ...]
    classes: tuple[ClassEvaluation, ...]
    failures: tuple[Failure, ...]
    coalescence_radius_m: float = COALESCENCE_RADIUS_M
    track_scores: Mapping[str, float] = field(default_factory=dict)
    gt_frames: Mapping[str, Mapping[int, GtFrame]] = field(default_factory=dict)
    track_evals: Mapping[str, TrackEval] = field(default_factory=dict)
    frames: tuple[int, int] | None = None
    scores: OfficialScores | None = None

    def gt_frame(self, gt_id: str, frame: int) -> GtFrame | None:
        """How the evaluation saw object ``gt_id`` at ``frame`` (None: not annotated there)."""
        return self.gt_frames.get(gt_id, {}).get(frame)

    def of_kind(self, kind: FailureKind) -> list[Failure]:
        return [f for f in self.failures if f.kind is kind]

    def threshold_of(self, class_name: str) -> float | None:
        """The score from which the evaluation counted boxes of ``class_name`` (None: every box, or not scored)."""
        return next((c.threshold for c in self.classes if c.class_name == class_name), None)

    def ids(self) -> list[str]:
        """A stable id per failure, in order: ``<kind>:<n>`` numbering each kind from 1 by frame (e.g.
        ``id_switch:2``); ``gnnpmb failures`` prints them and ``gnnpmb-viz --focus`` takes them."""
        seen: dict[FailureKind, int] = {}
        out = []
        for f in self.failures:
            seen[f.kind] = seen.get(f.kind, 0) + 1
            out.append(f"{f.kind.value}:{seen[f.kind]}")
        return out

    def totals_text(self) -> str:
        """E.g. "3 id_switch, 4 fragmentation, 38 false_track, 27 miss, 0 coalescence, 1 identity_theft"."""
        return ", ".join(f"{len(self.of_kind(k))} {k.value}" for k in FailureKind)

    def scope_text(self) -> str:
        """What was evaluated: "" for the whole scene, else e.g. " in keyframes 0:6 (only those were tracked and
        evaluated)"."""
        if self.frames is None:
            return ""
        return f" in keyframes {self.frames[0]}:{self.frames[1]} (only those were tracked and evaluated)"

    def first_worth_opening(self, frames: range | None = None) -> str | None:
        """The id of the first failure of the first kind in ``OPEN_FIRST`` that occurred (at ``frames``, default
        all), preferring failures whose ground truth the evaluation did not interpolate (those are often the
        devkit's doing, see ``FailureBox``), and, within a kind, one after the first keyframe (a failure there has
        no history to show); None: no failure."""
        ids = [
            (i, f) for i, f in zip(self.ids(), self.failures, strict=True) if frames is None or f.frame_index in frames
        ]
        for allow_interpolated in (False, True):
            for kind in OPEN_FIRST:
                hits = [(i, f) for i, f in ids if f.kind is kind and (allow_interpolated or not f.gt_interpolated)]
                if hits:
                    return next((i for i, f in hits if f.frame_index > 0), hits[0][0])
        return None

    def by_id(self, failure_id: str) -> Failure | None:
        """The failure with ``failure_id`` (see ``ids``), None if there is none."""
        return dict(zip(self.ids(), self.failures, strict=True)).get(failure_id)

    def counts(self, kind: FailureKind) -> np.ndarray:
        """(F,) number of failures of ``kind`` per keyframe."""
        out = np.zeros(len(self.sample_tokens), dtype=np.int64)
        for f in self.of_kind(kind):
            out[f.frame_index] += 1
        return out

    def to_json(self) -> dict[str, Any]:
        return {
            "scene": self.scene_name,
            "tracker": self.tracker,
            "sample_tokens": list(self.sample_tokens),
            "coalescence_radius_m": self.coalescence_radius_m,
            "classes": [
                {
                    "class_name": c.class_name,
                    "threshold": c.threshold,
                    **{k: json_number(getattr(c, k)) for k in ("mota", "tp", "fp", "fn", "ids", "frag")},
                }
                for c in self.classes
            ],
            "totals": {kind.value: len(self.of_kind(kind)) for kind in FailureKind},
            "track_scores": dict(self.track_scores),
            "gt_frames": {g: [v.to_json() for v in frames.values()] for g, frames in self.gt_frames.items()},
            "track_evals": {t: v.to_json() for t, v in self.track_evals.items()},
            "frames": None if self.frames is None else list(self.frames),
            "scores": None if self.scores is None else self.scores.to_json(),
            "failures": [f.to_json() for f in self.failures],
        }

    @staticmethod
    def from_json(data: Mapping[str, Any]) -> FailureReport:
        """The report ``to_json`` wrote (totals are derived, so not read; a null count reads as NaN)."""
        counts = ("mota", "tp", "fp", "fn", "ids", "frag")
        return FailureReport(
            scene_name=str(data["scene"]),
            tracker=str(data["tracker"]),
            sample_tokens=tuple(data["sample_tokens"]),
            classes=tuple(
                ClassEvaluation(
                    c["class_name"],
                    None if c["threshold"] is None else float(c["threshold"]),
                    *(math.nan if c[k] is None else float(c[k]) for k in counts),
                )
                for c in data["classes"]
            ),
            failures=tuple(Failure.from_json(f) for f in data["failures"]),
            coalescence_radius_m=float(data["coalescence_radius_m"]),
            track_scores={str(k): float(v) for k, v in data.get("track_scores", {}).items()},
            gt_frames={
                str(g): {(v := GtFrame.from_json(row)).frame: v for row in rows}
                for g, rows in data.get("gt_frames", {}).items()
            },
            track_evals={str(t): TrackEval.from_json(v) for t, v in data.get("track_evals", {}).items()},
            frames=None if data.get("frames") is None else (int(data["frames"][0]), int(data["frames"][1])),
            scores=None if data.get("scores") is None else OfficialScores.from_json(data["scores"]),
        )


def _dropped_note(b: FailureBox) -> str:
    """Why an interpolated ground-truth box's annotation was not scored, in a table note's words."""
    if not b.annotated:
        return "not annotated"  # none at all: it left view and came back
    return "no points" if b.dropped in (None, Dropped.NO_POINTS.value) else b.dropped


def _unannotated(failure: Failure, annotated: Mapping[str, Mapping[int, Any]]) -> Failure:
    """``failure`` with each interpolated ground-truth box of an object that had no annotation at its keyframe
    marked so, and of one that had, why the evaluation dropped that annotation (``annotated``: object -> frame ->
    ``GtFrame``, ``gt_frames``)."""

    def marked(b: FailureBox) -> FailureBox:
        if not (b.is_gt and b.interpolated):
            return b
        g = annotated.get(b.object_id, {}).get(failure.frame_index)
        if g is None:
            return replace(b, annotated=False)
        return replace(b, dropped=g.dropped.value) if g.dropped is not None else b

    boxes = tuple(marked(b) for b in failure.boxes)
    return failure if boxes == failure.boxes else replace(failure, boxes=boxes)


def _box(role: str, box: TrackingBox) -> FailureBox:
    """The evaluation's box; a ground-truth box without a point count (the devkit's ``num_pts`` stays -1 on the
    boxes ``interpolate_tracks`` makes; annotated boxes with 0 points were filtered out before) is interpolated."""
    return FailureBox(
        role=role,
        object_id=str(box.tracking_id),
        translation_m=tuple(float(v) for v in box.translation),
        size_wlh_m=tuple(float(v) for v in box.size),
        quat_wxyz=tuple(float(v) for v in box.rotation),
        interpolated=role.endswith("gt") and box.num_pts < 0,
    )


def _split_with_scene(nusc: NuScenes, scene_name: str) -> str:
    """A split that holds ``scene_name`` (the devkit's ``create_tracks`` keeps only samples of a split)."""
    from nuscenes.utils.splits import create_splits_scenes

    splits = create_splits_scenes()
    custom = Path(nusc.dataroot) / nusc.version / "splits.json"
    if custom.is_file():
        try:
            splits.update(json.loads(custom.read_text(encoding="utf-8")))
        except (OSError, UnicodeDecodeError, ValueError) as exc:
            raise DataError(f"custom split file {custom} is not valid JSON ({type(exc).__name__})") from None
    for name, scenes in sorted(splits.items(), key=lambda kv: len(kv[1])):
        if scene_name in scenes:
            return name
    raise DataError(
        f"scene {scene_name} is in no nuScenes split, so the devkit cannot evaluate it; list it in "
        f'{custom} as a custom split (e.g. {{"my_split": ["{scene_name}"]}})'
    )


def _prepared(nusc: NuScenes, boxes: EvalBoxes, cfg: TrackingConfig) -> tuple[EvalBoxes, EvalBoxes, EvalBoxes]:
    """The devkit's box preparation: ego distances, then its class-range, point-count and bike-rack filter.
    Returns the boxes with ego distances before the filter, the boxes it kept, and a copy of the latter: the
    devkit's ``create_tracks`` appends the boxes it interpolates to the lists it is given."""
    from nuscenes.eval.common.loaders import add_center_dist, filter_eval_boxes

    boxes = add_center_dist(nusc, boxes)
    raw = _copy(boxes)
    if any(boxes.boxes[t] for t in boxes.sample_tokens):  # the filter asserts at least one box exists
        boxes = filter_eval_boxes(nusc, boxes, cfg.class_range, verbose=False)
    return raw, boxes, _copy(boxes)


def devkit_tracks(
    nusc: NuScenes,
    tokens: Sequence[str],
    results: Mapping[str, Sequence[Mapping[str, Any]]],
    split: str,
    cfg: TrackingConfig,
    whose: str = "",
) -> tuple[EvalBoxes, EvalBoxes, EvalBoxes, EvalBoxes, dict, dict]:
    """The devkit's loading of ground truth and of ``results`` (submission boxes by sample token) on the samples
    ``tokens``, as ``TrackingEval`` does (call it inside ``quiet_devkit``): the ground truth before and after its
    filter (``_prepared``), the predictions likewise, then both as tracks by scene (``create_tracks``). Results that
    are not submission boxes raise ``DataError`` (``whose``: which results, e.g. " of scene-0103")."""
    from nuscenes.eval.common.data_classes import EvalBoxes
    from nuscenes.eval.common.loaders import load_gt_of_sample_tokens
    from nuscenes.eval.tracking.data_classes import TrackingBox
    from nuscenes.eval.tracking.loaders import create_tracks

    try:
        pred = EvalBoxes.deserialize({t: list(results.get(t, [])) for t in tokens}, TrackingBox)
    except (AssertionError, KeyError, TypeError, ValueError) as exc:
        raise DataError(f"the tracking results{whose} are not valid submission boxes: {exc}") from None
    gt = load_gt_of_sample_tokens(nusc, tokens, TrackingBox, verbose=False)
    raw_gt, prepared_gt, kept_gt = _prepared(nusc, gt, cfg)
    raw_pred, prepared_pred, kept_pred = _prepared(nusc, pred, cfg)
    tracks_gt = create_tracks(prepared_gt, nusc, split, gt=True)
    return raw_gt, kept_gt, raw_pred, kept_pred, tracks_gt, create_tracks(prepared_pred, nusc, split, gt=False)


def _copy(boxes: EvalBoxes) -> EvalBoxes:
    """Another ``EvalBoxes`` with the same boxes in new lists."""
    from nuscenes.eval.common.data_classes import EvalBoxes

    out = EvalBoxes()
    for token in boxes.sample_tokens:
        out.add_boxes(token, list(boxes.boxes[token]))
    return out


@dataclass(slots=True)
class _Frame:
    """One keyframe the accumulator saw for one class."""

    frame_index: int
    gt: dict[str, TrackingBox]
    pred: dict[str, TrackingBox]
    events: list[tuple[str, str | None, str | None]] = field(default_factory=list)


def _accumulate(
    scene_gt: Mapping[int, list[TrackingBox]],
    scene_pred: Mapping[int, list[TrackingBox]],
    class_name: str,
    threshold: float | None,
    dist_th_tp: float,
    frame_of_timestamp: Mapping[int, int],
) -> list[_Frame]:
    """Per-frame MATCH/SWITCH/MISS/FP events of one class at one score threshold (the devkit's accumulator).

    Frames are fed exactly as ``TrackingEvaluation.accumulate_threshold`` feeds them: class filter, score
    threshold on the track-averaged score, BEV centre distances, pairs at >= dist_th_tp forbidden, frames with
    neither ground truth nor tracks skipped.
    """
    from nuscenes.eval.tracking.mot import MOTAccumulatorCustom
    from sklearn.metrics.pairwise import euclidean_distances

    acc = MOTAccumulatorCustom()
    frames: list[_Frame] = []
    for timestamp in scene_gt:
        gt = [b for b in scene_gt[timestamp] if b.tracking_name == class_name]
        every_pred = [b for b in scene_pred.get(timestamp, []) if b.tracking_name == class_name]
        pred = every_pred if threshold is None else [b for b in every_pred if b.tracking_score >= threshold]
        if not gt and not pred:
            continue
        if not gt or not pred:
            distances = np.ones((0, 0))
        else:
            distances = euclidean_distances(
                np.array([b.translation[:2] for b in gt]), np.array([b.translation[:2] for b in pred])
            )
        distances[distances >= dist_th_tp] = np.nan
        acc.update([b.tracking_id for b in gt], [b.tracking_id for b in pred], distances, frameid=len(frames))
        frames.append(
            _Frame(
                frame_of_timestamp[timestamp],
                {str(b.tracking_id): b for b in gt},
                {str(b.tracking_id): b for b in every_pred},
            )
        )
    events = acc.events
    types = events["Type"].astype(str).to_numpy()
    keep = ~np.isin(types, list(_NOT_EVENTS))
    frame_ids = events.index.get_level_values(0).to_numpy()[keep]
    oids = events["OId"].to_numpy()[keep]
    hids = events["HId"].to_numpy()[keep]
    for frame_id, kind, oid, hid in zip(frame_ids, types[keep], oids, hids, strict=True):
        frames[int(frame_id)].events.append(
            (kind, None if _missing(oid) else str(oid), None if _missing(hid) else str(hid))
        )
    return frames


def _missing(value: Any) -> bool:
    return value is None or (isinstance(value, float) and np.isnan(value))


def _bev_distance(a: TrackingBox, b: TrackingBox) -> float:
    return float(np.hypot(a.translation[0] - b.translation[0], a.translation[1] - b.translation[1]))


def _class_failures(
    frames: Sequence[_Frame],
    class_name: str,
    tokens: Sequence[str],
    dist_th_tp: float,
    coalescence_radius_m: float,
) -> list[Failure]:
    """Derive every failure of one class from its per-frame events (see the module docstring)."""
    out: list[Failure] = []

    def add(kind: FailureKind, fr: _Frame, gt_ids, track_ids, boxes, generation: int = 0) -> None:
        out.append(
            Failure(
                kind,
                fr.frame_index,
                tokens[fr.frame_index],
                class_name,
                tuple(gt_ids),
                tuple(track_ids),
                tuple(boxes),
                generation,
            )
        )

    last_track: dict[str, str] = {}  # object -> track it was last matched to (the accumulator's memory)
    history: dict[str, list[tuple[_Frame, bool]]] = defaultdict(list)  # object -> (frame, missed) in order
    seen_tracks: set[str] = set()
    last_seen: dict[str, TrackingBox] = {}  # track -> its latest box
    # Tracks that may steal an identity: born false (generation 1, lost nothing) or robbed by a thief
    # (the thief's generation + 1, and the object it lost: taking that one back is no theft).
    candidates: dict[str, tuple[int, str | None]] = {}
    for fr in frames:
        matched = {o: h for kind, o, h in fr.events if kind in ("MATCH", "SWITCH")}
        switches = [(o, h) for kind, o, h in fr.events if kind == "SWITCH"]
        for kind, o, h in fr.events:
            if kind == "SWITCH":
                old = last_track[o]
                boxes = [_box("gt", fr.gt[o]), _box("new track", fr.pred[h])]
                if old in fr.pred:
                    boxes.append(_box("old track", fr.pred[old]))
                elif old in last_seen:  # the lost track where it was last reported
                    boxes.append(_box("old track", last_seen[old]))
                add(FailureKind.ID_SWITCH, fr, [o], [old, h], boxes)
            elif kind == "MISS":
                add(FailureKind.MISS, fr, [o], [], [_box("missed gt", fr.gt[o])])
            elif kind == "FP":
                add(FailureKind.FALSE_TRACK, fr, [], [h], [_box("false track", fr.pred[h])])
            if o is not None:
                history[o].append((fr, kind == "MISS"))

        # Cascading identity theft: a switch whose new track is a candidate; its victim becomes one (same
        # frame included, so a chain of thefts within one frame is followed).
        stolen: set[str] = set()
        changed = True
        while changed:
            changed = False
            for o, h in switches:
                if o in stolen or h not in candidates or candidates[h][1] == o:
                    continue
                victim = last_track[o]
                generation = candidates[h][0]
                boxes = [_box("gt", fr.gt[o]), _box("thief track", fr.pred[h])]
                if victim in fr.pred:
                    boxes.append(_box("victim track", fr.pred[victim]))
                add(FailureKind.IDENTITY_THEFT, fr, [o], [h, victim], boxes, generation)
                stolen.add(o)
                candidates.setdefault(victim, (generation + 1, o))
                changed = True
        for h in matched.values():
            candidates.pop(h, None)
        for kind, _o, h in fr.events:
            if kind == "FP" and h not in seen_tracks:
                candidates[h] = (1, None)
        seen_tracks.update(h for _kind, _o, h in fr.events if h is not None)

        # Coalescence: a missed object next to an object whose track also lies within match distance of it.
        covered: dict[str, list[str]] = defaultdict(list)
        for kind, o, _h in fr.events:
            if kind != "MISS":
                continue
            near = [
                (_bev_distance(fr.gt[o], fr.gt[b]), b)
                for b, h in matched.items()
                if _bev_distance(fr.gt[o], fr.gt[b]) < coalescence_radius_m
                and _bev_distance(fr.gt[o], fr.pred[h]) < dist_th_tp
            ]
            if near:
                covered[min(near)[1]].append(o)
        for b, missed in covered.items():
            h = matched[b]
            boxes = [_box("track", fr.pred[h]), _box("matched gt", fr.gt[b])]
            boxes += [_box("missed gt", fr.gt[o]) for o in missed]
            add(FailureKind.COALESCENCE, fr, [b, *missed], [h], boxes)
        last_track.update(matched)
        last_seen.update(fr.pred)

    # Fragmentation (the devkit's FRAG): tracked -> missed transitions inside an object's tracked span.
    for o, steps in history.items():
        tracked = [i for i, (_fr, missed) in enumerate(steps) if not missed]
        if not tracked:
            continue
        track_of = None
        for i in range(tracked[0], tracked[-1] + 1):
            fr, missed = steps[i]
            if missed and not steps[i - 1][1]:
                add(FailureKind.FRAGMENTATION, fr, [o], [track_of], [_box("missed gt", fr.gt[o])])
            if not missed:
                track_of = next(h for kind, oo, h in fr.events if oo == o and kind != "MISS")
    return out


def find_failures(
    nusc: NuScenes,
    scene_name: str,
    results: Mapping[str, Sequence[Mapping[str, Any]]],
    tracker: str,
    coalescence_radius_m: float = COALESCENCE_RADIUS_M,
    keyframes: range | None = None,
    classes: Sequence[str] | None = None,
) -> FailureReport:
    """Evaluate one scene of a tracking submission with the devkit and list its failures.

    results: submission boxes keyed by sample token (``submission.run_results``); samples of the scene without
    an entry count as empty. keyframes: evaluate only these (those a ``--frames`` run tracked), as if the
    scene held no others; None or the whole scene: all. classes: evaluate only these (those a ``--classes`` run
    tracked: the objects of the others are no one's misses); None: every tracking class. Failures are sorted by
    frame, then kind, class and ids; the report keeps the official metrics of the same accumulation
    (``FailureReport.scores``).
    """
    tokens = scene_sample_tokens(nusc, scene_name)
    window = range(len(tokens))
    if keyframes is not None:
        window = range(max(keyframes.start, 0), min(keyframes.stop, len(tokens)))
    evaluated = tokens[window.start : window.stop]
    frame_of_timestamp = {nusc.get("sample", t)["timestamp"]: i for i, t in enumerate(tokens)}
    split = _split_with_scene(nusc, scene_name)
    cfg = tracking_config()
    with quiet_devkit():
        raw_gt, kept_gt, raw_pred, kept_pred, tracks_gt, tracks_pred = devkit_tracks(
            nusc, evaluated, results, split, cfg, f" of {scene_name}"
        )
        scene_token = nusc.get("sample", evaluated[0])["scene_token"]
        evaluations: list[ClassEvaluation] = []
        failures: list[Failure] = []
        matches: dict[str, list[tuple[int, str]]] = defaultdict(list)  # track -> (frame, object) it was matched to
        class_data = []
        for class_name in cfg.class_names:
            if classes is not None and class_name not in classes:
                continue
            md = class_evaluation(tracks_gt, tracks_pred, class_name, cfg).accumulate()
            class_data.append((class_name, md))
            if np.all(np.isnan(md.mota)):
                continue  # no ground truth of this class: the devkit does not score it
            best = int(np.nanargmax(md.mota))
            threshold = None if np.isnan(md.confidence[best]) else float(md.confidence[best])
            evaluations.append(
                ClassEvaluation(
                    class_name,
                    threshold,
                    *(float(md.get_metric(m)[best]) for m in ("mota", "tp", "fp", "fn", "ids", "frag")),
                )
            )
            frames = _accumulate(
                tracks_gt[scene_token],
                tracks_pred[scene_token],
                class_name,
                threshold,
                cfg.dist_th_tp,
                frame_of_timestamp,
            )
            failures += _class_failures(frames, class_name, tokens, cfg.dist_th_tp, coalescence_radius_m)
            for fr in frames:
                for kind, o, h in fr.events:
                    if kind in ("MATCH", "SWITCH"):
                        matches[h].append((fr.frame_index, o))
        scores = official_scores(class_data, cfg)
    kind_order = {kind: i for i, kind in enumerate(FailureKind)}
    failures.sort(key=lambda f: (f.frame_index, kind_order[f.kind], f.class_name, f.gt_ids, f.track_ids))
    track_scores = {
        str(b.tracking_id): float(b.tracking_score) for boxes in tracks_pred[scene_token].values() for b in boxes
    }
    whole = len(window) == len(tokens)
    annotated = gt_frames(raw_gt, kept_gt, tracks_gt[scene_token], frame_of_timestamp, tokens, cfg.class_range)
    return FailureReport(
        scene_name,
        tracker,
        tuple(tokens),
        tuple(evaluations),
        tuple(_unannotated(f, annotated) for f in failures),
        coalescence_radius_m,
        track_scores,
        annotated,
        track_evals(
            results,
            raw_pred,
            kept_pred,
            tracks_pred[scene_token],
            track_scores,
            frame_of_timestamp,
            tokens,
            matches,
            cfg.class_range,
        ),
        None if whole else (window.start, window.stop),
        scores,
    )
