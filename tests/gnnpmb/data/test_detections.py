import json
import math
import os

import numpy as np
import pytest

from gnnpmb.data.detections import load_detection_file, untracked_detection_boxes, write_detection_file
from gnnpmb.errors import DataError


def box(token: str, name: str = "car", score: float = 0.8, x: float = 1.0) -> dict:
    return {
        "sample_token": token,
        "translation": [x, 2.0, 0.9],
        "size": [1.9, 4.5, 1.6],
        "rotation": [math.cos(0.2), 0.0, 0.0, math.sin(0.2)],
        "velocity": [3.0, -1.0],
        "detection_name": name,
        "detection_score": score,
        "attribute_name": "vehicle.moving",
    }


def submission(results: dict) -> dict:
    return {"meta": {"use_camera": False, "use_lidar": True}, "results": results}


@pytest.fixture
def det_file(tmp_path):
    results = {
        "s0": [box("s0"), box("s0", "barrier", 0.9), box("s0", "pedestrian", 0.3, x=5.0)],
        "s1": [],
        "s2": [box("s2", "traffic_cone"), box("s2", "construction_vehicle"), box("s2", "truck", 0.1)],
        "other": [box("other", "bus")],
    }
    path = tmp_path / "dets.json"
    write_detection_file(path, submission(results))
    return path


def test_loads_requested_samples_and_tracking_classes(det_file):
    out = load_detection_file(det_file, ["s2", "s0", "s1"])
    assert list(out) == ["s2", "s0", "s1"]
    s0 = out["s0"]
    assert list(s0.class_name) == ["car", "pedestrian"]
    np.testing.assert_allclose(s0.translation_m, [[1.0, 2.0, 0.9], [5.0, 2.0, 0.9]])
    np.testing.assert_allclose(s0.size_wlh_m[0], [1.9, 4.5, 1.6])
    np.testing.assert_allclose(s0.quat_wxyz[0], [math.cos(0.2), 0, 0, math.sin(0.2)])
    np.testing.assert_allclose(s0.velocity_mps[0], [3.0, -1.0])
    np.testing.assert_allclose(s0.score, [0.8, 0.3])
    assert list(s0.instance_id) == ["", ""]
    assert len(out["s1"]) == 0 and out["s1"].translation_m.shape == (0, 3)
    assert list(out["s2"].class_name) == ["truck"]


def test_the_index_keeps_the_boxes_of_untracked_names_aside(det_file, tmp_path, monkeypatch):
    """The tracking loader drops barrier, traffic_cone and construction_vehicle boxes; the explanations name them
    (a car seen only as a construction_vehicle was seen). They come from the index, read once per file whatever its
    size (the explainer re-read files of at most 100 MB and said nothing of larger ones: full-split files are
    300-700 MB)."""
    monkeypatch.setenv("GNNPMB_CACHE_DIR", str(tmp_path / "cache"))
    got = untracked_detection_boxes(det_file, ["s2", "s0", "s1"])
    assert got == {
        "s0": (("barrier", 0.9, 1.0, 2.0),),
        "s2": (("traffic_cone", 0.8, 1.0, 2.0), ("construction_vehicle", 0.8, 1.0, 2.0)),
    }
    (side,) = (tmp_path / "cache" / "index").glob("detections-*/untracked.arrow")
    raw = bytearray(side.read_bytes())
    raw[300] ^= 0xFF  # damaged after it was built: rebuilt, the same boxes
    side.write_bytes(bytes(raw))
    assert untracked_detection_boxes(det_file, ["s0", "s2"]) == got


def test_indexed_once_and_again_when_rewritten(det_file, tmp_path, monkeypatch):
    from gnnpmb.data import detection_index, detections

    monkeypatch.setenv("GNNPMB_CACHE_DIR", str(tmp_path / "cache"))
    builds = []
    build = detection_index._build
    monkeypatch.setattr(detection_index, "_build", lambda *a: builds.append(1) or build(*a))
    first = load_detection_file(det_file, ["s0"])
    detections._opened.clear()  # a new process: the index on disk is reused
    again = load_detection_file(det_file, ["s0", "s1"])
    assert len(builds) == 1 and np.array_equal(again["s0"].translation_m, first["s0"].translation_m)
    write_detection_file(det_file, submission({"s0": [box("s0", "bicycle", 0.5)]}))
    fresh = load_detection_file(det_file, ["s0"])
    assert list(fresh["s0"].class_name) == ["bicycle"] and len(builds) == 2


