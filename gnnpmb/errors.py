"""User-facing errors: the CLI prints ``str(error)`` as one line and exits non-zero, without a traceback."""

from __future__ import annotations


class GnnpmbError(Exception):
    """Base of every error caused by the user's input (paths, files, names); the message says how to fix it."""


class DataError(GnnpmbError):
    """A dataset, scene or detection file that cannot be used."""


class UnknownNameError(GnnpmbError):
    """An unknown tracker, class, scene or preset name."""


class NotThisDatasetError(DataError):
    """An input file (detections, tracking results) without entries for samples of the dataset it is used on, or
    with samples the dataset does not have: made for another split, version or dataset. ``cli.errors`` adds a hint
    when the built-in demo was used because no dataroot was given."""
