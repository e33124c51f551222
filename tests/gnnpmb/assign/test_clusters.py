"""Gated clusters = connected components of the track-measurement gate graph."""

from __future__ import annotations

import numpy as np

from gnnpmb.assign import clusters
from gnnpmb.assign.clusters import gate_clusters


def as_lists(clusters):
    return [(c.tracks.tolist(), c.meas.tolist()) for c in clusters]


def test_hand_made_gate_splits_into_components():
    inside = np.zeros((5, 6), dtype=bool)
    inside[0, [0, 1]] = True
    inside[2, 1] = True  # track 2 joins track 0 through measurement 1
    inside[1, 3] = True
    inside[4, [4, 5]] = True  # track 3 and measurement 2 gate nothing
    assert as_lists(gate_clusters(inside)) == [([0, 2], [0, 1]), ([1], [3]), ([4], [4, 5])]


def test_empty_and_ungated():
    assert gate_clusters(np.zeros((0, 3), dtype=bool)) == []
    assert gate_clusters(np.zeros((3, 0), dtype=bool)) == []
    assert gate_clusters(np.zeros((2, 2), dtype=bool)) == []


def test_chain_is_one_cluster():
    inside = np.eye(4, dtype=bool) | np.eye(4, k=1, dtype=bool)  # t0-m0-t... a chain through every node
    assert as_lists(gate_clusters(inside)) == [([0, 1, 2, 3], [0, 1, 2, 3])]


def reference_components(inside: np.ndarray) -> set[tuple[tuple[int, ...], tuple[int, ...]]]:
    """Flood fill from every gated track (independent reference)."""
    k, m = inside.shape
    seen_t: set[int] = set()
    out = set()
    for start in range(k):
        if start in seen_t or not inside[start].any():
            continue
        tracks, meas, stack = {start}, set(), [start]
        while stack:
            t = stack.pop()
            for j in np.flatnonzero(inside[t]).tolist():
                if j not in meas:
                    meas.add(j)
                    for t2 in np.flatnonzero(inside[:, j]).tolist():
                        if t2 not in tracks:
                            tracks.add(t2)
                            stack.append(t2)
        seen_t |= tracks
        out.add((tuple(sorted(tracks)), tuple(sorted(meas))))
    return out


def test_random_gates_match_flood_fill():
    rng = np.random.default_rng(3)
    for _ in range(20):
        k, m = rng.integers(0, 30, size=2)
        inside = rng.random((k, m)) < 0.06
        clusters = gate_clusters(inside)
        found = {(tuple(c.tracks.tolist()), tuple(c.meas.tolist())) for c in clusters}
        assert found == reference_components(inside)
        firsts = [int(c.tracks[0]) for c in clusters]
        assert firsts == sorted(firsts)


def test_small_and_large_graph_paths_agree(monkeypatch):
    """The Python union-find for small graphs gives the NumPy path's clusters, array for array (order, dtype),
    with and without isolated tracks."""
    rng = np.random.default_rng(5)
    cases = [rng.random((k, m)) < p for k, m, p in [(3, 12, 0.3), (6, 25, 0.15), (12, 40, 0.1), (1, 1, 1.0)]]
    cases += [rng.random((int(k), int(m))) < 0.1 for k, m in rng.integers(1, 20, size=(30, 2))]
    for isolated in (False, True):
        small = [gate_clusters(inside, isolated) for inside in cases]
        monkeypatch.setattr(clusters, "SMALL_GRAPH_EDGES", -1)
        large = [gate_clusters(inside, isolated) for inside in cases]
        monkeypatch.undo()
        for got, want in zip(small, large, strict=True):
            assert len(got) == len(want)
            for g, w in zip(got, want, strict=True):
                for x, y in ((g.tracks, w.tracks), (g.meas, w.meas)):
                    assert x.dtype == y.dtype and x.shape == y.shape and (x == y).all()
