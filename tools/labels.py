"""Counting the labels a saved recording shows in each 3D view at each frame, and which of them overlap.

What a person sees is decided by the viewer, so this reads what the viewer reads: the recording's default
blueprint (each 3D view's name, origin, contents query, camera and the entities it hides) and, per entity, the
latest value at or before the frame of each component (static values win; a ``Clear`` empties what came before
it). A label is drawn, as Rerun 0.41 draws it (``re_view_spatial``'s ``show_labels_fallback`` and
``process_labels``), when ``show_labels`` is true, or unset and the batch has one label or fewer than 30
instances; its text is the instance's label, else its class's name from the annotation context; one label on a
batch of many instances is drawn once. Empty texts are not counted.

Overlap is decided in the default camera of the bird's-eye and perspective views: the label's anchor (box centre,
point, strip midpoint) projected with the view's eye (Rerun's default vertical field of view, ``FOV_Y_DEG``) into
the view's rectangle, the text box as Rerun places it (centred under the anchor; its size the one
``viz.label_size`` measured in the web viewer). The view's size in pixels is laid out from the blueprint's
containers at 1920 x 1080 (``layout_px``); the check keeps ``MARGIN_PX`` of air.

Camera views (2D views on a ``Pinhole`` camera entity) count the labels of 2D entities under the camera whose
anchor lies in the image, and of 3D entities their contents include projected through the keyframe's ego pose, the
camera's ``Transform3D`` and its pinhole (in front of the camera and inside the image); their overlaps are decided
at the size the full recording's camera grid shows an image at 1920 x 1080 (``CAMERA_SCALE``).

By hand: ``uv run python -m tools.labels FILE.rrd`` prints the most labels per view and the overlaps.
"""

from __future__ import annotations

import argparse
import math
import sys
import uuid
from collections import defaultdict
from collections.abc import Iterable, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
from rerun.chunk import RrdReader
from scipy.spatial.transform import Rotation

from viz.label_size import text_box

MAX_NUM_LABELS_PER_ENTITY = 30
"""Rerun hides the labels of a batch with this many instances or more unless ``show_labels`` says otherwise."""
FOV_Y_DEG = 55.0
"""Vertical field of view of a 3D view's default eye (Rerun's ``DEFAULT_FOV_Y``)."""
MARGIN_PX = 2.0
"""Two text boxes closer than this count as overlapping."""
ANCHORS = {
    "Boxes3D": ("centers", "half_sizes"),
    "Points3D": ("positions", "positions"),
    "LineStrips3D": ("strips", "strips"),
    "Ellipsoids3D": ("centers", "half_sizes"),
    "Arrows3D": ("origins", "vectors"),
    "Points2D": ("positions", "positions"),
    "LineStrips2D": ("strips", "strips"),
    "Boxes2D": ("centers", "half_sizes"),
}
"""Archetype -> (component that places the label, component whose length is the number of instances)."""
TOP_BAR_PX = 36.0
TIME_PANEL_PX = 25.0
"""The web viewer's top bar and collapsed time panel at 1920 x 1080; the rest holds the blueprint's root container."""
TITLE_PX = 24.0
"""A view's title bar (or its tab bar), above its content."""
CONTAINER_KINDS = {1: "tabs", 2: "horizontal", 3: "vertical", 4: "grid"}


@dataclass(frozen=True, slots=True)
class View3D:
    """One 3D view of the blueprint: its name, origin, contents rules (``+ path/**``), the entities it hides, and
    its eye (position, look target, up; in the origin's frame) when the blueprint sets one."""

    name: str
    origin: str
    rules: tuple[str, ...]
    hidden: tuple[str, ...]
    eye: tuple[tuple[float, ...], tuple[float, ...], tuple[float, ...]] | None
    size_px: tuple[float, float] = (0.0, 0.0)
    """Width and height of the view's content at 1920 x 1080, laid out from the blueprint (``layout_px``)."""

    @property
    def camera(self) -> bool:
        """A 2D view on a camera (its origin a pinhole entity, ``world/ego_vehicle/CAM_*``)."""
        return self.eye is None and "/CAM_" in self.origin

    def shows(self, entity: str) -> bool:
        """Whether the view's contents include ``entity`` and it is not hidden (most specific rule wins)."""
        best, verdict = -1, False
        for rule in self.rules:
            sign, _, pattern = rule.partition(" ")
            if pattern.endswith("/**"):
                base = pattern[:-3]
                hit = entity == base or entity.startswith(base + "/")
            else:
                base, hit = pattern, entity == pattern
            if hit and len(base) >= best:
                best, verdict = len(base), sign == "+"
        return verdict and not any(entity == h or entity.startswith(h + "/") for h in self.hidden)


