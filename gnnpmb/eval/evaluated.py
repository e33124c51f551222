"""What the devkit's evaluation did with each ground-truth object and each track of a scene, as it computed it.

``TrackingEval`` prepares boxes in three steps (``nuscenes.eval.common.loaders.filter_eval_boxes`` and
``nuscenes.eval.tracking.loaders.create_tracks``): it drops boxes beyond the class's range of the ego vehicle,
ground-truth boxes with no LiDAR or radar points and two-wheelers in a bike rack; it replaces each track's
scores by their average over the boxes it kept; and it interpolates every object's and every track's boxes over
the frames missing between its first and last kept box, with the two ends' weights swapped (nuscenes-devkit issue
#1141). ``gt_frames`` and ``track_evals`` record the outcome per frame from the devkit's own output (the boxes it
kept and the tracks it built), so an explanation quotes the evaluation rather than re-deriving it.
"""

from __future__ import annotations

import enum
import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

if TYPE_CHECKING:
    from nuscenes.eval.common.data_classes import EvalBoxes
    from nuscenes.eval.tracking.data_classes import TrackingBox


class GtStatus(enum.Enum):
    """What the evaluation scored an annotated object against at one frame: exactly one of these."""

    SCORED = "scored"  # its annotated box
    INTERPOLATED = "interpolated"  # a box the devkit interpolated (the annotated one was dropped)
    BEYOND_RANGE = "beyond the class range"  # nothing: its box lies beyond the class's range, not interpolated
    NO_BOX = "no box"  # nothing: its box was dropped (no points, bike rack) and could not be interpolated


class Dropped(enum.Enum):
    """Why the devkit dropped an annotated box (the filters of ``filter_eval_boxes``, in its order)."""

    BEYOND_RANGE = "beyond the class range"
    NO_POINTS = "no LiDAR or radar points"
    BIKE_RACK = "in a bike rack"


@dataclass(frozen=True, slots=True)
class GtFrame:
    """One annotated object at one frame, as evaluated.

    annotated_xy_m: its annotated BEV centre (global); evaluated_xy_m: the centre of the box it was scored
    against (None: none); dropped: why the annotated box was dropped (None: kept); points: LiDAR + radar points in
    the box; ego_distance_m: the devkit's distance to the ego vehicle; range_m: the class's range; between: for an
    interpolated box, the frames whose kept boxes it was interpolated from; unswapped_xy_m: where an interpolation
    with the ends' weights the right way round would have put it.
    """

    frame: int
    status: GtStatus
    annotated_xy_m: tuple[float, float]
    evaluated_xy_m: tuple[float, float] | None
    dropped: Dropped | None
    points: int
    ego_distance_m: float
    range_m: float
    between: tuple[int, int] | None = None
    unswapped_xy_m: tuple[float, float] | None = None

    @property
    def offset_m(self) -> float:
        """BEV distance of the evaluated box from the annotated one (0 when scored as annotated, nan: no box)."""
        if self.evaluated_xy_m is None:
            return math.nan
        return math.hypot(
            self.evaluated_xy_m[0] - self.annotated_xy_m[0], self.evaluated_xy_m[1] - self.annotated_xy_m[1]
        )

    def to_json(self) -> list[Any]:
        return [
            self.frame,
            self.status.value,
            list(self.annotated_xy_m),
            None if self.evaluated_xy_m is None else list(self.evaluated_xy_m),
            None if self.dropped is None else self.dropped.value,
            self.points,
            self.ego_distance_m,
            self.range_m,
            None if self.between is None else list(self.between),
            None if self.unswapped_xy_m is None else list(self.unswapped_xy_m),
        ]

    @staticmethod
    def from_json(data: Sequence[Any]) -> GtFrame:
        frame, status, annotated, evaluated, dropped, points, ego, reach, between, unswapped = data
        return GtFrame(
            int(frame),
            GtStatus(status),
            (float(annotated[0]), float(annotated[1])),
            None if evaluated is None else (float(evaluated[0]), float(evaluated[1])),
            None if dropped is None else Dropped(dropped),
            int(points),
            float(ego),
            float(reach),
            None if between is None else (int(between[0]), int(between[1])),
            None if unswapped is None else (float(unswapped[0]), float(unswapped[1])),
        )


@dataclass(frozen=True, slots=True)
class DroppedBox:
    """A submitted box the devkit's filter dropped: its frame, the devkit's distance of it to the ego vehicle
    (``add_center_dist``), its class's range and why (``Dropped.BEYOND_RANGE``: at or beyond the range, which the
    filter keeps strictly inside; else ``Dropped.BIKE_RACK``: submitted boxes are not filtered on points)."""

    frame: int
    ego_distance_m: float
    range_m: float

    @property
    def reason(self) -> Dropped:
        return Dropped.BEYOND_RANGE if self.ego_distance_m >= self.range_m else Dropped.BIKE_RACK


