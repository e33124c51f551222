"""The demo's six cameras: nuScenes' camera layout and intrinsics, their table rows, and a small rasteriser that
renders the demo world into them as JPEGs.

Layout: the six ``CAM_*`` channels with the calibration of the real nuScenes car (``calibrated_sensor`` of the
``n015`` log: translation in the ego frame, rotation ``quat_wxyz`` from the camera frame (x right, y down, z
forward) to the ego frame, and the 3x3 intrinsic matrix), 1600 x 900 pixels. Each keyframe has one keyframe
``sample_data`` row per camera, taken at the LiDAR keyframe's time with its own ``ego_pose`` row (the same pose).

Rendering (``render_scene_images``): flat-shaded polygons drawn far to near (the painter's algorithm, by distance
to the camera, so a near box hides a far one): sky, the ground, the road strip and its centre line, then every
annotated box's camera-facing faces in its class colour (the devkit's ``get_colormap``), each clipped at the near
plane and projected with the intrinsics. numpy and pillow only.

The images are rendered on first use of a scene's cameras, not when the demo is built: 1600 x 900 JPEGs cost
~30 ms each to draw and encode, so the 720 of the three default scenes would multiply the demo's build time (about
4 s) several times over. ``ensure_scene_images`` writes a scene's missing images (each atomically). A change to
the rendering bumps ``gnnpmb.data.demo.GENERATOR_VERSION``, so no cache keeps images of an older renderer.
"""

from __future__ import annotations

import io
import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from gnnpmb.atomic import write_bytes

IMAGE_WIDTH_PX = 1600
IMAGE_HEIGHT_PX = 900
JPEG_QUALITY = 75
NEAR_PLANE_M = 0.5
DRAW_RANGE_M = 120.0
"""Boxes farther than this from the camera are not drawn (nuScenes annotates up to about this far)."""
ROAD_HALF_WIDTH_M = 3.5
WIDE_ROAD_LEFT_M = 7.0
"""The left edge of a road with two oncoming lanes (scene-0103)."""
ROAD_AHEAD_M = 260.0
ROAD_BEHIND_M = 80.0
GROUND_RADIUS_M = 2000.0
"""The ground is a 32-gon of this radius around the camera: its far edge lies a few pixels below the horizon."""
SKY_RGB = (176, 196, 222)
GROUND_RGB = (122, 134, 104)
ROAD_RGB = (82, 84, 90)
LINE_RGB = (225, 225, 210)
LINE_HALF_WIDTH_M = 0.08
LIGHT_DIR = np.array([0.35, 0.25, 0.9]) / np.linalg.norm([0.35, 0.25, 0.9])


@dataclass(frozen=True, slots=True)
class CameraMount:
    """One camera of the nuScenes car: channel, translation_m (3,) and rotation quat_wxyz (4,) of the camera frame
    in the ego frame, intrinsic (3, 3) pixels."""

    channel: str
    translation_m: tuple[float, float, float]
    quat_wxyz: tuple[float, float, float, float]
    intrinsic: tuple[tuple[float, float, float], ...]


def _k(f: float, cx: float, cy: float) -> tuple[tuple[float, float, float], ...]:
    return ((f, 0.0, cx), (0.0, f, cy), (0.0, 0.0, 1.0))


CAMERAS: tuple[CameraMount, ...] = (
    CameraMount(
        "CAM_FRONT",
        (1.70079118954, 0.0159456324149, 1.51095763913),
        (0.4998015430569128, -0.5030316162024876, 0.4997798114386805, -0.49737083824542755),
        _k(1266.417203046554, 816.2670197447984, 491.50706579294757),
    ),
    CameraMount(
        "CAM_FRONT_RIGHT",
        (1.5508477543, -0.493404796419, 1.49574800619),
        (0.2060347966337182, -0.2026940577919598, 0.6824507824531167, -0.6713610884174485),
        _k(1260.8474446004698, 807.968244525554, 495.3344268742088),
    ),
    CameraMount(
        "CAM_BACK_RIGHT",
        (1.0148780988, -0.480568219723, 1.56239545128),
        (0.12280980120078765, -0.132400842670559, -0.7004305821388234, 0.690496031265798),
        _k(1259.5137405846733, 807.2529053838625, 501.19579884916527),
    ),
    CameraMount(
        "CAM_BACK",
        (0.0283260309358, 0.00345136761476, 1.57910346144),
        (0.5037872666382278, -0.49740249788611096, -0.4941850223835201, 0.5045496097725578),
        _k(809.2209905677063, 829.2196003259838, 481.77842384512485),
    ),
    CameraMount(
        "CAM_BACK_LEFT",
        (1.03569100218, 0.484795032713, 1.59097014818),
        (0.6924185592174665, -0.7031619420114925, -0.11648342771943819, 0.11203317912370753),
        _k(1256.7414812095406, 792.1125740759628, 492.7757465151356),
    ),
    CameraMount(
        "CAM_FRONT_LEFT",
        (1.52387798135, 0.494631336551, 1.50932822144),
        (0.6757265034669446, -0.6736266522251881, 0.21214015046209478, -0.21122827103904068),
        _k(1272.5979470598488, 826.6154927353808, 479.75165386361925),
    ),
)
"""The six cameras in nuScenes' channel order (clockwise from the front)."""