@dataclass(frozen=True, slots=True)
class Label:
    """A label drawn at ``frame`` by ``entity``: its text and anchor in the global frame (x, y, z, metres)."""

    entity: str
    text: str
    anchor_m: tuple[float, float, float]


@dataclass(slots=True)
class _Entity:
    archetype: str
    rows: list[tuple[tuple[int, int], dict[str, Any]]] = field(default_factory=list)
    """((frame, row order) or (-1, order) for static, components) in order."""

    def latest(self, frame: int, component: str) -> Any:
        static = [c[component] for (f, _), c in self.rows if f == -1 and c.get(component) is not None]
        if static:
            return static[-1]
        value = None
        for (f, _), c in self.rows:
            if f == -1 or f > frame:
                continue
            if c.get("clear"):
                value = None
            elif c.get(component) is not None:
                value = c[component]
        return value


def _strip_id(path: str) -> str:
    return path.lstrip("/")


def layout_px(
    containers: dict[str, dict[str, Any]], root: str, viewport: tuple[int, int] = (1920, 1080)
) -> dict[str, tuple[float, float]]:
    """View id -> (width, height) of its content: the root container fills the viewport less ``TOP_BAR_PX`` and
    ``TIME_PANEL_PX``; a horizontal (vertical) container splits its width (height) by its shares (equal without),
    a grid into ``grid_columns`` columns and as many equal rows as needed, tabs give each child the whole rect; a
    view loses ``TITLE_PX`` to its title. Borders (a few pixels) are left out."""
    sizes: dict[str, tuple[float, float]] = {}

    def place(node: str, w: float, h: float) -> None:
        kind, _, node_id = node.partition("/")
        if kind == "view":
            sizes[node_id] = (w, max(h - TITLE_PX, 0.0))
            return
        c = containers.get(node_id, {})
        children = list(c.get("ContainerBlueprint:contents") or [])
        if not children:
            return
        layout = CONTAINER_KINDS.get((c.get("ContainerBlueprint:container_kind") or [1])[0], "tabs")
        if layout == "tabs":
            for child in children:
                place(child, w, h)
        elif layout == "grid":
            cols = (c.get("ContainerBlueprint:grid_columns") or [math.ceil(math.sqrt(len(children)))])[0]
            rows = math.ceil(len(children) / cols)
            for child in children:
                place(child, w / cols, h / rows)
        else:
            key = "ContainerBlueprint:col_shares" if layout == "horizontal" else "ContainerBlueprint:row_shares"
            shares = list(c.get(key) or [1.0] * len(children))
            for child, share in zip(children, shares, strict=False):
                part = share / sum(shares)
                place(child, w * part, h) if layout == "horizontal" else place(child, w, h * part)

    place(f"container/{root}", float(viewport[0]), viewport[1] - TOP_BAR_PX - TIME_PANEL_PX)
    return sizes


