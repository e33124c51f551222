"""The focus overlay of a bug-report recording (``gnnpmb-viz --focus``): what went wrong, where, and the story.

* ``focus/summary`` and ``focus/how_to_read`` (static TextDocuments, written by ``viz.focus_summary``): the
  failure explained in words, and what every mark of the views means;
* ``world/focus``: the involved ground-truth objects and the detections the involved tracks were given, drawn
  slightly enlarged in their class colours;
* ``world/trackers/<tracker>/focus``: that tracker's involved tracks, enlarged, in their colours (their own
  boxes carry the id labels);
* ``world/trackers/<tracker>/focus/callouts``: the labels of the involved objects and, at the failure's frame,
  of every other object the Why names (``GT 8bccf2``,
  ``m10 0.83 → track 26``, ``26 predicted r=0.04``, ``31 predicted r=0.02, missed``) in a column beside them with
  leader lines (``viz.callouts``), so labels of objects on one spot do not cover each other; each assignment is
  said once, on the detection;
* ``world/focus/as_evaluated``: where the evaluation put an object it interpolated (``viz.evaluated``);
* ``world/focus/evaluation_range``: the evaluation's range around the ego vehicle, when the failure lies near it.

``focus_legends`` places the legends of the series views the layout opens with (``viz.legend``).
"""

from __future__ import annotations

import math
import re
from collections.abc import Collection, Mapping, Sequence

import numpy as np
import rerun as rr

from gnnpmb.compare import Comparison, DisagreementKind
from gnnpmb.data.scene import SceneData
from gnnpmb.eval.failures import FailureReport, short_id
from gnnpmb.focus import FocusTarget
from gnnpmb.focus_cameras import FocusSight
from gnnpmb.pipeline import FrameResult
from gnnpmb.types import Boxes, TrackEstimate
from gnnpmb.why.facts import TrackerFacts, TrackStep, UseMode, Went
from gnnpmb.why.findings import Finding
from gnnpmb.why.words import existence_text, plain, share_text, went_text, why_lines
from viz import compare, paths
from viz.blueprint import (
    focus_axis_frames,
    focus_doc,
    focus_eye_height_m,
    focus_perspective_eye,
    focus_world,
    reading_guide_doc,
)
from viz.callouts import (
    FOCUS_VIEW_WIDTH_PX,
    FOV_Y_DEG,
    M_PER_PX_PER_HEIGHT,
    Callout,
    focus_height_m,
    focus_views_px,
    log_callouts,
)
from viz.colors import CLASS_COLORS, GREY, class_ids, faded, pack_rgba
from viz.evaluated import (
    evaluated_offsets,
    log_evaluated,
    log_evaluation_range,
    range_near_focus,
    unannotated_evaluated,
)
from viz.failures import FOCUS_MARGIN_M, MARKER_MARGIN_M, MARKER_SCALE
from viz.focus_summary import TrackerView, focus_markdown
from viz.geometry import (
    RerunBoxes,
    estimate_boxes,
    footprint_corners_xy,
    quat_wxyz_to_xyzw,
    rerun_boxes,
    size_wlh_to_xyz,
)
from viz.label_room import Eye, keep_clear
from viz.label_size import CLEARANCE_PX, text_box
from viz.legend import COMPARISON_PLOT_HEIGHT_PX, LegendPlacement, existence_range, place_legend
from viz.logger import TrackerLogger
from viz.markers import send_text_lines
from viz.reading_guide import READING_GUIDE
from viz.scene import detection_label
from viz.timeline import Clock

SCALE = 1.15
MARGIN_M = 0.25
LINE_RADIUS_M = 0.12
GHOST_LOOKBACK = 20
"""An involved track not output this frame is drawn at its prediction with its last output box of at most this
many frames back."""
GHOST_KEEP = 0.55
GHOST_LINE_RADIUS_M = 0.05


def tracker_focus(tracker: str) -> str:
    """Boxes3D of one tracker's involved tracks (only in that tracker's views)."""
    return f"{paths.tracker_world(tracker)}/focus"