def test_an_index_built_by_other_code_is_rebuilt(tmp_path, monkeypatch):
    """A problem's text (and every box) is derived into the index when it is built: an index left by an older
    version of the conversion code must not serve that version's wording or boxes."""
    from gnnpmb.data import detection_index, detections

    monkeypatch.setenv("GNNPMB_CACHE_DIR", str(tmp_path / "cache"))
    bad = box("s0")
    bad.pop("size")
    path = tmp_path / "bad.json"
    path.write_text(json.dumps(submission({"s0": [bad], "s1": [box("s1")]})))
    with monkeypatch.context() as old_code:
        old_code.setattr(detection_index, "code_identity", lambda *modules: ["code", "an older version"])
        old_code.setattr(detections, "convert_sample", lambda token, entries: "the older wording")
        with pytest.raises(DataError, match="the older wording"):
            load_detection_file(path, ["s0"])
    detections._opened.clear()  # a new process running the current code
    with pytest.raises(DataError, match="box 0 of sample s0 has no 'size' field"):
        load_detection_file(path, ["s0"])
    assert len(load_detection_file(path, ["s1"])["s1"]) == 1


def test_damaged_index_is_rebuilt(det_file, tmp_path, monkeypatch):
    from gnnpmb.data import detections

    monkeypatch.setenv("GNNPMB_CACHE_DIR", str(tmp_path / "cache"))
    expected = load_detection_file(det_file, ["s0", "s2"])
    (boxes,) = (tmp_path / "cache" / "index").glob("detections-*/boxes.arrow")
    raw = bytearray(boxes.read_bytes())
    raw[300] ^= 0xFF  # a flipped bit inside the first sample's values: the size still matches
    boxes.write_bytes(bytes(raw))
    got = load_detection_file(det_file, ["s0", "s2"])
    assert np.array_equal(got["s0"].translation_m, expected["s0"].translation_m)
    detections._opened.clear()
    boxes.write_bytes(bytes(raw[:-10]))  # truncated: not trusted when opened
    got = load_detection_file(det_file, ["s0"])
    assert np.array_equal(got["s0"].score, expected["s0"].score)


def test_missing_file(tmp_path):
    with pytest.raises(DataError, match="detections file not found"):
        load_detection_file(tmp_path / "nope.json", ["s0"])


