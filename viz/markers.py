"""Column-wise logging of per-frame markers shared by the failure and comparison overlays.

Both overlays draw, per kind, enlarged boxes around the involved objects at their frame, a per-frame count series
and one TextLog line per finding; everything goes out with ``send_columns`` (a few calls for a whole scene).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence

import numpy as np
import rerun as rr

from viz.geometry import quat_wxyz_to_xyzw, size_wlh_to_xyz

TimeIndexes = Callable[[np.ndarray], list[rr.TimeColumn]]


def time_indexes(frames: np.ndarray, timestamps_us: np.ndarray) -> TimeIndexes:
    """``at -> [frame, timestamp] columns`` for the rows ``at`` of (F,) keyframe indices and their timestamps."""
    stamps = np.asarray(timestamps_us, dtype="datetime64[us]")

    def indexes(at: np.ndarray) -> list[rr.TimeColumn]:
        return [rr.TimeColumn("frame", sequence=frames[at]), rr.TimeColumn("timestamp", timestamp=stamps[at])]

    return indexes


def send_counts(
    stream: rr.RecordingStream,
    path: str,
    name: str,
    color: tuple[int, int, int],
    indexes: list[rr.TimeColumn],
    counts: np.ndarray,
) -> None:
    """A named, coloured count series with one value per row of ``indexes``."""
    stream.log(path, rr.SeriesLines(names=name, colors=[color]), static=True)
    stream.send_columns(path, indexes=indexes, columns=rr.Scalars.columns(scalars=counts.astype(np.float64)))


def send_marker_boxes(
    stream: rr.RecordingStream,
    path: str,
    indexes: list[rr.TimeColumn],
    boxes: Sequence,
    labels: Sequence[str],
    lengths: np.ndarray,
    *,
    color: tuple[int, int, int],
    scale: float,
    margin_m: float,
    line_radius_m: float,
) -> None:
    """Boxes (objects with ``translation_m``, ``size_wlh_m``, ``quat_wxyz``) drawn ``scale`` times larger plus
    ``margin_m``, ``lengths[i]`` of them at row i of ``indexes`` (0 = an empty batch, clearing the frame)."""
    sizes = size_wlh_to_xyz(np.array([b.size_wlh_m for b in boxes], dtype=np.float64))
    stream.send_columns(
        path,
        indexes=indexes,
        columns=rr.Boxes3D.columns(
            centers=np.array([b.translation_m for b in boxes], dtype=np.float64),
            half_sizes=0.5 * (sizes * scale + margin_m),
            quaternions=quat_wxyz_to_xyzw(np.array([b.quat_wxyz for b in boxes], dtype=np.float64)),
            colors=np.tile(np.array(color, dtype=np.uint8), (len(boxes), 1)),
            radii=np.full(len(boxes), line_radius_m, dtype=np.float32),
            labels=list(labels),
        ).partition(lengths),
    )


def send_text_lines(
    stream: rr.RecordingStream, path: str, indexes: list[rr.TimeColumn], texts: list[str], levels: list[str]
) -> None:
    """One TextLog line per row of ``indexes``."""
    stream.send_columns(path, indexes=indexes, columns=rr.TextLog.columns(text=texts, level=levels))