def read_views(rrd: Path, kinds: tuple[str, ...] = ("3D", "camera")) -> list[View3D]:
    """The views of the recording's default blueprint of ``kinds``: "3D", "camera" (a 2D view on a camera
    entity), "2D" (any other 2D view)."""
    reader = RrdReader(rrd)
    blueprints = reader.blueprints()
    if not blueprints:
        return []
    props: dict[str, dict[str, Any]] = defaultdict(dict)
    hidden: dict[str, list[str]] = defaultdict(list)
    containers: dict[str, dict[str, Any]] = defaultdict(dict)
    root = ""
    for chunk in reader.stream(store=blueprints[0]):
        path = chunk.entity_path
        for row in chunk.to_record_batch().to_pylist():
            if path == "/viewport" and row.get("ViewportBlueprint:root_container"):
                root = str(uuid.UUID(bytes=bytes(row["ViewportBlueprint:root_container"][0])))
            if path.startswith("/container/"):
                containers[path.split("/")[2]].update({k: v for k, v in row.items() if v is not None})
            if not path.startswith("/view/"):
                continue
            view_id = path.split("/")[2]
            if "/ViewContents/overrides/" in path:
                if row.get("EntityBehavior:visible") == [False]:
                    entity = path.split("/ViewContents/overrides/", 1)[1].removesuffix("/visualizers")
                    hidden[view_id].append(entity)
                continue
            for key, value in row.items():
                if value is not None and not key.startswith(("rerun.", "log_time", "blueprint")):
                    props[view_id][key] = value
    sizes = layout_px(containers, root)
    views = []
    for view_id, p in props.items():
        kind = p.get("ViewBlueprint:class_identifier")
        origin = _strip_id(p["ViewBlueprint:space_origin"][0])
        camera = kind == ["2D"] and "/CAM_" in origin
        if ("camera" if camera else (kind or ["?"])[0]) not in kinds:
            continue
        eye = None
        if p.get("EyeControls3D:position"):
            eye = (
                tuple(p["EyeControls3D:position"][0]),
                tuple(p["EyeControls3D:look_target"][0]),
                tuple(p["EyeControls3D:eye_up"][0]),
            )
        views.append(
            View3D(
                name=p["ViewBlueprint:display_name"][0],
                origin=origin,
                rules=tuple(r.replace("$origin", origin) for r in p.get("ViewContents:query", ["+ $origin/**"])),
                hidden=tuple(hidden[view_id]),
                eye=eye,
                size_px=sizes.get(view_id, (0.0, 0.0)),
            )
        )
    return sorted(views, key=lambda v: v.name)


