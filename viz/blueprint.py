"""The default viewer layout, built in code.

Per tracker a bird's-eye view (top-down, following the ego car, no LiDAR by default) and a perspective 3D view,
each showing the shared scene (ground truth, detections, comparison markers) and only that tracker's entities:
its tracks (one entity per track, with trails), association lines, gates and failure markers; candidate
Bernoullis and suppressed detections are hidden by default (one click in the blueprint tree brings them back).
Beside them the tracker's panel: the decision view (why each detection went where it did: a document and a
labelled cost grid), the story log (INFO and up by default), per-track series and tracker-specific plots.

Several trackers: their views side by side above the comparison panel; their panels as tabs on the right.

A *focus* layout (``gnnpmb.focus.FocusTarget``, ``gnnpmb-viz --focus``) opens at the failure: the time panel
uses the ``focus`` timeline, which ends at the failure frame, so the viewer (following the newest data) shows
that frame on opening (the ``frame`` timeline still holds the frames after it); the cameras look at the place
from above and from the side, and the series views show only the involved tracks.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from typing import TYPE_CHECKING

import rerun as rr
import rerun.blueprint as rrb

from gnnpmb.data.sensors import CAMERA_ORDER
from gnnpmb.events import Panel
from gnnpmb.runs import Capabilities, tracker_capabilities
from gnnpmb.why.findings import FRAMES_BEFORE
from viz import compare, paths
from viz.callouts import COMPARED_CAMERA_HEIGHTS_PX, FOCUS_ROW_SHARES, FOCUS_VIEW_WIDTH_PX
from viz.cameras import with_cameras
from viz.failures import failure_log
from viz.label_room import BEV_EYE_POSITION_M, BEV_TARGET_M, BEV_UP, EYE_POSITION_M, EYE_TARGET_M
from viz.legend import FOCUS_PAST_FRAMES, LegendPlacement

if TYPE_CHECKING:
    from gnnpmb.focus import FocusTarget

FOCUS_HEIGHT_M: dict[str, float] = {"pedestrian": 16.0, "bicycle": 18.0, "motorcycle": 18.0, "car": 28.0}
"""Height of the bird's-eye camera above a focused place by class (small objects closer)."""
DEFAULT_FOCUS_HEIGHT_M = 40.0
"""The same for the other classes."""


def focus_eye_height_m(class_name: str, runs: int, camera: bool) -> float:
    """Height of a focus bird's-eye view's eye above the focused place: the class's (``FOCUS_HEIGHT_M``), raised in
    a view taller than wide (runs side by side, ``viz.callouts.COMPARED_CAMERA_HEIGHTS_PX``) so that its width
    shows ``NARROW_VIEW_WIDTH`` times the metres the class's height shows up and down."""
    tall_px = COMPARED_CAMERA_HEIGHTS_PX[runs > 1, camera]
    wide_px = FOCUS_VIEW_WIDTH_PX / max(runs, 1)
    return FOCUS_HEIGHT_M.get(class_name, DEFAULT_FOCUS_HEIGHT_M) * max(1.0, NARROW_VIEW_WIDTH * tall_px / wide_px)


NARROW_VIEW_WIDTH = 1.25
"""A narrow focus view's width in metres over the height in metres the class's eye height shows. At 1.0 (the
width as wide as a square view's) an object moving across the two-run view (576 x 791 px) took its labels past
the sides at 3 of 13 recorded frames in dev set scene-0916 megvii phd / cphd ``--focus diff:fixed:20``; at 1.25,
0 and 2 (``tools.labels``)."""
COMPARED_ROW_SHARES = (4, 1)
"""With two runs or more, the left column's rows: the scene views, the comparison panel below them."""
STORY_COLUMNS = rrb.TextLogColumns(
    text_log_columns=[
        rrb.components.TextLogColumn(kind="LogLevel", visible=True),
        rrb.components.TextLogColumn(kind="Body", visible=True),
        rrb.components.TextLogColumn(kind="EntityPath", visible=False),
    ]
)
"""Story and failure logs show level and text (the class is in the line; the entity path only takes room)."""
FOCUS_TIMELINE = "focus"
"""Timeline of focus recordings: the frame index, logged only up to the failure frame (see module docstring)."""
STORY_LEVELS = ("INFO", "WARN", "ERROR", "CRITICAL")
"""Levels the story log shows by default (DEBUG: per-frame summaries and candidates, one click away)."""


