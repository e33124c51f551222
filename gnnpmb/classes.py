"""The nuScenes tracking class names, importable without numpy (the CLI's help text needs them at start-up)."""

from __future__ import annotations

TRACKING_CLASSES: tuple[str, ...] = ("bicycle", "bus", "car", "motorcycle", "pedestrian", "trailer", "truck")
"""The seven nuScenes tracking classes, in the devkit's (alphabetical) order."""

TRACKING_NAME_OF_CATEGORY: dict[str, str] = {
    "vehicle.bicycle": "bicycle",
    "vehicle.bus.bendy": "bus",
    "vehicle.bus.rigid": "bus",
    "vehicle.car": "car",
    "vehicle.motorcycle": "motorcycle",
    "human.pedestrian.adult": "pedestrian",
    "human.pedestrian.child": "pedestrian",
    "human.pedestrian.construction_worker": "pedestrian",
    "human.pedestrian.police_officer": "pedestrian",
    "vehicle.trailer": "trailer",
    "vehicle.truck": "truck",
}
"""The tracking class of each nuScenes category that has one: the devkit's ``category_to_tracking_name``
(``nuscenes.eval.tracking.utils``) as a table, read without importing the devkit, whose package loads
scikit-learn and matplotlib (a second of CPU in each process that indexes a dataset);
``tests/gnnpmb/data/test_dataset_index.py`` checks it against the devkit's."""
