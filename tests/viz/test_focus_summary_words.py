"""Words of the focus summary (``viz.focus_summary``) from hand-made facts."""

from __future__ import annotations

from types import SimpleNamespace

from gnnpmb.events import AxisKind, AxisLabel, CostScale
from gnnpmb.explain import PairChoice
from gnnpmb.focus import FocusTarget
from gnnpmb.why.facts import Destination, UseMode, Went
from viz.focus_summary import _parting


def _view(went: Destination, choice: PairChoice | None, births: dict[int, tuple[int, int]] | None = None):
    """A tracker's view whose detection m0 went to ``went``; births: track id -> (frame, detection) that started it."""
    use = SimpleNamespace(destinations={0: went}, mode=UseMode.ASSIGNED)
    decided = SimpleNamespace(conflicts=[SimpleNamespace(choices=[choice])] if choice is not None else [])
    facts = SimpleNamespace(
        use=lambda f, c: use, decisions=lambda f, c: decided, origin=lambda t, c: (births or {}).get(t)
    )
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


def test_where_trackers_part_needs_another_place_not_another_track_number() -> None:
    # dev set scene-0655 megvii gnnpmb beside pmbm, coalescence:1: "gnnpmb: m11 → new track 104 · pmbm: m11 → new
    # track 231" and "m9 → track 104 · m9 → track 231" (both tracks started by m11 at frame 14) were listed as where
    # the trackers part: 61 of 63 lines; the runs only number their tracks differently
    focus = FocusTarget("t", 15, (0.0, 0.0), "pedestrian", {"gnnpmb": (104,), "pmbm": (231,)}, ())
    both_new = {
        "gnnpmb": _view(Destination(0, Went.NEW_TRACK, 104, 1.0), None),
        "pmbm": _view(Destination(0, Went.NEW_TRACK, 231, 1.0), None),
    }
    assert _parting(focus, both_new) == []
    same_birth = {
        "gnnpmb": _view(Destination(0, Went.TRACK, 104, 1.0), None, {104: (14, 11)}),
        "pmbm": _view(Destination(0, Went.TRACK, 231, 1.0), None, {231: (14, 11)}),
    }
    assert _parting(focus, same_birth) == []
    other_birth = {
        "gnnpmb": _view(Destination(0, Went.TRACK, 104, 1.0), None, {104: (14, 11)}),
        "pmbm": _view(Destination(0, Went.TRACK, 231, 1.0), None, {231: (12, 10)}),
    }
    (line,) = _parting(focus, other_birth)
    assert line == "gnnpmb: m0 → **track 104** · pmbm: m0 → **track 231**"
    other_kind = {
        "gnnpmb": _view(Destination(0, Went.NEW_TRACK, 104, 1.0), None),
        "pmbm": _view(Destination(0, Went.TRACK, 231, 1.0), None, {231: (12, 10)}),
    }
    (line,) = _parting(focus, other_kind)
    assert line == "gnnpmb: m0 → **new track 104** · pmbm: m0 → **track 231**"
