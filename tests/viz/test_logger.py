from __future__ import annotations

import dataclasses
from pathlib import Path

import numpy as np
import pytest
import rerun as rr
from rerun.chunk import RrdReader

from gnnpmb.events import (
    Assignment,
    AxisKind,
    AxisLabel,
    Born,
    Cardinality,
    CostMatrix,
    Extracted,
    FrameStarted,
    Gated,
    GlobalHypotheses,
    IntensityWeights,
    ListSink,
    Marginals,
    Merged,
    Posterior,
    Predicted,
    Pruned,
    PruneReason,
    TrackLogic,
    TrackLogicAction,
)
from gnnpmb.types import TrackEstimate
from tests.viz.rrd import at_frame, latest_at, read_rows
from viz import paths
from viz.colors import track_colors
from viz.logger import TrackerLogger, axis_dim_name, cost_heat, cost_markdown

T = "gnnpmb"
T0_US = 1_533_151_603_547_590


def est(track_id: int, x: float, r: float, class_name: str = "car") -> TrackEstimate:
    return TrackEstimate(track_id, class_name, (x, 2.0, 0.9), (2.0, 4.5, 1.6), (1.0, 0.0, 0.0, 0.0), (1.0, 0.0), 0.9, r)


def meas(j: int) -> AxisLabel:
    return AxisLabel(AxisKind.MEASUREMENT, j)


def track(t: int) -> AxisLabel:
    return AxisLabel(AxisKind.TRACK, t)


def new(j: int) -> AxisLabel:
    return AxisLabel(AxisKind.NEW_TRACK, j)


def frame(i: int) -> FrameStarted:
    return FrameStarted(T, i, f"s{i}", T0_US + 500_000 * i, 0.0 if i == 0 else 0.5)


def scripted_events() -> list:
    """Frame 0: two cars born. Frame 1: both predicted and gated, track 2 pruned, track 1 extracted; a bus
    class with nothing. Frame 2: no car tracks at all. Plus one event of every other kind."""
    cov = np.tile(np.diag([1.0, 1.0, 2.0, 2.0]), (2, 1, 1))
    mean2 = np.array([[10.0, 2.0, 1.0, 0.0], [20.0, 5.0, 0.0, 0.0]])
    return [
        frame(0),
        Predicted("car", np.zeros(0, int), np.zeros((0, 4)), np.zeros((0, 4, 4)), np.zeros(0)),
        CostMatrix("car", np.array([[np.inf, -1.0], [-2.0, np.inf]]), (meas(0), meas(1)), (new(1), new(0))),
        Assignment("car", ((meas(0), new(0)), (meas(1), new(1))), -3.0, ()),
        Born("car", np.array([1, 2]), np.array([0, 1]), mean2, np.array([0.97, 0.4])),
        Posterior("car", np.array([1, 2]), mean2, cov, np.array([0.97, 0.4])),
        Extracted("car", (est(1, 10.0, 0.97),), 0.9),
        TrackLogic("car", 1, TrackLogicAction.CONFIRMED, 3, 4),
        frame(1),
        Predicted("car", np.array([1, 2]), mean2, cov, np.array([0.68, 0.28])),
        Gated("car", np.array([1, 2]), np.array([0]), np.array([[True], [False]]), mean2[:, :2], cov[:, :2, :2], 40.0),
        CostMatrix("car", np.array([[-4.0, np.inf, 0.0]]), (meas(0),), (track(1), track(2), new(0))),
        Posterior("car", np.array([1, 2]), mean2, cov, np.array([0.99, 1e-7])),
        Pruned("car", 2, PruneReason.LOW_EXISTENCE, 1e-7),
        Extracted("car", (est(1, 11.0, 0.99),), 0.9),
        Extracted("bus", (), 0.9),
        GlobalHypotheses("car", np.array([-0.1, -2.4]), ((1,), (1, 2)), ((0,), (0, 1))),
        Marginals("car", np.array([[0.8, 0.2]]), (meas(0),), (track(1), new(0)), "lbp", 7),
        Merged("car", 1, (1, 3), (0.7, 0.3)),
        Cardinality("car", np.array([0.1, 0.6, 0.3])),
        IntensityWeights("car", np.array([1, 3]), np.array([0.8, 0.3])),
        frame(2),
        Extracted("car", (), 0.9),
        Posterior("car", np.zeros(0, int), np.zeros((0, 4)), np.zeros((0, 4, 4)), np.zeros(0)),
    ]


