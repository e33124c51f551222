"""The scene as the files give it, read with code of its own: the detection file's boxes per keyframe and the
annotations (nothing of ``gnnpmb.data`` or ``gnnpmb.why``).

Detection ``mN`` is the N-th box of the keyframe's sample in the file, counting only the seven tracking classes (the
order the file lists them in); an annotation's object id is its instance token, its class the devkit's
``category_to_tracking_name``, its points ``num_lidar_pts + num_radar_pts``. Distances are between box centres in
the ground plane (x, y), in metres.
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

NEAR_M = 2.0
"""The reach the sentences name ("within 2 m"): the checker's own copy of it."""


@dataclass(frozen=True)
class Detection:
    class_name: str
    score: float
    xy_m: tuple[float, float]
    box: tuple[float, ...] = ()
    """Size (w, l, h, m), rotation (w, x, y, z) and centre height (m): what a box that carries it repeats."""


@dataclass(frozen=True)
class Annotation:
    """points: LiDAR + radar returns in the box (the devkit drops a box with none); radar: those of them radar."""

    class_name: str
    xy_m: tuple[float, float]
    points: int
    radar: int = 0
    footprint: tuple[float, ...] = ()
    """Width, length (m) and heading (rad) of its box on the ground (empty: not read)."""

    def contains(self, xy_m: tuple[float, float]) -> bool:
        """Whether the ground point ``xy_m`` lies inside the box's footprint."""
        if not self.footprint:
            return False
        w, length, yaw = self.footprint
        dx, dy = xy_m[0] - self.xy_m[0], xy_m[1] - self.xy_m[1]
        along, across = dx * math.cos(yaw) + dy * math.sin(yaw), -dx * math.sin(yaw) + dy * math.cos(yaw)
        return abs(along) <= length / 2 and abs(across) <= w / 2


POINTS = r"([\d,]+(?:–[\d,]+)?) LiDAR and (?:([\d,]+(?:–[\d,]+)?) )?radar points"
"""A box's points as the text says them: ``12 LiDAR and radar points`` (the sum) or ``0 LiDAR and 3 radar points``
(apart); a span ``2–5`` over several frames. Groups: the sum or the LiDAR count, the radar count (None: the sum)."""


def _span(values: list[int]) -> str:
    lo, hi = min(values), max(values)
    return f"{lo:,}" if lo == hi else f"{lo:,}–{hi:,}"


def points_problem(anns: list[Annotation], said: str, radar_said: str | None) -> tuple[str, str] | None:
    """(kind, the truth) where the points said of the boxes ``anns`` (one per frame) are wrong ("detector") or
    the sum hides that some were radar returns only ("misleading": a LiDAR detector had nothing to see there);
    None where they hold."""
    total, radar = [a.points for a in anns], [a.radar for a in anns]
    lidar = [t - r for t, r in zip(total, radar, strict=True)]
    if not anns:
        return "detector", "no annotation"
    if radar_said is None:
        if said != _span(total):
            return "detector", f"points {_span(total)}"
        if any(radar):
            return "misleading", f"{_span(lidar)} LiDAR and {_span(radar)} radar points: the sum hides the radar"
        return None
    if said != _span(lidar) or radar_said != _span(radar):
        return "detector", f"{_span(lidar)} LiDAR and {_span(radar)} radar points"
    return None


