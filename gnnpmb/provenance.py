"""Provenance of a recording: everything needed to re-run its trackers and check that they give the same
tracks.

A ``Provenance`` holds the command line, package versions, the full tracker parameters, the dataset (dataroot,
version, synthetic or real, scene name and token), where the detections came from with a content hash, the
seed, frame range and classes, and per tracker a digest of its output tracks. ``to_json``/``from_json`` give a
canonical JSON form (sorted keys) that ``viz.provenance`` stores in the recording.

Track digest (``track_digest``), stable across runs and machines for equal outputs:

* an estimate is one text line ``"<track_id> <class> <x> <y> <z> <w> <l> <h> <qw> <qx> <qy> <qz> <vx> <vy>
  <score> <existence> <meas_index>"`` with lengths, sizes and velocities at 4 decimals (0.1 mm, 0.1 mm/s) and
  quaternion, score and existence at 6 decimals (negative zero written as zero), so float noise far below what
  a viewer shows does not count as a difference;
* a frame's digest is the SHA-256 (hex) of its lines sorted by track id, joined by newlines (an empty frame
  hashes the empty string);
* the overall digest is the SHA-256 of the lines ``"<keyframe index> <frame digest>"`` joined by newlines.

Detections hash (``detections_sha256``): a detection file is hashed byte for byte (``file_sha256``); simulated
detections are hashed from the generated boxes (``boxes_sha256``), stored next to the preset and seed.
"""

from __future__ import annotations

import dataclasses
import hashlib
import json
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from importlib import metadata
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from gnnpmb.errors import DataError
from gnnpmb.types import Boxes, TrackEstimate

if TYPE_CHECKING:
    from gnnpmb.data.nuscenes import DatasetLocation

FORMAT_VERSION = 1
"""Bumped when the stored layout or the digest definition changes."""
PACKAGES: tuple[str, ...] = ("gnnpmb-viz", "rerun-sdk", "nuscenes-devkit", "numpy")
"""Distributions whose versions a recording records."""
_CHUNK_BYTES = 1 << 20


def package_versions(packages: Sequence[str] = PACKAGES) -> dict[str, str]:
    """Installed version of each distribution ("not installed" if missing)."""
    out = {}
    for name in packages:
        try:
            out[name] = metadata.version(name)
        except metadata.PackageNotFoundError:
            out[name] = "not installed"
    return out


SOURCE_KEY = "gnnpmb source"
"""The ``versions`` entry of a recording that holds ``source_digest``: two trees of one package version can hold
different code (a checkout, an edit), which a version number does not show."""


def source_digest() -> str:
    """SHA-256 (hex, first 16 digits) of the ``gnnpmb`` package's source files (``.py`` and ``.toml``, by relative
    path), the code that computes the tracks."""
    import gnnpmb

    root = Path(gnnpmb.__file__).parent
    digest = hashlib.sha256()
    for path in sorted(root.rglob("*")):
        if path.suffix in (".py", ".toml") and path.is_file():
            digest.update(path.relative_to(root).as_posix().encode() + b"\0" + path.read_bytes() + b"\0")
    return digest.hexdigest()[:16]


def recorded_versions() -> dict[str, str]:
    """What a recording keeps of the code: the package versions and the ``SOURCE_KEY`` digest."""
    return package_versions() | {SOURCE_KEY: source_digest()}


def code_differs(recorded: Mapping[str, str]) -> bool:
    """Whether a recording's ``versions`` name other ``gnnpmb`` code than this (its source digest differs; a
    recording without one says nothing)."""
    return SOURCE_KEY in recorded and recorded[SOURCE_KEY] != source_digest()


def file_sha256(path: Path) -> str:
    """SHA-256 (hex) of a file's bytes, read in 1 MiB blocks."""
    digest = hashlib.sha256()
    with open(path, "rb") as f:
        while block := f.read(_CHUNK_BYTES):
            digest.update(block)
    return digest.hexdigest()


