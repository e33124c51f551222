"""Where two or more trackers disagree, frame by frame, judged against the ground truth.

The estimates compared are the tracks each tracker shows (``gnnpmb.stages.findings.compare_runs``: existence at
least the viewer's show floor), so the lines say "shown". Per tracker and keyframe, the estimates are matched to the
ground-truth boxes with the nuScenes tracking criterion: BEV centre distance below ``MATCH_DISTANCE_M`` (2 m,
``dist_th_tp`` of ``tracking_nips_2019``), same class, one-to-one, the pairing found by the Hungarian method (most
pairs, then least summed distance).
Then, for every pair of trackers (A, B), in either role:

* ``missed_by_one``: a GT object A's estimates cover and B's do not.
* ``id_change``: a GT object both cover, where A now gives it another id than the last time A covered it while
  B gives it the same id as the last time B covered it (one tracker switched, the other kept its id); A's old
  track must have left the object (no longer output within the match distance, shown or not), as the devkit keeps
  a pair still within reach.
* ``only_in_one``: an estimate of A matched to no GT object of its class with no estimate of B of its class
  closer than ``MATCH_DISTANCE_M`` (a track only A reports; said with the class: an object of another class, and
  B's track of that class, may be there).

Objects both trackers miss, and switches both trackers make, are agreements and not listed. Frames must be
given in time order (``id_change`` remembers each tracker's last id per object across frames).
"""

from __future__ import annotations

import enum
import itertools
from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import numpy as np

from gnnpmb.assign.lsap import linear_sum_assignment
from gnnpmb.eval.failures import short_id
from gnnpmb.types import Boxes, TrackEstimate

MATCH_DISTANCE_M = 2.0
"""The devkit's centre-distance threshold for a true positive (a pair at or above it never matches)."""
_FORBIDDEN = 1e9
"""Cost of an impossible pair: larger than any sum of real distances, so the most possible pairs come
first."""


class DisagreementKind(enum.Enum):
    MISSED_BY_ONE = "missed_by_one"
    ID_CHANGE = "id_change"
    ONLY_IN_ONE = "only_in_one"


@dataclass(frozen=True, slots=True)
class Disagreement:
    """One disagreement at one keyframe (``frame_index`` into the scene's keyframes).

    tracker: the tracker that covers the object (``missed_by_one``), switched its id (``id_change``) or
    reports the lone track (``only_in_one``); other: the tracker that misses it, kept its id, or has nothing
    there. gt_id: the GT instance ("" for ``only_in_one``). track_ids: ``missed_by_one`` (tracker's track,),
    ``id_change`` (tracker's previous id, its new id, other's id), ``only_in_one`` (tracker's track,).
    translation_m (3,), size_wlh_m (3,), quat_wxyz (4,): the GT box, or the lone track's box (global frame).
    elsewhere: for ``missed_by_one``, other's track within the match distance of the object that the one-to-one
    matching gave to another object, and that object's GT id (two objects close together, one track between them:
    "other none" would be false, dev set scene-0655 centerpoint jpda, 74 of 907 lines); for ``only_in_one``, an
    object of the lone track's class within the match distance that tracker's other track is matched to (a
    duplicate: "on no GT" would be false, dev set scene-0061 pointpillars topmb), as (that track, the GT id).
    unshown (``missed_by_one``): other's track within the match distance of the object that other output but
    below the show floor (``compare_trackers``), which the evaluation may well have matched to it (dev set
    scene-0655 centerpoint gnnpmb, truck 8e5770 at frame 16: track 59 at existence 0.49).
    """

    kind: DisagreementKind
    frame_index: int
    class_name: str
    tracker: str
    other: str
    gt_id: str
    track_ids: tuple[int, ...]
    translation_m: tuple[float, float, float]
    size_wlh_m: tuple[float, float, float]
    quat_wxyz: tuple[float, float, float, float]
    elsewhere: tuple[int, str] | None = None
    unshown: int | None = None

    def describe(self) -> str:
        """One readable line naming trackers and ids, short enough for a log row beside the views (about 80
        characters with its kind)."""
        gt = f"{self.class_name} GT {short_id(self.gt_id)}"
        match self.kind:
            case DisagreementKind.MISSED_BY_ONE:
                mine = f"{gt}: {self.tracker} shows track {self.track_ids[0]} on it"
                if self.elsewhere is not None:
                    track, other_gt = self.elsewhere
                    return f"{mine}, {self.other}'s track {track} beside it is on GT {short_id(other_gt)}"
                if self.unshown is not None:
                    return (
                        f"{mine}, {self.other}'s track {self.unshown} on it is output but below the display threshold"
                    )
                return f"{mine}, {self.other} none"
            case DisagreementKind.ID_CHANGE:
                old, new, kept = self.track_ids
                return f"{gt}: {self.tracker} switched track {old} -> {new}, {self.other} kept {kept}"
            case DisagreementKind.ONLY_IN_ONE:
                lone = f"{self.class_name} track {self.track_ids[0]} of {self.tracker}"
                if self.elsewhere is not None:
                    track, gt_id = self.elsewhere
                    lone += f" beside GT {short_id(gt_id)}, which its track {track} is on"
                    return f"{lone}; {self.other} shows no {self.class_name} track there"
                # the matching is per class: a truck track on a car is on no truck GT, and the other run may show a
                # car track there (dev set scene-0916 pointpillars simpletrack vs cphd: "truck track 48 of
                # simpletrack on no GT; cphd shows none there" 0.1 m from a car cphd showed)
                return f"{lone} on no {self.class_name} GT; {self.other} shows no {self.class_name} track there"
        raise AssertionError(self.kind)