def log_focus(
    stream: rr.RecordingStream,
    focus: FocusTarget,
    scene: SceneData,
    views: Mapping[str, TrackerView],
    loggers: Mapping[str, TrackerLogger],
    clock: Clock,
    shown: range,
    finding: Finding | None = None,
    sight: FocusSight | None = None,
) -> None:
    """The summary document and, at every keyframe of ``shown``, the highlighted objects. views: per tracker its
    evidence (report, facts, run) as the document shows it; finding: the failure's (None: the focus is no
    failure); sight: the cameras that held the focus object in view (None: no cameras)."""
    stream.log(
        focus_doc(),
        rr.TextDocument(focus_markdown(focus, finding, views, shown, scene, sight), media_type="text/markdown"),
        static=True,
    )
    stream.log(reading_guide_doc(), rr.TextDocument(READING_GUIDE, media_type="text/markdown"), static=True)
    reports = {t: v.evidence.report for t, v in views.items()}
    for tracker, logger in loggers.items():
        _log_involved_story(stream, clock, scene, focus, tracker, logger)
    frames = {t: {f.keyframe.index: f for f in v.evidence.run.frames} for t, v in views.items()}
    gt_ids = set(focus.gt_ids)
    why = " ".join(plain(line) for line in why_lines(finding)) if finding is not None else ""
    named_gt = named_objects(why, scene.keyframes[focus.frame_index].gt, gt_ids)
    named_meas = named_detections(finding, why, focus.frame_index)
    failure_report = reports.get(focus.failure_tracker or "")
    evaluated = evaluated_offsets(focus, failure_report)
    unannotated = unannotated_evaluated(focus, failure_report)
    reach_m = range_near_focus(focus, scene)
    eye_height_m = focus_eye_height_m(focus.class_name, len(loggers), sight is not None)
    eyes = focus_eyes(focus, len(loggers), sight is not None)
    named_gt = named_in_view(named_gt, scene.keyframes[focus.frame_index].gt, eyes[0])
    for i in shown:
        keyframe = scene.keyframes[i]
        clock.set(stream, i, keyframe.timestamp_us)
        gt = keyframe.gt
        labelled = list(gt_ids) + (named_gt if i == focus.frame_index else [])
        rows = np.flatnonzero(np.isin(gt.instance_id.astype(str), labelled)) if len(gt) else np.zeros(0, int)
        centers = [gt.translation_m[rows]]
        sizes = [size_wlh_to_xyz(gt.size_wlh_m[rows])]
        quats = [quat_wxyz_to_xyzw(gt.quat_wxyz[rows])]
        names = [gt.class_name[rows]]
        labels = [f"GT {short_id(str(t))}" for t in gt.instance_id[rows]]
        gt_callouts = [
            Callout(tuple(gt.translation_m[r]), label, CLASS_COLORS.get(str(gt.class_name[r]), GREY))
            for r, label in zip(rows.tolist(), labels, strict=True)
        ]
        involved = rows[np.isin(gt.instance_id[rows].astype(str), list(gt_ids))]
        z_m = float(gt.translation_m[(involved if involved.size else rows)[0], 2]) if rows.size else scene.ground_z_m
        gt_corners = footprint_corners_xy(RerunBoxes(centers[0], sizes[0], quats[0]), SCALE, MARGIN_M)
        depth_m = max(eye_height_m - z_m, 1.0)  # the eye sits at eye_height_m in the global frame
        height_m, view_x_m, view_y_m = _callout_room(focus, depth_m, len(loggers), sight is not None)
        if i == focus.frame_index:
            gt_callouts += [
                Callout(
                    (*seen.evaluated_xy_m, z_m),
                    f"GT {short_id(gt_id)} as evaluated ({seen.offset_m:.1f} m off)",
                    CLASS_COLORS.get(focus.class_name, GREY),
                )
                for gt_id, seen in evaluated.items()
            ]
            gt_callouts += [
                Callout(
                    at,
                    f"GT {short_id(gt_id)} as evaluated (no annotation here)",
                    CLASS_COLORS.get(focus.class_name, GREY),
                )
                for gt_id, at in unannotated.items()
            ]
        if reach_m is not None:
            label_at = log_evaluation_range(stream, focus, scene, i, reach_m, z_m)
            gt_callouts.append(
                Callout(
                    label_at,
                    f"evaluation range for {focus.class_name}: {reach_m:g} m",
                    CLASS_COLORS.get(focus.class_name, GREY),
                )
            )
        meas: set[int] = set()
        detections = None
        for tracker, ids in focus.track_ids.items():
            frame = frames[tracker].get(i)
            if frame is None:
                log_callouts(stream, paths.focus_callouts(tracker), [], height_m)
                continue
            chosen = [e for e in frame.estimates if e.track_id in ids]
            palette = loggers[tracker].involved_rgb
            id_callouts = log_track_ids(stream, tracker, chosen, palette, eyes)
            boxes = estimate_boxes(chosen)
            stream.log(
                tracker_focus(tracker),
                rr.Boxes3D(
                    centers=boxes.centers_m,
                    half_sizes=0.5 * (boxes.sizes_xyz_m * SCALE + MARGIN_M),
                    quaternions=boxes.quat_xyzw,
                    colors=np.array([palette[e.track_id] for e in chosen], dtype=np.uint8).reshape(-1, 3),
                    radii=LINE_RADIUS_M,
                ),
            )
            facts = views[tracker].facts
            steps = {t: facts.steps(t, focus.class_name).get(i) for t in sorted(ids)}
            ghosts = _log_ghosts(
                stream,
                tracker,
                frames[tracker],
                i,
                steps,
                {e.track_id for e in chosen},
                palette,
                facts.output_only,
                failure_frame=i == focus.frame_index,
            )
            given = {e.meas_index for e in chosen if e.meas_index >= 0}
            given |= {m for s in steps.values() if s is not None for m in s.used}
            # and, for a track that used none, the detection nearest it (by NIS) in its gate: where that one went
            given |= {s.gated[0][0] for s in steps.values() if s is not None and not s.used and s.gated}
            if i == focus.frame_index:
                given |= named_meas
            meas |= given
            detections = frame.detections.boxes
            use = facts.use(i, focus.class_name)
            mode = use.mode if use is not None else UseMode.ASSIGNED
            named = [
                gt_corners,
                footprint_corners_xy(boxes, SCALE, MARGIN_M),
                _marker_corners(reports.get(tracker), i, ids),
            ]
            if detections is not None and given:
                named.append(footprint_corners_xy(rerun_boxes(detections.subset(np.array(sorted(given))))))
            log_callouts(
                stream,
                paths.focus_callouts(tracker),
                gt_callouts
                + _detection_callouts(
                    detections,
                    sorted(given),
                    facts,
                    i,
                    focus.class_name,
                    mode,
                    {e.track_id for e in frame.estimates},
                )
                + _prediction_callouts(
                    steps, z_m, palette, facts.has_existence, mode, _said(given, facts, i, focus.class_name, mode)
                )
                + ghosts
                + id_callouts,
                height_m,
                view_x_m,
                view_y_m,
                np.concatenate(named),
                label_z_m=z_m,
            )
        if meas and detections is not None:
            given = sorted(meas)
            det = detections.subset(np.array(given, dtype=np.int64))
            centers.append(det.translation_m)
            sizes.append(size_wlh_to_xyz(det.size_wlh_m))
            quats.append(quat_wxyz_to_xyzw(det.quat_wxyz))
            names.append(det.class_name)
            labels += [detection_label(m, s) for m, s in zip(given, det.score, strict=True)]
        size = np.concatenate(sizes).reshape(-1, 3)
        stream.log(
            focus_world(),
            rr.Boxes3D(
                centers=np.concatenate(centers).reshape(-1, 3),
                half_sizes=0.5 * (size * SCALE + MARGIN_M),
                quaternions=np.concatenate(quats).reshape(-1, 4),
                class_ids=class_ids(np.concatenate(names)),
                labels=labels,
                radii=LINE_RADIUS_M,
                show_labels=False,
            ),
        )
        if evaluated:
            log_evaluated(stream, focus, scene, evaluated if i == focus.frame_index else {})


