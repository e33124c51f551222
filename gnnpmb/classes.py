"""The nuScenes tracking class names, importable without numpy (the CLI's help text needs them at start-up)."""

from __future__ import annotations

TRACKING_CLASSES: tuple[str, ...] = ("bicycle", "bus", "car", "motorcycle", "pedestrian", "trailer", "truck")
"""The seven nuScenes tracking classes, in the devkit's (alphabetical) order."""
