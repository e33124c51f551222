"""Boxes drawn into the camera images: each keyframe's ground truth, kept detections and every tracker's tracks,
projected through the camera's calibration and clipped to the image; words only on the boxes of that frame's
failures.

Rerun projects 3D boxes into a 2D view itself, but draws a box partly outside the image beyond the image's edge and
every 3D label with it. Here the boxes are projected through the camera's calibration and clipped to the image
(``viz.box_projection``: all of a layer's boxes in one camera at once); a box whose centre is behind the camera or
outside the image (mostly outside it) is not drawn.

Labels: one per failure box of the frame (``viz.failures`` words, the run's name in front when only one of several
runs has it), at the top of the box's drawn part, kept apart at the size the camera grid shows an image
(``CAMERA_VIEW_SCALE``, ``viz.label_room.keep_clear``) by the failure kinds' order; ``MAX_CAMERA_LABELS`` at most
per image. In a focus recording only the focus's objects are labelled.

Each layer of each camera is one ``send_columns`` call (one chunk per camera and layer, two where the recording
opens at a failure), a keyframe's strips one row.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass

import numpy as np
import rerun as rr

from gnnpmb.data.scene import SceneData
from gnnpmb.data.sensors import SceneSensors
from gnnpmb.eval.failures import OPEN_FIRST, FailureKind, FailureReport
from gnnpmb.types import FrameDetections, TrackEstimate
from viz import paths
from viz.box_projection import CameraFrame, project_boxes, take_lines
from viz.colors import class_colors, readable_text, track_color
from viz.failure_style import KIND_COLORS
from viz.failures import failure_label
from viz.label_room import keep_clear
from viz.label_size import text_box
from viz.rows import flat_strips_array
from viz.timeline import Clock

CAMERA_VIEW_SCALE = 0.15
"""Screen pixels per image pixel of one camera in a two-run recording's 3 x 2 camera grid at 1920 x 1080 (a
1600 x 900 image in a 384 x 139 px view: 0.154; 0.148 measured on a web viewer's screenshot); larger elsewhere."""
MAX_CAMERA_LABELS = 4
"""Labels per camera image and frame, at most."""
DETECTION_RGB = (170, 170, 170)


@dataclass(frozen=True, slots=True)
class Box:
    """One box to draw in the cameras at one keyframe: centre, size (w, l, h) and rotation (w, x, y, z) in the
    global frame, its colour, and its label ("" for none; a failure box's words) with the label's rank."""

    frame: int
    center_m: tuple[float, float, float]
    size_wlh_m: tuple[float, float, float]
    quat_wxyz: tuple[float, float, float, float]
    rgb: tuple[int, int, int]
    label: str = ""
    rank: int = 0


def scene_boxes(
    scene: SceneData,
    frames: range,
    detections: Sequence[FrameDetections],
    tracks: Mapping[str, Mapping[tuple[int, int], TrackEstimate]],
    reports: Mapping[str, FailureReport],
    involved: Mapping[str, set[str]] | None = None,
) -> dict[str, list[Box]]:
    """The boxes of each layer at the keyframes ``frames``: ``gt`` (class colours), ``detections`` (the kept ones;
    ``detections[k]`` is frame ``frames[k]``), each run's drawn tracks (``tracks``: per run, (frame, track id) ->
    estimate; the track's colour) and ``failures`` (each run's failure boxes in the kind's colour, labelled; with
    ``involved``, per run the ids a focus is about, only those labelled)."""
    layers: dict[str, list[Box]] = {"gt": [], "detections": []}
    for k, i in enumerate(frames):
        gt = scene.keyframes[i].gt
        for j, rgb in enumerate(class_colors(gt.class_name)[:, :3].tolist() if len(gt.class_name) else []):
            layers["gt"].append(
                Box(i, tuple(gt.translation_m[j]), tuple(gt.size_wlh_m[j]), tuple(gt.quat_wxyz[j]), tuple(rgb))
            )
        det = detections[k]
        for j in np.flatnonzero(det.kept):
            b = det.boxes
            layers["detections"].append(
                Box(i, tuple(b.translation_m[j]), tuple(b.size_wlh_m[j]), tuple(b.quat_wxyz[j]), DETECTION_RGB)
            )
    shown = set(frames)
    for name, drawn in tracks.items():
        layers[name] = [
            Box(f, e.translation_m, e.size_wlh_m, e.quat_wxyz, track_color(track_id))
            for (f, track_id), e in sorted(drawn.items())
            if f in shown
        ]
    layers["failures"] = failure_boxes(reports, shown, involved)
    return layers