@dataclass(frozen=True, slots=True)
class TrackEval:
    """One submitted track, as evaluated: submitted (frames it has a box in the submission), kept (those the
    class-range and bike-rack filters kept), interpolated (frames the evaluation filled in between its kept
    boxes); submitted_mean: its score averaged over every submitted box; averaged_score: over the kept ones, the
    score the devkit compares with the class's threshold (None: no box kept, the track is not evaluated); matches:
    (frame, object) for each frame at which the devkit's accumulator matched the track to an object (a MATCH or
    SWITCH event at the class's best-MOTA threshold), in frame order; dropped: its submitted boxes the class-range
    or bike-rack filter dropped, in frame order."""

    submitted: tuple[int, ...]
    kept: tuple[int, ...]
    interpolated: tuple[int, ...]
    submitted_mean: float
    averaged_score: float | None
    matches: tuple[tuple[int, str], ...] = ()
    dropped: tuple[DroppedBox, ...] = ()

    def dropped_at(self, frame: int) -> DroppedBox | None:
        """Its box at ``frame`` that the devkit's filter dropped (None: kept, or none submitted there)."""
        return next((d for d in self.dropped if d.frame == frame), None)

    def matched_at(self, frame: int) -> str | None:
        """The object the evaluation matched the track to at ``frame`` (None: none, e.g. a false track there)."""
        return next((g for x, g in self.matches if x == frame), None)

    def to_json(self) -> dict[str, Any]:
        """The fields; ``matches`` as object -> its frames (each object's id written once)."""
        frames: dict[str, list[int]] = {}
        for x, g in self.matches:
            frames.setdefault(g, []).append(x)
        return {
            "submitted": list(self.submitted),
            "kept": list(self.kept),
            "interpolated": list(self.interpolated),
            "submitted_mean": self.submitted_mean,
            "averaged_score": self.averaged_score,
            "matches": frames,
            "dropped": [[d.frame, d.ego_distance_m, d.range_m] for d in self.dropped],
        }

    @staticmethod
    def from_json(data: Mapping[str, Any]) -> TrackEval:
        """The track ``to_json`` wrote; one written before ``matches`` or ``dropped`` existed raises KeyError (a cached
        report of an older version is evaluated again, not read as if the evaluation had matched or dropped
        nothing)."""
        averaged = data["averaged_score"]
        matches = sorted((int(x), str(g)) for g, frames in data["matches"].items() for x in frames)
        return TrackEval(
            tuple(int(f) for f in data["submitted"]),
            tuple(int(f) for f in data["kept"]),
            tuple(int(f) for f in data["interpolated"]),
            float(data["submitted_mean"]),
            None if averaged is None else float(averaged),
            tuple(matches),
            tuple(DroppedBox(int(f), float(ego), float(reach)) for f, ego, reach in data["dropped"]),
        )


def gt_frames(
    raw: EvalBoxes,
    kept: EvalBoxes,
    tracks: Mapping[int, Sequence[TrackingBox]],
    frame_of_timestamp: Mapping[int, int],
    token_of_frame: Sequence[str],
    class_range: Mapping[str, float],
) -> dict[str, dict[int, GtFrame]]:
    """Instance token -> frame -> ``GtFrame`` for every tracking-class annotation of a scene.

    raw: the scene's ground truth with ego distances (``add_center_dist``), before filtering; kept: after
    ``filter_eval_boxes``; tracks: the devkit's ``create_tracks`` output for the scene (timestamp -> boxes)."""
    kept_ids = {t: {str(b.tracking_id) for b in kept[t]} for t in kept.sample_tokens}
    evaluated: dict[tuple[str, int], tuple[float, float]] = {}
    for timestamp, boxes in tracks.items():
        f = frame_of_timestamp[timestamp]
        for b in boxes:
            evaluated[(str(b.tracking_id), f)] = (float(b.translation[0]), float(b.translation[1]))
    out: dict[str, dict[int, GtFrame]] = {}
    annotated: dict[str, dict[int, tuple[float, float]]] = {}
    for f, token in enumerate(token_of_frame):
        for b in raw[token] if token in raw.sample_tokens else ():
            annotated.setdefault(str(b.tracking_id), {})[f] = (float(b.translation[0]), float(b.translation[1]))
    for f, token in enumerate(token_of_frame):
        for b in raw[token] if token in raw.sample_tokens else ():
            gt_id, reach = str(b.tracking_id), float(class_range[b.tracking_name])
            xy = annotated[gt_id][f]
            if gt_id in kept_ids.get(token, set()):
                status, dropped, at = GtStatus.SCORED, None, xy
            else:
                dropped = (
                    Dropped.BEYOND_RANGE
                    if not b.ego_dist < reach
                    else Dropped.NO_POINTS
                    if b.num_pts == 0
                    else Dropped.BIKE_RACK
                )
                at = evaluated.get((gt_id, f))
                if at is not None:
                    status = GtStatus.INTERPOLATED
                elif dropped is Dropped.BEYOND_RANGE:
                    status = GtStatus.BEYOND_RANGE
                else:
                    status = GtStatus.NO_BOX
            out.setdefault(gt_id, {})[f] = GtFrame(f, status, xy, at, dropped, int(b.num_pts), float(b.ego_dist), reach)
    _add_interpolation_ends(out, annotated, token_of_frame, frame_of_timestamp)
    return out