def failures_root(tracker: str) -> str:
    """Parent of one tracker's failure-count series (``paths.failure_count``)."""
    return f"{paths.tracker_root(tracker)}/failures"


def focus_doc() -> str:
    """TextDocument describing the focused failure (static)."""
    return "focus/summary"


def reading_guide_doc() -> str:
    """TextDocument explaining the marks of a focus recording's views (static)."""
    return "focus/how_to_read"


def focus_world() -> str:
    """Boxes3D highlighting the involved ground truth, tracks and detections at each frame."""
    return f"{paths.WORLD}/focus"


def _contents(tracker: str) -> list[str]:
    cameras = [f"- {paths.camera(c)}/**" for c in CAMERA_ORDER]  # the camera views show them
    return ["+ world/**", "- world/trackers/**", f"+ {paths.tracker_world(tracker)}/**", *cameras]


def _hidden(tracker: str, *, lidar: bool, callouts: bool = False) -> dict[str, rrb.EntityBehavior]:
    """Entities a view holds but does not show: candidates, suppressed detections, the LiDAR (``lidar``) and
    the focus callouts (``callouts``; their column is laid out for the bird's-eye camera)."""
    hidden = [paths.tracker_world(tracker) + "/candidates", paths.DETECTIONS_SUPPRESSED]
    if lidar:
        hidden += [paths.LIDAR, paths.SWEEP_LIDAR]
    if callouts:
        hidden += [paths.focus_callouts(tracker), paths.focus_callouts(tracker) + "/leaders"]
    return {p: rrb.EntityBehavior(visible=False) for p in hidden}


def focus_perspective_eye(
    focus: FocusTarget,
) -> tuple[tuple[float, float, float], tuple[float, float, float]]:
    """(position, look target), global, of a focus recording's perspective eye: behind, left of and above the
    focused place, looking at it (z up)."""
    x, y = focus.center_xy_m
    return (x - 14.0, y - 14.0, 16.0), (x, y, 0.0)


def spatial_view(tracker: str, focus: FocusTarget | None = None) -> rrb.Spatial3DView:
    """Perspective 3D view of the scene and this tracker's entities (not the other trackers')."""
    if focus is None:
        origin, eye = paths.EGO, rrb.EyeControls3D(position=EYE_POSITION_M, look_target=EYE_TARGET_M, eye_up=(0, 0, 1))
    else:
        origin = paths.WORLD
        position, target = focus_perspective_eye(focus)
        eye = rrb.EyeControls3D(position=position, look_target=target, eye_up=(0, 0, 1))
    return rrb.Spatial3DView(
        origin=origin,
        contents=_contents(tracker),
        name=f"{tracker} 3D",
        eye_controls=eye,
        overrides=_hidden(tracker, lidar=False, callouts=focus is not None),
    )


def bev_view(tracker: str, focus: FocusTarget | None = None, runs: int = 1, camera: bool = False) -> rrb.Spatial3DView:
    """Top-down view without LiDAR: tracks, trails, association lines, gates, detections, ground truth; a focus
    view's eye is placed for ``runs`` side by side with a ``camera`` view below (``focus_eye_height_m``)."""
    if focus is None:
        origin = paths.EGO
        eye = rrb.EyeControls3D(position=BEV_EYE_POSITION_M, look_target=BEV_TARGET_M, eye_up=BEV_UP)
    else:
        x, y = focus.center_xy_m
        origin = paths.WORLD
        height = focus_eye_height_m(focus.class_name, runs, camera)
        eye = rrb.EyeControls3D(position=(x, y, height), look_target=(x, y, 0.0), eye_up=(0, 1, 0))
    return rrb.Spatial3DView(
        origin=origin,
        contents=_contents(tracker),
        name=f"{tracker} bird's-eye",
        eye_controls=eye,
        overrides=_hidden(tracker, lidar=True),
    )


def _matrix_view(origin: str, name: str) -> rrb.TensorView:
    return rrb.TensorView(
        origin=origin,
        name=name,
        slice_selection=rrb.TensorSliceSelection(width=1, height=0),
        scalar_mapping=rrb.TensorScalarMapping(colormap="Viridis"),
    )


def _hypotheses_view(tracker: str, classes: Sequence[str]) -> rrb.View | rrb.Container:
    return rrb.TimeSeriesView(origin=paths.hypothesis_weights.root(tracker), name=f"{tracker} hypothesis log w")


