"""3D boxes projected into camera images and clipped to them, many boxes at once.

Each box's eight corners go global -> camera (``CameraFrame``: the keyframe's ego pose and the camera's calibration)
-> pixels (the intrinsic ``K``: ``u = K p / p_z``); an edge is cut where it crosses ``NEAR_M`` in front of the
camera, then the box's edges are clipped to the image rectangle (shapely, one call over all boxes). A box whose
centre is behind the camera or outside the image (mostly outside it) is not drawn.

The arithmetic is the same per box as projecting the boxes one by one: the matrix products are stacked (numpy
runs each box's small product as its own), so every box's pixels come out the same to the last bit.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from gnnpmb.data.scene import Pose
from gnnpmb.data.sensors import CameraImage, camera_in_ego

NEAR_M = 0.1
"""Edges are cut this far in front of the camera (metres)."""
EDGES = ((0, 1), (1, 2), (2, 3), (3, 0), (4, 5), (5, 6), (6, 7), (7, 4), (0, 4), (1, 5), (2, 6), (3, 7))
"""The twelve edges of a box between its corners (``box_corners`` order: bottom face, then top face)."""
_CORNER_SIGNS = np.array(
    [[1, -1, -1, 1, 1, -1, -1, 1], [1, 1, -1, -1, 1, 1, -1, -1], [-1, -1, -1, -1, 1, 1, 1, 1]], dtype=np.int64
)
"""(3, 8) the corners' signs along the box's length, width and height (``box_corners`` order)."""


def rotations(quat_wxyz: np.ndarray) -> np.ndarray:
    """(N, 4) unit quaternions (w, x, y, z) -> (N, 3, 3) rotation matrices."""
    w, x, y, z = np.asarray(quat_wxyz, dtype=np.float64).reshape(-1, 4).T
    return np.stack(
        [
            np.stack([1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)], axis=-1),
            np.stack([2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)], axis=-1),
            np.stack([2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)], axis=-1),
        ],
        axis=-2,
    )


def box_corners(center_m: np.ndarray, size_wlh_m: np.ndarray, quat_wxyz: np.ndarray) -> np.ndarray:
    """(N, 8, 3) corners in the global frame of N boxes ((N, 3) centres, (N, 3) sizes w, l, h, (N, 4) rotations):
    bottom face then top face, counter-clockwise from front-left (the length along the box's x axis, as the
    devkit's ``Box``)."""
    size = np.asarray(size_wlh_m, dtype=np.float64).reshape(-1, 3)
    x = _CORNER_SIGNS[0] * size[:, 1:2] / 2
    y = _CORNER_SIGNS[1] * size[:, 0:1] / 2
    z = _CORNER_SIGNS[2] * size[:, 2:3] / 2
    local = np.stack([x, y, z], axis=-1)
    centre = np.asarray(center_m, dtype=np.float64).reshape(-1, 1, 3)
    return local @ rotations(quat_wxyz).transpose(0, 2, 1) + centre


@dataclass(frozen=True, slots=True)
class CameraFrame:
    """Global -> camera for one image at one keyframe: ``to_camera(p)`` maps (N, 3) global points to (N, 3)
    camera points (x right, y down, z forward); ``K`` (3, 3); the image's width and height in pixels."""

    rotation: np.ndarray
    translation_m: np.ndarray
    intrinsic: np.ndarray
    width_px: int
    height_px: int

    @staticmethod
    def of(image: CameraImage, ego: Pose) -> CameraFrame:
        cam_r, cam_t = camera_in_ego(image, ego)
        ego_r = rotations(np.asarray(ego.quat_wxyz, dtype=np.float64))[0]
        # global -> ego: ego_r.T (p - ego_t); ego -> camera: cam_r.T (q - cam_t)
        rotation = cam_r.T @ ego_r.T
        translation = -cam_r.T @ (ego_r.T @ np.asarray(ego.translation_m, dtype=np.float64) + cam_t)
        return CameraFrame(rotation, translation, np.asarray(image.intrinsic), image.width_px, image.height_px)


@dataclass(frozen=True, slots=True)
class _Cameras:
    """One camera per box, stacked: (N, 3, 3) rotations, (N, 1, 3) translations, (N, 3, 3) intrinsics, (N,)
    image widths and heights."""

    rotation: np.ndarray
    translation_m: np.ndarray
    intrinsic: np.ndarray
    width_px: np.ndarray
    height_px: np.ndarray

    @staticmethod
    def of(cams: list[CameraFrame]) -> _Cameras:
        return _Cameras(
            np.array([c.rotation for c in cams], dtype=np.float64).reshape(-1, 3, 3),
            np.array([c.translation_m for c in cams], dtype=np.float64).reshape(-1, 1, 3),
            np.array([c.intrinsic for c in cams], dtype=np.float64).reshape(-1, 3, 3),
            np.array([c.width_px for c in cams], dtype=np.int64),
            np.array([c.height_px for c in cams], dtype=np.int64),
        )

    def take(self, rows: np.ndarray) -> _Cameras:
        return _Cameras(
            self.rotation[rows],
            self.translation_m[rows],
            self.intrinsic[rows],
            self.width_px[rows],
            self.height_px[rows],
        )

    def to_camera(self, points_m: np.ndarray) -> np.ndarray:
        """(N, P, 3) global points, box n's in camera n -> (N, P, 3) camera points."""
        return points_m @ self.rotation.transpose(0, 2, 1) + self.translation_m

    def pixels(self, camera_points_m: np.ndarray) -> np.ndarray:
        """(N, P, 3) camera points with z > 0 -> (N, P, 2) pixels (u right, v down)."""
        uvw = camera_points_m @ self.intrinsic.transpose(0, 2, 1)
        return uvw[..., :2] / uvw[..., 2:3]


@dataclass(frozen=True, slots=True)
class Polylines:
    """The drawn parts of N boxes, flat: (P, 2) float32 pixels of all polylines, (S + 1,) offsets of the S
    polylines into them and (S,) the box each belongs to (box by box, each box's in clipping's order)."""

    points_px: np.ndarray
    offsets: np.ndarray
    box: np.ndarray

    def of_box(self, n: int) -> list[np.ndarray]:
        """Box ``n``'s polylines, (K, 2) each (none: not drawn)."""
        lo, hi = np.searchsorted(self.box, [n, n + 1])
        return [self.points_px[self.offsets[s] : self.offsets[s + 1]] for s in range(lo, hi)]


def take_lines(points: np.ndarray, offsets: np.ndarray, lines: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Polylines ``lines`` ((L,) indices, in that order) of the flat polylines (``points``, ``offsets``, as in
    ``Polylines``): their points and their (L + 1,) offsets into them."""
    starts = offsets[:-1][lines]
    lengths = offsets[1:][lines] - starts
    taken = np.zeros(len(lines) + 1, dtype=np.int64)
    np.cumsum(lengths, out=taken[1:])
    return points[np.repeat(starts - taken[:-1], lengths) + np.arange(taken[-1])], taken


def project_boxes(
    center_m: np.ndarray, size_wlh_m: np.ndarray, quat_wxyz: np.ndarray, cams: list[CameraFrame]
) -> Polylines:
    """The drawn part of each of N boxes ((N, 3) centres, (N, 3) sizes w, l, h, (N, 4) rotations) in its camera
    (``cams[n]``): pixel polylines clipped to the image, none for a box whose centre is behind the camera or
    outside the image (module docstring)."""
    import shapely

    n = len(cams)
    none = Polylines(np.zeros((0, 2), dtype=np.float32), np.zeros(1, dtype=np.int64), np.zeros(0, dtype=np.int64))
    if n == 0:
        return none
    stacked = _Cameras.of(cams)
    centre_m = np.asarray(center_m, dtype=np.float64).reshape(n, 1, 3)
    centre = stacked.to_camera(centre_m)[:, 0]
    ahead = np.flatnonzero(centre[:, 2] > NEAR_M)
    uv = stacked.take(ahead).pixels(centre[ahead][:, None])[:, 0]
    inside = (uv[:, 0] >= 0) & (uv[:, 0] <= stacked.width_px[ahead]) & (uv[:, 1] >= 0)
    inside &= uv[:, 1] <= stacked.height_px[ahead]
    drawn = ahead[inside]
    if drawn.size == 0:
        return none
    cams_drawn = stacked.take(drawn)
    size = np.asarray(size_wlh_m, dtype=np.float64).reshape(n, 3)[drawn]
    quat = np.asarray(quat_wxyz, dtype=np.float64).reshape(n, 4)[drawn]
    corners = cams_drawn.to_camera(box_corners(centre_m[drawn], size, quat))
    edges = np.array(EDGES)
    a, b = corners[:, edges[:, 0]], corners[:, edges[:, 1]]  # (M, 12, 3) each
    a_near, b_near = a[..., 2] < NEAR_M, b[..., 2] < NEAR_M
    kept = ~(a_near & b_near)
    cut = kept & (a_near | b_near)
    box_of, edge_of = np.nonzero(cut)
    a_cut, b_cut = a[box_of, edge_of], b[box_of, edge_of]
    t = (NEAR_M - a_cut[:, 2:3]) / (b_cut[:, 2:3] - a_cut[:, 2:3])
    at_near = a_cut + t * (b_cut - a_cut)
    behind = a_near[box_of, edge_of]
    a[box_of[behind], edge_of[behind]] = at_near[behind]
    b[box_of[~behind], edge_of[~behind]] = at_near[~behind]
    box_of, edge_of = np.nonzero(kept)  # box by box, each box's edges in ``EDGES`` order
    segments = np.stack([a[box_of, edge_of], b[box_of, edge_of]], axis=1)  # (S, 2, 3)
    pixels = cams_drawn.take(box_of).pixels(segments)
    lines = shapely.linestrings(pixels.reshape(-1, 2), indices=np.repeat(np.arange(len(segments)), 2))
    boxes = shapely.multilinestrings(lines, indices=box_of)
    clipped = np.empty(len(boxes), dtype=object)
    for w, h in {(int(w), int(h)) for w, h in zip(cams_drawn.width_px, cams_drawn.height_px, strict=True)}:
        same = (cams_drawn.width_px == w) & (cams_drawn.height_px == h)
        clipped[same] = shapely.clip_by_rect(boxes[same], 0.0, 0.0, w, h)
    merged = clipped.copy()
    full = ~shapely.is_empty(clipped)
    merged[full] = shapely.line_merge(clipped[full])
    parts, owner = shapely.get_parts(merged, return_index=True)
    coords, part = shapely.get_coordinates(parts, return_index=True)
    lengths = np.bincount(part, minlength=len(parts))
    offsets = np.zeros(len(parts) + 1, dtype=np.int64)
    np.cumsum(lengths, out=offsets[1:])
    points, offsets = take_lines(coords.astype(np.float32), offsets, np.flatnonzero(lengths >= 2))
    return Polylines(points, offsets, drawn[owner[lengths >= 2]])