def _add_interpolation_ends(
    out: dict[str, dict[int, GtFrame]],
    annotated: Mapping[str, Mapping[int, tuple[float, float]]],
    token_of_frame: Sequence[str],
    frame_of_timestamp: Mapping[int, int],
) -> None:
    """For each interpolated box: the kept frames it lies between and the centre a correctly weighted
    interpolation of their annotated centres would give (the devkit weights the ends the wrong way round)."""
    stamp_of = {f: t for t, f in frame_of_timestamp.items()}
    for gt_id, frames in out.items():
        kept = sorted(f for f, g in frames.items() if g.status is GtStatus.SCORED)
        for f, g in list(frames.items()):
            if g.status is not GtStatus.INTERPOLATED:
                continue
            left = max((k for k in kept if k < f), default=None)
            right = min((k for k in kept if k > f), default=None)
            if left is None or right is None:
                continue
            share = (stamp_of[f] - stamp_of[left]) / (stamp_of[right] - stamp_of[left])
            a, b = np.asarray(annotated[gt_id][left]), np.asarray(annotated[gt_id][right])
            right_way = (1.0 - share) * a + share * b
            frames[f] = GtFrame(
                g.frame,
                g.status,
                g.annotated_xy_m,
                g.evaluated_xy_m,
                g.dropped,
                g.points,
                g.ego_distance_m,
                g.range_m,
                (left, right),
                (float(right_way[0]), float(right_way[1])),
            )


def track_evals(
    results: Mapping[str, Sequence[Mapping[str, Any]]],
    raw: EvalBoxes,
    kept: EvalBoxes,
    tracks: Mapping[int, Sequence[TrackingBox]],
    averaged: Mapping[str, float],
    frame_of_timestamp: Mapping[int, int],
    token_of_frame: Sequence[str],
    matches: Mapping[str, Sequence[tuple[int, str]]],
    class_range: Mapping[str, float],
) -> dict[str, TrackEval]:
    """Tracking id -> ``TrackEval`` for every track of the scene's submission ``results`` (boxes by sample token),
    from the boxes with the devkit's ego distances (``raw``, before its filter), those it kept (``class_range``:
    the filter's range per class), the tracks it built (a frame where it has a box of the track that is not one
    it kept is one it interpolated), the scores it averaged (``averaged``: id -> the score its tracks carry) and
    its accumulator's matches (``matches``: id -> (frame, object) pairs)."""
    submitted: dict[str, list[tuple[int, float]]] = {}
    for f, token in enumerate(token_of_frame):
        for box in results.get(token, ()):
            submitted.setdefault(str(box["tracking_id"]), []).append((f, float(box["tracking_score"])))
    kept_frames: dict[str, list[int]] = {}
    frame_of_token = {t: f for f, t in enumerate(token_of_frame)}
    for token in kept.sample_tokens:
        f = frame_of_token.get(token)
        if f is None:
            continue
        for b in kept[token]:
            kept_frames.setdefault(str(b.tracking_id), []).append(f)
    dropped: dict[str, list[DroppedBox]] = {}
    for token in raw.sample_tokens:
        f = frame_of_token.get(token)
        if f is None:
            continue
        for b in raw[token]:
            t = str(b.tracking_id)
            if f not in kept_frames.get(t, ()):
                dropped.setdefault(t, []).append(DroppedBox(f, float(b.ego_dist), float(class_range[b.tracking_name])))
    in_tracks: dict[str, set[int]] = {}
    for timestamp, boxes in tracks.items():
        for b in boxes:
            in_tracks.setdefault(str(b.tracking_id), set()).add(frame_of_timestamp[timestamp])
    out = {}
    for t, frames in submitted.items():
        kept_t = tuple(sorted(kept_frames.get(t, [])))
        out[t] = TrackEval(
            submitted=tuple(f for f, _ in frames),
            kept=kept_t,
            interpolated=tuple(sorted(in_tracks.get(t, set()) - set(kept_t))),
            submitted_mean=float(np.mean([s for _, s in frames])),
            averaged_score=averaged.get(t),
            matches=tuple(sorted(matches.get(t, ()))),
            dropped=tuple(sorted(dropped.get(t, ()), key=lambda d: d.frame)),
        )
    return out