def _marginals_view(tracker: str, classes: Sequence[str]) -> rrb.View | rrb.Container:
    return rrb.Tabs(
        *[_matrix_view(paths.marginals(tracker, c), f"{tracker} marginals {c}") for c in classes],
        name=f"{tracker} marginals",
    )


def _cardinality_view(tracker: str, classes: Sequence[str]) -> rrb.View | rrb.Container:
    return rrb.Vertical(
        rrb.TimeSeriesView(origin=paths.cardinality_mean.root(tracker), name="expected count"),
        rrb.BarChartView(origin=paths.cardinality_pmf.root(tracker), name="cardinality pmf"),
        name=f"{tracker} cardinality",
    )


def _intensity_view(tracker: str, classes: Sequence[str]) -> rrb.View | rrb.Container:
    return rrb.Vertical(
        rrb.TimeSeriesView(origin=paths.intensity_total.root(tracker), name="total intensity"),
        rrb.BarChartView(origin=paths.intensity_weights.root(tracker), name="component weights"),
        name=f"{tracker} intensity",
    )


PANEL_VIEWS: dict[Panel, Callable[[str, Sequence[str]], rrb.View | rrb.Container]] = {
    Panel.HYPOTHESES: _hypotheses_view,
    Panel.MARGINALS: _marginals_view,
    Panel.CARDINALITY: _cardinality_view,
    Panel.INTENSITY: _intensity_view,
}
"""The view of each tracker-specific panel; which panels a tracker gets, it declares (``registry.tracker_panels``)."""


def _extra_views(tracker: str, classes: Sequence[str], caps: Capabilities) -> list[rrb.View | rrb.Container]:
    return [PANEL_VIEWS[panel](tracker, classes) for panel in caps.panels]


def _caps(tracker: str, caps: Mapping[str, Capabilities] | None) -> Capabilities:
    """What run ``tracker`` can show: as given, else the registry's tracker of that name."""
    given = (caps or {}).get(tracker)
    return given if given is not None else tracker_capabilities(tracker)


def existence_word(caps: Capabilities) -> str:
    """What a run's per-track value is called in its plot: ``weight`` for a PHD or CPHD filter (the trackers whose
    tracks are intensity components, ``Panel.INTENSITY``: an expected number of objects, which its events carry
    capped at 1, ``gnnpmb.phd.gmphd``), ``existence`` (a probability) for the others."""
    return "weight" if Panel.INTENSITY in caps.panels else "existence"


def _series_title(caps: Capabilities) -> str:
    """The per-track value's plot title: a PHD weight says that the plot caps it (the focus text gives 1.10)."""
    word = existence_word(caps)
    return "weight (capped at 1)" if word == "weight" else word


def failure_counts_view(tracker: str) -> rrb.TimeSeriesView:
    return rrb.TimeSeriesView(origin=failures_root(tracker), name=f"{tracker} failures per frame")


def _series_contents(root: str, near: FocusTarget | None, tracker: str, focused: bool = False) -> list[str] | str:
    """Every series, or near a failure (a focus, or the one a full recording opens at) the involved tracks' (and
    their class's extraction threshold). In a focus recording (``focused``) a run with no involved track shows only
    the threshold: not every track of the scene (a spaghetti of 40 lines beside the failure of the other run,
    dev set scene-0103 ``--focus diff:introduced:1``)."""
    if near is None or not near.track_ids.get(tracker):
        return f"+ {root}/{near.class_name}/threshold" if focused and near is not None else "$origin/**"
    return [f"+ {root}/{near.class_name}/{t}" for t in (*near.track_ids[tracker], "threshold")]


def _legend_args(root: str, legends: Mapping[str, LegendPlacement] | None, visible: bool) -> dict:
    """The legend (and y axis) of the series view at ``root``: as placed in ``legends`` (``viz.legend``), else
    Rerun's default corner, shown or not."""
    placed = (legends or {}).get(root)
    return placed.view_args() if placed is not None else {"plot_legend": rrb.PlotLegend(visible=visible)}


def focus_axis_frames(focus: FocusTarget) -> tuple[int, int]:
    """(first, last) frame a focus recording's plots show on opening, at the failure frame (``_focus_axis``)."""
    before = min(focus.frame_index, FRAMES_BEFORE)
    return focus.frame_index - before, focus.frame_index + FOCUS_PAST_FRAMES + FRAMES_BEFORE - before