class Recording:
    """The label-bearing entities of a recording (and the ego poses), read once; ``labels`` answers per view
    and frame."""

    def __init__(self, rrd: Path) -> None:
        self.views = read_views(rrd)
        self.entities: dict[tuple[str, str], _Entity] = {}
        """(entity path, archetype) -> its label-related rows."""
        self.frames: set[int] = set()
        self.ego: dict[int, tuple[np.ndarray, np.ndarray]] = {}
        self.class_names: dict[int, str] = {}
        self.pinholes: dict[str, tuple[np.ndarray, tuple[float, float]]] = {}
        """Camera entity -> (K (3, 3), (width, height) in pixels)."""
        self.cameras: dict[str, dict[int, tuple[np.ndarray, np.ndarray]]] = defaultdict(dict)
        """Camera entity -> frame -> (rotation (3, 3), translation (3,)): the camera in the ego frame."""
        clears: dict[str, list[int]] = defaultdict(list)
        labelled = {
            (_strip_id(chunk.entity_path), a)
            for chunk in RrdReader(rrd).store().stream()
            for a in ANCHORS
            if {f"{a}:labels", f"{a}:class_ids"} & set(chunk.to_record_batch().schema.names)
        }
        order = 0
        for chunk in RrdReader(rrd).store().stream():
            path = _strip_id(chunk.entity_path)
            batch = chunk.to_record_batch()
            names = batch.schema.names
            if "frame" in names:
                self.frames.update(v for v in batch.column("frame").to_pylist() if v is not None)
            if "AnnotationContext:context" in names:
                for row in batch.column("AnnotationContext:context").to_pylist():
                    for cls in (c for batch_row in row or () for c in batch_row or ()):
                        info = cls["class_description"]["info"]
                        if info.get("label"):
                            self.class_names[int(info["id"])] = info["label"]
            if path == "world/ego_vehicle" and "Transform3D:translation" in names:
                for row in batch.select(
                    [n for n in ("frame", "Transform3D:translation", "Transform3D:quaternion") if n in names]
                ).to_pylist():
                    if row.get("Transform3D:translation") and row.get("frame") is not None:
                        self.ego[row["frame"]] = (
                            np.asarray(row["Transform3D:translation"][0], dtype=np.float64),
                            np.asarray((row.get("Transform3D:quaternion") or [[0, 0, 0, 1]])[0], dtype=np.float64),
                        )
            if "Pinhole:image_from_camera" in names:
                for row in batch.select(["Pinhole:image_from_camera", "Pinhole:resolution"]).to_pylist():
                    if row["Pinhole:image_from_camera"]:
                        k = np.reshape(row["Pinhole:image_from_camera"][0], (3, 3)).T
                        self.pinholes[path] = (k, tuple(row["Pinhole:resolution"][0]))
            if "/CAM_" in path and "Transform3D:mat3x3" in names and "frame" in names:
                for row in batch.select(["frame", "Transform3D:mat3x3", "Transform3D:translation"]).to_pylist():
                    if row["Transform3D:mat3x3"] and row["frame"] is not None:
                        self.cameras[path][row["frame"]] = (
                            np.reshape(row["Transform3D:mat3x3"][0], (3, 3)).T,
                            np.asarray(row["Transform3D:translation"][0], dtype=np.float64),
                        )
            if "Clear:is_recursive" in names:
                for row in batch.select([n for n in ("frame", "Clear:is_recursive") if n in names]).to_pylist():
                    if row.get("Clear:is_recursive") is not None:
                        clears[path].append(row.get("frame", -1) if not chunk.is_static else -1)
            for archetype in ANCHORS:
                if (path, archetype) in labelled:
                    order = self._read(path, archetype, chunk.is_static, batch, order)
        for key, entity in self.entities.items():
            path = key[0]
            for frame in (f for p, fs in clears.items() for f in fs if path == p or path.startswith(p + "/")):
                if frame >= 0:
                    entity.rows.append(((frame, -1), {"clear": True}))
            entity.rows.sort(key=lambda r: (r[0][0], r[0][1]))

    def _read(self, path: str, archetype: str, static: bool, batch: Any, order: int) -> int:
        """Keep one archetype's label-related rows of a chunk of entity ``path``; returns the row counter."""
        names = batch.schema.names
        anchor, count = ANCHORS[archetype]
        wanted = {
            "labels": f"{archetype}:labels",
            "show_labels": f"{archetype}:show_labels",
            "class_ids": f"{archetype}:class_ids",
            "anchor": f"{archetype}:{anchor}",
            "count": f"{archetype}:{count}",
        }
        present = {k: v for k, v in wanted.items() if v in names}
        frames = batch.column("frame").to_pylist() if "frame" in names and not static else None
        columns = {k: batch.column(v).to_pylist() for k, v in present.items()}
        entity = self.entities.setdefault((path, archetype), _Entity(archetype))
        for i in range(batch.num_rows):
            values = {k: col[i] for k, col in columns.items()}
            if all(v is None for v in values.values()):
                continue
            frame = -1 if frames is None else frames[i]
            if frame is None:
                continue
            if values.get("count") is not None:
                values["n"] = len(values["count"])
            values.pop("count", None)
            order += 1
            entity.rows.append(((frame, order), values))
        return order

    def labels(self, view: View3D, frame: int) -> list[Label]:
        """The labels ``view`` draws at ``frame`` (module docstring)."""
        out: list[Label] = []
        for (path, _), entity in self.entities.items():
            if not view.shows(path):
                continue
            anchors = entity.latest(frame, "anchor")
            if not anchors:
                continue
            n = entity.latest(frame, "n") or len(anchors)
            texts = entity.latest(frame, "labels") or []
            show = entity.latest(frame, "show_labels")
            show = bool(show[0]) if show else (len(texts) == 1 or n < MAX_NUM_LABELS_PER_ENTITY)
            if not show:
                continue
            if len(texts) == 1 and n > 1:
                points = np.asarray([_anchor(a) for a in anchors], dtype=np.float64)
                lo, hi = points.min(axis=0), points.max(axis=0)
                out.append(Label(path, texts[0], tuple(0.5 * (lo + hi))))
                continue
            class_ids = entity.latest(frame, "class_ids") or []
            for i, a in enumerate(anchors[:n]):
                text = texts[i] if i < len(texts) else None
                if text is None and class_ids:
                    text = self.class_names.get(int(class_ids[min(i, len(class_ids) - 1)]))
                if text:
                    out.append(Label(path, text, _anchor(a)))
        if view.camera:
            return [label for label in out if self.pixel(view, frame, label) is not None]
        return out

    def pixel(self, view: View3D, frame: int, label: Label) -> tuple[float, float] | None:
        """Where a camera view draws ``label`` in its image (pixels), None when it is behind the camera or
        outside the image. 2D entities under the camera are in pixels already; 3D ones are projected."""
        k, (width, height) = self.pinholes[view.origin]
        if label.entity.startswith(view.origin + "/"):
            u, v = label.anchor_m[:2]
        else:
            frames = self.cameras[view.origin]
            at = frames.get(frame) or frames[max((f for f in frames if f <= frame), default=min(frames))]
            ego_point = np.asarray(label.anchor_m, dtype=np.float64)
            if not label.entity.startswith("world/ego_vehicle"):
                pose = self.ego.get(frame) or self.ego[max(f for f in self.ego if f <= frame)]
                ego_point = Rotation.from_quat(pose[1]).as_matrix().T @ (ego_point - pose[0])
            p = at[0].T @ (ego_point - at[1])
            if p[2] <= 0:
                return None
            u, v = (k @ p)[:2] / p[2]
        return (float(u), float(v)) if 0 <= u <= width and 0 <= v <= height else None

    def to_origin(self, view: View3D, frame: int, label: Label) -> np.ndarray:
        """A label's anchor in the view's origin frame (the ego frame for views on ``world/ego_vehicle``)."""
        p = np.asarray(label.anchor_m, dtype=np.float64)
        if label.entity.startswith("world/ego_vehicle") or view.origin != "world/ego_vehicle":
            return p
        pose = self.ego.get(frame) or self.ego[max(f for f in self.ego if f <= frame)]
        return Rotation.from_quat(pose[1]).as_matrix().T @ (p - pose[0])


