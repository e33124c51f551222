from __future__ import annotations

from pathlib import Path

import pytest
import rerun.blueprint as rrb
from rerun.chunk import RrdReader

from gnnpmb.data.sensors import CAMERA_ORDER
from viz import compare, paths
from viz.blueprint import EYE_POSITION_M, EYE_TARGET_M, default_blueprint, failures_root
from viz.failures import failure_log
from viz.recording import close_recording, open_recording


def views(node) -> list:
    """Every view in a blueprint (depth first)."""
    if isinstance(node, rrb.Blueprint):
        return views(node.root_container)
    if hasattr(node, "class_identifier"):
        return [node]
    return [v for child in node.contents for v in views(child)]


def stored_views(path: Path) -> dict[str, tuple[str, str]]:
    """View name -> (class identifier, origin) of the default blueprint saved in an ``.rrd``."""
    reader = RrdReader(path)
    (blueprint,) = reader.blueprints()
    out = {}
    for chunk in reader.stream(store=blueprint):
        for row in chunk.to_record_batch().to_pylist():
            if row.get("ViewBlueprint:display_name"):
                out[row["ViewBlueprint:display_name"][0]] = (
                    row["ViewBlueprint:class_identifier"][0],
                    row["ViewBlueprint:space_origin"][0],
                )
    return out


def test_a_birds_eye_and_a_perspective_view_per_tracker_showing_only_its_own_tracks() -> None:
    all_views = views(default_blueprint(["gnnpmb", "pmbm"], ["car", "bus"]))
    spatial = [v for v in all_views if isinstance(v, rrb.Spatial3DView)]
    assert [v.name for v in spatial] == ["gnnpmb bird's-eye", "gnnpmb 3D", "pmbm bird's-eye", "pmbm 3D"]
    for v, name in zip(spatial, ["gnnpmb", "gnnpmb", "pmbm", "pmbm"], strict=True):
        assert v.origin == paths.EGO  # the camera follows the ego vehicle
        assert v.contents[:3] == ["+ world/**", "- world/trackers/**", f"+ world/trackers/{name}/**"]
        assert v.contents[3:] == [f"- world/ego_vehicle/{c}/**" for c in CAMERA_ORDER]  # the camera views show them


def hidden(view: rrb.Spatial3DView) -> set[str]:
    """Entities a view hides by default (one click away in its blueprint tree)."""
    return {p for p, behavior in view.visualizer_overrides.items() if "visible=[False]" in repr(behavior)}


def test_birds_eye_hides_lidar_candidates_and_suppressed_detections_by_default() -> None:
    bev, persp = [v for v in views(default_blueprint(["gnnpmb"], ["car"])) if isinstance(v, rrb.Spatial3DView)]
    assert hidden(bev) == {
        paths.LIDAR,
        paths.SWEEP_LIDAR,
        "world/trackers/gnnpmb/candidates",
        paths.DETECTIONS_SUPPRESSED,
    }
    assert hidden(persp) == {"world/trackers/gnnpmb/candidates", paths.DETECTIONS_SUPPRESSED}


def test_decision_story_existence_failure_and_log_views_per_tracker() -> None:
    all_views = views(default_blueprint(["gnnpmb", "pmbm"], ["car", "bus"]))
    origins = {(type(v).__name__, v.origin) for v in all_views}
    for t in ["gnnpmb", "pmbm"]:
        assert ("TextDocumentView", paths.decisions(t)) in origins
        assert ("Spatial2DView", paths.decision_matrix(t)) in origins
        assert ("TimeSeriesView", paths.existence_root(t)) in origins
        assert ("TimeSeriesView", paths.nis_root(t)) in origins
        assert ("TimeSeriesView", paths.chosen_cost_root(t)) in origins
        assert ("TimeSeriesView", paths.candidate_count.root(t)) in origins
        assert ("TimeSeriesView", failures_root(t)) in origins
        assert ("TextLogView", paths.events.root(t)) in origins
        assert ("TextLogView", failure_log(t)) in origins
    assert failures_root("pmbm") == paths.failure_count("pmbm", "miss").rsplit("/", 1)[0]
    assert ("TimeSeriesView", paths.hypothesis_weights.root("pmbm")) in origins
    assert ("TimeSeriesView", paths.hypothesis_weights.root("gnnpmb")) not in origins


def test_comparison_panel_only_with_several_trackers() -> None:
    def origins(trackers: list[str]) -> set[tuple[str, str]]:
        return {(type(v).__name__, v.origin) for v in views(default_blueprint(trackers, ["car"]))}

    several = origins(["gnnpmb", "jpda", "gnn"])
    assert ("TimeSeriesView", compare.counts_root()) in several
    assert ("TextLogView", compare.log_path()) in several
    single = origins(["gnnpmb"])
    assert ("TimeSeriesView", compare.counts_root()) not in single
    assert ("TextLogView", compare.log_path()) not in single
    assert ("Spatial3DView", paths.EGO) in single
    assert compare.markers_path(compare.DisagreementKind.ID_CHANGE, "jpda").startswith(paths.tracker_world("jpda"))