def boxes_sha256(detections: Mapping[str, Boxes], sample_tokens: Sequence[str]) -> str:
    """SHA-256 (hex) of the detections of ``sample_tokens`` (in that order): per sample its token, box count,
    then the float arrays as little-endian float64 bytes and the class names (a sample without detections
    counts as empty)."""
    digest = hashlib.sha256()
    for token in sample_tokens:
        boxes = detections.get(token, Boxes.empty())
        digest.update(f"{token} {len(boxes)}\n".encode())
        for array in (
            boxes.translation_m,
            boxes.size_wlh_m,
            boxes.quat_wxyz,
            boxes.velocity_mps,
            boxes.score,
        ):
            digest.update(np.ascontiguousarray(array, dtype="<f8").tobytes())
        digest.update("\n".join(str(c) for c in boxes.class_name).encode())
    return digest.hexdigest()


_DECIMALS = np.array([4] * 6 + [6] * 4 + [4] * 2 + [6] * 2)
"""Decimals of the numbers of a line: x y z w l h, the quaternion, vx vy, score and existence."""
_LINE_NUMBERS = " ".join(f"%.{d}f" for d in _DECIMALS.tolist())


def _lines(estimates: Sequence[TrackEstimate]) -> list[str]:
    """The canonical text line of each estimate (see the module docstring), rounded in one pass per frame."""
    values = np.array(
        [[*e.translation_m, *e.size_wlh_m, *e.quat_wxyz, *e.velocity_mps, e.score, e.existence] for e in estimates],
        dtype=np.float64,
    ).reshape(-1, len(_DECIMALS))
    rounded = np.where(_DECIMALS == 4, np.round(values, 4), np.round(values, 6)) + 0.0  # -0.0 + 0.0 == +0.0
    return [
        f"{e.track_id} {e.class_name} {_LINE_NUMBERS % tuple(row)} {e.meas_index}"
        for e, row in zip(estimates, rounded.tolist(), strict=True)
    ]


def estimate_line(e: TrackEstimate) -> str:
    """The canonical text line of one estimate (see the module docstring)."""
    return _lines([e])[0]


def frame_digest(estimates: Sequence[TrackEstimate]) -> str:
    """SHA-256 (hex) of one frame's estimates: their lines sorted by track id, joined by newlines."""
    lines = _lines(sorted(estimates, key=lambda e: (e.track_id, e.class_name)))
    return hashlib.sha256("\n".join(lines).encode()).hexdigest()


class _Fields:
    """``to_json``: a frozen dataclass as JSON-ready data, field names as keys (nested dataclasses likewise)."""

    __slots__ = ()

    def to_json(self) -> dict[str, Any]:
        return dataclasses.asdict(self)  # type: ignore[call-overload]


@dataclass(frozen=True, slots=True)
class TrackDigest(_Fields):
    """Digest of one tracker's output: ``frames`` (F,) per-frame digests of the keyframes ``frame_indices``,
    ``overall`` over all of them."""

    overall: str
    frame_indices: tuple[int, ...]
    frames: tuple[str, ...]

    def first_difference(self, other: TrackDigest) -> int | None:
        """Keyframe index of the first frame whose digest differs from ``other`` (frames present in only one
        count as different); None if the outputs are identical."""
        if self.overall == other.overall and self.frame_indices == other.frame_indices:
            return None
        mine = dict(zip(self.frame_indices, self.frames, strict=True))
        theirs = dict(zip(other.frame_indices, other.frames, strict=True))
        for index in sorted(set(mine) | set(theirs)):
            if mine.get(index) != theirs.get(index):
                return index
        return None

    def differing_frames(self, other: TrackDigest) -> int:
        """Number of keyframes whose digests differ (or that only one of the two has)."""
        mine = dict(zip(self.frame_indices, self.frames, strict=True))
        theirs = dict(zip(other.frame_indices, other.frames, strict=True))
        return sum(mine.get(i) != theirs.get(i) for i in set(mine) | set(theirs))

    @staticmethod
    def from_json(data: Mapping[str, Any]) -> TrackDigest:
        return TrackDigest(
            str(data["overall"]),
            tuple(int(i) for i in data["frame_indices"]),
            tuple(map(str, data["frames"])),
        )


