import dataclasses

import numpy as np
import pytest

from gnnpmb.types import TRACKING_CLASSES, Boxes, FrameDetections, Measurements


def random_boxes(rng: np.random.Generator, n: int) -> Boxes:
    """``n`` cars with random numbers in [0, 1) and no instance ids."""
    return Boxes(
        translation_m=rng.random((n, 3)),
        size_wlh_m=rng.random((n, 3)),
        quat_wxyz=rng.random((n, 4)),
        velocity_mps=rng.random((n, 2)),
        score=rng.random(n),
        class_name=np.array(["car"] * n, dtype=object),
        instance_id=np.array([""] * n, dtype=object),
    )


def frame(rng: np.random.Generator, n: int) -> FrameDetections:
    names = np.array([*TRACKING_CLASSES, "barrier"], dtype=object)
    boxes = dataclasses.replace(
        random_boxes(rng, n),
        class_name=rng.choice(names, size=n),
        instance_id=np.array([f"i{i}" for i in range(n)], dtype=object),
    )
    kept = rng.random(n) < 0.7
    return FrameDetections(boxes=boxes, kept=kept, below_threshold=~kept, suppressed_by_nms=np.zeros(n, bool))


def assert_same(a: Measurements, b: Measurements) -> None:
    for x, y in [(a.source_index, b.source_index)] + [
        (getattr(a.boxes, f), getattr(b.boxes, f)) for f in Boxes.__dataclass_fields__
    ]:
        assert x.dtype == y.dtype and x.shape == y.shape
        np.testing.assert_array_equal(x, y)


@pytest.mark.parametrize("n", [0, 1, 5, 60])
def test_measurements_by_class_equals_measurements_per_class(n):
    rng = np.random.default_rng(n)
    det = frame(rng, n)
    classes = [*TRACKING_CLASSES, "barrier", "not-a-class"]
    grouped = det.measurements_by_class(classes)
    assert list(grouped) == classes
    for c in classes:
        assert_same(grouped[c], det.measurements(c))
        assert not np.shares_memory(grouped[c].boxes.translation_m, det.boxes.translation_m)
    assert sum(len(grouped[c]) for c in classes) == int(det.kept.sum())