def failure_boxes(
    reports: Mapping[str, FailureReport], frames: set[int], involved: Mapping[str, set[str]] | None = None
) -> list[Box]:
    """Each run's failure boxes at ``frames`` in the kind's colour with ``viz.failures`` words; a ground-truth box
    several runs share (same frame, kind, role and instance) is drawn once, its label prefixed by the runs' names
    when only some runs have it; a track's box is its run's own (track ids are per run), prefixed with the run's
    name when there are several runs. With ``involved`` only the focus's objects get words."""
    runs: dict[tuple[int, FailureKind, str, str, str], list[str]] = {}
    first: dict[tuple[int, FailureKind, str, str, str], object] = {}
    for name, report in reports.items():
        for failure in report.failures:
            if failure.frame_index not in frames:
                continue
            for box in failure.boxes:
                owner = "" if box.is_gt else name
                key = (failure.frame_index, failure.kind, box.role, box.object_id, owner)
                if name not in runs.setdefault(key, []):
                    runs[key].append(name)
                first.setdefault(key, box)
    out = []
    for key, names in runs.items():
        frame, kind, _, object_id, _ = key
        box = first[key]
        text = failure_label(kind, box)
        if len(names) < len(reports):
            text = f"{', '.join(names)}: {text}"
        if involved is not None and not any(object_id in involved.get(n, set()) for n in names):
            text = ""
        out.append(
            Box(
                frame, box.translation_m, box.size_wlh_m, box.quat_wxyz, KIND_COLORS[kind], text, OPEN_FIRST.index(kind)
            )
        )
    return sorted(out, key=lambda b: (b.frame, b.rank, b.label))


@dataclass(frozen=True, slots=True)
class _Drawn:
    """One layer of one camera: its S polylines keyframe by keyframe ((P, 2) pixels, the (S + 1,) offsets of the
    polylines into them, the (n + 1,) offsets of each of the n keyframes' polylines, (S, 3) uint8 colours) and
    per keyframe the labels (anchor pixel, text, colour)."""

    points_px: np.ndarray
    line_offsets: np.ndarray
    frame_offsets: np.ndarray
    rgb: np.ndarray
    anchors: list[list[tuple[float, float]]]
    texts: list[list[str]]
    label_rgb: list[list[tuple[int, int, int]]]

    def lines_of(self, rows: np.ndarray) -> np.ndarray:
        """The polylines of keyframes ``rows`` (indices into the n keyframes), in order."""
        return np.concatenate(
            [np.arange(self.frame_offsets[r], self.frame_offsets[r + 1]) for r in rows] or [np.zeros(0, np.int64)]
        )


def draw_layer(boxes: Sequence[Box], cams: Mapping[int, CameraFrame], frames: Sequence[int]) -> _Drawn:
    """``boxes`` projected into one camera at each of ``frames`` (``cams``: that camera at each keyframe), a
    keyframe's polylines in the order of its boxes; the labelled ones kept apart at ``CAMERA_VIEW_SCALE`` (at
    most ``MAX_CAMERA_LABELS``)."""
    at = {f: k for k, f in enumerate(frames)}
    n = len(frames)
    shown = [box for box in boxes if box.frame in at and box.frame in cams]
    lines = project_boxes(
        np.array([box.center_m for box in shown], dtype=np.float64).reshape(-1, 3),
        np.array([box.size_wlh_m for box in shown], dtype=np.float64).reshape(-1, 3),
        np.array([box.quat_wxyz for box in shown], dtype=np.float64).reshape(-1, 4),
        [cams[box.frame] for box in shown],
    )
    frame_of_box = np.array([at[box.frame] for box in shown], dtype=np.int64)
    frame_of_line = frame_of_box[lines.box]
    order = np.argsort(frame_of_line, kind="stable")
    points, line_offsets = take_lines(lines.points_px, lines.offsets, order)
    frame_offsets = np.zeros(n + 1, dtype=np.int64)
    np.cumsum(np.bincount(frame_of_line, minlength=n), out=frame_offsets[1:])
    rgb = np.array([box.rgb for box in shown], dtype=np.uint8).reshape(-1, 3)[lines.box[order]]
    wanted: list[list[tuple[int, object, tuple[float, float, float, float], str, tuple[float, float], tuple]]] = [
        [] for _ in range(n)
    ]
    for b, box in enumerate(shown):
        parts = lines.of_box(b) if box.label else []
        if not parts:
            continue
        k = at[box.frame]
        points_b = np.concatenate(parts)
        cam = cams[box.frame]
        anchor = _inside_image(
            box.label,
            float(0.5 * (points_b[:, 0].min() + points_b[:, 0].max())),
            float(points_b[:, 1].min()),
            cam.width_px,
            cam.height_px,
        )
        screen = text_box(box.label, anchor[0] * CAMERA_VIEW_SCALE, anchor[1] * CAMERA_VIEW_SCALE)
        wanted[k].append((box.rank, len(wanted[k]), screen, box.label, anchor, box.rgb))
    anchors, texts, label_rgb = [], [], []
    for candidates in wanted:
        keep = keep_clear([(rank, key, screen) for rank, key, screen, *_ in candidates])
        chosen = [c for c in sorted(candidates, key=lambda c: (c[0], c[1])) if c[1] in keep][:MAX_CAMERA_LABELS]
        texts.append([c[3] for c in chosen])
        anchors.append([c[4] for c in chosen])
        label_rgb.append([readable_text(c[5]) for c in chosen])
    return _Drawn(points, line_offsets, frame_offsets, rgb, anchors, texts, label_rgb)