@pytest.fixture
def logged(saved_stream: tuple[rr.RecordingStream, Path]) -> tuple[dict, Path]:
    stream, path = saved_stream
    logger = TrackerLogger(stream, T)
    for event in scripted_events():
        logger.emit(event)
    logger.finish()
    logger.finish()
    stream.disconnect()
    return read_rows(path), path


def test_tracks_are_boxes_with_id_colours_and_labels_and_vanish_without_tracks(logged: tuple[dict, Path]) -> None:
    rows = logged[0][paths.tracks(T, "car")]
    first = at_frame(rows, 0)[0]
    assert first["Boxes3D:labels"] == ["1 car r=0.97"]
    np.testing.assert_allclose(first["Boxes3D:centers"], [[10.0, 2.0, 0.9]], rtol=1e-6)
    # devkit wlh (2.0, 4.5, 1.6) -> half extents along the box's x, y, z
    np.testing.assert_allclose(first["Boxes3D:half_sizes"], [[2.25, 1.0, 0.8]], rtol=1e-6)
    r, g, b = track_colors(np.array([1]))[0]
    assert first["Boxes3D:colors"] == [(int(r) << 24) | (int(g) << 16) | (int(b) << 8) | 255]
    np.testing.assert_allclose(latest_at(rows, 1, "Boxes3D:centers"), [[11.0, 2.0, 0.9]], rtol=1e-6)
    assert latest_at(rows, 2, "Boxes3D:centers") is None
    assert paths.tracks(T, "bus") not in logged[0]  # never had tracks: nothing to draw or clear


def test_gates_are_closed_ellipses_cleared_when_not_redrawn(logged: tuple[dict, Path]) -> None:
    rows = logged[0][paths.gates(T, "car")]
    strips = latest_at(rows, 1, "LineStrips3D:strips")
    assert len(strips) == 2
    outline = np.array(strips[0])
    assert outline.shape == (33, 3)
    np.testing.assert_allclose(outline[0], outline[-1], atol=1e-9)
    # cov[:2, :2] = I and threshold 40: a circle of radius sqrt(40) around (10, 2), drawn at the track's box height.
    np.testing.assert_allclose(np.hypot(outline[:, 0] - 10.0, outline[:, 1] - 2.0), np.sqrt(40.0), rtol=1e-6)
    np.testing.assert_allclose(outline[:, 2], 0.9, rtol=1e-6)
    np.testing.assert_allclose(np.array(strips[1])[:, 2], 0.0)  # track 2 was never extracted: gate_z_m
    assert latest_at(rows, 2, "LineStrips3D:strips") is None
    assert latest_at(logged[0][paths.predicted(T, "car")], 1, "Points3D:positions.len") == 2


def test_cost_matrix_heat_map_and_table(logged: tuple[dict, Path]) -> None:
    rows = logged[0][paths.cost_matrix(T, "car")]
    tensor = at_frame(rows, 0)[0]["Tensor:data"][0]
    assert tensor["shape"] == [2, 2]
    assert tensor["names"] == ["meas", "new"]
    lo, hi = at_frame(rows, 0)[0]["Tensor:value_range"][0]
    heat = np.array(tensor["buffer"]).reshape(2, 2)
    assert heat[0, 1] == pytest.approx(1.0) and heat[1, 0] == pytest.approx(2.0)
    assert heat[0, 0] == heat[1, 1] == pytest.approx(lo) and lo < 1.0 and hi == pytest.approx(2.0)
    # Frame 1: track 2 has no measurement in its gate, so its all-impossible column is left out of the heat map.
    assert at_frame(rows, 1)[0]["Tensor:data"][0]["names"] == ["meas", "track|new"]
    assert at_frame(rows, 1)[0]["Tensor:data"][0]["shape"] == [1, 2]
    assert latest_at(rows, 2, "Tensor:data") is None
    table = at_frame(logged[0][paths.cost_axes(T, "car")], 1)[0]["TextDocument:text"][0]
    assert "| **meas 0** | -4.00 | - | 0.00 |" in table
    assert "track 2" in table