def focus_eyes(focus: FocusTarget, runs: int, camera: bool) -> tuple[Eye, Eye]:
    """The bird's-eye and perspective cameras of a focus recording (``viz.blueprint``), global, at the sizes its
    layout gives them at 1920 x 1080 (``viz.callouts.focus_views_px``)."""
    x, y = focus.center_xy_m
    (bev_w, bev_h), (persp_w, persp_h) = focus_views_px(runs, camera)
    position, target = focus_perspective_eye(focus)
    return (
        Eye((x, y, focus_eye_height_m(focus.class_name, runs, camera)), (x, y, 0.0), (0.0, 1.0, 0.0), bev_h, bev_w),
        Eye(position, target, (0.0, 0.0, 1.0), persp_h, persp_w),
    )


def log_track_ids(
    stream: rr.RecordingStream,
    tracker: str,
    estimates: Sequence[TrackEstimate],
    palette: Mapping[int, tuple[int, int, int]],
    eyes: Sequence[Eye],
) -> list[Callout]:
    """Whether each involved track drawn at the current frame (``estimates``) shows its id on its box, said at every
    frame (a value logged once holds until the next one); returns the callouts (``track 164``, in the track's
    ``palette`` colour) of the ids ``crowded_ids`` takes off their boxes."""
    crowded = crowded_ids(estimates, eyes)
    for e in estimates:
        shown = rr.Boxes3D.from_fields(show_labels=e.track_id not in crowded)
        stream.log(paths.track(tracker, e.class_name, e.track_id), shown)
    return [
        Callout(tuple(e.translation_m), f"track {e.track_id}", palette[e.track_id])
        for e in estimates
        if e.track_id in crowded
    ]