def test_tracker_specific_views() -> None:
    origins = {v.origin for v in views(default_blueprint(["topmb", "cphd"], ["car"]))}
    assert paths.marginals("topmb", "car") in origins
    assert {paths.cardinality_pmf.root("cphd"), paths.cardinality_mean.root("cphd")} <= origins
    assert {paths.intensity_total.root("cphd"), paths.intensity_weights.root("cphd")} <= origins
    with pytest.raises(ValueError, match="at least one tracker"):
        default_blueprint([], ["car"])


def test_blueprint_is_accepted_in_strict_mode_and_saved(tmp_path: Path, strict: None) -> None:
    out = tmp_path / "bp.rrd"
    stream = open_recording("bp", out, default_blueprint(["gnnpmb", "jpda", "phd"], ["car"]), strict=True)
    close_recording(stream, out)
    stored = stored_views(out)
    assert stored["gnnpmb 3D"] == ("3D", paths.EGO) and stored["phd bird's-eye"] == ("3D", paths.EGO)
    assert stored["disagreements"] == ("TextLog", compare.log_path())
    assert stored["disagreements per frame"] == ("TimeSeries", compare.counts_root())
    assert stored["jpda failures per frame"] == ("TimeSeries", failures_root("jpda"))
    eyes = [
        row
        for chunk in RrdReader(out).stream(store=RrdReader(out).blueprints()[0])
        for row in chunk.to_record_batch().to_pylist()
        if row.get("EyeControls3D:position")
    ]
    assert len(eyes) == 6
    assert [list(EYE_POSITION_M)] in [e["EyeControls3D:position"] for e in eyes]
    assert [list(EYE_TARGET_M)] in [e["EyeControls3D:look_target"] for e in eyes]
    panel = [
        row
        for chunk in RrdReader(out).stream(store=RrdReader(out).blueprints()[0])
        for row in chunk.to_record_batch().to_pylist()
        if row.get("TimePanelBlueprint:timeline")
    ]
    assert panel[0]["TimePanelBlueprint:timeline"] == ["frame"]  # paused: opens at the first frame


def test_the_viewer_names_no_tracker_and_lays_out_the_panels_each_declares() -> None:
    from pathlib import Path

    import viz.blueprint
    from gnnpmb.events import Panel
    from gnnpmb.registry import TRACKER_NAMES, tracker_panels

    source = Path(viz.blueprint.__file__).read_text()
    assert not [name for name in TRACKER_NAMES if f'"{name}"' in source]
    assert tracker_panels("cphd") == (Panel.CARDINALITY, Panel.INTENSITY)
    assert tracker_panels("pmbm") == (Panel.HYPOTHESES,) and tracker_panels("gnnpmb") == ()
    assert set(viz.blueprint.PANEL_VIEWS) == set(Panel)


def test_an_existence_plot_only_for_trackers_whose_tracks_have_an_existence_probability() -> None:
    from gnnpmb.registry import TRACKER_NAMES, tracker_has_existence

    without = {name for name in TRACKER_NAMES if not tracker_has_existence(name)}
    # track logic (a track exists or not) and the model-based baselines' hits and misses or track scores
    assert without == {"gnn", "jpda", "greedy", "ab3dmot", "prob3dmot", "simpletrack", "immortal", "cbmot"}
    origins = {v.origin for v in views(default_blueprint(["gnnpmb", "gnn"], ["car"]))}
    assert paths.existence_root("gnnpmb") in origins and paths.existence_root("gnn") not in origins
    assert paths.nis_root("gnn") in origins and paths.chosen_cost_root("gnn") in origins
    assert paths.candidate_count.root("gnnpmb") in origins and paths.candidate_count.root("gnn") not in origins


def test_no_innovation_plot_for_a_tracker_without_gates() -> None:
    from gnnpmb.registry import TRACKER_NAMES, tracker_has_gates

    # distances and box overlaps; prob3dmot's Mahalanobis distance is a Gaussian gate
    ungated = {"greedy", "cbmot", "ab3dmot", "simpletrack", "immortal"}
    assert {name for name in TRACKER_NAMES if not tracker_has_gates(name)} == ungated
    origins = {v.origin for v in views(default_blueprint(["gnn", "greedy"], ["car"]))}
    assert paths.nis_root("gnn") in origins and paths.nis_root("greedy") not in origins
    assert paths.chosen_cost_root("greedy") in origins


