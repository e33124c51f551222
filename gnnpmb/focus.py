"""Failure focus: from what the user names (``--focus``) to the frame, place, class and ids a bug-report
recording opens on.

Accepted forms:

* a failure id printed by ``gnnpmb failures`` (``id_switch:1``, ``coalescence:2``, ...), looked up in the failures
  of the first tracker;
* ``track:ID``: the first failure (ID switch, identity theft, coalescence, fragmentation, false track) that involves
  that track in any tracker's failures, else the last frame the track was reported;
* ``gt:TOKEN`` (a prefix of a ground-truth instance token is enough): the first failure involving that object,
  misses last, else the first frame it is visible.

The involved tracks of the other trackers are those reported within ``NEAR_M`` of the involved objects at the
focus frame, so a comparison recording highlights what each tracker did at the same place.
"""

from __future__ import annotations

import re
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, replace

import numpy as np

from gnnpmb.data.boxes3d import containing_box
from gnnpmb.data.scene import SceneData
from gnnpmb.errors import GnnpmbError
from gnnpmb.eval.failures import Failure, FailureKind, FailureReport, short_id
from gnnpmb.types import TrackEstimate
from gnnpmb.why.findings import FRAMES_BEFORE, NEAR_M

FRAMES_AFTER = 4
"""A focus recording holds the keyframes from ``FRAMES_BEFORE`` (``why.findings``) before the focus frame to
FRAMES_AFTER after it."""
NEAR_FRAMES = 4
"""... and so are tracks that were that close to it in this many keyframes before the failure (a track that
followed the object with too low a score to be counted is often the failure's cause)."""
_FOCUS_RE = re.compile(r"^(?P<kind>[a-z_]+):(?P<ref>\S+)$")
_DIFF_REF = re.compile(r"^(fixed|introduced|kept):[1-9][0-9]*$")
_KIND_ORDER = (
    FailureKind.IDENTITY_THEFT,
    FailureKind.ID_SWITCH,
    FailureKind.COALESCENCE,
    FailureKind.FRAGMENTATION,
    FailureKind.FALSE_TRACK,
    FailureKind.MISS,
)


@dataclass(frozen=True, slots=True)
class FocusTarget:
    """What a focus recording opens on.

    title: the failure in words; frame_index: the keyframe shown on opening; center_xy_m: global BEV centre of
    the place; class_name; track_ids: involved track ids per tracker; gt_ids: involved instance tokens;
    failure_id: the id ``gnnpmb failures`` prints (None when the focus is not a failure); failure_kind,
    failure_tracker and failure_tracks: the
    failure's kind, the tracker it is of and its own track ids in their order (e.g. old, new for an ID switch;
    thief, victim for an identity theft).
    """

    title: str
    frame_index: int
    center_xy_m: tuple[float, float]
    class_name: str
    track_ids: dict[str, tuple[int, ...]]
    gt_ids: tuple[str, ...]
    failure_id: str | None = None
    failure_kind: FailureKind | None = None
    failure_tracker: str | None = None
    failure_tracks: tuple[int, ...] = ()

    def object_ids(self, tracker: str) -> set[str]:
        """The ids the failure report names this focus's objects by, for ``tracker``: the involved instance tokens
        and that tracker's involved track ids (as strings)."""
        return {*self.gt_ids, *(str(t) for t in self.track_ids.get(tracker, ()))}

    def window(self, frames: range) -> range:
        """The keyframes of a focus recording, within ``frames``."""
        start = max(frames.start, self.frame_index - FRAMES_BEFORE)
        return range(start, min(frames.stop, self.frame_index + FRAMES_AFTER + 1))


