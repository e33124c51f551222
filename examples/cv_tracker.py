"""A tracker that is not this project's: constant velocity, greedy nearest matching, written as a nuScenes tracking
submission, to be opened with ``--results`` like any other tracker's results file.

It knows nothing of the registry, events or facts: it reads the detections, tracks them and writes boxes. Per
class, each track predicts its centre by its velocity; detections (score >= ``MIN_SCORE``) are matched to the
nearest prediction within ``MATCH_M``, closest pairs first; a matched track outputs its detection's box and score
(and learns its velocity from the two centres), an unmatched one coasts for up to ``MAX_MISSES`` frames, output at
its prediction with its last box's size, heading and height and half its score; an unmatched detection starts a
track. Ids are unique across classes.

Usage: ``uv run python -m examples.cv_tracker --split mini_val --detector centerpoint --out cv.json``
(``--scene scene-0103`` for one scene; ``--dataroot``/``--nuscenes-version`` and ``--detections FILE.json`` for
real data).
"""

from __future__ import annotations

import argparse
import itertools
from collections.abc import Iterator, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from gnnpmb.types import TRACKING_CLASSES, Boxes

MIN_SCORE = 0.3
MATCH_M = 2.0
MAX_MISSES = 2


@dataclass
class _Track:
    track_id: int
    xy: np.ndarray
    velocity: np.ndarray
    box: dict[str, Any]
    misses: int = 0


@dataclass
class ConstantVelocityTracker:
    """Greedy constant-velocity tracking of one scene (module docstring); ``step`` gives a keyframe's boxes."""

    ids: Iterator[int] = field(default_factory=lambda: itertools.count(1))
    tracks: dict[str, list[_Track]] = field(default_factory=dict)

    def step(self, token: str, detections: Boxes, dt_s: float) -> list[dict[str, Any]]:
        out = []
        for class_name in TRACKING_CLASSES:
            keep = np.flatnonzero((np.asarray(detections.class_name) == class_name) & (detections.score >= MIN_SCORE))
            out += self._class_step(token, class_name, detections, keep, dt_s)
        return out

    def _class_step(
        self, token: str, class_name: str, det: Boxes, keep: np.ndarray, dt_s: float
    ) -> list[dict[str, Any]]:
        tracks = self.tracks.setdefault(class_name, [])
        predicted = np.array([t.xy + t.velocity * dt_s for t in tracks]).reshape(-1, 2)
        xy = det.translation_m[keep, :2]
        d = np.hypot(predicted[:, None, 0] - xy[None, :, 0], predicted[:, None, 1] - xy[None, :, 1])
        pairs = sorted((d[i, j], i, j) for i in range(len(tracks)) for j in range(keep.size) if d[i, j] < MATCH_M)
        used_t, used_m, out = set(), set(), []
        for _, i, j in pairs:
            if i in used_t or j in used_m:
                continue
            used_t.add(i)
            used_m.add(j)
            m = int(keep[j])
            t = tracks[i]
            xy = det.translation_m[m, :2]
            t.velocity = (xy - t.xy) / dt_s if dt_s > 0 else t.velocity
            t.xy, t.misses = xy.copy(), 0
            t.box = _detection_box(token, det, m, t.track_id)
            out.append(t.box)
        alive = []
        for i, t in enumerate(tracks):
            if i not in used_t:
                t.misses += 1
                if t.misses > MAX_MISSES:
                    continue
                t.xy = predicted[i]
                z = t.box["translation"][2]
                t.box = {**t.box, "sample_token": token, "translation": [*map(float, t.xy), z]}
                t.box["tracking_score"] = 0.5 * t.box["tracking_score"]
                out.append(t.box)
            alive.append(t)
        for j in range(keep.size):
            if j not in used_m:
                m = int(keep[j])
                track_id = next(self.ids)
                xy = det.translation_m[m, :2].copy()
                box = _detection_box(token, det, m, track_id)
                alive.append(_Track(track_id, xy, np.zeros(2), box))
                out.append(box)
        self.tracks[class_name] = alive
        return out


def _detection_box(token: str, det: Boxes, m: int, track_id: int) -> dict[str, Any]:
    return {
        "sample_token": token,
        "translation": [float(v) for v in det.translation_m[m]],
        "size": [float(v) for v in det.size_wlh_m[m]],
        "rotation": [float(v) for v in det.quat_wxyz[m]],
        "velocity": [float(v) for v in det.velocity_mps[m]],
        "tracking_id": str(track_id),
        "tracking_name": str(det.class_name[m]),
        "tracking_score": float(det.score[m]),
    }


def track_scenes(
    scene_names: Sequence[str],
    dataroot: Path | None,
    version: str | None,
    detector: str,
    seed: int = 0,
    detections_file: Path | None = None,
) -> dict[str, list[dict[str, Any]]]:
    """Boxes by sample token of every keyframe of ``scene_names`` (each scene tracked on its own), on the
    detections of ``detections_file``, else of the simulated ``detector``."""
    from gnnpmb.data.nuscenes import load_scene, resolve_dataroot
    from gnnpmb.pipeline import get_detections

    location = resolve_dataroot(dataroot, version, tuple(scene_names))
    results: dict[str, list[dict[str, Any]]] = {}
    for name in scene_names:
        scene = load_scene(location, name)
        detections = get_detections(scene, detections_file, detector, seed)
        tracker, previous = ConstantVelocityTracker(), None
        for k in scene.keyframes:
            dt_s = 0.0 if previous is None else (k.timestamp_us - previous) * 1e-6
            previous = k.timestamp_us
            results[k.sample_token] = tracker.step(k.sample_token, detections[k.sample_token], dt_s)
    return results


def main(argv: Sequence[str] | None = None) -> None:
    from gnnpmb.data.nuscenes import resolve_dataroot, split_scenes
    from gnnpmb.errors import GnnpmbError
    from gnnpmb.eval.submission import SUBMISSION_META, write_json

    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    where = parser.add_mutually_exclusive_group()
    where.add_argument("--scene", action="append", help="scene name (repeatable)")
    where.add_argument("--split", default="mini_val", help="split (default mini_val)")
    parser.add_argument("--detector", default="centerpoint", help="simulated detector preset")
    parser.add_argument("--detections", type=Path, help="nuScenes detection results .json (instead of --detector)")
    parser.add_argument("--dataroot", type=Path)
    parser.add_argument("--nuscenes-version")
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--out", type=Path, required=True)
    args = parser.parse_args(argv)
    try:
        scenes = args.scene or split_scenes(args.split, resolve_dataroot(args.dataroot, args.nuscenes_version))
        results = track_scenes(scenes, args.dataroot, args.nuscenes_version, args.detector, args.seed, args.detections)
        write_json(args.out, {"meta": dict(SUBMISSION_META), "results": results})
    except GnnpmbError as exc:
        parser.exit(2, f"error: {exc}\n")
    boxes = sum(len(b) for b in results.values())
    print(f"constant velocity: {len(scenes)} scenes, {len(results)} samples, {boxes} boxes -> {args.out}")


if __name__ == "__main__":
    main()