def _anchor(value: Any) -> tuple[float, float, float]:
    """A label's anchor from the placing component's value: a point, or a strip (its middle)."""
    if value and isinstance(value[0], list | tuple):
        pts = np.asarray(value, dtype=np.float64)
        return tuple(0.5 * (pts.min(axis=0) + pts.max(axis=0)))
    return tuple(float(v) for v in value)


def screen_boxes(
    rec: Recording, view: View3D, frame: int, size_px: tuple[float, float]
) -> list[tuple[Label, tuple[float, float, float, float]]]:
    """The labels of ``view`` at ``frame`` inside its rectangle, each with its text box (x0, y0, x1, y1) in
    pixels (module docstring). Needs the view's eye."""
    if view.eye is None:
        raise ValueError(f"view {view.name} has no eye in the blueprint")
    eye, target, up = (np.asarray(v, dtype=np.float64) for v in view.eye)
    forward = (target - eye) / np.linalg.norm(target - eye)
    right = np.cross(forward, up)
    right /= np.linalg.norm(right)
    screen_up = np.cross(right, forward)
    w, h = size_px
    focal = 0.5 * h / math.tan(math.radians(FOV_Y_DEG) / 2)
    out = []
    for label in rec.labels(view, frame):
        d = rec.to_origin(view, frame, label) - eye
        depth = float(d @ forward)
        if depth <= 0:
            continue
        x = 0.5 * w + focal * float(d @ right) / depth
        y = 0.5 * h - focal * float(d @ screen_up) / depth
        if not (0 <= x <= w and 0 <= y <= h):
            continue
        out.append((label, text_box(label.text, x, y)))
    return out


def camera_scale(rec: Recording, view: View3D) -> float:
    """Screen pixels per image pixel of camera view ``view``: its image fitted into the view's content."""
    _, (width, height) = rec.pinholes[view.origin]
    return min(view.size_px[0] / width, view.size_px[1] / height)


def camera_boxes(rec: Recording, view: View3D, frame: int) -> list[tuple[Label, tuple[float, float, float, float]]]:
    """The labels of camera view ``view`` at ``frame``, each with its text box in screen pixels (``camera_scale``)."""
    out = []
    scale = camera_scale(rec, view)
    for label in rec.labels(view, frame):
        u, v = rec.pixel(view, frame, label)
        x, y = u * scale, v * scale
        out.append((label, text_box(label.text, x, y)))
    return out