def parse_focus(spec: str) -> tuple[str, str]:
    """``kind:ref`` -> (kind, ref), checked; raises GnnpmbError naming the accepted forms."""
    match = _FOCUS_RE.match(spec.strip())
    kinds = {k.value for k in FailureKind}
    if match is None or (match["kind"] not in kinds | {"track", "gt", "diff"}):
        raise GnnpmbError(
            f"bad --focus '{spec}': use track:ID, gt:TOKEN, a failure id such as id_switch:1 "
            f"(gnnpmb failures SCENE --tracker T lists them) or a change such as diff:introduced:1 (gnnpmb diff A B)"
        )
    if match["kind"] == "track" and not match["ref"].isdigit():
        raise GnnpmbError(f"bad --focus '{spec}': track:ID takes a track number, e.g. track:802")
    if match["kind"] == "diff" and not _DIFF_REF.match(match["ref"]):
        raise GnnpmbError(f"bad --focus '{spec}': use diff:fixed:N, diff:introduced:N or diff:kept:N")
    return match["kind"], match["ref"]


def resolve_focus(
    spec: str,
    scene: SceneData,
    reports: Mapping[str, FailureReport],
    estimates: Mapping[str, Sequence[Sequence[TrackEstimate]]],
    frames: range,
) -> FocusTarget:
    """The focus named by ``spec`` on ``scene``.

    reports: each tracker's failures (trackers in command-line order); estimates[tracker][k]: its tracks at
    keyframe ``frames[k]``. Raises GnnpmbError (one line saying how to find a valid id) when nothing matches.
    """
    kind, ref = parse_focus(spec)
    trackers = list(reports)
    tracked = _Tracked(scene, reports, estimates, frames)
    if kind == "track":
        return tracked.track_focus(int(ref))
    if kind == "gt":
        return tracked.gt_focus(ref)
    if kind == "diff":
        from gnnpmb.diff import diff_failure

        failure, run, fid, entry = diff_failure(ref, reports)
        if failure.frame_index not in frames:
            raise GnnpmbError(f"--focus {spec}: {entry.diff_id} is at frame {failure.frame_index}, outside --frames")
        target = tracked.from_failure(failure, run, fid)
        a, b = list(reports)[:2]
        title = f"{entry.diff_id} ({entry.change.value} from {a} to {b}): {target.title}"
        return replace(target, title=title)
    first = trackers[0]
    failure = reports[first].by_id(spec.strip())
    if failure is None or failure.frame_index not in frames:
        ids = [i for i in reports[first].ids() if i.startswith(kind + ":")]
        known = f"it has {ids[0]} to {ids[-1]}" if ids else f"it has no {kind.replace('_', ' ')}"
        window = reports[first].frames
        same = f" --frames {window[0]}:{window[1]}" if window is not None else ""
        raise GnnpmbError(
            f"--focus {spec}: no such failure of {first} on {scene.name} in the tracked frames ({known}); "
            f"gnnpmb failures {scene.name} --tracker {first}{same} lists them"
        )
    return tracked.from_failure(failure, first, spec.strip())


def opening_focus(
    scene: SceneData,
    reports: Mapping[str, FailureReport],
    estimates: Mapping[str, Sequence[Sequence[TrackEstimate]]],
    frames: range,
) -> FocusTarget | None:
    """Where a full recording opens: the first failure worth a look of the first tracker in ``frames``
    (``FailureReport.first_worth_opening``) as a focus target, named by its failure id; None with no failure or no
    report. Arguments as ``resolve_focus``'s."""
    first = next(iter(reports), None)
    if first is None:
        return None
    failure_id = reports[first].first_worth_opening(frames)
    failure = reports[first].by_id(failure_id) if failure_id is not None else None
    if failure is None:
        return None
    return _Tracked(scene, reports, estimates, frames).from_failure(failure, first, failure_id)


