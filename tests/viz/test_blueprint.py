from __future__ import annotations

from pathlib import Path

import pytest
import rerun.blueprint as rrb
from rerun.chunk import RrdReader

from viz import paths
from viz.blueprint import default_blueprint
from viz.recording import close_recording, open_recording


def views(node) -> list:
    """Every view in a blueprint (depth first)."""
    if isinstance(node, rrb.Blueprint):
        return views(node.root_container)
    if hasattr(node, "class_identifier"):
        return [node]
    return [v for child in node.contents for v in views(child)]


def test_one_3d_view_per_tracker_showing_only_its_own_tracks() -> None:
    all_views = views(default_blueprint(["gnnpmb", "pmbm"], ["car", "bus"]))
    spatial = [v for v in all_views if isinstance(v, rrb.Spatial3DView)]
    assert [v.name for v in spatial] == ["gnnpmb 3D", "pmbm 3D"]
    for v, name in zip(spatial, ["gnnpmb", "pmbm"], strict=True):
        assert v.origin == paths.WORLD
        assert v.contents == ["+ world/**", "- world/trackers/**", f"+ world/trackers/{name}/**"]


def test_cost_existence_and_log_views_per_tracker() -> None:
    all_views = views(default_blueprint(["gnnpmb", "pmbm"], ["car", "bus"]))
    origins = {(type(v).__name__, v.origin) for v in all_views}
    for t in ["gnnpmb", "pmbm"]:
        for c in ["car", "bus"]:
            assert ("TensorView", paths.cost_matrix(t, c)) in origins
            assert ("TextDocumentView", paths.cost_axes(t, c)) in origins
        assert ("TimeSeriesView", paths.existence_root(t)) in origins
        assert ("TextLogView", paths.events_root(t)) in origins
    assert ("TimeSeriesView", paths.hypotheses_root("pmbm")) in origins
    assert ("TimeSeriesView", paths.hypotheses_root("gnnpmb")) not in origins


def test_tracker_specific_views() -> None:
    origins = {v.origin for v in views(default_blueprint(["topmb", "cphd"], ["car"]))}
    assert paths.marginals("topmb", "car") in origins
    assert {paths.cardinality_pmf_root("cphd"), paths.cardinality_mean_root("cphd")} <= origins
    assert {paths.intensity_total_root("cphd"), paths.intensity_weights_root("cphd")} <= origins
    with pytest.raises(ValueError, match="at least one tracker"):
        default_blueprint([], ["car"])


def test_blueprint_is_accepted_in_strict_mode_and_saved(tmp_path: Path, strict: None) -> None:
    out = tmp_path / "bp.rrd"
    stream = open_recording("bp", out, default_blueprint(["gnnpmb", "jpda", "phd"], ["car"]), strict=True)
    close_recording(stream, out)
    assert len(RrdReader(out).blueprints()) == 1
