"""The default viewer layout, built in code.

One tracker: its 3D view on the left (shared LiDAR, ground truth and detections plus its own tracks, gates,
predictions and failure markers); on the right its panel: cost matrices (one tab per class, heat map over its
labelled table), series (existence, candidates, failures per frame, tracker-specific plots) and logs (events,
failures).

Several trackers (a comparison): one 3D view per tracker side by side on the same timeline, each showing the
shared scene, the comparison markers (``world/comparison``) and only that tracker's own entities; below them
the comparison panel (disagreements per frame and each tracker's failures per frame as tabs, beside the
disagreement log); on the right one tab per tracker with its panel.
"""

from __future__ import annotations

from collections.abc import Sequence

import rerun.blueprint as rrb

from viz import compare, paths
from viz.failures import failure_log

_EXTRA_PLOTS: dict[str, tuple[str, ...]] = {
    "pmbm": ("hypotheses",),
    "topmb": ("marginals",),
    "jpda": ("marginals",),
    "phd": ("intensity",),
    "cphd": ("cardinality", "intensity"),
}
"""Which tracker-specific plots each tracker fills (the names of ``TRACKER_NAMES``)."""


EYE_POSITION_M = (-18.0, -14.0, 22.0)
EYE_TARGET_M = (10.0, 0.0, 0.0)
"""Default camera of the 3D views in the ego frame (x forward, z up): behind, left of and above the car,
looking at a point 10 m ahead. The views' origin is the ego vehicle, so the camera follows the car through the
scene."""


def failures_root(tracker: str) -> str:
    """Parent of one tracker's failure-count series (``paths.failure_count``)."""
    return f"{paths.tracker_root(tracker)}/failures"


def spatial_view(tracker: str) -> rrb.Spatial3DView:
    """3D view of everything under ``world`` except the other trackers' entities, seen from the ego vehicle's
    frame (``EYE_POSITION_M``)."""
    return rrb.Spatial3DView(
        origin=paths.EGO,
        contents=[
            f"+ {paths.WORLD}/**",
            f"- {paths.WORLD_TRACKERS}/**",
            f"+ {paths.tracker_world(tracker)}/**",
        ],
        name=f"{tracker} 3D",
        eye_controls=rrb.EyeControls3D(
            position=EYE_POSITION_M, look_target=EYE_TARGET_M, eye_up=(0.0, 0.0, 1.0)
        ),
    )


def _matrix_view(origin: str, name: str) -> rrb.TensorView:
    return rrb.TensorView(
        origin=origin,
        name=name,
        slice_selection=rrb.TensorSliceSelection(width=1, height=0),
        scalar_mapping=rrb.TensorScalarMapping(colormap="Viridis"),
    )


def cost_views(tracker: str, classes: Sequence[str]) -> rrb.Tabs:
    """One tab per class: the cost heat map above its row/column table."""
    return rrb.Tabs(
        *[
            rrb.Vertical(
                _matrix_view(paths.cost_matrix(tracker, c), f"{tracker} cost {c}"),
                rrb.TextDocumentView(origin=paths.cost_axes(tracker, c), name=f"{tracker} cost table {c}"),
                row_shares=[3, 2],
                name=c,
            )
            for c in classes
        ],
        name=f"{tracker} cost matrices",
    )


def _extra_views(tracker: str, classes: Sequence[str]) -> list[rrb.View | rrb.Container]:
    views: list[rrb.View | rrb.Container] = []
    for kind in _EXTRA_PLOTS.get(tracker, ()):
        if kind == "hypotheses":
            views.append(
                rrb.TimeSeriesView(origin=paths.hypotheses_root(tracker), name=f"{tracker} hypothesis log w")
            )
        elif kind == "marginals":
            views.append(
                rrb.Tabs(
                    *[_matrix_view(paths.marginals(tracker, c), f"{tracker} marginals {c}") for c in classes],
                    name=f"{tracker} marginals",
                )
            )
        elif kind == "cardinality":
            views.append(
                rrb.Vertical(
                    rrb.TimeSeriesView(origin=paths.cardinality_mean_root(tracker), name="expected count"),
                    rrb.BarChartView(origin=paths.cardinality_pmf_root(tracker), name="cardinality pmf"),
                    name=f"{tracker} cardinality",
                )
            )
        elif kind == "intensity":
            views.append(
                rrb.Vertical(
                    rrb.TimeSeriesView(origin=paths.intensity_total_root(tracker), name="total intensity"),
                    rrb.BarChartView(origin=paths.intensity_weights_root(tracker), name="component weights"),
                    name=f"{tracker} intensity",
                )
            )
        else:
            raise ValueError(f"no view for plot kind {kind!r}")
    return views


def failure_counts_view(tracker: str) -> rrb.TimeSeriesView:
    return rrb.TimeSeriesView(origin=failures_root(tracker), name=f"{tracker} failures per frame")


def tracker_panel(tracker: str, classes: Sequence[str]) -> rrb.Vertical:
    """Cost matrices, series (existence of tracks and of never-extracted candidates, failure counts and
    tracker-specific plots as tabs) and logs (events, failures as tabs) of one tracker."""
    series = rrb.Tabs(
        rrb.TimeSeriesView(origin=paths.existence_root(tracker), name=f"{tracker} existence"),
        rrb.TimeSeriesView(origin=paths.candidates_root(tracker), name=f"{tracker} candidates"),
        failure_counts_view(tracker),
        *_extra_views(tracker, classes),
    )
    logs = rrb.Tabs(
        rrb.TextLogView(origin=paths.events_root(tracker), name=f"{tracker} events"),
        rrb.TextLogView(origin=failure_log(tracker), name=f"{tracker} failures"),
    )
    return rrb.Vertical(cost_views(tracker, classes), series, logs, row_shares=[5, 3, 2], name=tracker)


def comparison_panel(trackers: Sequence[str]) -> rrb.Horizontal:
    """Disagreements per frame (and each tracker's failures per frame) as tabs, beside the disagreement
    log."""
    counts = rrb.Tabs(
        rrb.TimeSeriesView(origin=compare.counts_root(), name="disagreements per frame"),
        *[failure_counts_view(t) for t in trackers],
    )
    log = rrb.TextLogView(origin=compare.log_path(), name="disagreements")
    return rrb.Horizontal(counts, log, column_shares=[2, 3], name="comparison")


def default_blueprint(trackers: Sequence[str], classes: Sequence[str]) -> rrb.Blueprint:
    """The layout for a recording of ``trackers`` (one or more, side by side) over ``classes``."""
    if not trackers:
        raise ValueError("default_blueprint needs at least one tracker")
    panels = [tracker_panel(t, classes) for t in trackers]
    if len(trackers) == 1:
        layout = rrb.Horizontal(spatial_view(trackers[0]), panels[0], column_shares=[3, 2])
    else:
        left = rrb.Vertical(
            rrb.Horizontal(*[spatial_view(t) for t in trackers]),
            comparison_panel(trackers),
            row_shares=[3, 1],
        )
        layout = rrb.Horizontal(left, rrb.Tabs(*panels), column_shares=[3, 2])
    return rrb.Blueprint(
        layout,
        rrb.TimePanel(state="expanded", timeline="frame"),
        rrb.SelectionPanel(state="collapsed"),
        rrb.BlueprintPanel(state="collapsed"),
    )