def test_event_log_levels_and_texts(logged: tuple[dict, Path]) -> None:
    rows = logged[0][paths.events(T, "car")]
    frame0 = [(t, lv) for r in at_frame(rows, 0) for t, lv in zip(r["TextLog:text"], r["TextLog:level"], strict=True)]
    assert ("born track 1 from meas 0 at (10.0, 2.0) r=0.970", "INFO") in frame0
    assert ("track 1 confirmed (3/4 hits)", "INFO") in frame0
    assert any(t.startswith("h0 assignment, cost -3.000: meas 0->new 0") and lv == "DEBUG" for t, lv in frame0)
    frame1 = [(t, lv) for r in at_frame(rows, 1) for t, lv in zip(r["TextLog:text"], r["TextLog:level"], strict=True)]
    assert ("pruned track 2: existence below pruning threshold (last 1e-07)", "WARN") in frame1
    assert any(t.startswith("merged 1, 3 into 1") for t, _ in frame1)
    assert any(t.startswith("marginals 1x2 by lbp, 7 iterations") for t, _ in frame1)


def test_existence_series_are_sent_column_wise_one_chunk_per_track(logged: tuple[dict, Path]) -> None:
    rows, path = logged
    series = rows[paths.existence(T, "car", 1)]
    temporal = [r for r in series if not r["static"]]
    assert [r["frame"] for r in temporal] == [0, 1]
    assert [r["Scalars:scalars"][0] for r in temporal] == pytest.approx([0.97, 0.99])
    assert [r for r in series if r["static"]][0]["SeriesLines:names"] == ["1 car"]
    chunks = [c for c in RrdReader(path).store().stream() if c.entity_path == "/" + paths.existence(T, "car", 1)]
    assert len([c for c in chunks if not c.is_static]) == 1
    # Track 2 is never extracted: its series is a candidate's, kept out of the default existence plot.
    assert paths.existence(T, "car", 2) not in rows
    assert [r["frame"] for r in rows[paths.candidate_existence(T, "car", 2)] if not r["static"]] == [0, 1]


def test_tracker_specific_plots(logged: tuple[dict, Path]) -> None:
    rows = logged[0]
    weights = [r["Scalars:scalars"][0] for r in rows[paths.hypothesis_weight(T, "car", 1)] if not r["static"]]
    assert weights == pytest.approx([-2.4])
    marg = at_frame(rows[paths.marginals(T, "car")], 1)[0]
    assert marg["Tensor:data"][0]["buffer"] == pytest.approx([0.8, 0.2])
    assert marg["Tensor:value_range"][0] == [0.0, 1.0]
    assert at_frame(rows[paths.cardinality_pmf(T, "car")], 1)[0]["BarChart:values"][0]["buffer"] == pytest.approx(
        [0.1, 0.6, 0.3]
    )
    mean = [r["Scalars:scalars"][0] for r in rows[paths.cardinality_mean(T, "car")] if not r["static"]]
    assert mean == pytest.approx([1.2])
    total = [r["Scalars:scalars"][0] for r in rows[paths.intensity_total(T, "car")] if not r["static"]]
    assert total == pytest.approx([1.1])


def test_events_outside_a_frame_and_unknown_events_are_rejected(saved_stream) -> None:
    stream, _ = saved_stream
    logger = TrackerLogger(stream, T)
    with pytest.raises(RuntimeError, match="FrameStarted"):
        logger.emit(Extracted("car", (), 0.9))
    logger.emit(frame(0))
    with pytest.raises(TypeError, match="cannot log"):
        logger.emit("not an event")  # type: ignore[arg-type]
    stream.disconnect()


def test_logger_is_a_sink_usable_in_a_tee() -> None:
    from gnnpmb.events import EventSink, TeeSink

    assert isinstance(TrackerLogger(rr.RecordingStream("x"), T), EventSink)
    assert TeeSink(ListSink(), TrackerLogger(rr.RecordingStream("y"), T)).enabled