def _focus_axis(focus: FocusTarget) -> rrb.TimeAxis:
    """A focus recording's plots run past the failure frame, where they open: a track started at that frame (one
    point) sat on the plot's edge, half cut (dev set scene-0916 megvii phd id_switch:1, track 24). They start
    ``FRAMES_BEFORE`` frames before it, where the recording starts, and never before the scene's first frame; near
    that frame they run as much further past it, so the axis is always that many frames wide: at a failure at
    frame 0 the data's own range was one frame wide, and the x axis read "#0 #0 #0 ..." (dev set scene-0916
    centerpoint miss:2)."""
    first, last = focus_axis_frames(focus)
    return rrb.TimeAxis(
        view_range=rr.TimeRange(
            start=rr.TimeRangeBoundary.absolute(seq=first),
            end=rr.TimeRangeBoundary.cursor_relative(seq=last - focus.frame_index),
        )
    )


def track_series_views(
    tracker: str,
    focus: FocusTarget | None = None,
    legends: Mapping[str, LegendPlacement] | None = None,
    caps: Capabilities | None = None,
    opening: FocusTarget | None = None,
) -> list[rrb.TimeSeriesView]:
    """Existence (for a tracker that has it, ``registry.tracker_has_existence``), normalised innovation (for a
    tracker that gates, ``registry.tracker_has_gates``) and chosen cost (for a tracker that chooses an assignment,
    ``registry.declared``) per track; only the involved tracks when focused, or in a full recording the
    tracks at the failure it opens at (``opening``), with a legend naming them (placed by ``legends``, keyed by
    the view's origin). caps: what the run can show (default: the registry's)."""
    caps = caps or tracker_capabilities(tracker)
    existence = [(paths.existence_root(tracker), _series_title(caps))] if caps.has_existence else []
    nis = [(paths.nis_root(tracker), "NIS (innovation²/S)")] if caps.has_gates else []
    cost = [(paths.chosen_cost_root(tracker), "chosen cost")] if caps.has_costs else []
    near = focus or opening
    few = near is not None and bool(near.track_ids.get(tracker))
    at = f" · tracks at {opening.failure_id}" if focus is None and opening is not None and few else ""
    return [
        rrb.TimeSeriesView(
            origin=root,
            contents=_series_contents(root, near, tracker, focused=focus is not None),
            name=f"{tracker} {what}{at}",
            axis_x=_focus_axis(focus) if focus is not None else None,
            **_legend_args(root, legends, few or focus is not None),
        )
        for root, what in (
            *existence,
            *nis,
            *cost,
        )
    ]


def story_view(tracker: str, focus: FocusTarget | None = None, *, involved: bool = False) -> rrb.TextLogView:
    """The tracker's story log: every class; with a focus its class, or (``involved``) only the lines that name
    an involved track."""
    if focus is None:
        origin, name = paths.events.root(tracker), f"{tracker} story"
    elif involved:
        origin, name = paths.involved_story(tracker), f"{tracker} story (involved tracks)"
    else:
        origin, name = paths.events(tracker, focus.class_name), f"{tracker} story (every {focus.class_name})"
    return rrb.TextLogView(
        origin=origin,
        name=name,
        rows=rrb.TextLogRows(filter_by_log_level=list(STORY_LEVELS)),
        columns=STORY_COLUMNS,
    )


def decision_views(tracker: str) -> rrb.Horizontal:
    """The decision document beside the labelled cost grid (rows m<idx>, columns track ids and "new")."""
    return rrb.Horizontal(
        rrb.TextDocumentView(origin=paths.decisions(tracker), name=f"{tracker} decisions"),
        rrb.Spatial2DView(origin=paths.decision_matrix(tracker), name=f"{tracker} cost grid"),
        column_shares=[3, 2],
        name=f"{tracker} decisions",
    )


