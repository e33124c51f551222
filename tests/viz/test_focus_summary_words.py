"""Words of the focus summary (``viz.focus_summary``) from hand-made facts."""

from __future__ import annotations

from types import SimpleNamespace

from gnnpmb.events import AxisKind, AxisLabel, CostScale
from gnnpmb.explain import PairChoice
from gnnpmb.focus import FocusTarget
from gnnpmb.why.facts import Destination, UseMode, Went
from viz.focus_summary import _parting


def _view(went: Destination, choice: PairChoice | None) -> SimpleNamespace:
    use = SimpleNamespace(destinations={0: went}, mode=UseMode.ASSIGNED)
    decided = SimpleNamespace(conflicts=[SimpleNamespace(choices=[choice])] if choice is not None else [])
    facts = SimpleNamespace(use=lambda f, c: use, decisions=lambda f, c: decided)
    return SimpleNamespace(facts=facts)


def test_where_trackers_part_a_new_track_column_holding_the_threshold_is_said_as_the_threshold() -> None:
    # viewer review, demo scene-0103 pointpillars ab3dmot: a box tracker's new-track column holds its IoU
    # threshold; "next new 3D IoU 0.10" read as a new track's IoU
    iou = CostScale("1 - IoU (3D)", "", 0.05, threshold=0.9, similarity="3D IoU")
    m0, t210, new = AxisLabel(AxisKind.MEASUREMENT, 0), AxisLabel(AxisKind.TRACK, 210), AxisLabel(AxisKind.NEW_TRACK, 0)
    views = {
        "ab3dmot": _view(Destination(0, Went.TRACK, 210, 1.0), PairChoice(m0, t210, 0.7, new, 0.9, 0.2, scale=iou)),
        "pmbm": _view(Destination(0, Went.NEW_TRACK, 17, 1.0), None),
    }
    focus = FocusTarget("t", 3, (0.0, 0.0), "car", {"ab3dmot": (210,), "pmbm": (17,)}, ())
    (line,) = _parting(focus, views)
    assert "ab3dmot: m0 → **track 210** (3D IoU 0.30; next a new track, the 3D IoU threshold 0.10)" in line
