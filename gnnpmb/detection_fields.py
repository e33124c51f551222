"""The detection box fields a track carries: what every tracker copies from its associated detection.

Only x, y (and vx, vy) are filtered; z, size, rotation and the score pass through from the detection that last
updated a track (paper sec. V-B), and ``meas_index`` names that detection for the viewer. Bernoullis, Gaussian
mixture components and vector tracks all hold one ``DetectionFields`` (their field ``det``), so the copy from
detections to tracks and from tracks to ``TrackEstimate`` is written once, here.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from gnnpmb.soa import StructOfArrays
from gnnpmb.types import Measurements, TrackEstimate, track_estimates


@dataclass(frozen=True, slots=True)
class DetectionFields(StructOfArrays):
    """K items' detection fields, struct-of-arrays.

    score: (K,) score of the detection; z_m: (K,) its box centre's height; size_wlh_m: (K, 3); quat_wxyz: (K, 4);
    meas_index: (K,) its source index (``Measurements.source_index``) if it updated the item this frame, else -1.
    """

    score: np.ndarray
    z_m: np.ndarray
    size_wlh_m: np.ndarray
    quat_wxyz: np.ndarray
    meas_index: np.ndarray

    def __len__(self) -> int:
        return len(self.score)

    @staticmethod
    def empty() -> DetectionFields:
        return DetectionFields(
            score=np.zeros(0),
            z_m=np.zeros(0),
            size_wlh_m=np.zeros((0, 3)),
            quat_wxyz=np.zeros((0, 4)),
            meas_index=np.zeros(0, dtype=np.int64),
        )

    @staticmethod
    def from_measurements(meas: Measurements, index: np.ndarray) -> DetectionFields:
        """The fields of the measurements ``index`` (local indices into ``meas``), in that order."""
        boxes = meas.boxes
        return DetectionFields(
            score=np.asarray(boxes.score[index], dtype=float),
            z_m=np.asarray(boxes.translation_m[index, 2], dtype=float),
            size_wlh_m=np.asarray(boxes.size_wlh_m[index], dtype=float),
            quat_wxyz=np.asarray(boxes.quat_wxyz[index], dtype=float),
            meas_index=np.asarray(meas.source_index, dtype=np.int64)[index],
        )

    def gather_with(self, meas: Measurements, source: np.ndarray) -> DetectionFields:
        """The fields of the K items followed by those of the M measurements ``meas``, gathered by ``source``
        (N,): source[i] < K picks item source[i], K + j measurement j (``from_measurements``)."""
        boxes = meas.boxes
        pairs = (
            (self.score, boxes.score),
            (self.z_m, boxes.translation_m[:, 2]),
            (self.size_wlh_m, boxes.size_wlh_m),
            (self.quat_wxyz, boxes.quat_wxyz),
            (self.meas_index, meas.source_index),
        )
        return DetectionFields(*(np.concatenate([own, theirs])[source] for own, theirs in pairs))

    def undetected(self) -> DetectionFields:
        """The same fields with no detection this frame (``meas_index`` -1): after a prediction."""
        return DetectionFields(
            score=self.score,
            z_m=self.z_m,
            size_wlh_m=self.size_wlh_m,
            quat_wxyz=self.quat_wxyz,
            meas_index=np.full(len(self), -1, dtype=np.int64),
        )

    def take(self, rows: np.ndarray, detected: DetectionFields) -> DetectionFields:
        """A copy in which items ``rows`` take the fields of ``detected`` (one per row, in order): the items
        associated with a detection this frame; the other items keep theirs."""
        out = {name: getattr(self, name).copy() for name in _FIELDS}
        for name in _FIELDS:
            out[name][rows] = getattr(detected, name)
        return DetectionFields(**out)

    def to_estimates(
        self,
        class_name: str,
        track_id: np.ndarray,
        mean: np.ndarray,
        score: np.ndarray,
        existence: np.ndarray,
    ) -> list[TrackEstimate]:
        """One ``TrackEstimate`` per item: x, y, vx, vy from ``mean`` (K, 4), z, size, rotation and meas_index from
        these fields; ``track_id``, ``score`` and ``existence`` (K,) are the tracker's."""
        # Python scalars from ``tolist`` once per array (the same values as float()/int() of each numpy element,
        # several times faster than indexing element by element), the tuples zipped from columns, and the
        # estimates built column-wise by ``track_estimates``.
        k = len(self)
        if not len(track_id) == len(mean) == len(score) == len(existence) == k:
            raise ValueError(f"{k} items but {len(track_id)} ids, {len(mean)} means, {len(score)} scores")
        if not k:
            return []
        x, y, vx, vy = np.asarray(mean, dtype=np.float64)[:, :4].T.tolist()
        return track_estimates(
            (
                np.asarray(track_id).tolist(),
                [class_name] * k,
                list(zip(x, y, np.asarray(self.z_m, dtype=np.float64).tolist(), strict=True)),
                list(zip(*np.asarray(self.size_wlh_m, dtype=np.float64).T.tolist(), strict=True)),
                list(zip(*np.asarray(self.quat_wxyz, dtype=np.float64).T.tolist(), strict=True)),
                list(zip(vx, vy, strict=True)),
                np.asarray(score, dtype=np.float64).tolist(),
                np.asarray(existence, dtype=np.float64).tolist(),
                np.asarray(self.meas_index).tolist(),
            )
        )


_FIELDS: tuple[str, ...] = ("score", "z_m", "size_wlh_m", "quat_wxyz", "meas_index")


class _ReadThrough:
    """Descriptor: ``obj.<name>`` reads ``obj.det.<name>``."""

    def __set_name__(self, owner: type, name: str) -> None:
        self.name = name

    def __get__(self, obj: CarriesDetectionFields, owner: type | None = None) -> np.ndarray:
        return getattr(obj.det, self.name)


class CarriesDetectionFields:
    """Mixin for a struct-of-arrays with a ``det: DetectionFields`` field: its fields read as the item's own."""

    __slots__ = ()
    det: DetectionFields
    score = _ReadThrough()
    z_m = _ReadThrough()
    size_wlh_m = _ReadThrough()
    quat_wxyz = _ReadThrough()
    meas_index = _ReadThrough()