def crowded_ids(estimates: Sequence[TrackEstimate], eyes: Sequence[Eye]) -> set[int]:
    """The ids of the involved tracks ``estimates`` (one frame's) whose id labels, drawn centred under their box
    centres, would cover another's or run past a view's edge in one of ``eyes``: their ids go to the callout column
    (``track 164``), which keeps its labels apart, and off their boxes. Two tracks on one object printed one id over
    the other: demo scene-0103 pointpillars immortal ``--focus id_switch:1``, "2" under "164" in the perspective
    view at frames 11-15; dev set scene-0103 cphd ``--focus identity_theft:1``, "23" and "40" in both views at
    frame 13."""
    out: set[int] = set()
    for eye in eyes:
        boxes = []
        for e in estimates:
            at = eye.screen_px(np.asarray(e.translation_m, dtype=np.float64))
            if at is None:
                continue
            box = text_box(str(e.track_id), *at)
            if eye.cuts(box, at):
                out.add(e.track_id)
            boxes.append((e.track_id, box))
        for k, (a, ra) in enumerate(boxes):
            for b, rb in boxes[k + 1 :]:
                if not keep_clear([(0, a, ra), (0, b, rb)]) >= {a, b}:
                    out |= {a, b}
    return out


def named_objects(text: str, gt: Boxes, involved: Collection[str]) -> list[str]:
    """The ids of the annotations of ``gt`` (one keyframe's) that a finding's Why ``text`` names ("... lay 0.3 m
    from pedestrian GT 9d0a73") but that are not ``involved``: the view labels every object the text points to,
    at the failure's frame (dev set scene-0916 centerpoint miss:20: the neighbour whose box the sentence named
    had no label, so a reader could not find it)."""
    if not text or not len(gt):
        return []
    ids = [str(t) for t in gt.instance_id]
    return [t for t in ids if t not in involved and re.search(rf"\bGT {re.escape(short_id(t))}\b", text)]


def named_in_view(named: Sequence[str], gt: Boxes, eye: Eye) -> list[str]:
    """The ids of ``named`` (annotations of ``gt``, one keyframe's) whose centre the bird's-eye ``eye`` shows. The
    Why names an object of another frame too ("at frame 15 truck m4 ... lay 0.4 m from truck GT 9da03c"); where it
    has gone by the failure's frame, out of the view, its label only led a line across the view and out of it (demo
    scene-0103 ``--tracker gnnpmb:gnnpmb/params/paper.toml --tracker gnnpmb --focus diff:fixed:1``: GT 9da03c 21 m
    away at frame 24)."""
    out = []
    for t, xyz in zip(gt.instance_id.astype(str).tolist(), gt.translation_m, strict=True):
        at = eye.screen_px(np.asarray(xyz, dtype=np.float64)) if t in named else None
        if at is not None and abs(at[0]) <= 0.5 * eye.width_px and abs(at[1]) <= 0.5 * eye.height_px:
            out.append(t)
    return out


def named_detections(finding: Finding | None, text: str, frame: int) -> set[int]:
    """The detections (source indices) near the failure's object at ``frame`` that the finding's Why ``text`` names
    ("... but a truck detection, m0 (score 0.97), 0.3 m away: the detector gave it the wrong class"): the view
    labels them at that frame (dev set scene-0916 centerpoint miss:2: the truck box the sentence named had no
    label). Only a detection the finding's sighting holds at ``frame`` counts, so a name of another frame's
    detection never labels this frame's box of the same index."""
    s = finding.sighting(frame) if finding is not None else None
    if s is None:
        return set()
    near = (s.nearest_any, s.nearest_own, s.neighbours_own, s.off, s.in_box, s.removed_own)
    said = {int(m) for m in re.findall(r"\bm(\d+)\b", text)}
    return {n.meas for n in near if n is not None and n.meas in said}