@dataclass(frozen=True, slots=True)
class Comparison:
    """Every disagreement between ``trackers`` over the keyframes ``frame_indices`` (time order), sorted by
    frame, kind, class, tracker and ids."""

    trackers: tuple[str, ...]
    frame_indices: tuple[int, ...]
    disagreements: tuple[Disagreement, ...]

    def of_kind(self, kind: DisagreementKind) -> list[Disagreement]:
        return [d for d in self.disagreements if d.kind is kind]

    def counts(self, kind: DisagreementKind) -> np.ndarray:
        """(F,) number of disagreements of ``kind`` at each of the F keyframes ``frame_indices``."""
        position = {f: i for i, f in enumerate(self.frame_indices)}
        out = np.zeros(len(self.frame_indices), dtype=np.int64)
        for d in self.of_kind(kind):
            out[position[d.frame_index]] += 1
        return out

    def totals(self) -> dict[DisagreementKind, int]:
        return {kind: len(self.of_kind(kind)) for kind in DisagreementKind}

    def within(self, frames: range) -> Comparison:
        """The comparison restricted to the keyframes in ``frames``."""
        return Comparison(
            self.trackers,
            tuple(f for f in self.frame_indices if f in frames),
            tuple(d for d in self.disagreements if d.frame_index in frames),
        )


def match_to_gt(
    gt_xy: np.ndarray,
    gt_class: np.ndarray,
    track_xy: np.ndarray,
    track_class: np.ndarray,
    max_dist_m: float = MATCH_DISTANCE_M,
) -> np.ndarray:
    """(G,) index of the track matched to each GT object, -1 if none.

    gt_xy (G, 2), gt_class (G,), track_xy (K, 2), track_class (K,). A pair is possible when the classes are
    equal and the BEV centre distance is < max_dist_m; the Hungarian method picks the one-to-one pairing with
    the most possible pairs and, among those, the least summed distance.
    """
    n_gt, n_tracks = len(gt_class), len(track_class)
    out = np.full(n_gt, -1, dtype=np.int64)
    if n_gt == 0 or n_tracks == 0:
        return out
    dist = np.linalg.norm(np.asarray(gt_xy, float)[:, None, :] - np.asarray(track_xy, float)[None, :, :], axis=2)
    ok = (np.asarray(gt_class, dtype=object)[:, None] == np.asarray(track_class, dtype=object)[None, :]) & (
        dist < max_dist_m
    )
    if not ok.any():
        return out
    rows, cols = linear_sum_assignment(np.where(ok, dist, _FORBIDDEN))
    keep = ok[rows, cols]
    out[rows[keep]] = cols[keep]
    return out