def track_digest(frame_indices: Sequence[int], frames: Sequence[Sequence[TrackEstimate]]) -> TrackDigest:
    """The digest of a tracker's estimates ``frames`` at keyframes ``frame_indices`` (see the module
    docstring)."""
    if len(frame_indices) != len(frames):
        raise ValueError(f"got {len(frame_indices)} frame indices for {len(frames)} frames of estimates")
    per_frame = tuple(frame_digest(f) for f in frames)
    indices = tuple(int(i) for i in frame_indices)
    text = "\n".join(f"{i} {d}" for i, d in zip(indices, per_frame, strict=True))
    return TrackDigest(hashlib.sha256(text.encode()).hexdigest(), indices, per_frame)


@dataclass(frozen=True, slots=True)
class DetectionsSource(_Fields):
    """Where the detections came from: ``kind`` "file" (``path``) or "simulated" (``preset``, ``seed``), and
    the SHA-256 of the file bytes or of the generated boxes."""

    kind: str
    sha256: str
    path: str | None = None
    preset: str | None = None
    seed: int | None = None

    def __post_init__(self) -> None:
        if self.kind not in ("file", "simulated"):
            raise ValueError(f"unknown detections kind {self.kind!r}")

    def describe(self) -> str:
        if self.kind == "file":
            return f"file {self.path} (sha256 {self.sha256[:12]})"
        return f"simulated {self.preset} detector, seed {self.seed} (sha256 {self.sha256[:12]})"

    @staticmethod
    def from_json(data: Mapping[str, Any]) -> DetectionsSource:
        seed = data.get("seed")
        return DetectionsSource(
            str(data["kind"]),
            str(data["sha256"]),
            data.get("path"),
            data.get("preset"),
            None if seed is None else int(seed),
        )


@dataclass(frozen=True, slots=True)
class Provenance(_Fields):
    """Everything a recording was made from (see the module docstring). frame_start/frame_end: the keyframes
    ``range(frame_start, frame_end)``; config: ``TrackerConfig.as_dict()``; track_digests: tracker ->
    digest."""

    argv: tuple[str, ...]
    versions: dict[str, str]
    config: dict[str, Any]
    dataroot: str
    version: str
    synthetic: bool
    scene_name: str
    scene_token: str
    detections: DetectionsSource
    seed: int
    frame_start: int
    frame_end: int
    classes: tuple[str, ...]
    trackers: tuple[str, ...]
    track_digests: dict[str, TrackDigest] = field(default_factory=dict)
    format_version: int = FORMAT_VERSION

    @property
    def frame_range(self) -> range:
        return range(self.frame_start, self.frame_end)

    @property
    def data_source(self) -> str:
        """ "synthetic demo" or "nuScenes <version>"."""
        return "synthetic demo" if self.synthetic else f"nuScenes {self.version}"

    def dumps(self) -> str:
        """Canonical JSON text (sorted keys, no spaces)."""
        return json.dumps(self.to_json(), sort_keys=True, separators=(",", ":"))

    @staticmethod
    def from_json(data: Mapping[str, Any]) -> Provenance:
        """Parse ``to_json`` output; a DataError names what is missing or malformed."""
        if not isinstance(data, Mapping):
            raise DataError("the stored provenance is not a JSON object")
        version = data.get("format_version")
        if version != FORMAT_VERSION:
            raise DataError(
                f"the stored provenance has format version {version}; this gnnpmb-viz reads version "
                f"{FORMAT_VERSION} (re-record with this version)"
            )
        try:
            return Provenance(
                argv=tuple(map(str, data["argv"])),
                versions={str(k): str(v) for k, v in data["versions"].items()},
                config=dict(data["config"]),
                dataroot=str(data["dataroot"]),
                version=str(data["version"]),
                synthetic=bool(data["synthetic"]),
                scene_name=str(data["scene_name"]),
                scene_token=str(data["scene_token"]),
                detections=DetectionsSource.from_json(data["detections"]),
                seed=int(data["seed"]),
                frame_start=int(data["frame_start"]),
                frame_end=int(data["frame_end"]),
                classes=tuple(map(str, data["classes"])),
                trackers=tuple(map(str, data["trackers"])),
                track_digests={str(k): TrackDigest.from_json(v) for k, v in data["track_digests"].items()},
            )
        except (KeyError, TypeError, ValueError, AttributeError) as exc:
            raise DataError(f"the stored provenance is malformed ({type(exc).__name__}: {exc})") from None

    @staticmethod
    def loads(text: str) -> Provenance:
        try:
            data = json.loads(text)
        except json.JSONDecodeError as exc:
            raise DataError(f"the stored provenance is not valid JSON ({exc})") from None
        return Provenance.from_json(data)