def test_in_a_focus_a_run_with_no_involved_track_plots_no_track(tmp_path: Path) -> None:
    """``--focus diff:introduced:1`` on the dev set's scene-0103: the failure is B's, A has no involved track, and
    A's existence plot held every track of the scene (40 lines); now only its class's threshold."""
    import rerun as rr

    from gnnpmb.focus import FocusTarget

    focus = FocusTarget("t", 5, (0.0, 0.0), "car", {"gnnpmb": (1,), "pmbm": ()}, ("abc",))
    path = tmp_path / "bp.rrd"
    stream = rr.RecordingStream("bp-test")
    stream.save(path, default_blueprint=default_blueprint(["gnnpmb", "pmbm"], ["car"], focus))
    stream.disconnect()
    reader = RrdReader(path)
    (blueprint,) = reader.blueprints()
    queries = [
        row["ViewContents:query"]
        for chunk in reader.stream(store=blueprint)
        for row in chunk.to_record_batch().to_pylist()
        if row.get("ViewContents:query") and "/existence/" in str(row["ViewContents:query"])
    ]
    assert sorted(queries) == [
        [f"+ {paths.existence_root('gnnpmb')}/car/1", f"+ {paths.existence_root('gnnpmb')}/car/threshold"],
        [f"+ {paths.existence_root('pmbm')}/car/threshold"],
    ]


@pytest.mark.parametrize(
    ("frame", "start", "end"),
    [(0, 0, 9), (3, 0, 6), (20, 12, 1)],  # (frame, absolute start, end relative to the time cursor)
)
def test_a_focus_plot_opens_nine_frames_wide_and_never_before_the_first_frame(frame: int, start: int, end: int) -> None:
    """A failure at frame 0 opened plots one frame wide whose x axis read "#0 #0 #0 ..." (dev set scene-0916
    centerpoint miss:2); later ones start where the recording does, 8 frames before, and end one frame past the
    time cursor, so a track started at the failure frame is not cut by the plot's edge."""
    from gnnpmb.focus import FocusTarget
    from viz.blueprint import track_series_views

    focus = FocusTarget("t", frame, (0.0, 0.0), "car", {"gnnpmb": (1,)}, ())
    for view in track_series_views("gnnpmb", focus):
        axis = view.properties["TimeAxis"].view_range.as_arrow_array()
        absolute, cursor_relative = 2, 1  # the union's type codes (Rerun's TimeRangeBoundary)
        assert axis.field("start").type_codes.to_pylist() == [absolute]
        assert axis.field("end").type_codes.to_pylist() == [cursor_relative]
        assert (axis.field("start").to_pylist(), axis.field("end").to_pylist()) == ([start], [end])


def test_a_focus_comparisons_plot_says_it_counts_every_class(tmp_path: Path) -> None:
    """With a focus the disagreement log opens on the focused class, the plot counts every class: its name says so
    (demo scene-9001 pmbm beside gnnpmb ``--focus coalescence:2``: "1" at the failure frame, a car track, beside an
    empty log of bicycles)."""
    from gnnpmb.focus import FocusTarget

    focus = FocusTarget("t", 19, (0.0, 0.0), "bicycle", {"pmbm": (1,), "gnnpmb": (2,)}, ("abc",))
    out = tmp_path / "bp.rrd"
    stream = open_recording("bp", out, default_blueprint(["pmbm", "gnnpmb"], ["bicycle", "car"], focus))
    close_recording(stream, out)
    stored = stored_views(out)
    assert stored["disagreements per frame (every class)"] == ("TimeSeries", compare.counts_root())
    assert stored["disagreements (bicycle)"] == ("TextLog", compare.focus_log_path())


def test_a_focus_with_no_disagreement_of_its_class_opens_the_whole_disagreement_log() -> None:
    """The runs disagreed about a car, not about the focused bicycles: the log of bicycles was an empty panel beside
    a plot counting 1 (demo scene-9001 pmbm beside gnnpmb ``--focus coalescence:2``). It opens on the whole log,
    which holds what the plot counts; with a disagreement of the class, on the class's."""
    from gnnpmb.focus import FocusTarget

    focus = FocusTarget("t", 19, (0.0, 0.0), "bicycle", {"pmbm": (1,), "gnnpmb": (2,)}, ("abc",))
    for quiet, name in ((True, "disagreements"), (False, "disagreements (bicycle)")):
        bp = default_blueprint(["pmbm", "gnnpmb"], ["bicycle", "car"], focus, focus_class_quiet=quiet)
        comparison = bp.root_container.contents[0].contents[1]  # the left column: the scene, the comparison
        (logs,) = [c for c in comparison.contents if isinstance(c, rrb.Tabs)][1:]
        assert logs.contents[logs.active_tab].name == name