def test_truncated_json_says_where(tmp_path):
    path = tmp_path / "cut.json"
    text = json.dumps(submission({"s0": [box("s0")] * 3}), indent=1)
    path.write_text(text[: len(text) // 2])
    with pytest.raises(DataError, match=r"not valid JSON: .* at line \d+, column \d+ .*truncated") as info:
        load_detection_file(path, ["s0"])
    assert "\n" not in str(info.value)


def test_not_a_submission(tmp_path):
    path = tmp_path / "x.json"
    path.write_text(json.dumps({"meta": {}}))
    with pytest.raises(DataError, match="no 'results' object"):
        load_detection_file(path, ["s0"])
    path.write_text(json.dumps({"results": [1, 2]}))
    with pytest.raises(DataError, match="not an object keyed by sample token"):
        load_detection_file(path, ["s0"])


@pytest.mark.parametrize(
    ("change", "message"),
    [
        (lambda b: b.pop("size"), "box 1 of sample s0 has no 'size' field"),
        (
            lambda b: b.update(rotation=[1.0, 0.0, 0.0]),
            "box 1 of sample s0 field 'rotation' must be a list of 4",
        ),
        (
            lambda b: b.update(translation=[1.0, float("inf"), 0.0]),
            "field 'translation' has a NaN or infinite",
        ),
        (lambda b: b.update(translation=[1.0, "a", 0.0]), "field 'translation' must be a list of 3 numbers"),
        (lambda b: b.pop("detection_score"), "box 1 of sample s0 has no 'detection_score' field"),
        (lambda b: b.update(detection_score=1.5), "'detection_score' must lie in \\[0, 1\\]"),
        (lambda b: b.update(detection_name="cat"), "detection_name 'cat', not a nuScenes detection class"),
        (lambda b: b.update(size=[1.9, -4.5, 1.6]), "field 'size' must be positive and at most 100 m"),
        (lambda b: b.update(size=[1.9, 0.0, 1.6]), "field 'size' must be positive"),
        (lambda b: b.update(size=[1.9, 4.5, 1e3]), "field 'size' must be positive and at most 100 m"),
        (lambda b: b.update(rotation=[0.0, 0.0, 0.0, 0.0]), "field 'rotation' is not a rotation"),
        (lambda b: b.update(translation=[1e308, 2.0, 0.9]), "field 'translation' is beyond 1e\\+05 m"),
        (lambda b: b.update(translation=[1.0, "2", 0.9]), "field 'translation' must hold numbers"),
        (lambda b: b.update(size=[1.9, None, 1.6]), "field 'size' must"),
        (lambda b: b.update(detection_score="0.8"), "field 'detection_score' must be a number, got '0.8'"),
        (lambda b: b.update(detection_score=True), "field 'detection_score' must be a number"),
        (lambda b: b.update(velocity=[1e308, 0.0]), "field 'velocity' is faster than 200 m/s"),
    ],
)
def test_malformed_box_names_sample_and_field(tmp_path, change, message):
    bad = box("s0")
    change(bad)
    path = tmp_path / "bad.json"
    path.write_text(json.dumps(submission({"s0": [box("s0"), bad], "s1": []})))
    with pytest.raises(DataError, match=message):
        load_detection_file(path, ["s1", "s0"])
    # A sample that is not requested may be malformed.
    assert len(load_detection_file(path, ["s1"])["s1"]) == 0


def test_nan_velocity_means_unknown_and_becomes_zero(tmp_path):
    path = tmp_path / "nan_velocity.json"
    raw = submission({"s0": [box("s0"), box("s0")]})
    raw["results"]["s0"][0]["velocity"] = [float("nan"), float("nan")]
    path.write_text(json.dumps(raw))
    boxes = load_detection_file(path, ["s0"])["s0"]
    assert boxes.velocity_mps[0].tolist() == [0.0, 0.0]
    assert np.isfinite(boxes.velocity_mps).all()


def test_sample_entry_not_a_list(tmp_path):
    path = tmp_path / "bad.json"
    path.write_text(json.dumps(submission({"s0": {"boxes": []}})))
    with pytest.raises(DataError, match="results entry of sample s0 is a dict, not a list of boxes"):
        load_detection_file(path, ["s0"])


def test_missing_samples_are_counted(det_file):
    tokens = ["s0", "x1", "x2", "s1"]
    with pytest.raises(DataError) as info:
        load_detection_file(det_file, tokens, scene_name="scene-0103")
    text = str(info.value)
    assert "no boxes entry for 2 of the 4 samples of scene-0103" in text
    assert "first missing: x1" in text and "another split or version" in text
    with pytest.raises(DataError, match="no boxes entry for 1 of the 1 requested samples"):
        load_detection_file(det_file, ["zzz"])


def test_write_is_atomic_and_leaves_no_temp_files(tmp_path):
    path = tmp_path / "sub" / "dets.json"
    write_detection_file(path, submission({"s0": [box("s0")]}))
    before = path.read_bytes()
    with pytest.raises(ValueError):
        write_detection_file(path, submission({"s0": [box("s0", score=float("nan"))]}))
    assert path.read_bytes() == before
    assert os.listdir(path.parent) == ["dets.json"]
    assert json.loads(before)["results"]["s0"][0]["detection_name"] == "car"