@dataclass(frozen=True, slots=True)
class _Tracked:
    """What a focus is found in (``resolve_focus``'s arguments)."""

    scene: SceneData
    reports: Mapping[str, FailureReport]
    estimates: Mapping[str, Sequence[Sequence[TrackEstimate]]]
    frames: range

    def from_failure(self, failure: Failure, tracker: str, failure_id: str | None) -> FocusTarget:
        """The focus on ``failure`` of ``tracker`` (printed as ``failure_id``; None: not named by a failure id)."""
        centers = np.array([b.translation_m[:2] for b in failure.boxes], dtype=np.float64).reshape(-1, 2)
        gt_centers = np.array([b.translation_m[:2] for b in failure.boxes if b.is_gt], dtype=np.float64).reshape(-1, 2)
        # The ground truth is where the failure happens; a lost track's last box can be frames old and metres away.
        place = gt_centers if len(gt_centers) else centers
        center = place.mean(axis=0) if len(place) else _ego_xy(self.scene, failure.frame_index)
        ids: dict[str, tuple[int, ...]] = {}
        gt_ids = failure.gt_ids or _gt_under_false_track(failure, self.scene)
        for name, per_frame in self.estimates.items():
            own = {int(t) for t in failure.track_ids} if name == tracker else set()
            near: set[int] = set()
            start = self.frames.start
            for i in range(max(start, failure.frame_index - NEAR_FRAMES), failure.frame_index + 1):
                near |= _tracks_near(per_frame[i - start], failure.class_name, gt_xy(self.scene, i, failure.gt_ids))
            if name != tracker and failure.frame_index in self.frames:
                near |= self._named(name, failure, gt_ids, per_frame[failure.frame_index - start])
            ids[name] = tuple(sorted(own | near))
        label = failure_id or failure.kind.value
        return FocusTarget(
            title=f"{label} at frame {failure.frame_index} ({tracker}): {failure.describe()}",
            frame_index=failure.frame_index,
            center_xy_m=(float(center[0]), float(center[1])),
            class_name=failure.class_name,
            track_ids=ids,
            gt_ids=gt_ids,
            failure_id=failure_id,
            failure_kind=failure.kind,
            failure_tracker=tracker,
            failure_tracks=tuple(int(t) for t in failure.track_ids),
        )

    def _named(
        self, name: str, failure: Failure, gt_ids: Sequence[str], estimates: Sequence[TrackEstimate]
    ) -> set[int]:
        """The tracks of another run the failure's explanation names (``why.reason.others``) that ``_tracks_near``
        does not find: the track its evaluation matched the object to at the failure's frame (at a box it
        interpolated, possibly 2 m or more from the annotation), for a false track its tracks output within
        ``NEAR_M`` of the object under it (``gt_ids``: the failure's objects, or that one), and with no annotated
        object its tracks output within ``NEAR_M`` of the failure's box."""
        out: set[int] = set()
        report = self.reports.get(name)
        if report is not None and gt_ids:
            out |= {int(t) for t, e in report.track_evals.items() if e.matched_at(failure.frame_index) in gt_ids}
        under = gt_xy(self.scene, failure.frame_index, gt_ids)
        out |= _tracks_near(estimates, failure.class_name, under)
        if not len(under) and failure.boxes:
            box = np.asarray(failure.boxes[0].translation_m[:2], dtype=np.float64).reshape(1, 2)
            out |= _tracks_near(estimates, failure.class_name, box)
        return out

    def first_failure(self, involved: Callable[[Failure], bool]) -> FocusTarget | None:
        """The focus on the first failure satisfying ``involved``, by kind priority then frame (None: no such)."""
        found = [
            (_KIND_ORDER.index(f.kind), f.frame_index, name, fid, f)
            for name, report in self.reports.items()
            for fid, f in zip(report.ids(), report.failures, strict=True)
            if f.frame_index in self.frames and involved(f)
        ]
        if not found:
            return None
        _, _, name, fid, failure = min(found, key=lambda x: x[:2])
        return self.from_failure(failure, name, fid)

    def track_focus(self, track_id: int) -> FocusTarget:
        hit = self.first_failure(lambda f: str(track_id) in f.track_ids)
        if hit is not None:
            return hit
        for name, per_frame in self.estimates.items():
            seen = [(k, e) for k, est in enumerate(per_frame) for e in est if e.track_id == track_id]
            if seen:
                k, e = seen[-1]
                return FocusTarget(
                    title=f"track {track_id} ({name}, {e.class_name}), last reported at frame {self.frames[k]}",
                    frame_index=self.frames[k],
                    center_xy_m=(float(e.translation_m[0]), float(e.translation_m[1])),
                    class_name=e.class_name,
                    track_ids={n: (track_id,) if n == name else () for n in self.estimates},
                    gt_ids=(),
                )
        raise GnnpmbError(
            f"--focus track:{track_id}: no tracker reported a track {track_id} on {self.scene.name} in the tracked "
            "frames"
        )

    def gt_focus(self, prefix: str) -> FocusTarget:
        scene, frames = self.scene, self.frames
        tokens = sorted(
            {str(t) for i in frames for t in scene.keyframes[i].gt.instance_id if str(t).startswith(prefix)}
        )
        if not tokens:
            raise GnnpmbError(f"--focus gt:{prefix}: no ground-truth object of {scene.name} has an id starting so")
        if len(tokens) > 1:
            shown = ", ".join(short_id(t) for t in tokens[:5])
            raise GnnpmbError(f"--focus gt:{prefix} is ambiguous ({shown}...); give more characters of the id")
        token = tokens[0]
        hit = self.first_failure(lambda f: token in f.gt_ids)
        if hit is not None:
            return hit
        for i in frames:
            gt = scene.keyframes[i].gt
            rows = np.flatnonzero(gt.instance_id == token)
            if rows.size:
                xy = gt.translation_m[rows[0], :2]
                class_name = str(gt.class_name[rows[0]])
                near = {
                    name: tuple(sorted(_tracks_near(per_frame[i - frames.start], class_name, xy[None, :])))
                    for name, per_frame in self.estimates.items()
                }
                return FocusTarget(
                    title=f"GT {short_id(token)} ({class_name}) first visible at frame {i}, no failure",
                    frame_index=i,
                    center_xy_m=(float(xy[0]), float(xy[1])),
                    class_name=class_name,
                    track_ids=near,
                    gt_ids=(token,),
                )
        raise AssertionError("token found above")