def tracker_panel(
    tracker: str,
    classes: Sequence[str],
    focus: FocusTarget | None = None,
    legends: Mapping[str, LegendPlacement] | None = None,
    caps: Capabilities | None = None,
    opening: FocusTarget | None = None,
    failure_index: bool = False,
) -> rrb.Vertical:
    """Decision view, story and failure logs, and series (per-track, candidates, failures, extra plots); with a
    focus the summary of the failure comes first (beside a tab on how to read the views) and the decision
    document goes to a tab beside the story. Candidates (Bernoullis too unlikely to be drawn as tracks) only for
    a tracker with existences. caps: what the run can show (default: the registry's): the decision view only for a
    tracker that chooses an assignment. A full recording whose failures were found (``failure_index``) opens on its
    failure index; its per-track plots show the tracks at the failure it opens at (``opening``)."""
    caps = caps or tracker_capabilities(tracker)
    candidates = []
    if caps.has_existence:
        candidates = [rrb.TimeSeriesView(origin=paths.candidate_count.root(tracker), name=f"{tracker} candidates")]
    series = rrb.Tabs(
        *track_series_views(tracker, focus, legends, caps, opening),
        *candidates,
        failure_counts_view(tracker),
        *_extra_views(tracker, classes, caps),
    )
    logs = rrb.Tabs(
        story_view(tracker, focus),
        rrb.TextLogView(origin=failure_log(tracker), name=f"{tracker} failure log", columns=STORY_COLUMNS),
    )
    if focus is not None:
        decisions = []
        if caps.has_costs:
            decisions = [
                rrb.TextDocumentView(origin=paths.decisions(tracker), name=f"{tracker} decisions"),
                rrb.Spatial2DView(origin=paths.decision_matrix(tracker), name=f"{tracker} cost grid"),
            ]
        logs = rrb.Tabs(
            story_view(tracker, focus, involved=True),
            story_view(tracker, focus),
            *decisions,
            rrb.TextLogView(origin=failure_log(tracker), name=f"{tracker} failure log", columns=STORY_COLUMNS),
        )
        summary = rrb.Tabs(
            rrb.TextDocumentView(origin=focus_doc(), name="focus"),
            rrb.TextDocumentView(origin=reading_guide_doc(), name="how to read the views"),
        )
        return rrb.Vertical(summary, logs, series, row_shares=[6, 3, 3], name=tracker)
    top = (
        [rrb.TextDocumentView(origin=paths.failure_index_doc(tracker), name=f"{tracker} failures")]
        if failure_index
        else []
    )
    top += [decision_views(tracker)] if caps.has_costs else []
    if not top:
        return rrb.Vertical(logs, series, row_shares=[3, 2], name=tracker)
    return rrb.Vertical(rrb.Tabs(*top, active_tab=0), logs, series, row_shares=[5, 3, 2], name=tracker)


def comparison_panel(
    trackers: Sequence[str],
    legends: Mapping[str, LegendPlacement] | None = None,
    focus: FocusTarget | None = None,
    focus_class_quiet: bool = False,
) -> rrb.Horizontal:
    """Disagreements per frame (and each tracker's failures per frame) as tabs, beside the disagreement log; with
    a focus, the log opens on the disagreements about the focused class (the whole log is the next tab) and the
    plot, which counts every class's, says so: beside an empty log of the focused class it read as a disagreement
    the log did not hold (demo scene-9001 pmbm beside gnnpmb ``--focus coalescence:2``: a car track at frame 19,
    the log of bicycles empty); when the runs disagree about nothing of the focused class up to the failure
    (``focus_class_quiet``), the log opens on the whole log instead, which holds what the plot counts."""
    counts = rrb.Tabs(
        rrb.TimeSeriesView(
            origin=compare.counts_root(),
            name="disagreements per frame" if focus is None else "disagreements per frame (every class)",
            **_legend_args(compare.counts_root(), legends, True),
        ),
        *[failure_counts_view(t) for t in trackers],
    )
    log = rrb.TextLogView(origin=compare.log_path(), name="disagreements", columns=STORY_COLUMNS)
    if focus is not None:
        about = rrb.TextLogView(
            origin=compare.focus_log_path(), name=f"disagreements ({focus.class_name})", columns=STORY_COLUMNS
        )
        log = rrb.Tabs(about, log, active_tab=1 if focus_class_quiet else 0)
    return rrb.Horizontal(counts, log, column_shares=[2, 3], name="comparison")