@dataclass(frozen=True, slots=True)
class _Frame:
    """One tracker's shown estimates of one frame as arrays: xy (K, 2), class (K,), ids (K,), and the match
    gt_track (G,) (track index per GT object, -1 if none); every: its whole output (N estimates, those below the
    show floor too) as (xy (N, 2), class (N,), ids (N,), shown (N,) bool)."""

    estimates: Sequence[TrackEstimate]
    xy: np.ndarray
    classes: np.ndarray
    ids: np.ndarray
    gt_track: np.ndarray
    every: tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]


def _frame(output: Sequence[TrackEstimate], gt: Boxes, max_dist_m: float, show_min_existence: float) -> _Frame:
    n = len(output)
    xy = np.array([e.translation_m[:2] for e in output], dtype=np.float64).reshape(n, 2)
    classes = np.array([e.class_name for e in output], dtype=object)
    ids = np.array([e.track_id for e in output], dtype=np.int64)
    shown = np.array([e.existence >= show_min_existence for e in output], dtype=bool)
    estimates = [e for e, s in zip(output, shown, strict=True) if s]
    gt_track = match_to_gt(gt.xy, gt.class_name, xy[shown], classes[shown], max_dist_m)
    return _Frame(estimates, xy[shown], classes[shown], ids[shown], gt_track, (xy, classes, ids, shown))


def _gt_box(gt: Boxes, g: int) -> tuple[tuple[float, float, float], ...]:
    return (
        tuple(float(v) for v in gt.translation_m[g]),
        tuple(float(v) for v in gt.size_wlh_m[g]),
        tuple(float(v) for v in gt.quat_wxyz[g]),
    )


def compare_trackers(
    gt: Sequence[Boxes],
    estimates: Mapping[str, Sequence[Sequence[TrackEstimate]]],
    frame_indices: Sequence[int] | None = None,
    max_dist_m: float = MATCH_DISTANCE_M,
    show_min_existence: float = 0.0,
) -> Comparison:
    """Disagreements between the trackers of ``estimates`` (tracker -> per-frame output, in time order) over
    frames whose ground truth is ``gt`` (per frame; ``instance_id`` names the objects), between the estimates
    shown (existence at least ``show_min_existence``; the others only named, ``Disagreement.unshown``).
    frame_indices: the keyframe index of each frame (default 0, 1, ...). See the module docstring for the kinds."""
    names = tuple(estimates)
    if len(names) < 2:
        raise ValueError(f"comparing needs at least two trackers, got {len(names)}")
    indices = tuple(range(len(gt))) if frame_indices is None else tuple(int(i) for i in frame_indices)
    for name in names:
        if len(estimates[name]) != len(gt):
            raise ValueError(f"{name} has {len(estimates[name])} frames of estimates for {len(gt)} frames of GT")
    if len(indices) != len(gt):
        raise ValueError(f"got {len(indices)} frame indices for {len(gt)} frames")
    last_id: dict[str, dict[str, int]] = {name: {} for name in names}
    out: list[Disagreement] = []
    for frame_index, gt_boxes, per_tracker in zip(
        indices, gt, zip(*(estimates[n] for n in names), strict=True), strict=True
    ):
        frames = {
            n: _frame(e, gt_boxes, max_dist_m, show_min_existence) for n, e in zip(names, per_tracker, strict=True)
        }
        gt_ids = [str(i) for i in gt_boxes.instance_id]
        for a, b in itertools.combinations(names, 2):
            out += _missed_by_one(frame_index, gt_boxes, gt_ids, frames, a, b, max_dist_m)
            out += _missed_by_one(frame_index, gt_boxes, gt_ids, frames, b, a, max_dist_m)
            out += _id_changes(frame_index, gt_boxes, gt_ids, frames, last_id, a, b, max_dist_m)
            out += _only_in_one(frame_index, gt_boxes, gt_ids, frames, a, b, max_dist_m)
            out += _only_in_one(frame_index, gt_boxes, gt_ids, frames, b, a, max_dist_m)
        for n, fr in frames.items():
            for g in np.flatnonzero(fr.gt_track >= 0).tolist():
                last_id[n][gt_ids[g]] = int(fr.ids[fr.gt_track[g]])
    kind_order = {kind: i for i, kind in enumerate(DisagreementKind)}
    out.sort(
        key=lambda d: (
            d.frame_index,
            kind_order[d.kind],
            d.class_name,
            d.tracker,
            d.other,
            d.gt_id,
            d.track_ids,
        )
    )
    return Comparison(names, indices, tuple(out))