def _inside_image(text: str, u: float, v: float, width_px: int, height_px: int) -> tuple[float, float]:
    """A label's anchor (pixels) moved so that its text, centred under it at ``CAMERA_VIEW_SCALE``, stays inside
    the image: a label cut by the view's edge reads as something else. A text wider than the image is centred on
    it, so that it runs into the view's margins beside a letterboxed image evenly rather than off one side."""
    x0, y0, x1, y1 = (c / CAMERA_VIEW_SCALE for c in text_box(text, 0.0, 0.0))
    u = 0.5 * width_px if x1 - x0 > width_px else min(max(u, -x0), width_px - x1)
    v = min(max(v, 0.0), height_px - y1)
    return u, v


def log_camera_boxes(
    stream: rr.RecordingStream,
    scene: SceneData,
    sensors: SceneSensors,
    frames: range,
    clock: Clock,
    layers: Mapping[str, Sequence[Box]],
) -> None:
    """Each layer of ``layers`` (``scene_boxes``) drawn into every camera at the keyframes ``frames``: one
    LineStrips2D per camera and layer (``paths.camera_boxes``), failures thicker, and the failures' labels as
    Points2D (``paths.camera_labels``) in their kind's colour darkened to be read (``colors.readable_text``)."""
    index = np.array(list(frames), dtype=np.int64)
    stamps = np.array([scene.keyframes[i].timestamp_us for i in index], dtype=np.int64)
    for channel in sensors.channels:
        cams = {
            i: CameraFrame.of(image, scene.keyframes[i].ego_pose)
            for i in frames
            for image in sensors.cameras[i]
            if image.channel == channel
        }
        for layer, boxes in layers.items():
            drawn = draw_layer(boxes, cams, list(frames))
            radius = rr.components.Radius.ui_points(2.5 if layer == "failures" else 1.0)
            clock.send(stream, paths.camera_boxes(channel, layer), index, stamps, _strip_columns(drawn, radius))
            if layer == "failures":
                clock.send(stream, paths.camera_labels(channel), index, stamps, _label_columns(drawn))


def _strip_columns(drawn: _Drawn, radius: rr.components.Radius) -> Callable[[np.ndarray], rr.ComponentColumnList]:
    def columns(rows: np.ndarray) -> rr.ComponentColumnList:
        lines = drawn.lines_of(rows)
        strips = flat_strips_array(*take_lines(drawn.points_px, drawn.line_offsets, lines), dims=2)
        lengths = drawn.frame_offsets[rows + 1] - drawn.frame_offsets[rows]
        cols = rr.LineStrips2D.columns(strips=strips, colors=drawn.rgb[lines], radii=[radius] * len(lines))
        return cols.partition(lengths)

    return columns


def _label_columns(drawn: _Drawn) -> Callable[[np.ndarray], rr.ComponentColumnList]:
    def columns(rows: np.ndarray) -> rr.ComponentColumnList:
        anchors = [a for r in rows for a in drawn.anchors[r]]
        lengths = [len(drawn.anchors[r]) for r in rows]
        cols = rr.Points2D.columns(
            positions=np.asarray(anchors, dtype=np.float32).reshape(-1, 2),
            labels=[t for r in rows for t in drawn.texts[r]],
            colors=[c for r in rows for c in drawn.label_rgb[r]],
            radii=[rr.components.Radius.ui_points(3.0)] * len(anchors),
        )
        return rr.ComponentColumnList([*cols.partition(lengths), *rr.Points2D.columns(show_labels=[True] * len(rows))])

    return columns
