"""Which of a scene's LiDAR files are on disk: the viewer draws without the ones that are not.

The nuScenes metadata (the ``v1.0-*`` tables) is a small download; the sensor blobs (``samples/``, ``sweeps/``)
are ~300 GB, and tracking, evaluation and the explanations need none of them. A dataroot with the tables and
no LiDAR file at all is a metadata-only download: the viewer draws boxes, tracks and failures without the point
cloud and says so once. A dataroot with some of a scene's LiDAR files (an interrupted download, a partial copy)
is drawn with the sweeps it has; the notice names how many keyframes lack theirs, which, and one missing path.
A file that is there but damaged is still an error (``gnnpmb.data.nuscenes.load_lidar_points``): it should be
downloaded again, not drawn around. What the user is told is worded by the viewer (``viz.scene.lidar_notice``).
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass
from pathlib import Path

from gnnpmb.data.scene import SceneData


@dataclass(frozen=True, slots=True)
class LidarPresence:
    """The keyframes ``checked`` (indices into ``SceneData.keyframes``) and those of them whose LIDAR_TOP file is
    not on disk (``missing``, ascending); ``example``: the first missing file's path (None when none is)."""

    scene_name: str
    checked: tuple[int, ...]
    missing: tuple[int, ...]
    example: Path | None

    @property
    def complete(self) -> bool:
        """Every checked keyframe has its LiDAR file."""
        return not self.missing

    @property
    def absent(self) -> bool:
        """No checked keyframe has its LiDAR file (a metadata-only dataroot)."""
        return bool(self.checked) and len(self.missing) == len(self.checked)

    def has(self, frame: int) -> bool:
        """Whether keyframe ``frame``'s LiDAR file is on disk."""
        return frame not in self.missing


def lidar_presence(scene: SceneData, frames: Iterable[int]) -> LidarPresence:
    """Which of the keyframes ``frames`` of ``scene`` have their LIDAR_TOP file on disk (one ``stat`` each)."""
    checked = tuple(frames)
    missing = tuple(i for i in checked if not scene.keyframes[i].lidar_path.is_file())
    example = scene.keyframes[missing[0]].lidar_path if missing else None
    return LidarPresence(scene.name, checked, missing, example)