def test_cost_heat_sentinel_sits_below_every_finite_value() -> None:
    heat, (lo, hi) = cost_heat(np.array([[1.0, np.inf], [np.nan, 3.0]]))
    assert heat.dtype == np.float32
    assert hi == pytest.approx(-1.0) and heat[1, 1] == pytest.approx(-3.0)
    assert heat[0, 1] == heat[1, 0] == pytest.approx(lo) and lo < -3.0
    all_inf, (lo2, hi2) = cost_heat(np.full((2, 2), np.inf))
    assert np.all(all_inf == lo2) and lo2 < hi2
    single, (lo3, hi3) = cost_heat(np.array([[2.0]]))
    assert lo3 < single[0, 0] <= hi3


def test_axis_names_and_large_table() -> None:
    assert axis_dim_name((track(1), track(2), new(0))) == "track|new"
    assert axis_dim_name(()) == "empty"
    cost = np.full((30, 60), np.inf)
    cost[np.arange(30), 30 + np.arange(30)] = 0.5
    cost[3, 7] = -1.25
    big = CostMatrix(
        "car",
        cost,
        tuple(meas(j) for j in range(30)),
        tuple([track(t) for t in range(30)] + [new(j) for j in range(30)]),
    )
    text = cost_markdown(big)
    assert "|" not in text
    assert "- **meas 3**: track 7 -1.25, new 3 0.50\n" in text
    assert "- **meas 4**: new 4 0.50\n" in text


def test_two_trackers_share_one_recording_without_touching_each_other(saved_stream) -> None:
    stream, path = saved_stream
    for name, x in [("gnnpmb", 10.0), ("pmbm", 50.0)]:
        logger = TrackerLogger(stream, name, log_predicted=False)
        for event in scripted_events():
            if isinstance(event, FrameStarted):
                event = FrameStarted(name, event.frame_index, event.sample_token, event.timestamp_us, event.dt_s)
            elif isinstance(event, Extracted) and event.estimates:
                event = Extracted("car", (est(1, x, 0.97),), 0.9)
            logger.emit(event)
        logger.finish()
    stream.disconnect()
    rows = read_rows(path)
    for name, x in [("gnnpmb", 10.0), ("pmbm", 50.0)]:
        assert latest_at(rows[paths.tracks(name, "car")], 1, "Boxes3D:centers")[0][0] == pytest.approx(x)
        assert len([r for r in rows[paths.existence(name, "car", 1)] if not r["static"]]) == 2
        assert paths.predicted(name, "car") not in rows


def test_cost_heat_map_hides_columns_with_no_possible_assignment() -> None:
    from gnnpmb.events import AxisKind, AxisLabel, CostMatrix
    from viz.logger import compact_cost

    inf = np.inf
    event = CostMatrix(
        "car",
        np.array([[1.0, inf, 2.0, inf], [inf, inf, inf, 3.0]]),
        (AxisLabel(AxisKind.MEASUREMENT, 0), AxisLabel(AxisKind.MEASUREMENT, 1)),
        (
            AxisLabel(AxisKind.TRACK, 5),
            AxisLabel(AxisKind.TRACK, 6),
            AxisLabel(AxisKind.NEW_TRACK, 0),
            AxisLabel(AxisKind.NEW_TRACK, 1),
        ),
    )
    out = compact_cost(event)
    assert [str(c) for c in out.cols] == ["track 5", "new 0", "new 1"]
    assert out.cost.shape == (2, 3) and "1 columns" in out.description
    full = dataclasses.replace(event, cost=np.ones((2, 4)))
    assert compact_cost(full) is full


def test_gates_of_unlikely_candidates_are_not_drawn(saved_stream: tuple[rr.RecordingStream, Path]) -> None:
    stream, path = saved_stream
    logger = TrackerLogger(stream, T, gate_min_existence=0.5)
    for event in scripted_events():
        logger.emit(event)
    logger.finish()
    stream.disconnect()
    strips = latest_at(read_rows(path)[paths.gates(T, "car")], 1, "LineStrips3D:strips")
    assert len(strips) == 1  # track 1 (prior r = 0.68) only; track 2 (r = 0.28) is below 0.5
    np.testing.assert_allclose(np.hypot(np.array(strips[0])[:, 0] - 10.0, np.array(strips[0])[:, 1] - 2.0),
                               np.sqrt(40.0), rtol=1e-6)