def _gt_under_false_track(failure: Failure, scene: SceneData) -> tuple[str, ...]:
    """For a false track: the ground-truth object of its class nearest its box within ``NEAR_M`` at the failure
    frame, else the nearest of any class there, which the evaluation did not match to it (out of its range, no
    points, another class), else the one whose box holds its centre (part of a long object): the object its Why
    names (``why.reason``: its nearest of the class first, as world7 scene-0796 pointpillars gnn false_track:16
    named car d97fc4 at 1.87 m while a bicycle lay 1.79 m away, and the focus opened on the bicycle); () if none
    or another kind of failure."""
    if failure.kind is not FailureKind.FALSE_TRACK or not failure.boxes:
        return ()
    gt = scene.keyframes[failure.frame_index].gt
    if not len(gt):
        return ()
    xy = np.asarray(failure.boxes[0].translation_m[:2])
    d = np.hypot(*(gt.translation_m[:, :2] - xy).T)
    mine = np.flatnonzero(gt.class_name == failure.class_name)
    k = int(mine[np.argmin(d[mine])]) if mine.size and d[mine].min() <= NEAR_M else int(np.argmin(d))
    if d[k] <= NEAR_M:
        return (str(gt.instance_id[k]),)
    hit = containing_box(gt, xy)
    return () if hit is None else (str(gt.instance_id[hit[0]]),)


def _tracks_near(estimates: Sequence[TrackEstimate], class_name: str, centers_xy: np.ndarray) -> set[int]:
    if centers_xy.size == 0:
        return set()
    out = set()
    for e in estimates:
        if e.class_name != class_name:
            continue
        d = np.hypot(centers_xy[:, 0] - e.translation_m[0], centers_xy[:, 1] - e.translation_m[1])
        if d.min() < NEAR_M:
            out.add(e.track_id)
    return out


def gt_xy(scene: SceneData, frame_index: int, gt_ids: Sequence[str]) -> np.ndarray:
    """(G, 2) BEV centres of the ground-truth objects ``gt_ids`` present at keyframe ``frame_index``."""
    gt = scene.keyframes[frame_index].gt
    if not len(gt) or not gt_ids:
        return np.zeros((0, 2))
    return np.asarray(gt.translation_m[np.isin(gt.instance_id.astype(str), list(gt_ids)), :2], dtype=np.float64)


def _ego_xy(scene: SceneData, frame_index: int) -> np.ndarray:
    return np.asarray(scene.keyframes[frame_index].ego_pose.translation_m[:2], dtype=np.float64)