def _callout_room(
    focus: FocusTarget, depth_m: float, runs: int, camera: bool
) -> tuple[float, tuple[float, float], tuple[float, float]]:
    """(the height ``viz.callouts`` sizes the column with, the x range and the y range the bird's-eye view shows)
    for callouts ``depth_m`` below its eye: labels drawn at the objects' height are nearer the eye than the ground
    (a pedestrian's 0.9 m under a 16 m eye: 6 % larger on screen), and a camera view below or the comparison
    panel makes the view shorter (``viz.callouts.focus_height_m``); ``CLEARANCE_PX`` inside its edges."""
    height_m = focus_height_m(depth_m, runs > 1, camera)
    m_per_px = M_PER_PX_PER_HEIGHT * height_m
    half_wide_m = (0.5 * FOCUS_VIEW_WIDTH_PX / max(runs, 1) - CLEARANCE_PX) * m_per_px
    half_tall_m = depth_m * math.tan(math.radians(0.5 * FOV_Y_DEG)) - CLEARANCE_PX * m_per_px  # its vertical FOV
    x, y = focus.center_xy_m
    return height_m, (x - half_wide_m, x + half_wide_m), (y - half_tall_m, y + half_tall_m)


def tracker_views(evidence: Mapping[str, object], loggers: Mapping[str, TrackerLogger]) -> dict[str, TrackerView]:
    """Each tracker's ``TrackerView`` from its evidence and its logger (story, gates, shown tracks)."""
    return {
        t: TrackerView(ev, loggers[t].has_gates, tuple(loggers[t].story), frozenset(loggers[t].reported_ever))
        for t, ev in evidence.items()
    }


def _log_involved_story(
    stream: rr.RecordingStream, clock: Clock, scene: SceneData, focus: FocusTarget, tracker: str, logger: TrackerLogger
) -> None:
    """The story lines of the focused class about one of ``tracker``'s involved tracks, at their frames (not the
    per-frame DEBUG summaries, which the class's whole story keeps)."""
    ids = set(focus.track_ids.get(tracker, ()))
    lines = [
        line
        for line in logger.story
        if line.class_name == focus.class_name and line.level != "DEBUG" and set(line.track_ids) & ids
    ]
    if not lines:
        return
    frames = np.array([line.frame for line in lines], dtype=np.int64)
    stamps = np.array([scene.keyframes[f].timestamp_us for f in frames.tolist()], dtype=np.int64)
    send_text_lines(
        stream,
        clock,
        paths.involved_story(tracker),
        frames,
        stamps,
        [line.text for line in lines],
        [line.level for line in lines],
    )


def _marker_corners(report: FailureReport | None, frame: int, track_ids: Collection[int]) -> np.ndarray:
    """(M, 2) footprint corners of the failure markers drawn at ``frame`` around the focus's tracks, as wide as the
    focused failure's (``viz.failures``). A track's marker stands where the evaluation saw it, which may be a box it
    interpolated and the track never output (dev set scene-0916 megvii phd diff:fixed:20: a label ran over the false
    track's marker)."""
    ids = {str(t) for t in track_ids}
    boxes = (
        [b for f in report.failures if f.frame_index == frame for b in f.boxes if not b.is_gt and b.object_id in ids]
        if report is not None
        else []
    )
    if not boxes:
        return np.zeros((0, 2))
    drawn = RerunBoxes(
        np.array([b.translation_m for b in boxes], dtype=np.float64),
        size_wlh_to_xyz(np.array([b.size_wlh_m for b in boxes], dtype=np.float64)),
        quat_wxyz_to_xyzw(np.array([b.quat_wxyz for b in boxes], dtype=np.float64)),
    )
    return footprint_corners_xy(drawn, MARKER_SCALE, MARKER_MARGIN_M + FOCUS_MARGIN_M)