def tables_fingerprint(location: DatasetLocation) -> list[list[Any]]:
    """The identity of every table file (``gnnpmb.data.file_identity``: size, times, inode, a digest of its first
    and last blocks): cheap even for trainval, and changes whenever a table is written, even in place."""
    from gnnpmb.data.file_identity import file_identity

    folder = location.dataroot / location.version
    return [[p.name, *file_identity(p)[1:]] for p in sorted(folder.glob("*.json"))]


_SCORING_STUDY_FILES = frozenset({"study/data.py", "study/evaluate.py"})


def code_version() -> str:
    """SHA-256 of the ``gnnpmb`` package's source files and the versions of the packages that score the runs,
    so a change of tracker code or of the evaluation invalidates cached results. Of ``gnnpmb/study`` only the
    files that produce scores count (editing plots or the runner keeps the cache)."""
    import gnnpmb

    root = Path(gnnpmb.__file__).parent
    digest = hashlib.sha256()
    for path in sorted(root.rglob("*")):
        relative = path.relative_to(root).as_posix()
        if relative.startswith("study/") and relative not in _SCORING_STUDY_FILES:
            continue
        if path.suffix in (".py", ".toml") and path.is_file():
            digest.update(str(path.relative_to(root)).encode() + b"\0" + path.read_bytes() + b"\0")
    digest.update(json.dumps(package_versions(("nuscenes-devkit", "motmetrics", "numpy")), sort_keys=True).encode())
    return digest.hexdigest()


def digest_report(recorded: dict[str, TrackDigest], now: dict[str, TrackDigest]) -> tuple[list[str], bool]:
    """One line per tracker ("identical" or its first differing keyframe) and whether all are identical."""
    lines, same = [], True
    for tracker, digest in now.items():
        before = recorded.get(tracker)
        if before is None:
            lines.append(f"{tracker}: no recorded track digest to compare with")
            same = False
            continue
        first = before.first_difference(digest)
        if first is None:
            lines.append(f"{tracker}: identical ({len(digest.frames)} frames)")
        else:
            lines.append(
                f"{tracker}: DIFFERENT from keyframe {first} on "
                f"({before.differing_frames(digest)} of {len(digest.frames)} frames differ)"
            )
            same = False
    return lines, same


def version_notes(recorded: dict[str, str]) -> list[str]:
    """A note for each package whose version differs from the recorded one, and one when the ``gnnpmb`` source
    files differ (``SOURCE_KEY``), whatever the version says."""
    packages = {k: v for k, v in recorded.items() if k != SOURCE_KEY}
    now = package_versions(tuple(packages))
    notes = [f"note: recorded with {k} {v}, now {now[k]}" for k, v in packages.items() if now.get(k) != v]
    if code_differs(recorded):
        notes.append(
            f"note: recorded with other gnnpmb code (source digest {recorded[SOURCE_KEY]}, now {source_digest()}): "
            "tracks may differ because the code differs"
        )
    return notes