@dataclass
class SceneTruth:
    """detections[frame] = the keyframe's boxes in file order (tracking classes only); objects[frame][instance] =
    its annotation (tracking classes only)."""

    detections: list[list[Detection]]
    objects: list[dict[str, Annotation]]
    ego_xy_m: list[tuple[float, float]] | None = None
    """Per keyframe, the ego pose of its LIDAR_TOP sample data (as the devkit's ``add_center_dist`` takes it)."""
    untracked: list[list[Detection]] | None = None
    """Per keyframe, the file's boxes of a class no tracker follows (barrier, traffic cone): no ``mN`` names them,
    but "no detection within 2 m" said with no class is false beside one."""
    others: list[dict[str, Annotation]] | None = None
    """Per keyframe, the annotations of categories the devkit does not track (ambulance, stroller, barrier ...),
    their class the category: a box on one is no "detection of no tracked object" left unnamed (audit truth52)."""

    @classmethod
    def read(cls, nusc, scene_name: str, detection_file: Path) -> SceneTruth:
        from nuscenes.eval.tracking.utils import category_to_tracking_name

        results = json.loads(Path(detection_file).read_text(encoding="utf-8"))["results"]
        scene = next(s for s in nusc.scene if s["name"] == scene_name)
        detections, objects, ego, untracked, others, token = [], [], [], [], [], scene["first_sample_token"]
        while token:
            sample = nusc.get("sample", token)
            pose = nusc.get("ego_pose", nusc.get("sample_data", sample["data"]["LIDAR_TOP"])["ego_pose_token"])
            ego.append((float(pose["translation"][0]), float(pose["translation"][1])))
            boxes = [
                Detection(
                    b["detection_name"],
                    float(b["detection_score"]),
                    tuple(map(float, b["translation"][:2])),
                    tuple(map(float, [*b["size"], *b["rotation"], b["translation"][2]])),
                )
                for b in results.get(token, [])
            ]
            detections.append([d for d in boxes if d.class_name in TRACKING])
            untracked.append([d for d in boxes if d.class_name not in TRACKING])
            here: dict[str, Annotation] = {}
            elsewhere: dict[str, Annotation] = {}
            for a in (nusc.get("sample_annotation", t) for t in sample["anns"]):
                name = category_to_tracking_name(a["category_name"])
                points = int(a["num_lidar_pts"]) + int(a["num_radar_pts"])
                xy = tuple(map(float, a["translation"][:2]))
                qw, qx, qy, qz = a["rotation"]
                yaw = math.atan2(2 * (qw * qz + qx * qy), 1 - 2 * (qy * qy + qz * qz))
                foot = (float(a["size"][0]), float(a["size"][1]), yaw)
                into, label = (here, name) if name is not None else (elsewhere, a["category_name"])
                into[a["instance_token"]] = Annotation(label, xy, points, int(a["num_radar_pts"]), foot)
            objects.append(here)
            others.append(elsewhere)
            token = sample["next"]
        return cls(detections, objects, ego, untracked, others)

    def object_of(self, frame: int, short_id: str) -> tuple[str, Annotation] | None:
        """The annotation at ``frame`` whose instance token starts with ``short_id`` (as the text prints it)."""
        hit = (
            [(k, a) for k, a in self.objects[frame].items() if k.startswith(short_id)]
            if frame < len(self.objects)
            else []
        )
        return hit[0] if len(hit) == 1 else None

    def distances(self, frame: int, xy_m: tuple[float, float]) -> np.ndarray:
        """(M,) ground-plane distance of each detection of ``frame`` from ``xy_m``."""
        dets = self.detections[frame]
        if not dets:
            return np.zeros(0)
        return np.hypot(*(np.array([d.xy_m for d in dets]) - np.asarray(xy_m)).T)

    def untracked_near(self, frame: int, xy_m: tuple[float, float]) -> list[str]:
        """The file's boxes of an untracked class within ``NEAR_M`` of ``xy_m`` at ``frame``: "class score"."""
        boxes = self.untracked[frame] if self.untracked is not None and frame < len(self.untracked) else []
        return [f"{d.class_name} {d.score:.2f}" for d in boxes if math.dist(d.xy_m, xy_m) < NEAR_M]

    def untracked_own(self, frame: int, gt_id: str) -> list[str]:
        """``untracked_near`` object ``gt_id`` at ``frame`` that lie nearer it than any other annotation, tracked or
        not (a barrier box on an annotated barrier beside a worker is the barrier's; audit truth52)."""
        a = self.objects[frame].get(gt_id) if frame < len(self.objects) else None
        boxes = self.untracked[frame] if self.untracked is not None and frame < len(self.untracked) else []
        if a is None:
            return []
        others = [o.xy_m for k, o in self.objects[frame].items() if k != gt_id]
        others += [o.xy_m for o in (self.others[frame].values() if self.others and frame < len(self.others) else [])]
        return [
            f"{d.class_name} {d.score:.2f}"
            for d in boxes
            if math.dist(d.xy_m, a.xy_m) < NEAR_M
            and all(math.dist(o, d.xy_m) >= math.dist(a.xy_m, d.xy_m) - 1e-6 for o in others)
        ]

    def untracked_on(self, frame: int, xy_m: tuple[float, float]) -> list[str]:
        """The annotations of untracked categories within ``NEAR_M`` of ``xy_m`` at ``frame``, or whose box contains
        it: "category id" (the id's first 6 characters)."""
        here = self.others[frame] if self.others is not None and frame < len(self.others) else {}
        return [
            f"{a.class_name} {k[:6]}" for k, a in here.items() if math.dist(a.xy_m, xy_m) < NEAR_M or a.contains(xy_m)
        ]

    def untracked_owner(self, frame: int, m: int, xy_m: tuple[float, float]) -> str | None:
        """The annotation of an untracked category ("category id") detection ``m`` at ``frame`` lies nearer than
        the object at ``xy_m``, else None (a stroller's box beside its pusher is the stroller's; audit truth52)."""
        here = self.others[frame] if self.others is not None and frame < len(self.others) else {}
        d = self.detections[frame][m].xy_m
        best = min(here.items(), key=lambda kv: math.dist(kv[1].xy_m, d), default=None)
        if best is None or math.dist(best[1].xy_m, d) >= math.dist(xy_m, d) - 1e-6:
            return None
        return f"{best[1].class_name} {best[0][:6]}"

    def owner(self, frame: int, m: int, xy_m: tuple[float, float]) -> tuple[str, float] | None:
        """The annotated object (id, distance m) nearest detection ``m`` at ``frame`` when it lies nearer the
        detection than the object at ``xy_m`` does, else None (the detection is that object's)."""
        d = self.detections[frame][m].xy_m
        best = min(self.objects[frame].items(), key=lambda kv: math.dist(kv[1].xy_m, d), default=None)
        if best is None or math.dist(best[1].xy_m, d) >= math.dist(xy_m, d) - 1e-6:
            return None
        return best[0], math.dist(best[1].xy_m, d)

    def claimant(self, frame: int, m: int, xy_m: tuple[float, float], class_name: str) -> tuple[str, float] | None:
        """``owner``, or else, for a detection of a class other than ``class_name`` (the object at ``xy_m``'s), the
        nearest annotation of the detection's own class within ``NEAR_M`` of it: that object's box, which the devkit
        would match there (audit truth51, world7: a rider annotated as a bicycle and a pedestrian on one spot)."""
        hit = self.owner(frame, m, xy_m)
        d = self.detections[frame][m]
        if hit is not None or d.class_name == class_name:
            return hit
        mine = [(math.dist(a.xy_m, d.xy_m), k) for k, a in self.objects[frame].items() if a.class_name == d.class_name]
        near = min((x for x in mine if x[0] < NEAR_M), default=None)
        return None if near is None else (near[1], near[0])

    def inside(self, frame: int, xy_m: tuple[float, float]) -> list[str]:
        """The objects of ``frame`` whose box contains the ground point ``xy_m`` (audit truth50, world6: a truck's
        trailer box 3 m from its centre is part of it, not "of no object")."""
        return [k for k, a in self.objects[frame].items() if a.contains(xy_m)] if frame < len(self.objects) else []

    def in_box(self, frame: int, gt_id: str) -> list[int]:
        """Detections of ``frame`` whose centre lies inside object ``gt_id``'s box and within ``NEAR_M`` of no
        other annotated object."""
        a = self.objects[frame].get(gt_id) if frame < len(self.objects) else None
        if a is None:
            return []
        others = [o.xy_m for k, o in self.objects[frame].items() if k != gt_id]
        return [
            m
            for m, d in enumerate(self.detections[frame])
            if a.contains(d.xy_m) and all(math.dist(o, d.xy_m) >= NEAR_M for o in others)
        ]

    def near(self, frame: int, xy_m: tuple[float, float], class_name: str | None = None) -> list[int]:
        """Detections of ``frame`` within ``NEAR_M`` of ``xy_m`` (of ``class_name`` only, if given)."""
        d = self.distances(frame, xy_m)
        return [
            m
            for m in np.flatnonzero(d < NEAR_M).tolist()
            if class_name is None or self.detections[frame][m].class_name == class_name
        ]


TRACKING = ("bicycle", "bus", "car", "motorcycle", "pedestrian", "trailer", "truck")
"""The nuScenes tracking classes (the devkit's ``TRACKING_NAMES``), whose boxes the detection ids count."""
