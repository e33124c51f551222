"""Row buffering: the Arrow arrays built for a flush equal Rerun's own conversion, and rows sent for many
entities at once read back per entity, on the right timelines."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import rerun as rr
from rerun.components import LineStrip2DBatch, LineStrip3DBatch

from tests.viz.rrd import read_rows
from viz.rows import EntityRows, RowBuffer, send_entities, strips_array
from viz.timeline import Clock

T0_US = 1_533_151_603_547_590


def test_strips_built_at_once_equal_rerun_s_own_conversion() -> None:
    rng = np.random.default_rng(0)
    ragged = [rng.normal(size=(k, 3)) for k in (2, 5, 1, 11)]
    same_length = rng.normal(size=(3, 33, 3))
    rows = [ragged, same_length, [], [[(0.0, 1.0, 2.0), (3.0, 4.0, 5.0)]]]
    flat = [*ragged, *same_length, np.array([[0.0, 1.0, 2.0], [3.0, 4.0, 5.0]])]
    assert strips_array([strip for row in rows for strip in row]).equals(LineStrip3DBatch(flat).as_arrow_array())
    assert strips_array([]).equals(LineStrip3DBatch([]).as_arrow_array())
    pixels = [rng.normal(size=(k, 2)).astype(np.float32) for k in (2, 7, 3)]
    assert strips_array(pixels, dims=2).equals(LineStrip2DBatch(pixels).as_arrow_array())
    assert strips_array([], dims=2).equals(LineStrip2DBatch([]).as_arrow_array())


def _stamps(frames: list[int]) -> np.ndarray:
    return T0_US + 500_000 * np.asarray(frames, dtype=np.int64)


def test_entities_sent_together_keep_their_rows_and_the_focus_timeline_ends_at_focus_end(
    saved_stream: tuple[rr.RecordingStream, Path],
) -> None:
    stream, path = saved_stream
    clock = Clock(focus_end=1)
    a = EntityRows("s/a", np.array([0, 1, 2]), _stamps([0, 1, 2]), {"scalars": (np.array([0.5, 0.6, 0.7]), np.ones(3))})
    late = EntityRows("s/late", np.array([2, 3]), _stamps([2, 3]), {"scalars": (np.array([1.0, 2.0]), np.ones(2))})
    wide = EntityRows("s/wide", np.array([1, 2]), _stamps([1, 2]), {"scalars": (np.arange(6.0), np.array([4, 2]))})
    send_entities(stream, clock, rr.Scalars, [a, late, wide])
    stream.disconnect()
    rows = read_rows(path)
    got = {
        p: [(r["frame"], r.get("focus"), r["Scalars:scalars"]) for r in rows[f"s/{p}"]] for p in ("a", "late", "wide")
    }
    assert got["a"] == [(0, 0, [0.5]), (1, 1, [0.6]), (2, None, [0.7])]
    assert got["late"] == [(2, None, [1.0]), (3, None, [2.0])]  # nothing of it on the focus timeline
    assert got["wide"] == [(1, 1, [0.0, 1.0, 2.0, 3.0]), (2, None, [4.0, 5.0])]
    stamps = [r["timestamp"].value // 1000 for r in rows["s/a"]]
    assert stamps == _stamps([0, 1, 2]).tolist()


def test_buffered_rows_read_back_per_entity_with_clears_as_empty_rows(
    saved_stream: tuple[rr.RecordingStream, Path],
) -> None:
    stream, path = saved_stream
    buffer = RowBuffer(stream, Clock())
    for frame in (0, 1):
        for k, path_k in enumerate(("w/p", "w/q")):
            xyz = np.full((k + 1, 3), float(frame))
            buffer.put(path_k, rr.Points3D, frame, _stamps([frame])[0], k + 1, positions=xyz, labels=["x"] * (k + 1))
            buffer.put(path_k, rr.Boxes3D, frame, _stamps([frame])[0], 1, centers=np.full((1, 3), float(frame + k)))
    buffer.put("w/q", rr.LineStrips3D, 1, _stamps([1])[0], 1, strips=[np.zeros((2, 3))])
    buffer.clear("w/q", 2, _stamps([2])[0])
    buffer.flush()
    stream.disconnect()
    rows = read_rows(path)
    # Points3D positions read back as their length (tests.viz.rrd.LENGTH_ONLY)
    p = [(r["frame"], r["Points3D:positions.len"], r["Points3D:labels"]) for r in rows["w/p"] if "Points3D:labels" in r]
    assert p == [(0, 1, ["x"]), (1, 1, ["x"])]
    assert [(r["frame"], r["Boxes3D:centers"]) for r in rows["w/q"] if "Boxes3D:centers" in r] == [
        (0, [[1.0, 1.0, 1.0]]),
        (1, [[2.0, 2.0, 2.0]]),
        (2, []),
    ]
    q_points = [(r["frame"], r["Points3D:positions.len"]) for r in rows["w/q"] if "Points3D:labels" in r]
    assert q_points == [(0, 2), (1, 2), (2, 0)]  # the clear: an empty batch from frame 2 on
    q_strips = [(r["frame"], r["LineStrips3D:strips"]) for r in rows["w/q"] if "LineStrips3D:strips" in r]
    assert q_strips == [(1, [[[0.0, 0.0, 0.0], [0.0, 0.0, 0.0]]]), (2, [])]


def test_rows_out_of_frame_order_are_refused_with_a_focus_clock(saved_stream: tuple[rr.RecordingStream, Path]) -> None:
    stream, _ = saved_stream
    rows = EntityRows("s/x", np.array([2, 1]), _stamps([2, 1]), {"scalars": (np.array([1.0, 2.0]), np.ones(2))})
    with pytest.raises(ValueError, match="not in frame order"):
        send_entities(stream, Clock(focus_end=1), rr.Scalars, [rows])


def test_a_row_builder_runs_once_per_flush_over_every_row_of_the_entity(
    saved_stream: tuple[rr.RecordingStream, Path],
) -> None:
    stream, path = saved_stream
    calls: list[int] = []

    def boxes(raw: dict[str, np.ndarray]) -> dict[str, object]:
        calls.append(raw["x"].size)
        return {
            "centers": np.column_stack([raw["x"], np.zeros((raw["x"].size, 2))]),
            "labels": [f"{x:g}" for x in raw["x"]],
        }

    buffer = RowBuffer(stream, Clock())
    buffer.put("b", rr.Boxes3D, 0, _stamps([0])[0], 2, build=boxes, x=np.array([1.0, 2.0]))
    buffer.put("b", rr.Boxes3D, 1, _stamps([1])[0], 1, build=boxes, x=np.array([3.0]))
    buffer.clear("b", 2, _stamps([2])[0])
    buffer.flush()
    stream.disconnect()
    assert calls == [3]
    rows = [(r["frame"], [c[0] for c in r["Boxes3D:centers"]], r["Boxes3D:labels"]) for r in read_rows(path)["b"]]
    assert rows == [(0, [1.0, 2.0], ["1", "2"]), (1, [3.0], ["3"]), (2, [], [])]