def focus_legends(
    focus: FocusTarget, loggers: Mapping[str, TrackerLogger], comparison: Comparison | None = None
) -> dict[str, LegendPlacement]:
    """Legend placements (``viz.legend``) of the series views a focus recording opens with, keyed by the view's
    origin: per tracker the existence (the involved tracks and the class's threshold) and NIS views, and the
    disagreement counts; from the values the views show, which end at the focus frame."""
    out: dict[str, LegendPlacement] = {}
    last = focus.frame_index
    for tracker, logger in loggers.items():
        ids = focus.track_ids.get(tracker, ())
        views = {
            paths.existence_root(tracker): [
                *(paths.existence(tracker, focus.class_name, t) for t in ids),
                paths.extraction_threshold(tracker, focus.class_name),
            ],
            paths.nis_root(tracker): [paths.nis(tracker, focus.class_name, t) for t in ids],
        }
        if not logger.has_existence:
            del views[paths.existence_root(tracker)]
        for root, series in views.items():
            sent = [logger.sent_series[p] for p in series if p in logger.sent_series]
            # The legend names every series of the view, also those without a value up to the focus frame.
            lines = [(f[f <= last], v[f <= last]) for f, v in sent]
            fixed = None
            if root == paths.existence_root(tracker):
                tracks = [logger.sent_series[p] for p in series[:-1] if p in logger.sent_series]  # not the threshold
                fixed = existence_range([v[f <= last] for f, v in tracks])
            out[root] = place_legend(lines, len(sent), y_range=fixed, x_range=focus_axis_frames(focus))
    if comparison is not None:
        frames = np.asarray(comparison.frame_indices)
        upto = frames <= last
        counts = [(frames[upto], comparison.counts(kind)[upto]) for kind in DisagreementKind]
        out[compare.counts_root()] = place_legend(counts, plot_height_px=COMPARISON_PLOT_HEIGHT_PX)
    return out


def _detection_callouts(
    detections: Boxes,
    given: list[int],
    facts: TrackerFacts,
    frame: int,
    class_name: str,
    mode: UseMode,
    output: Collection[int] | None = None,
) -> list[Callout]:
    """``m<idx> <score> → <where it went>`` at each detection ``given`` (indices into the frame's detections;
    where it went: ``why.facts.Destination``, in the tracker's terms), ``, not output`` after a track the run did
    not output at that frame (``output``: the ids it did; None: not known): "m1 0.85 → track 103" pointed at no
    box, for 103 was a tentative track, first output a frame later (dev set scene-0916 centerpoint, gnn beside
    ab3dmot ``--focus id_switch:1``, ab3dmot's view)."""
    out = []
    for m in given:
        d = facts.destination(frame, class_name, m)
        went = f" {went_text(d, mode)}" if d is not None else ""
        if (
            d is not None
            and output is not None
            and d.went in (Went.TRACK, Went.NEW_TRACK)
            and mode is not UseMode.OUTPUT
        ):
            went += ", not output" if d.track_id not in output else ""
        out.append(
            Callout(
                tuple(detections.translation_m[m]),
                detection_label(m, detections.score[m]) + went,
                CLASS_COLORS.get(str(detections.class_name[m]), GREY),
            )
        )
    return out


def _said(
    given: Collection[int], facts: TrackerFacts, frame: int, class_name: str, mode: UseMode
) -> set[tuple[int, int]]:
    """The (detection, track) pairs the labels of detections ``given`` state: ``m24 0.54 → track 12``, ``→ track 55
    (p 1.00)``. None for a PHD's weights (``track 96 (54 % of m16)`` is the detection's share, not the track's) or a
    run known by its output only (``under track 12's box`` says where a box lay, not what an update used)."""
    if mode in (UseMode.OUTPUT, UseMode.WEIGHTS):
        return set()
    out = set()
    for m in given:
        d = facts.destination(frame, class_name, m)
        if d is not None and d.went is Went.TRACK:
            out.add((m, d.track_id))
    return out


def predicted_ghosts(tracker: str) -> str:
    """Boxes3D of one tracker's involved tracks that are predicted but not output this frame."""
    return f"{tracker_focus(tracker)}/predicted"


