"""The multi-class tracker: its per-class filters are made at the first step, where its names are checked, and
kept for the steps after it."""

from __future__ import annotations

import pytest

from gnnpmb.config import TrackerConfig
from gnnpmb.data.preprocess import preprocess
from gnnpmb.errors import UnknownNameError
from gnnpmb.events import ListSink, MeasurementsReceived
from gnnpmb.tracker import MultiClassTracker
from gnnpmb.types import Boxes

CONFIG = TrackerConfig()


def _empty_frame(classes: tuple[str, ...]):
    return preprocess(Boxes.empty(), CONFIG.preprocess, classes)


def test_the_filters_are_made_at_the_first_step_and_kept():
    mot = MultiClassTracker("gnnpmb", CONFIG, ("car", "pedestrian"))
    assert mot.trackers == {}
    sink = ListSink()
    assert mot.step(_empty_frame(mot.classes), 0.0, sink) == []
    made = dict(mot.trackers)
    assert list(made) == ["car", "pedestrian"]
    assert [e.class_name for e in sink.events if isinstance(e, MeasurementsReceived)] == ["car", "pedestrian"]
    mot.step(_empty_frame(mot.classes), 0.5, sink)
    assert all(mot.trackers[c] is made[c] for c in made)
    assert all(t.ids is mot.ids for t in made.values())  # one id space


@pytest.mark.parametrize(
    ("name", "classes", "message"),
    [("gnnpmbb", ("car",), "unknown tracker 'gnnpmbb'"), ("gnnpmb", ("car", "tram"), "unknown class 'tram'")],
)
def test_a_wrong_name_is_refused_at_the_first_step(name, classes, message):
    mot = MultiClassTracker(name, CONFIG, classes)
    with pytest.raises(UnknownNameError, match=message):
        mot.step(_empty_frame(("car",)), 0.0, ListSink())