def _missed_by_one(
    frame_index: int, gt: Boxes, gt_ids: list[str], frames: Mapping[str, _Frame], a: str, b: str, max_dist_m: float
) -> list[Disagreement]:
    fa, fb = frames[a], frames[b]
    return [
        Disagreement(
            DisagreementKind.MISSED_BY_ONE,
            frame_index,
            str(gt.class_name[g]),
            a,
            b,
            gt_ids[g],
            (int(fa.ids[fa.gt_track[g]]),),
            *_gt_box(gt, g),
            elsewhere=_elsewhere(fb, gt, gt_ids, g, max_dist_m),
            unshown=_unshown(fb, gt, g, max_dist_m),
        )
        for g in np.flatnonzero((fa.gt_track >= 0) & (fb.gt_track < 0)).tolist()
    ]


def _nearest(xy: np.ndarray, classes: np.ndarray, at_xy: np.ndarray, class_name: str, max_dist_m: float) -> int | None:
    """Index of the nearest of the (N, 2) points ``xy`` of ``classes`` (N,) equal to ``class_name`` closer than
    ``max_dist_m`` to ``at_xy`` (2,), or None."""
    if not len(xy):
        return None
    dist = np.linalg.norm(np.asarray(xy, dtype=np.float64).reshape(-1, 2) - np.asarray(at_xy, dtype=np.float64), axis=1)
    dist[(np.asarray(classes, dtype=object) != class_name) | (dist >= max_dist_m)] = np.inf
    k = int(np.argmin(dist))
    return k if np.isfinite(dist[k]) else None


def _unshown(fb: _Frame, gt: Boxes, g: int, max_dist_m: float) -> int | None:
    """Id of ``fb``'s unshown estimate of object ``g``'s class nearest it within ``max_dist_m``, or None."""
    xy, classes, ids, shown = fb.every
    k = _nearest(xy[~shown], classes[~shown], gt.xy[g], gt.class_name[g], max_dist_m)
    return None if k is None else int(ids[~shown][k])


def _elsewhere(fb: _Frame, gt: Boxes, gt_ids: list[str], g: int, max_dist_m: float) -> tuple[int, str] | None:
    """(id, GT id of the object it is matched to) of ``fb``'s nearest track of object ``g``'s class within
    ``max_dist_m`` of it, which the matching gave to another object (one within reach and free would have been
    given to ``g``); None when there is none."""
    k = _nearest(fb.xy, fb.classes, gt.xy[g], gt.class_name[g], max_dist_m)
    owner = np.flatnonzero(fb.gt_track == k) if k is not None else ()
    return (int(fb.ids[k]), gt_ids[int(owner[0])]) if len(owner) else None


