"""The event logger read back from a saved recording: what a user sees per entity and frame."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import rerun as rr
from rerun.chunk import RrdReader

from gnnpmb.events import (
    Assignment,
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
    MeasurementsReceived,
    Merged,
    Posterior,
    Predicted,
    Pruned,
    PruneReason,
    TrackLogic,
    TrackLogicAction,
)
from gnnpmb.types import TrackEstimate
from tests.labels import meas, missed, new, track
from tests.viz.rrd import at_frame, latest_at, read_rows
from viz import paths
from viz.colors import INVOLVED_PALETTE, faded, pack_rgba, track_colors
from viz.logger import DIMMED_KEEP, TrackerLogger
from viz.timeline import Clock

T = "gnnpmb"
T0_US = 1_533_151_603_547_590
INF = np.inf


def est(track_id: int, x: float, r: float, meas_index: int = -1, class_name: str = "car") -> TrackEstimate:
    return TrackEstimate(
        track_id, class_name, (x, 2.0, 0.9), (2.0, 4.5, 1.6), (1.0, 0.0, 0.0, 0.0), (1.0, 0.0), 0.9, r, meas_index
    )


def frame(i: int, tracker: str = T) -> FrameStarted:
    return FrameStarted(tracker, i, f"s{i}", T0_US + 500_000 * i, 0.0 if i == 0 else 0.5)


def received(xs: list[float]) -> MeasurementsReceived:
    n = len(xs)
    return MeasurementsReceived(
        "car", np.arange(n), np.array([[x, 2.0, 1.0] for x in xs]).reshape(n, 3), np.full(n, 0.8)
    )


def scripted_events() -> list:
    """Frame 0: m0 and m1 start tracks 1 (r 0.97, reported) and 2 (r 0.4, a candidate).
    Frame 1: both predicted; m0 (x 10.5) is in both gates, m1 (x 11) in track 1's; the solver gives m0 to track 1
    (cost -5) over track 2 (-4) and m1 to track 2 (-4.5; m1 alone would rather go to track 1 at -5, but the swap
    totals -9 against -9.5: margin 0.5) -- a close call.
    Track 2 then drops to 1e-7 and is pruned; track 1 is reported. The bus class has nothing.
    Frame 2: nothing; track 1 is pruned; and one event of every other tracker-specific kind."""
    cov = np.tile(np.diag([1.0, 1.0, 2.0, 2.0]), (2, 1, 1))
    mean2 = np.array([[10.0, 2.0, 1.0, 0.0], [20.0, 5.0, 0.0, 0.0]])
    return [
        frame(0),
        received([10.0, 20.0]),
        Predicted("car", np.zeros(0, int), np.zeros((0, 4)), np.zeros((0, 4, 4)), np.zeros(0)),
        CostMatrix("car", np.array([[-1.0, INF], [INF, -2.0]]), (meas(0), meas(1)), (new(0), new(1))),
        Assignment("car", ((meas(0), new(0)), (meas(1), new(1))), -3.0, ()),
        Born("car", np.array([1, 2]), np.array([0, 1]), mean2, np.array([0.97, 0.4])),
        Posterior("car", np.array([1, 2]), mean2, cov, np.array([0.97, 0.4])),
        Extracted("car", (est(1, 10.0, 0.97, 0),), 0.9),
        TrackLogic("car", 1, TrackLogicAction.DELETED, 0, 4),
        frame(1),
        received([10.5, 11.0]),
        Predicted("car", np.array([1, 2]), mean2, cov, np.array([0.68, 0.28])),
        Gated(
            "car",
            np.array([1, 2]),
            np.array([0, 1]),
            np.array([[True, True], [True, False]]),
            mean2[:, :2],
            cov[:, :2, :2],
            40.0,
            np.array([[0.25, 1.0], [99.25, 101.25]]),
        ),
        CostMatrix(
            "car",
            np.array([[-5.0, -4.0, 1.0, INF], [-5.0, -4.5, INF, 1.0]]),
            (meas(0), meas(1)),
            (track(1), track(2), new(0), new(1)),
        ),
        Assignment("car", ((meas(0), track(1)), (meas(1), track(2))), -9.5, ()),
        Posterior("car", np.array([1, 2]), mean2, cov, np.array([0.99, 1e-7])),
        Pruned("car", 2, PruneReason.LOW_EXISTENCE, 1e-7),
        Extracted("car", (est(1, 11.0, 0.99, 0),), 0.9),
        Extracted("bus", (), 0.9),
        GlobalHypotheses("car", np.array([-0.1, -2.4]), ((1,), (1, 2)), ((0,), (0, 1)), ((0.99,), (0.99, 0.5)), (0, 0)),
        Merged("car", 1, (1, 3), (0.7, 0.3)),
        frame(2),
        Posterior("car", np.zeros(0, int), np.zeros((0, 4)), np.zeros((0, 4, 4)), np.zeros(0)),
        Pruned("car", 1, PruneReason.LOW_WEIGHT, 0.05),  # frame 2 is a PHD's (IntensityWeights): a weight
        Extracted("car", (), 0.9),
        Marginals("car", np.array([[0.8, 0.2]]), (track(5),), (missed(), meas(0)), "lbp", 7),
        Cardinality("car", np.array([0.1, 0.6, 0.3])),
        IntensityWeights("car", np.array([1, 3]), np.array([0.8, 0.3])),
    ]


def log_all(stream: rr.RecordingStream, events: list, **kwargs) -> TrackerLogger:
    logger = TrackerLogger(stream, T, **kwargs)
    for event in events:
        logger.emit(event)
    logger.finish()
    logger.finish()
    return logger


@pytest.fixture
def logged(saved_stream: tuple[rr.RecordingStream, Path]) -> tuple[dict, Path]:
    stream, path = saved_stream
    log_all(stream, scripted_events())
    stream.disconnect()
    return read_rows(path), path


def lines(rows: list[dict], frame_index: int) -> list[tuple[str, str]]:
    return [
        (t, lv)
        for r in at_frame(rows, frame_index)
        for t, lv in zip(r["TextLog:text"], r["TextLog:level"], strict=True)
    ]


def test_each_track_is_one_entity_with_its_box_id_label_and_trail(logged: tuple[dict, Path]) -> None:
    rows = logged[0][paths.track(T, "car", 1)]
    first = at_frame(rows, 0)[0]
    assert first["Boxes3D:labels"] == ["1"]
    np.testing.assert_allclose(first["Boxes3D:centers"], [[10.0, 2.0, 0.9]], rtol=1e-6)
    # devkit wlh (2.0, 4.5, 1.6) -> half extents along the box's x, y, z
    np.testing.assert_allclose(first["Boxes3D:half_sizes"], [[2.25, 1.0, 0.8]], rtol=1e-6)
    assert first["Boxes3D:colors"] == [int(pack_rgba(track_colors(np.array([1])))[0])]
    np.testing.assert_allclose(latest_at(rows, 1, "Boxes3D:centers"), [[11.0, 2.0, 0.9]], rtol=1e-6)
    trail = latest_at(rows, 1, "LineStrips3D:strips")
    np.testing.assert_allclose(np.array(trail[0])[:, :2], [[10.0, 2.0], [10.0, 2.0]])  # posterior means, frames 0-1
    assert not latest_at(rows, 2, "Boxes3D:centers")  # cleared when no longer reported
    assert paths.track(T, "car", 2) not in logged[0]  # a candidate never gets a box
    assert not any(p.startswith(paths.tracks(T, "bus")) for p in logged[0])


def test_an_association_line_for_every_assigned_pair_and_dim_lines_for_gated_rejects(
    logged: tuple[dict, Path],
) -> None:
    rows = logged[0]
    chosen = at_frame(rows[paths.associations(T, "car")], 1)[0]
    strips = [np.array(s) for s in chosen["LineStrips3D:strips"]]
    assert len(strips) == 2  # m0 -> 1 and m1 -> 2: every assigned (detection, track) pair
    np.testing.assert_allclose(strips[0], [[10.0, 2.0, 1.0], [10.5, 2.0, 1.0]])  # prediction of 1 -> m0
    np.testing.assert_allclose(strips[1], [[20.0, 5.0, 1.0], [11.0, 2.0, 1.0]])
    assert chosen["LineStrips3D:labels"] == ["m0 → 1 (cost -5.00)", "m1 → 2 (cost -4.50)"]
    assert chosen["LineStrips3D:colors"] == [int(c) for c in pack_rgba(track_colors(np.array([1, 2])))]
    rejected = at_frame(rows[paths.gated_pairs(T, "car")], 1)[0]
    assert rejected["LineStrips3D:labels"] == [
        "m1 in gate of 1, not used (cost -5.00)",
        "m0 in gate of 2, not used (cost -4.00)",
    ]
    # Faint: the tracks' colours (1, 2) mixed towards the background, opaque (Rerun darkens see-through lines).
    assert rejected["LineStrips3D:colors"] == [int(c) for c in faded(pack_rgba(track_colors(np.array([1, 2]))), 0.45)]
    assert not latest_at(rows[paths.associations(T, "car")], 2, "LineStrips3D:strips")


def test_gates_and_predictions_only_for_tracks_worth_it(saved_stream: tuple[rr.RecordingStream, Path]) -> None:
    stream, path = saved_stream
    log_all(stream, scripted_events(), gate_min_existence=0.5)
    stream.disconnect()
    rows = read_rows(path)
    strips = latest_at(rows[paths.gates(T, "car")], 1, "LineStrips3D:strips")
    assert len(strips) == 1  # track 1 (prior r = 0.68) only; track 2 (r = 0.28) is a candidate
    outline = np.array(strips[0])
    assert outline.shape == (33, 3)
    np.testing.assert_allclose(outline[0], outline[-1], atol=1e-9)
    np.testing.assert_allclose(np.hypot(outline[:, 0] - 10.0, outline[:, 1] - 2.0), np.sqrt(40.0), rtol=1e-6)
    np.testing.assert_allclose(outline[:, 2], 0.9, rtol=1e-6)  # at the track's box height
    assert not latest_at(rows[paths.gates(T, "car")], 2, "LineStrips3D:strips")
    assert latest_at(rows[paths.predicted(T, "car")], 1, "Points3D:positions.len") == 1
    assert latest_at(rows[paths.candidates_world(T, "car")], 1, "Points3D:positions.len") == 1


def test_decision_view_names_the_choice_the_alternative_and_the_margin(logged: tuple[dict, Path]) -> None:
    rows = logged[0]
    doc = at_frame(rows[paths.decisions(T)], 1)[0]["TextDocument:text"][0]
    assert "track 1 and 1 candidate · detections m0, m1 — closest margin 0.50 **close call**" in doc
    assert "| m0 | **track 1** | -5.00 | track 2 | -4.00 | 0.50 |" in doc
    assert "| m1 | **track 2** | -4.50 | track 1 | -5.00 | 0.50 |" in doc
    grid = rows[f"{paths.decision_matrix(T)}/cells"]
    cells = at_frame(grid, 1)[0]
    # Columns: track 1, track 2 (a candidate, but given m1), new; rows m0, m1; finite cells only.
    assert cells["Boxes2D:labels"] == ["-5.0", "-4.0", "1.0", "-5.0", "-4.5", "1.0"]
    chosen = at_frame(rows[f"{paths.decision_matrix(T)}/chosen"], 1)[0]
    np.testing.assert_allclose(chosen["Boxes2D:centers"], [[0.5, 0.5], [1.5, 1.5]])
    axes = at_frame(rows[f"{paths.decision_matrix(T)}/axes"], 1)[0]["Points2D:labels"]
    assert axes == ["car, margin 0.50", "1", "2", "new", "m0", "m1"]
    frame0 = at_frame(rows[paths.decisions(T)], 0)[0]["TextDocument:text"][0]
    assert "2 detections no track competed for (outside every gate, or dearer than a new track by over 5)" in frame0
    assert "so each is a new track or clutter: m0, m1" in frame0


def test_story_log_tells_each_reported_track_and_aggregates_candidates(logged: tuple[dict, Path]) -> None:
    rows = logged[0][paths.events(T, "car")]
    frame0 = lines(rows, 0)
    assert ("track 1 confirmed (r=0.97, from m0)", "INFO") in frame0
    assert ("2 new candidates from m0, m1; 0 candidates pruned", "DEBUG") in frame0
    assert ("track 1 deleted (no hit in its last 4 frames)", "WARN") in frame0
    frame1 = lines(rows, 1)
    took = (
        "close call: m1 → track 2 (cost -4.50) over track 1 (-5.00), which took m0 (the lower total wins), margin 0.50"
    )
    assert (took, "INFO") in frame1  # the cheaper track 1 lost m1 because it took m0: said (truth48)
    assert ("0 new candidates; 1 candidates pruned", "DEBUG") in frame1
    assert ("merged 1, 3 into track 1 (weights 0.7, 0.3)", "INFO") in frame1
    assert any(t.startswith("2 detections: 2 updated tracks, 0 new or clutter") for t, _ in frame1)
    assert ("track 1 ended: mixture weight below pruning threshold (last w=0.05)", "WARN") in lines(rows, 2)
    assert max(len(t) for r in rows if "TextLog:text" in r for t in r["TextLog:text"]) < 200


def test_series_per_reported_track_one_chunk_each_and_candidates_counted(logged: tuple[dict, Path]) -> None:
    rows, path = logged
    series = rows[paths.existence(T, "car", 1)]
    temporal = [r for r in series if not r["static"]]
    assert [r["frame"] for r in temporal] == [0, 1]
    assert [r["Scalars:scalars"][0] for r in temporal] == pytest.approx([0.97, 0.99])
    assert [r for r in series if r["static"]][0]["SeriesLines:names"] == ["1 car existence"]
    chunks = [c for c in RrdReader(path).store().stream() if c.entity_path == "/" + paths.existence(T, "car", 1)]
    assert len([c for c in chunks if not c.is_static]) == 1
    nis = [r["Scalars:scalars"][0] for r in rows[paths.nis(T, "car", 1)] if not r["static"]]
    assert nis == pytest.approx([0.25])  # m0 at 0.5 m from the prediction, S = I
    cost = [r["Scalars:scalars"][0] for r in rows[paths.chosen_cost(T, "car", 1)] if not r["static"]]
    assert cost == pytest.approx([-5.0])
    # Track 2 was never reported: no series of its own, only the per-class candidate count.
    assert paths.existence(T, "car", 2) not in rows and paths.nis(T, "car", 2) not in rows
    counts = [r["Scalars:scalars"][0] for r in rows[paths.candidate_count(T, "car")] if not r["static"]]
    assert counts == [0.0, 0.0]  # at frame 1 both tracks were drawn (default gate_min_existence 0.1)


def test_tracker_specific_plots(logged: tuple[dict, Path]) -> None:
    rows = logged[0]
    weights = [r["Scalars:scalars"] for r in rows[paths.hypothesis_weights(T, "car")] if not r["static"]]
    assert weights[0][:2] == pytest.approx([-0.1, -2.4]) and np.isnan(weights[0][2:]).all()
    names = [r for r in rows[paths.hypothesis_weights(T, "car")] if r["static"]][0]["SeriesLines:names"]
    assert names[:2] == ["car h0", "car h1"]
    marg = at_frame(rows[paths.marginals(T, "car")], 2)[0]
    assert marg["Tensor:data"][0]["buffer"] == pytest.approx([0.8, 0.2])
    assert marg["Tensor:value_range"][0] == [0.0, 1.0]
    assert at_frame(rows[paths.cardinality_pmf(T, "car")], 2)[0]["BarChart:values"][0]["buffer"] == pytest.approx(
        [0.1, 0.6, 0.3]
    )
    mean = [r["Scalars:scalars"][0] for r in rows[paths.cardinality_mean(T, "car")] if not r["static"]]
    assert mean == pytest.approx([1.2])
    total = [r["Scalars:scalars"][0] for r in rows[paths.intensity_total(T, "car")] if not r["static"]]
    assert total == pytest.approx([1.1])


def test_focus_logs_only_its_frames_but_keeps_the_history(saved_stream: tuple[rr.RecordingStream, Path]) -> None:
    stream, path = saved_stream
    logger = log_all(stream, scripted_events(), clock=Clock(focus_end=1), log_frames=range(1, 3), focus_tracks={2})
    stream.disconnect()
    rows = read_rows(path)
    assert not at_frame(rows[paths.track(T, "car", 1)], 0)  # frame 0 is outside the recorded window
    (box,) = [r for r in at_frame(rows[paths.track(T, "car", 1)], 1) if "Boxes3D:labels" in r]  # beside the trail row
    assert box["Boxes3D:labels"] == ["1"]
    assert box["Boxes3D:show_labels"] == [False]  # not involved: its id a click away, not on screen
    # Track 1 is not involved: drawn pale so that the focused track 2 stands out.
    pale = faded(pack_rgba(track_colors(np.array([1]))), DIMMED_KEEP)
    assert box["Boxes3D:colors"] == [int(pale[0])]
    assert [r["frame"] for r in rows[paths.existence(T, "car", 1)] if not r["static"]] == [0, 1]  # history
    assert [r.get("focus") for r in rows[paths.existence(T, "car", 1)] if not r["static"]] == [0, 1]
    assert {r.get("focus") for r in at_frame(rows[paths.track(T, "car", 1)], 1)} == {1}
    assert {r.get("focus") for r in at_frame(rows[paths.track(T, "car", 1)], 2)} == {None}  # past the focus
    assert logger.has_gates  # the scripted tracker gates (greedy does not)
    step = logger.facts.steps(2, "car")[1]  # what the focus document and callouts read of the focused track
    assert (step.prior_existence, step.used, step.output) == (pytest.approx(0.28), (1,), None)
    assert step.gated == ((0, 99.25),)
    focused = rows[paths.predicted_focus(T, "car")]
    assert at_frame(focused, 1)[0]["Points3D:labels"] == ["2 predicted r=0.28"]
    style = {k: v for r in rows[paths.existence(T, "car", 2)] if r["static"] for k, v in r.items()}
    own = [int(pack_rgba(np.array([INVOLVED_PALETTE[0]]))[0])]  # its plot line: a distinct colour
    assert style["SeriesLines:colors"] == own and style["SeriesPoints:colors"] == own
    assert style["SeriesPoints:markers"] == [1]  # circles: a single sample shows too
    assert not [r for r in rows[paths.existence(T, "car", 1)] if "SeriesPoints:markers" in r]  # not involved
    # The label is shown by the focus callouts (viz.callouts), in a column, not on the point.
    assert [r for r in focused if r["static"]][0]["Points3D:show_labels"] == [False]


def test_events_outside_a_frame_and_unknown_events_are_rejected(saved_stream) -> None:
    stream, _ = saved_stream
    logger = TrackerLogger(stream, T)
    with pytest.raises(RuntimeError, match="FrameStarted"):
        logger.emit(Extracted("car", (), 0.9))
    logger.emit(frame(0))
    with pytest.raises(TypeError, match="cannot keep"):
        logger.emit("not an event")  # type: ignore[arg-type]
    stream.disconnect()


def test_logger_is_a_sink_usable_in_a_tee() -> None:
    from gnnpmb.events import EventSink, TeeSink

    assert isinstance(TrackerLogger(rr.RecordingStream("x"), T), EventSink)
    assert TeeSink(ListSink(), TrackerLogger(rr.RecordingStream("y"), T)).enabled


def test_two_trackers_share_one_recording_without_touching_each_other(saved_stream) -> None:
    stream, path = saved_stream
    for name, x in [("gnnpmb", 10.0), ("pmbm", 50.0)]:
        logger = TrackerLogger(stream, name, log_predicted=False)
        for event in scripted_events():
            if isinstance(event, FrameStarted):
                event = frame(event.frame_index, name)
            elif isinstance(event, Extracted) and event.estimates:
                event = Extracted("car", (est(1, x, 0.97),), 0.9)
            logger.emit(event)
        logger.finish()
    stream.disconnect()
    rows = read_rows(path)
    for name, x in [("gnnpmb", 10.0), ("pmbm", 50.0)]:
        assert latest_at(rows[paths.track(name, "car", 1)], 1, "Boxes3D:centers")[0][0] == pytest.approx(x)
        assert len([r for r in rows[paths.existence(name, "car", 1)] if not r["static"]]) == 2
        assert paths.predicted(name, "car") not in rows


def test_pmbm_hypotheses_are_listed_with_what_tells_them_apart(saved_stream) -> None:
    stream, path = saved_stream
    events = scripted_events()
    at = next(i for i, e in enumerate(events) if isinstance(e, GlobalHypotheses))
    events[at] = GlobalHypotheses(
        "car",
        np.log(np.array([0.6, 0.3, 0.1])),
        ((1, 2), (1, 2), (1,)),
        ((0, 0), (0, 5), (0,)),
        ((0.99, 0.1), (0.99, 0.2), (0.99,)),
        (0, 0, 0),
    )
    log_all(stream, events)
    stream.disconnect()
    doc = at_frame(read_rows(path)[paths.decisions(T)], 1)[0]["TextDocument:text"][0]
    assert "### car: 3 global hypotheses kept" in doc
    assert "| h0 | 0.600 | (the best, shown in the views) |" in doc
    assert "| h1 | 0.300 | other association for 1 candidate |" in doc
    assert "| h2 | 0.100 | without 1 candidate |" in doc


def test_no_existence_series_or_story_existence_for_a_tracker_without_existence_but_the_rest_is_drawn(
    saved_stream: tuple[rr.RecordingStream, Path],
) -> None:
    stream, path = saved_stream
    log_all(stream, scripted_events(), has_existence=False)
    stream.disconnect()
    rows = read_rows(path)
    assert not [p for p in rows if p.startswith(paths.existence_root(T) + "/")]
    assert [r["Scalars:scalars"][0] for r in rows[paths.nis(T, "car", 1)] if not r["static"]] == pytest.approx([0.25])
    assert any("LineStrips3D:strips" in r for r in at_frame(rows[paths.track(T, "car", 1)], 1))  # its trail
    assert paths.candidate_count(T, "car") not in rows  # every track counts: no candidates
    # The story names no existence either (a track-logic tracker's events carry 1).
    story = rows[paths.events(T, "car")]
    assert ("track 1 confirmed (from m0)", "INFO") in lines(story, 0)
    assert ("track 1 ended: mixture weight below pruning threshold", "WARN") in lines(story, 2)


def test_a_phd_filters_series_name_a_weight(saved_stream: tuple[rr.RecordingStream, Path]) -> None:
    """A PHD track's value is an expected number of objects (1.10 on the dev set), not an existence probability:
    its series and its plot say "weight", and the plot that the events cap it at 1 (dev set scene-0916, megvii,
    phd, ``--focus id_switch:1``)."""
    from gnnpmb.runs import tracker_capabilities
    from tests.viz.test_blueprint import stored_views
    from viz.blueprint import default_blueprint, existence_word

    stream, path = saved_stream
    log_all(stream, scripted_events(), existence_word=existence_word(tracker_capabilities("phd")))
    stream.disconnect()
    rows = read_rows(path)
    assert [r for r in rows[paths.existence(T, "car", 1)] if r["static"]][0]["SeriesLines:names"] == ["1 car weight"]
    bp = path.with_name("bp.rrd")
    out = rr.RecordingStream("bp-test")
    out.save(bp, default_blueprint=default_blueprint(["phd", "cphd", "gnnpmb"], ["car"]))
    out.disconnect()
    names = stored_views(bp)
    assert names["phd weight (capped at 1)"][1] == paths.existence_root("phd") and "cphd weight (capped at 1)" in names
    assert names["gnnpmb existence"][1] == paths.existence_root("gnnpmb") and "phd existence" not in names


def test_in_a_focus_a_run_with_no_involved_track_labels_none(saved_stream: tuple[rr.RecordingStream, Path]) -> None:
    """The other run of ``--focus diff:introduced:1`` (dev set scene-0103) has no involved track: it labelled every
    track, 15 a frame, overlapping; a focus recording labels its involved tracks only."""
    stream, path = saved_stream
    log_all(stream, scripted_events(), clock=Clock(focus_end=1), log_frames=range(1, 3), focus_tracks=set())
    stream.disconnect()
    (box,) = [r for r in at_frame(read_rows(path)[paths.track(T, "car", 1)], 1) if "Boxes3D:labels" in r]
    assert box["Boxes3D:labels"] == ["1"] and box["Boxes3D:show_labels"] == [False]


def test_a_phd_labels_plot_takes_its_heaviest_components_weight(saved_stream: tuple[rr.RecordingStream, Path]) -> None:
    """A GM-PHD label with two components (0.319, 0.088) is one series: the plot showed the last row's 0.09 where
    the focus text and the story gave the label's 0.32 (viewer review, dev set scene-0916 megvii phd id_switch:1,
    track 8 at frame 13)."""
    stream, path = saved_stream
    mean = np.array([[10.0, 2.0, 0.0, 0.0], [12.0, 2.0, 0.0, 0.0]])
    cov = np.tile(np.eye(4), (2, 1, 1))
    events = [frame(0), received([10.0]), Posterior("car", np.array([8, 8]), mean, cov, np.array([0.319, 0.088]))]
    events += [Extracted("car", (), 0.5)]
    log_all(stream, events, focus_tracks={8})
    stream.disconnect()
    samples = [r["Scalars:scalars"][0] for r in at_frame(read_rows(path)[paths.existence(T, "car", 8)], 0)]
    assert samples == pytest.approx([0.319])


def test_a_phd_component_lighter_than_another_of_its_label_says_whose_it_is() -> None:
    """A PHD track's id names its heaviest component (as the story and the focus text do); its lighter components
    say they are its, with w, not r, for a weight (dev set scene-0553 phd: '29 predicted r=0.14' beside 29's 1.00)."""
    from types import SimpleNamespace

    from viz.logger import TrackerLogger, _lighter

    ids, weight = np.array([29, 29, 7]), np.array([0.14, 1.0, 0.6])
    raw = {"ids": ids, "existence": weight, "lighter": _lighter(ids, weight)}
    phd = SimpleNamespace(existence_word="weight")
    assert TrackerLogger._point_labels(phd, "%d predicted {}=%.2f", raw) == [
        "a lighter component of 29, w=0.140",
        "29 predicted w=1.00",
        "7 predicted w=0.60",
    ]
    pmb = SimpleNamespace(existence_word="existence")
    assert TrackerLogger._point_labels(pmb, "candidate %d, {}=%.3f", raw)[0] == "candidate 29, r=0.140"


def test_a_phd_tracks_association_line_starts_at_its_heaviest_component(
    saved_stream: tuple[rr.RecordingStream, Path],
) -> None:
    """A GM-PHD label predicted as two components (w 0.32 at x 10, w 0.004 at x 14, listed last) used m0: its
    line starts where its predicted point ("8 predicted w=0.32") stands, at the heaviest component. It started at
    the last one listed: dev set scene-0103 cphd ``--focus identity_theft:1``, "m0 → 23" ran from a component of
    weight 0.004, 6 m from 23's predicted point and its focus label."""
    from gnnpmb.events import UpdateWeights

    stream, path = saved_stream
    mean = np.array([[10.0, 2.0, 0.0, 0.0], [14.0, 2.0, 0.0, 0.0]])
    cov = np.tile(np.eye(4), (2, 1, 1))
    events = [
        frame(0),
        received([10.5]),
        Predicted("car", np.array([8, 8]), mean, cov, np.array([0.32, 0.004])),
        UpdateWeights(
            "car",
            np.array([8]),
            np.array([0]),
            np.array([0.324]),
            np.array([0.1]),
            np.array([[0.224]]),
            np.array([0.01]),
        ),
        Posterior("car", np.array([8]), mean[:1], cov[:1], np.array([0.3])),
        Extracted("car", (), 0.5),
    ]
    log_all(stream, events, focus_tracks={8}, has_existence=True, existence_word="weight")
    stream.disconnect()
    rows = read_rows(path)
    (line,) = latest_at(rows[paths.associations(T, "car")], 0, "LineStrips3D:strips")
    labels = latest_at(rows[paths.predicted_focus(T, "car")], 0, "Points3D:labels")
    assert labels[0] == "8 predicted w=0.32"
    np.testing.assert_allclose(np.array(line)[0, :2], [10.0, 2.0])  # the heaviest component's mean
