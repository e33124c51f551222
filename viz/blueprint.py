"""The default viewer layout, built in code.

Left: one 3D view per tracker (side by side), each showing the shared LiDAR, ground truth and detections plus only
that tracker's tracks, gates and predictions. Right: per tracker (tabs) the cost matrices (one tab per class, heat
map over its labelled table), the existence probabilities and tracker-specific plots, and the event log.
"""

from __future__ import annotations

from collections.abc import Sequence

import rerun.blueprint as rrb

from viz import paths

_EXTRA_PLOTS: dict[str, tuple[str, ...]] = {
    "pmbm": ("hypotheses",),
    "topmb": ("marginals",),
    "jpda": ("marginals",),
    "phd": ("intensity",),
    "cphd": ("cardinality", "intensity"),
}
"""Which tracker-specific plots each tracker fills (the names of ``TRACKER_NAMES``)."""


def spatial_view(tracker: str) -> rrb.Spatial3DView:
    """3D view of everything under ``world`` except the other trackers' entities."""
    return rrb.Spatial3DView(
        origin=paths.WORLD,
        contents=[f"+ {paths.WORLD}/**", f"- {paths.WORLD_TRACKERS}/**", f"+ {paths.tracker_world(tracker)}/**"],
        name=f"{tracker} 3D",
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
            views.append(rrb.TimeSeriesView(origin=paths.hypotheses_root(tracker), name=f"{tracker} hypothesis log w"))
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


def tracker_panel(tracker: str, classes: Sequence[str]) -> rrb.Vertical:
    """Cost matrices, series (existence and tracker-specific plots as tabs) and the event log of one tracker."""
    series = rrb.Tabs(
        rrb.TimeSeriesView(origin=paths.existence_root(tracker), name=f"{tracker} existence"),
        *_extra_views(tracker, classes),
    )
    return rrb.Vertical(
        cost_views(tracker, classes),
        series,
        rrb.TextLogView(origin=paths.events_root(tracker), name=f"{tracker} events"),
        row_shares=[5, 3, 2],
        name=tracker,
    )


def default_blueprint(trackers: Sequence[str], classes: Sequence[str]) -> rrb.Blueprint:
    """The layout for a recording of ``trackers`` (one or more, side by side) over ``classes``."""
    if not trackers:
        raise ValueError("default_blueprint needs at least one tracker")
    spatial = [spatial_view(t) for t in trackers]
    left = spatial[0] if len(spatial) == 1 else rrb.Horizontal(*spatial)
    panels = [tracker_panel(t, classes) for t in trackers]
    right = panels[0] if len(panels) == 1 else rrb.Tabs(*panels)
    return rrb.Blueprint(
        rrb.Horizontal(left, right, column_shares=[3, 2]),
        rrb.TimePanel(state="expanded", timeline="frame"),
        rrb.SelectionPanel(state="collapsed"),
        rrb.BlueprintPanel(state="collapsed"),
    )