def _log_ghosts(
    stream: rr.RecordingStream,
    tracker: str,
    frames: Mapping[int, FrameResult],
    i: int,
    steps: Mapping[int, TrackStep | None],
    output: set[int],
    palette: Mapping[int, tuple[int, int, int]],
    output_only: bool = False,
    failure_frame: bool = False,
) -> list[Callout]:
    """A pale box at the predicted position of each involved track the tracker kept but did not output at frame
    ``i``, with the size and heading of its last output box (within ``GHOST_LOOKBACK`` frames): where the
    tracker expected the object, so a label "61 predicted …, missed" points at a track's shape, not at bare
    ground. A run known by its output only (``output_only``) predicts nothing we know of: its involved tracks not
    output are drawn pale at their last output box instead, with a callout ("5 last output at frame 8", returned
    for the callout column). At the failure frame (``failure_frame``) every involved track that was ever output is
    drawn, its last output box however old: one the tracker no longer predicts (deleted, or it lost the object
    before) pale there, with the same callout, so the lost track is always on screen. An empty batch when there is
    none."""
    ghosts, labels, callouts = [], [], []
    for t, step in steps.items():
        predicted = step is not None and step.predicted_xy_m is not None
        if t in output or (not output_only and not predicted and not failure_frame):
            continue
        back = i if failure_frame else GHOST_LOOKBACK
        found = next(
            (
                (j, e)
                for j in range(i - 1, max(-1, i - 1 - back), -1)
                for e in (frames[j].estimates if j in frames else ())
                if e.track_id == t
            ),
            None,
        )
        if found is None:
            continue
        at, last = found
        if output_only or not predicted:
            ghosts.append((t, (float(last.translation_m[0]), float(last.translation_m[1])), last))
            labels.append(f"{t} (last output at frame {at})")
            callouts.append(Callout(tuple(last.translation_m), f"{t} last output at frame {at}", palette[t]))
        else:
            ghosts.append((t, step.predicted_xy_m, last))
            labels.append(f"{t} (predicted)")
    boxes = estimate_boxes([e for *_, e in ghosts])
    centers = boxes.centers_m.copy()
    if ghosts:
        centers[:, :2] = np.array([xy for _, xy, _ in ghosts], dtype=np.float64)
    colors = pack_rgba(np.array([palette[t] for t, *_ in ghosts], dtype=np.uint8).reshape(-1, 3))
    stream.log(
        predicted_ghosts(tracker),
        rr.Boxes3D(
            centers=centers,
            half_sizes=0.5 * boxes.sizes_xyz_m,
            quaternions=boxes.quat_xyzw,
            colors=faded(colors, GHOST_KEEP),
            radii=GHOST_LINE_RADIUS_M,
            labels=labels,
            show_labels=False,
        ),
    )
    return callouts


def _prediction_callouts(
    steps: Mapping[int, TrackStep | None],
    z_m: float,
    palette: Mapping[int, tuple[int, int, int]],
    has_existence: bool,
    mode: UseMode = UseMode.ASSIGNED,
    said: Collection[tuple[int, int]] = (),
) -> list[Callout]:
    """``<id> predicted r=<existence> → m<idx>`` (the detection its update used most, with its share for a soft
    update) or ``, missed`` at each focused track's predicted position this frame, in the track's involved colour
    (``palette``). The existence is the predicted one; for PMBM, when the frame's assignment was decided in another
    prior hypothesis, the one there, with the best hypothesis's beside it. A PHD's or CPHD's track (``mode``
    ``WEIGHTS``) has a weight, not an existence: ``<id> predicted weight <w> → m<idx>``. Without existences:
    ``<id> predicted → m<idx>``. The ``→ m<idx>`` part is left out when the detection's own label already says it
    went to this track (``said``: (detection, track) pairs; ``m24 0.54 → track 12`` beside ``12 predicted r=0.95``):
    each assignment is read once."""
    out = []
    name = " weight " if mode is UseMode.WEIGHTS else " r="
    for t, step in steps.items():
        if step is None or step.predicted_xy_m is None:
            continue
        r = ""
        if has_existence and step.prior_existence is not None:
            r = f"{name}{existence_text(step.prior_existence)}"
            decided = step.decided_existence
            if decided is not None and existence_text(decided) != existence_text(step.prior_existence):
                best = existence_text(step.prior_existence)
                r = f"{name}{existence_text(decided)} in the deciding hypothesis ({best} in the best)"
        use = step.use
        if use is not None and use.shares:
            m, share = use.shares[0]
            extra = share_text(share, use.mode)
            went = "" if (m, t) in said else f" → m{m}" + (f" ({extra})" if extra else "")
        else:
            went = ", missed"
        out.append(Callout((*step.predicted_xy_m, z_m), f"{t} predicted{r}{went}", palette[t]))
    return out
