"""Column-wise logging of per-frame markers shared by the failure and comparison overlays.

Both overlays draw, per kind, enlarged boxes around the involved objects at their frame, a per-frame count series
and one TextLog line per finding; everything goes out with ``send_columns`` through the recording's ``Clock``
(a few calls for a whole scene).
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
import rerun as rr

from viz.colors import faded, pack_rgba
from viz.geometry import quat_wxyz_to_xyzw, size_wlh_to_xyz
from viz.timeline import Clock


def send_counts(
    stream: rr.RecordingStream,
    clock: Clock,
    path: str,
    name: str,
    color: tuple[int, int, int],
    frames: np.ndarray,
    timestamps_us: np.ndarray,
    counts: np.ndarray,
) -> None:
    """A named, coloured count series with one value per keyframe of (F,) ``frames``."""
    stream.log(path, rr.SeriesLines(names=name, colors=[color]), static=True)
    values = np.asarray(counts, dtype=np.float64)
    clock.send(stream, path, frames, timestamps_us, lambda rows: rr.Scalars.columns(scalars=values[rows]))


def send_marker_boxes(
    stream: rr.RecordingStream,
    clock: Clock,
    path: str,
    frames: np.ndarray,
    timestamps_us: np.ndarray,
    boxes: Sequence,
    labels: Sequence[str],
    lengths: np.ndarray,
    *,
    color: tuple[int, int, int],
    scale: float,
    margin_m: float,
    line_radius_m: float,
    show_labels: bool = True,
    pale: np.ndarray | None = None,
    pale_keep: float = 0.35,
) -> None:
    """Boxes (objects with ``translation_m``, ``size_wlh_m``, ``quat_wxyz``) drawn ``scale`` times larger plus
    ``margin_m``, ``lengths[i]`` of them at keyframe ``frames[i]`` (0 = an empty batch, clearing the frame).
    pale: (N,) bool per box, drawn with ``pale_keep`` of ``color`` (``colors.faded``): markers beside the point."""
    sizes = size_wlh_to_xyz(np.array([b.size_wlh_m for b in boxes], dtype=np.float64)).reshape(-1, 3)
    centers = np.array([b.translation_m for b in boxes], dtype=np.float64).reshape(-1, 3)
    quats = quat_wxyz_to_xyzw(np.array([b.quat_wxyz for b in boxes], dtype=np.float64)).reshape(-1, 4)
    lengths = np.asarray(lengths, dtype=np.int64)
    starts = np.concatenate([[0], np.cumsum(lengths)[:-1]])
    labels = list(labels)
    packed = np.full(len(labels), pack_rgba(np.array([color], dtype=np.uint8))[0], dtype=np.uint32)
    if pale is not None and np.any(pale):
        packed[np.asarray(pale, dtype=bool)] = faded(packed[:1], pale_keep)[0]

    def columns(rows: np.ndarray) -> rr.ComponentColumnList:
        idx = np.concatenate([np.arange(starts[r], starts[r] + lengths[r]) for r in rows]).astype(np.int64)
        return rr.Boxes3D.columns(
            centers=centers[idx],
            half_sizes=0.5 * (sizes[idx] * scale + margin_m),
            quaternions=quats[idx],
            colors=packed[idx],
            radii=np.full(idx.size, line_radius_m, dtype=np.float32),
            labels=[labels[i] for i in idx.tolist()],
        ).partition(lengths[rows])

    if not show_labels:
        stream.log(path, rr.Boxes3D.from_fields(show_labels=False), static=True)
    clock.send(stream, path, frames, timestamps_us, columns)


def send_text_lines(
    stream: rr.RecordingStream,
    clock: Clock,
    path: str,
    frames: np.ndarray,
    timestamps_us: np.ndarray,
    texts: list[str],
    levels: list[str],
) -> None:
    """One TextLog line per keyframe entry of (N,) ``frames``."""
    clock.send(
        stream,
        path,
        frames,
        timestamps_us,
        lambda rows: rr.TextLog.columns(text=[texts[i] for i in rows], level=[levels[i] for i in rows]),
    )