def _tracker_views(
    tracker: str,
    focus: FocusTarget | None,
    strip: range | None = None,
    rows: int = 1,
    runs: int = 1,
    strip_rows: int = 1,
    cameras: bool = False,
) -> rrb.Container:
    """The bird's-eye view above the perspective view; with a focus the bird's-eye view, where the failure is
    read, takes more of the height; with ``strip`` (a full recording whose failures were found: its frames) the
    failures over those frames below them, in ``rows`` rows (``viz.opening.log_failure_timeline``), the view as
    tall as ``strip_rows`` rows need (the most any run has; with ``cameras`` below, ``viz.opening.strip_share``).
    A focus on several ``runs`` puts the perspective view in a tab behind the bird's-eye view: a third of the width
    and a third of the height left it a strip no one could read (demo scene-0103, three runs: 110 px tall)."""
    if focus is not None and runs > 1:
        return rrb.Tabs(bev_view(tracker, focus, runs, cameras), spatial_view(tracker, focus), active_tab=0)
    if focus is not None:
        return rrb.Vertical(
            bev_view(tracker, focus, runs, cameras), spatial_view(tracker, focus), row_shares=list(FOCUS_ROW_SHARES)
        )
    if strip is not None:
        from viz.opening import SCENE_SHARES, failure_timeline, strip_share, timeline_bounds

        x_range, y_range = timeline_bounds(strip, rows, runs)
        strip_view = rrb.Spatial2DView(
            origin=failure_timeline(tracker),
            name=f"{tracker} failures over time",
            visual_bounds=rrb.VisualBounds2D(x_range=x_range, y_range=y_range),
        )
        shares = [*SCENE_SHARES, strip_share(strip_rows, cameras)]
        return rrb.Vertical(bev_view(tracker), spatial_view(tracker), strip_view, row_shares=shares)
    return rrb.Vertical(bev_view(tracker, focus), spatial_view(tracker, focus), row_shares=[3, 2])


def default_blueprint(
    trackers: Sequence[str],
    classes: Sequence[str],
    focus: FocusTarget | None = None,
    legends: Mapping[str, LegendPlacement] | None = None,
    caps: Mapping[str, Capabilities] | None = None,
    opening: FocusTarget | None = None,
    failure_index: bool = False,
    frames: range | None = None,
    timeline_rows: Mapping[str, int] | None = None,
    cameras: Sequence[str] = (),
    focus_camera: str | None = None,
    focus_class_quiet: bool = False,
) -> rrb.Blueprint:
    """The layout for a recording of ``trackers`` (one or more runs, side by side) over ``classes``; with ``focus``
    the layout opens at and looks at the failure. ``legends``: where the legends of series views go, keyed by
    the view's origin (``viz.legend.place_legend``; default: Rerun's corner); caps: what each run can show
    (``gnnpmb.runs.Capabilities``; default: the registry's tracker of that name). A full recording whose failures
    were found (``failure_index``) shows each run's failure index and its failures over ``frames`` (in
    ``timeline_rows`` rows per run), and opens at the failure ``opening`` (``viz.opening``): its ``focus`` timeline
    ends there. ``cameras``: the channels to show below the scene views (``viz.cameras.with_cameras``; in a focus
    recording only ``focus_camera``, the one that sees the focus object, when one does). ``focus_class_quiet``: the
    runs disagree about nothing of the focused class up to the failure (``comparison_panel``)."""
    if not trackers:
        raise ValueError("default_blueprint needs at least one tracker")
    strips = frames if focus is None and failure_index and frames is not None else None
    panels = [tracker_panel(t, classes, focus, legends, _caps(t, caps), opening, failure_index) for t in trackers]
    rows = timeline_rows or {}
    most = max(rows.values(), default=1)
    scene = rrb.Horizontal(
        *[_tracker_views(t, focus, strips, rows.get(t, 1), len(trackers), most, bool(cameras)) for t in trackers]
    )
    if cameras:
        scene = with_cameras(scene, cameras, focus is not None, focus_camera)
    if len(trackers) == 1:
        layout = rrb.Horizontal(scene, panels[0], column_shares=[3, 2])
    else:
        comparison = comparison_panel(trackers, legends, focus, focus_class_quiet)
        left = rrb.Vertical(scene, comparison, row_shares=list(COMPARED_ROW_SHARES))
        layout = rrb.Horizontal(left, rrb.Tabs(*panels), column_shares=[3, 2])
    if focus is None and opening is None:
        time_panel = rrb.TimePanel(state="collapsed", timeline="frame", play_state="paused")
    else:
        time_panel = rrb.TimePanel(state="collapsed", timeline=FOCUS_TIMELINE, play_state="following")
    return rrb.Blueprint(
        layout,
        time_panel,
        rrb.SelectionPanel(state="collapsed"),
        rrb.BlueprintPanel(state="collapsed"),
    )