def quat_matrix(quat_wxyz: np.ndarray | tuple[float, ...]) -> np.ndarray:
    """(3, 3) rotation matrix of a unit quaternion [w, x, y, z]."""
    w, x, y, z = (float(v) for v in quat_wxyz)
    n = math.sqrt(w * w + x * x + y * y + z * z)
    w, x, y, z = w / n, x / n, y / n, z / n
    return np.array(
        [
            [1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
            [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
            [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)],
        ]
    )


def image_filename(log_name: str, channel: str, timestamp_us: int) -> str:
    """The dataroot-relative path of one camera image, named as nuScenes names them."""
    return f"samples/{channel}/{log_name}__{channel}__{int(timestamp_us)}.jpg"


@dataclass(frozen=True, slots=True)
class WorldView:
    """What one keyframe's images show, in the global frame: the road's origin (2,), heading and left edge, the
    ego's road position s, and the boxes: centre_m (M, 3), size_wlh_m (M, 3), yaw_rad (M,), colour (M, 3)."""

    road_origin_m: tuple[float, float]
    road_heading_rad: float
    road_left_m: float
    ego_s_m: float
    centre_m: np.ndarray
    size_wlh_m: np.ndarray
    yaw_rad: np.ndarray
    rgb: np.ndarray


@dataclass(frozen=True, slots=True)
class CameraPose:
    """A camera in the global frame: rotation (3, 3) camera-to-global, position_m (3,), intrinsic (3, 3)."""

    rotation: np.ndarray
    position_m: np.ndarray
    intrinsic: np.ndarray

    @staticmethod
    def of(mount: CameraMount, ego_xy_m: np.ndarray, ego_yaw_rad: float) -> CameraPose:
        c, s = math.cos(ego_yaw_rad), math.sin(ego_yaw_rad)
        ego_r = np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])
        ego_t = np.array([float(ego_xy_m[0]), float(ego_xy_m[1]), 0.0])
        return CameraPose(
            rotation=ego_r @ quat_matrix(mount.quat_wxyz),
            position_m=ego_t + ego_r @ np.array(mount.translation_m),
            intrinsic=np.array(mount.intrinsic),
        )

    def to_camera(self, points_m: np.ndarray) -> np.ndarray:
        """(N, 3) global points in the camera frame."""
        return (np.asarray(points_m) - self.position_m) @ self.rotation


def _clip_near(poly_cam: np.ndarray) -> np.ndarray:
    """The part of a convex polygon (N, 3) in the camera frame in front of the near plane (Sutherland-Hodgman)."""
    out = []
    n = len(poly_cam)
    for i in range(n):
        a, b = poly_cam[i], poly_cam[(i + 1) % n]
        a_in, b_in = a[2] >= NEAR_PLANE_M, b[2] >= NEAR_PLANE_M
        if a_in:
            out.append(a)
        if a_in != b_in:
            t = (NEAR_PLANE_M - a[2]) / (b[2] - a[2])
            out.append(a + t * (b - a))
    return np.array(out).reshape(-1, 3)


def _pixels(poly_cam: np.ndarray, intrinsic: np.ndarray) -> list[tuple[float, float]] | None:
    """The projected, near-clipped polygon as pixel coordinates (None if nothing of it is in front)."""
    clipped = _clip_near(poly_cam)
    if len(clipped) < 3:
        return None
    uvw = clipped @ intrinsic.T
    uv = uvw[:, :2] / uvw[:, 2:3]
    uv = np.clip(uv, -1e5, 1e5)
    return [(float(u), float(v)) for u, v in uv]


_FACES = np.array([[0, 1, 2, 3], [4, 5, 6, 7], [0, 1, 5, 4], [2, 3, 7, 6], [1, 2, 6, 5], [3, 0, 4, 7]], dtype=np.int64)
"""The six faces of ``_box_corners`` (corner indices): bottom, top, front, back, right, left."""
_FACE_NORMALS = np.array([[0, 0, -1], [0, 0, 1], [1, 0, 0], [-1, 0, 0], [0, -1, 0], [0, 1, 0]], dtype=float)
"""Outward normals of ``_FACES`` in the box frame (x forward, y left, z up)."""