def _id_changes(
    frame_index: int,
    gt: Boxes,
    gt_ids: list[str],
    frames: Mapping[str, _Frame],
    last_id: Mapping[str, Mapping[str, int]],
    a: str,
    b: str,
    max_dist_m: float,
) -> list[Disagreement]:
    """A run switched the object's track when the one it had is no longer output within reach of it: a track still
    on the object that the one-to-one matching gave to a neighbour this frame (or that fell below the show floor)
    is no switch (the evaluation keeps a pair still within reach; dev set scene-0553 centerpoint, bicycles e533e4
    and c7c2af side by side)."""
    out = []
    fa, fb = frames[a], frames[b]
    for g in np.flatnonzero((fa.gt_track >= 0) & (fb.gt_track >= 0)).tolist():
        now = {a: int(fa.ids[fa.gt_track[g]]), b: int(fb.ids[fb.gt_track[g]])}
        before = {n: last_id[n].get(gt_ids[g]) for n in (a, b)}
        left = {n: before[n] is not None and not _still_on(frames[n], before[n], gt, g, max_dist_m) for n in (a, b)}
        switched = {n: before[n] is not None and before[n] != now[n] and left[n] for n in (a, b)}
        kept = {n: before[n] is not None and before[n] == now[n] for n in (a, b)}
        for x, y in ((a, b), (b, a)):
            if switched[x] and kept[y]:
                out.append(
                    Disagreement(
                        DisagreementKind.ID_CHANGE,
                        frame_index,
                        str(gt.class_name[g]),
                        x,
                        y,
                        gt_ids[g],
                        (int(before[x]), now[x], now[y]),
                        *_gt_box(gt, g),
                    )
                )
    return out


def _still_on(fr: _Frame, track_id: int, gt: Boxes, g: int, max_dist_m: float) -> bool:
    """Whether ``fr`` outputs track ``track_id`` of object ``g``'s class within ``max_dist_m`` of it, shown or
    below the show floor (the evaluation may still match it there: dev set scene-1077 megvii cphd, track 94 at
    weight below 0.5, 0.05 m from pedestrian 80d062)."""
    xy, classes, ids, _ = fr.every
    mine = (ids == track_id) & (classes == gt.class_name[g])
    return bool(np.any(np.linalg.norm(xy[mine] - gt.xy[g], axis=1) < max_dist_m))


def _only_in_one(
    frame_index: int, gt: Boxes, gt_ids: list[str], frames: Mapping[str, _Frame], a: str, b: str, max_dist_m: float
) -> list[Disagreement]:
    fa, fb = frames[a], frames[b]
    unmatched = np.ones(len(fa.ids), dtype=bool)
    unmatched[fa.gt_track[fa.gt_track >= 0]] = False
    lone = np.flatnonzero(unmatched)
    if lone.size and len(fb.ids):
        dist = np.linalg.norm(fa.xy[lone, None, :] - fb.xy[None, :, :], axis=2)
        near = ((dist < max_dist_m) & (fa.classes[lone, None] == fb.classes[None, :])).any(axis=1)
        lone = lone[~near]
    out = []
    for k in lone.tolist():
        e = fa.estimates[k]
        out.append(
            Disagreement(
                DisagreementKind.ONLY_IN_ONE,
                frame_index,
                e.class_name,
                a,
                b,
                "",
                (e.track_id,),
                tuple(float(v) for v in e.translation_m),
                tuple(float(v) for v in e.size_wlh_m),
                tuple(float(v) for v in e.quat_wxyz),
                elsewhere=_beside(fa, k, gt, gt_ids, max_dist_m),
            )
        )
    return out


def _beside(fa: _Frame, k: int, gt: Boxes, gt_ids: list[str], max_dist_m: float) -> tuple[int, str] | None:
    """(id of ``fa``'s track matched to it, its GT id) of the object of lone track ``k``'s class nearest it within
    ``max_dist_m`` (one within reach and unmatched would have been matched to ``k``); None when there is none."""
    g = _nearest(gt.xy, gt.class_name, fa.xy[k], fa.classes[k], max_dist_m)
    if g is None or fa.gt_track[g] < 0:
        return None
    return int(fa.ids[fa.gt_track[g]]), gt_ids[g]
