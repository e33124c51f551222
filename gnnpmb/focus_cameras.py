"""Which camera saw a focus recording's object: the cameras whose field of view held it at the focus frame.

The object is the failure's ground-truth box when it is annotated at that frame (a miss, a switch), else the
focus place (a false track's position) at ``OBJECT_HEIGHT_M`` above the ground. Occlusion is not considered: a
camera "holds the object in its view" when the point is in front of it and projects inside its image
(``gnnpmb.data.sensors.sightings``).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from gnnpmb.data.scene import SceneData
from gnnpmb.data.sensors import CameraSighting, SceneSensors, sightings
from gnnpmb.focus import FocusTarget

OBJECT_HEIGHT_M = 0.8
"""Height above the ground of a focus place without a ground-truth box (about a car's or a person's middle)."""


@dataclass(frozen=True, slots=True)
class FocusSight:
    """frame_index: the focus frame; gt_id: the instance token looked for (None: the focus place, e.g. a false
    track's, whose id is track_id when the failure names one); seen: the cameras whose view held it, most central
    first (empty: none did)."""

    frame_index: int
    gt_id: str | None
    seen: tuple[CameraSighting, ...]
    track_id: int | None = None

    @property
    def best_channel(self) -> str | None:
        return self.seen[0].channel if self.seen else None


def focus_sight(focus: FocusTarget, scene: SceneData, sensors: SceneSensors) -> FocusSight:
    """The cameras that held the focus object in view at the focus frame."""
    k = focus.frame_index
    gt = scene.keyframes[k].gt
    ids = gt.instance_id.astype(str) if len(gt) else np.zeros(0, dtype=str)
    for gt_id in focus.gt_ids:
        rows = np.flatnonzero(ids == gt_id)
        if rows.size:
            return FocusSight(k, gt_id, sightings(sensors.cameras[k], gt.translation_m[rows[0]]))
    x, y = focus.center_xy_m
    point = np.array([x, y, scene.keyframes[k].ego_pose.translation_m[2] + OBJECT_HEIGHT_M])
    track = focus.failure_tracks[0] if focus.failure_tracks else None
    return FocusSight(k, None, sightings(sensors.cameras[k], point), track)
