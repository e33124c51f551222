"""Annotated objects of categories the evaluation does not track, and detections of names it does not track
(audit truth52, world8).

The devkit maps ``vehicle.emergency.*``, ``vehicle.construction``, ``human.pedestrian.stroller``, ``wheelchair``,
``personal_mobility``, ``movable_object.*``, ``animal`` and ``static_object.bicycle_rack`` to no tracking class, so
a scene's ground truth (``Keyframe.gt``) leaves them out. A car box on an ambulance is then a false track "of no
tracked object", which is true, but the user looks for a ghost where an annotated ambulance stands. These are the
annotations the explainer names in such a clause. Likewise a car detected only as ``construction_vehicle`` (a
name the loader drops) was said to be missed by the detector: it was seen, with a class no tracker takes.
"""

from __future__ import annotations

from collections.abc import Mapping
from functools import lru_cache
from pathlib import Path

import numpy as np

from gnnpmb.data.boxes3d import containing_box
from gnnpmb.types import Boxes
from gnnpmb.why.findings import NEAR_M


def untracked_on(boxes: Boxes | None, xy_m: np.ndarray) -> tuple[str, str, float] | None:
    """The untracked annotation in ``boxes`` (``class_name`` holds its category) whose centre lies nearest
    ``xy_m`` within ``NEAR_M``, else the one whose box contains it: id, category and distance to its centre (m);
    None: no such annotation."""
    if boxes is None or not len(boxes):
        return None
    d = np.hypot(*(boxes.translation_m[:, :2] - np.asarray(xy_m, dtype=float)[:2]).T)
    k = int(np.argmin(d))
    if d[k] >= NEAR_M:
        hit = containing_box(boxes, xy_m)
        if hit is None:
            return None
        k = hit[0]
    return str(boxes.instance_id[k]), str(boxes.class_name[k]), float(d[k])


def untracked_text(part: tuple[str, str, float]) -> str:
    """``vehicle.emergency.ambulance 7b72e3 (0.2 m away), a category the evaluation does not track``."""
    gt_id, category, d = part
    return f"{category} {gt_id[:6]} ({d:.1f} m away), a category the evaluation does not track"


def is_untracked(part: tuple[str, str, float] | None) -> bool:
    """Whether a ``part_of``-like triple names an untracked annotation (its class is a dotted category)."""
    return part is not None and "." in part[1]


def untracked_by_token(scene: object) -> dict[str, Boxes]:
    """Per sample token, the scene's annotations of untracked categories; empty where the scene has no dataset
    index to read them from (a scene built in memory)."""
    dataroot, version, name = (getattr(scene, a, None) for a in ("dataroot", "version", "name"))
    if dataroot is None or version is None or name is None:
        return {}
    if not (Path(dataroot) / str(version) / "sample_annotation.json").is_file():
        return {}
    return _read(Path(dataroot), str(version), str(name), bool(getattr(scene, "synthetic", False)))


@lru_cache(maxsize=8)
def _read(dataroot: Path, version: str, name: str, synthetic: bool) -> dict[str, Boxes]:
    from gnnpmb.data.nuscenes import DatasetLocation, dataset_index

    part = dataset_index(DatasetLocation(dataroot, version, synthetic)).read(name)
    anns = part.annotations
    tokens = part.samples.column("token").to_pylist()
    rows = np.flatnonzero(~anns.column("tracking_name").is_valid().to_numpy(zero_copy_only=False))
    if not rows.size:
        return {}

    def cols(prefix: str, n: int) -> np.ndarray:
        return np.column_stack([anns.column(f"{prefix}_{i}").to_numpy()[rows] for i in range(n)])

    category = np.array(anns.column("category_name").to_pylist(), dtype=object)[rows]
    inst = np.array(anns.column("instance_token").to_pylist(), dtype=object)[rows]
    xyz, wlh, quat = cols("translation", 3), cols("size", 3), cols("rotation", 4)
    sample = anns.column("sample_index").to_numpy()[rows]
    out: dict[str, Boxes] = {}
    for k in np.unique(sample):
        sel = np.flatnonzero(sample == k)
        out[str(tokens[int(k)])] = Boxes(
            translation_m=xyz[sel],
            size_wlh_m=wlh[sel],
            quat_wxyz=quat[sel],
            velocity_mps=np.zeros((sel.size, 2)),
            score=np.ones(sel.size),
            class_name=category[sel],
            instance_id=inst[sel],
        )
    return out


def untracked_name_near(
    boxes: Mapping[str, tuple[tuple[str, float, float, float], ...]],
    token: str,
    xy_m: np.ndarray,
    annotated: np.ndarray | None = None,
) -> tuple[str, float, float] | None:
    """The nearest box of an untracked detection name within ``NEAR_M`` of ``xy_m`` in sample ``token`` that lies
    nearer it than any other annotated object (``annotated``: (N, 2) centres of the frame's other annotations,
    tracked or not; a barrier box on an annotated barrier beside a worker is the barrier's, dev set scene-0103):
    (name, score, distance m); None: none."""
    best = None
    for name, score, x, y in boxes.get(token, ()):
        d = float(np.hypot(x - float(xy_m[0]), y - float(xy_m[1])))
        if d >= NEAR_M or (best is not None and d >= best[2]):
            continue
        if annotated is not None and len(annotated) and np.hypot(*(annotated - (x, y)).T).min() < d - 1e-6:
            continue
        best = (name, score, d)
    return best


def untracked_detections(
    path: Path | None, tokens: tuple[str, ...]
) -> Mapping[str, tuple[tuple[str, float, float, float], ...]]:
    """Per sample token of ``tokens``, the boxes of untracked detection names in the detection file ``path``
    (name, score, x, y), from the file's index (``gnnpmb.data.detection_index``); empty without a file."""
    if path is None or not Path(path).is_file():
        return {}
    p = Path(path)
    return _untracked_detections(p, p.stat().st_mtime_ns, tokens)


@lru_cache(maxsize=4)
def _untracked_detections(
    path: Path, _mtime_ns: int, tokens: tuple[str, ...]
) -> dict[str, tuple[tuple[str, float, float, float], ...]]:
    from gnnpmb.data.detections import untracked_detection_boxes

    return untracked_detection_boxes(path, tokens)