def _box_corners(centre_m: np.ndarray, size_wlh_m: np.ndarray, yaw_rad: float) -> np.ndarray:
    """(8, 3) corners: bottom (z = -h/2) then top, each front-left, front-right, back-right, back-left."""
    w, length, h = size_wlh_m
    x = np.array([1, 1, -1, -1]) * 0.5 * length
    y = np.array([1, -1, -1, 1]) * 0.5 * w
    c, s = math.cos(yaw_rad), math.sin(yaw_rad)
    xy = np.stack([c * x - s * y, s * x + c * y], axis=1)
    bottom = np.column_stack([xy, np.full(4, -0.5 * h)])
    top = np.column_stack([xy, np.full(4, 0.5 * h)])
    return np.concatenate([bottom, top]) + centre_m


def _shade(rgb: np.ndarray, normal: np.ndarray) -> tuple[int, int, int]:
    k = 0.55 + 0.45 * max(0.0, float(normal @ LIGHT_DIR))
    return tuple(int(min(255, round(v * k))) for v in rgb)  # type: ignore[return-value]


def _road_quads(view: WorldView) -> list[tuple[np.ndarray, tuple[int, int, int]]]:
    """The road strip and its centre line as (4, 3) global quads with their colours."""
    c, s = math.cos(view.road_heading_rad), math.sin(view.road_heading_rad)
    ox, oy = view.road_origin_m

    def quad(d_lo: float, d_hi: float, z: float) -> np.ndarray:
        s_lo, s_hi = view.ego_s_m - ROAD_BEHIND_M, view.ego_s_m + ROAD_AHEAD_M
        sd = np.array([[s_lo, d_lo], [s_hi, d_lo], [s_hi, d_hi], [s_lo, d_hi]])
        x = ox + c * sd[:, 0] - s * sd[:, 1]
        y = oy + s * sd[:, 0] + c * sd[:, 1]
        return np.column_stack([x, y, np.full(4, z)])

    return [
        (quad(-ROAD_HALF_WIDTH_M, view.road_left_m, 0.0), ROAD_RGB),
        (quad(-LINE_HALF_WIDTH_M, LINE_HALF_WIDTH_M, 0.01), LINE_RGB),
    ]


def render_image(view: WorldView, camera: CameraPose) -> bytes:
    """One camera's JPEG (1600 x 900, quality 75) of ``view``: sky, ground, road, then the boxes far to near."""
    from PIL import Image, ImageDraw

    image = Image.new("RGB", (IMAGE_WIDTH_PX, IMAGE_HEIGHT_PX), SKY_RGB)
    draw = ImageDraw.Draw(image)
    k = camera.intrinsic
    angle = np.linspace(0.0, 2.0 * np.pi, 32, endpoint=False)
    ground = np.column_stack(
        [camera.position_m[0] + GROUND_RADIUS_M * np.cos(angle), camera.position_m[1] + GROUND_RADIUS_M * np.sin(angle)]
        + [np.zeros(angle.size)]
    )
    for quad, rgb in [(ground, GROUND_RGB), *_road_quads(view)]:
        pix = _pixels(camera.to_camera(quad), k)
        if pix is not None:
            draw.polygon(pix, fill=rgb)
    centres_cam = camera.to_camera(view.centre_m) if len(view.centre_m) else np.zeros((0, 3))
    distance = np.linalg.norm(centres_cam, axis=1)
    reach = 0.5 * np.linalg.norm(view.size_wlh_m, axis=1) if len(view.centre_m) else np.zeros(0)
    visible = (distance <= DRAW_RANGE_M) & (centres_cam[:, 2] > NEAR_PLANE_M - reach)
    for m in np.flatnonzero(visible)[np.argsort(-distance[visible], kind="stable")]:
        yaw = float(view.yaw_rad[m])
        corners = _box_corners(view.centre_m[m], view.size_wlh_m[m], yaw)
        corners_cam = camera.to_camera(corners)
        c, s = math.cos(yaw), math.sin(yaw)
        normals = _FACE_NORMALS @ np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]]).T
        facing = np.einsum("ij,ij->i", normals, camera.position_m - corners[_FACES[:, 0]]) > 0
        for face, normal in zip(_FACES[facing], normals[facing], strict=True):
            pix = _pixels(corners_cam[face], k)
            if pix is not None:
                draw.polygon(pix, fill=_shade(view.rgb[m], normal), outline=(40, 40, 40))
    buffer = io.BytesIO()
    image.save(buffer, format="JPEG", quality=JPEG_QUALITY)
    return buffer.getvalue()


def category_rgb(categories: list[str]) -> np.ndarray:
    """(M, 3) the devkit's colour of each nuScenes category."""
    from nuscenes.utils.color_map import get_colormap

    colours = get_colormap()
    return np.array([colours.get(c, (200, 200, 200)) for c in categories], dtype=float)


def render_views(dataroot: Path, jobs: list[tuple[str, WorldView, CameraPose]]) -> int:
    """Render and write every (dataroot-relative filename, view, camera) whose file is missing; the number
    written."""
    written = 0
    for filename, view, camera in jobs:
        target = dataroot / filename
        if target.is_file():
            continue
        target.parent.mkdir(parents=True, exist_ok=True)
        write_bytes(target, render_image(view, camera))
        written += 1
    return written