def overlaps(boxes: Sequence[tuple[Label, tuple[float, float, float, float]]]) -> list[tuple[Label, Label]]:
    """Pairs of labels whose text boxes overlap (or come closer than ``MARGIN_PX``)."""
    pairs = []
    for i, (a, ra) in enumerate(boxes):
        for b, rb in boxes[i + 1 :]:
            if (
                ra[0] < rb[2] + MARGIN_PX
                and rb[0] < ra[2] + MARGIN_PX
                and ra[1] < rb[3] + MARGIN_PX
                and rb[1] < ra[3] + MARGIN_PX
            ):
                pairs.append((a, b))
    return pairs


@dataclass(frozen=True, slots=True)
class LabelSummary:
    """Per 3D and camera view: the most labels at one frame (and that frame), and the overlaps per frame (in
    the views' default cameras)."""

    most: dict[str, tuple[int, int]]
    overlapping: dict[str, dict[int, list[tuple[str, str]]]]
    clipped: dict[str, dict[int, list[str]]] = field(default_factory=dict)
    """Per view, frame -> the labels whose text box runs past the view's edge (cut off)."""


def summarize(rrd: Path, frames: Iterable[int] | None = None) -> LabelSummary:
    rec = Recording(rrd)
    frames = sorted(rec.frames) if frames is None else list(frames)
    most: dict[str, tuple[int, int]] = {}
    overlapping: dict[str, dict[int, list[tuple[str, str]]]] = defaultdict(dict)
    clipped: dict[str, dict[int, list[str]]] = defaultdict(dict)
    for view in rec.views:
        for f in frames:
            n = len(rec.labels(view, f))
            if n > most.get(view.name, (-1, -1))[0]:
                most[view.name] = (n, f)
            if view.camera:
                boxes, rect = camera_boxes(rec, view, f), camera_rect(rec, view)
            elif view.eye is not None:
                boxes, rect = screen_boxes(rec, view, f, view.size_px), (0.0, 0.0, *view.size_px)
            else:
                continue
            pairs = overlaps(boxes)
            if pairs:
                overlapping[view.name][f] = [(a.text, b.text) for a, b in pairs]
            cut = [label.text for label, box in boxes if not inside(box, rect)]
            if cut:
                clipped[view.name][f] = cut
    return LabelSummary(most, dict(overlapping), dict(clipped))


def camera_rect(rec: Recording, view: View3D) -> tuple[float, float, float, float]:
    """The camera view's rectangle in the screen pixels of ``camera_boxes`` (the image fitted and centred)."""
    _, (width, height) = rec.pinholes[view.origin]
    scale = camera_scale(rec, view)
    dx, dy = 0.5 * (view.size_px[0] - width * scale), 0.5 * (view.size_px[1] - height * scale)
    return -dx, -dy, width * scale + dx, height * scale + dy


def inside(box: tuple[float, float, float, float], rect: tuple[float, float, float, float]) -> bool:
    """Whether a text box lies wholly inside a view's rectangle (else the view's edge cuts it off)."""
    return box[0] >= rect[0] and box[1] >= rect[1] and box[2] <= rect[2] and box[3] <= rect[3]


def main(argv: Sequence[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m tools.labels", description=__doc__.split("\n")[0])
    parser.add_argument("rrd", type=Path)
    args = parser.parse_args(argv)
    summary = summarize(args.rrd)
    for name, (n, f) in summary.most.items():
        over = summary.overlapping.get(name, {})
        cut = summary.clipped.get(name, {})
        print(
            f"{name}: at most {n} labels (frame {f}); overlapping pairs at {len(over)} frames; "
            f"labels cut by the view's edge at {len(cut)} frames"
        )
        for f, pairs in sorted(over.items())[:5]:
            print(f"  frame {f}: {pairs[:4]}")
        for f, texts in sorted(cut.items())[:3]:
            print(f"  frame {f}, cut: {texts[:4]}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
