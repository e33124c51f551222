"""Provenance: the documented track digest, content hashes and the JSON round trip."""

from __future__ import annotations

import dataclasses
import hashlib
import json
import re
from pathlib import Path

import numpy as np
import pytest

from gnnpmb.config import TrackerConfig
from gnnpmb.errors import DataError
from gnnpmb.provenance import (
    FORMAT_VERSION,
    PACKAGES,
    DetectionsSource,
    Provenance,
    boxes_sha256,
    estimate_line,
    file_sha256,
    frame_digest,
    package_versions,
    track_digest,
)
from gnnpmb.types import Boxes, TrackEstimate


def est(track_id: int, x: float = 1.0, **changes) -> TrackEstimate:
    e = TrackEstimate(
        track_id, "car", (x, -2.5, 0.75), (1.9, 4.6, 1.5), (0.5, 0.0, 0.0, -0.5), (3.0, 0.0), 0.8, 0.95, 7
    )
    return dataclasses.replace(e, **changes)


def sha(text: str) -> str:
    return hashlib.sha256(text.encode()).hexdigest()


def test_estimate_line_is_the_documented_format() -> None:
    assert estimate_line(est(12, x=1.23456789, velocity_mps=(-0.00001, 3.0))) == (
        "12 car 1.2346 -2.5000 0.7500 1.9000 4.6000 1.5000 0.500000 0.000000 0.000000 -0.500000 "
        "0.0000 3.0000 0.800000 0.950000 7"
    )


def test_frame_digest_is_order_free_and_ignores_noise_below_the_rounding() -> None:
    a, b = est(3), est(1, x=5.0)
    assert frame_digest([a, b]) == frame_digest([b, a]) == sha(f"{estimate_line(b)}\n{estimate_line(a)}")
    assert frame_digest([]) == sha("")
    assert frame_digest([est(3, x=1.0 + 1e-7)]) == frame_digest([a])
    assert frame_digest([est(3, x=1.001)]) != frame_digest([a])
    assert frame_digest([est(3, existence=0.96)]) != frame_digest([a])
    assert frame_digest([est(4)]) != frame_digest([a])


def test_track_digest_over_frames_and_first_difference() -> None:
    frames = [[est(1)], [], [est(1, x=2.0), est(2)]]
    digest = track_digest([5, 6, 7], frames)
    per_frame = [frame_digest(f) for f in frames]
    assert digest.frames == tuple(per_frame)
    assert digest.overall == sha("\n".join(f"{i} {d}" for i, d in zip([5, 6, 7], per_frame, strict=True)))
    assert digest.first_difference(track_digest([5, 6, 7], frames)) is None
    changed = track_digest([5, 6, 7], [[est(1)], [est(9)], [est(1, x=2.0)]])
    assert digest.first_difference(changed) == 6 and digest.differing_frames(changed) == 2
    shifted = track_digest([6, 7, 8], frames)
    assert shifted.overall != digest.overall and digest.first_difference(shifted) == 5
    with pytest.raises(ValueError, match="2 frame indices for 3 frames"):
        track_digest([0, 1], frames)


def boxes(xs: list[float]) -> Boxes:
    n = len(xs)
    return Boxes(
        translation_m=np.array([[x, 0.0, 0.0] for x in xs]).reshape(n, 3),
        size_wlh_m=np.ones((n, 3)),
        quat_wxyz=np.tile([1.0, 0.0, 0.0, 0.0], (n, 1)),
        velocity_mps=np.zeros((n, 2)),
        score=np.full(n, 0.5),
        class_name=np.array(["car"] * n, dtype=object),
        instance_id=np.array([""] * n, dtype=object),
    )


def test_hashes_of_detections() -> None:
    dets = {"s1": boxes([1.0, 2.0]), "s2": boxes([])}
    h = boxes_sha256(dets, ["s1", "s2"])
    assert h == boxes_sha256({"s2": boxes([]), "s1": boxes([1.0, 2.0])}, ["s1", "s2"])
    assert h == boxes_sha256({"s1": boxes([1.0, 2.0])}, ["s1", "s2"])  # a missing sample counts as empty
    assert h != boxes_sha256(dets, ["s2", "s1"])
    assert h != boxes_sha256({"s1": boxes([1.0, 2.0 + 1e-9]), "s2": boxes([])}, ["s1", "s2"])
    moved = dataclasses.replace(dets["s1"], class_name=np.array(["car", "bus"], dtype=object))
    assert h != boxes_sha256({"s1": moved, "s2": boxes([])}, ["s1", "s2"])


def test_file_hash(tmp_path: Path) -> None:
    path = tmp_path / "dets.json"
    data = bytes(range(256)) * 9000  # more than one 1 MiB block
    path.write_bytes(data)
    assert file_sha256(path) == hashlib.sha256(data).hexdigest()


def test_package_versions() -> None:
    versions = package_versions()
    assert tuple(versions) == PACKAGES
    assert versions["rerun-sdk"].startswith("0.41") and versions["numpy"][0] == "2"
    assert package_versions(("no-such-distribution-xyz",)) == {"no-such-distribution-xyz": "not installed"}


def provenance() -> Provenance:
    return Provenance(
        argv=("gnnpmb-viz", "scene-0103", "--tracker", "gnnpmb", "--frames", "2:6"),
        versions=package_versions(),
        config=TrackerConfig().as_dict(),
        dataroot="/data/nuscenes",
        version="v1.0-mini",
        synthetic=False,
        scene_name="scene-0103",
        scene_token="tok",
        detections=DetectionsSource("simulated", "ab" * 32, preset="centerpoint", seed=3),
        seed=3,
        frame_start=2,
        frame_end=6,
        classes=("car", "bus"),
        trackers=("gnnpmb",),
        track_digests={"gnnpmb": track_digest([2, 3, 4, 5], [[est(1)], [], [], [est(2)]])},
    )


def test_json_round_trip() -> None:
    p = provenance()
    text = p.dumps()
    assert Provenance.loads(text) == p
    assert json.loads(text)["format_version"] == FORMAT_VERSION
    assert p.frame_range == range(2, 6) and p.data_source == "nuScenes v1.0-mini"
    assert dataclasses.replace(p, synthetic=True).data_source == "synthetic demo"
    file_source = DetectionsSource("file", "cd" * 32, path="/x/dets.json")
    assert DetectionsSource.from_json(json.loads(json.dumps(file_source.to_json()))) == file_source
    assert file_source.describe() == "file /x/dets.json (sha256 cdcdcdcdcdcd)"
    assert p.detections.describe() == "simulated centerpoint detector, seed 3 (sha256 abababababab)"


def test_malformed_provenance_is_a_one_line_data_error() -> None:
    data = provenance().to_json()
    for broken, message in [
        ({**data, "format_version": 99}, "format version 99"),
        ({k: v for k, v in data.items() if k != "scene_token"}, "malformed (KeyError: 'scene_token')"),
        ({**data, "frame_start": "two"}, "malformed (ValueError"),
        ({**data, "detections": {**data["detections"], "kind": "camera"}}, "unknown detections kind"),
        ([1, 2], "not a JSON object"),
    ]:
        with pytest.raises(DataError, match=re.escape(message)) as info:
            Provenance.from_json(broken)
        assert "\n" not in str(info.value)
    with pytest.raises(DataError, match="not valid JSON"):
        Provenance.loads("{")
