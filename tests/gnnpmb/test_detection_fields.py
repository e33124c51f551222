import dataclasses

import numpy as np
import pytest

from gnnpmb.detection_fields import DetectionFields
from gnnpmb.types import Measurements, TrackEstimate, track_estimates
from tests.gnnpmb.test_types import random_boxes


def fields(rng: np.random.Generator, k: int) -> DetectionFields:
    return DetectionFields(
        score=rng.random(k),
        z_m=rng.random(k),
        size_wlh_m=rng.random((k, 3)),
        quat_wxyz=rng.random((k, 4)),
        meas_index=rng.integers(0, 50, size=k),
    )


def measurements(rng: np.random.Generator, m: int) -> Measurements:
    return Measurements(random_boxes(rng, m), np.arange(10, 10 + m))


def test_to_estimates_copies_every_field_of_every_item():
    rng = np.random.default_rng(0)
    det = fields(rng, 3)
    track_id, mean, score, existence = np.array([4, 7, 9]), rng.random((3, 4)), rng.random(3), rng.random(3)
    estimates = det.to_estimates("car", track_id, mean, score, existence)
    expected = [
        TrackEstimate(
            track_id=int(track_id[i]),
            class_name="car",
            translation_m=(float(mean[i, 0]), float(mean[i, 1]), float(det.z_m[i])),
            size_wlh_m=tuple(float(v) for v in det.size_wlh_m[i]),
            quat_wxyz=tuple(float(v) for v in det.quat_wxyz[i]),
            velocity_mps=(float(mean[i, 2]), float(mean[i, 3])),
            score=float(score[i]),
            existence=float(existence[i]),
            meas_index=int(det.meas_index[i]),
        )
        for i in range(3)
    ]
    assert estimates == expected
    assert all(type(v) is float for e in estimates for v in (*e.translation_m, *e.size_wlh_m, e.score))
    assert DetectionFields.empty().to_estimates("car", np.zeros(0), np.zeros((0, 4)), np.zeros(0), np.zeros(0)) == []
    with pytest.raises(ValueError):
        det.to_estimates("car", track_id[:2], mean, score, existence)


def test_gather_with_takes_items_then_measurements():
    rng = np.random.default_rng(1)
    det, meas = fields(rng, 3), measurements(rng, 2)
    source = np.array([2, 3, 0, 4, 4])
    out = det.gather_with(meas, source)
    from_meas = DetectionFields.from_measurements(meas, np.array([0, 1, 1]))
    for name in ("score", "z_m", "size_wlh_m", "quat_wxyz", "meas_index"):
        own, theirs = getattr(det, name), getattr(from_meas, name)
        expected = np.concatenate([own[[2]], theirs[[0]], own[[0]], theirs[[1, 2]]])
        assert np.array_equal(getattr(out, name), expected), name
    assert out.meas_index.dtype == np.int64


def test_track_estimates_equal_the_constructor():
    rng = np.random.default_rng(2)
    rows = [
        (int(i), "car", tuple(rng.random(3).tolist()), (1.0, 2.0, 3.0), (1.0, 0.0, 0.0, 0.0), (0.5, -0.5), 0.9, 0.1, -1)
        for i in rng.integers(0, 100, size=5)
    ]
    built = track_estimates([list(c) for c in zip(*rows, strict=True)])
    assert built == [TrackEstimate(*row) for row in rows]
    assert all(type(e) is TrackEstimate for e in built)
    assert [dataclasses.astuple(e) for e in built] == [dataclasses.astuple(TrackEstimate(*row)) for row in rows]
    with pytest.raises(dataclasses.FrozenInstanceError):
        built[0].score = 0.0
    assert track_estimates([[]] * 9) == []
    with pytest.raises(ValueError):
        track_estimates([list(c) for c in zip(*rows, strict=True)][:8])
    with pytest.raises(ValueError):
        track_estimates([list(c)[: 4 if j == 3 else 5] for j, c in enumerate(zip(*rows, strict=True))])
