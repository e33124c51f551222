"""Gate clustering: scipy's connected components vs the union-find with pointer jumping, on gate matrices of
the sizes the trackers see.

Usage: uv run python benchmarks/gate_clustering.py [--repeats 2000]

Prints the median time per call of each way to split a (K, M) gate matrix into its connected blocks
(bipartite components), for a sparse gate matrix like one class's frame (K tracks, M = K detections, about two
gated detections per track) at K = 5, 20, 80 and 320: ``gate_clusters`` (the union-find the trackers use) and
scipy's connected components (labels only, so a lower bound of that way). Run it on an otherwise idle machine.
"""

from __future__ import annotations

import argparse
import time
from collections.abc import Callable

import numpy as np
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import connected_components

from gnnpmb.assign.clusters import gate_clusters

SIZES: tuple[int, ...] = (5, 20, 80, 320)


def gate_matrix(k: int, rng: np.random.Generator) -> np.ndarray:
    """(K, K) bool: tracks and detections on a line, gated to their neighbours within about one spacing."""
    tracks = np.sort(rng.uniform(0.0, k, size=k))
    meas = np.sort(rng.uniform(0.0, k, size=k))
    return np.abs(tracks[:, None] - meas[None, :]) < 1.0


def scipy_components(inside: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The alternative: component labels of every track and measurement by scipy's ``connected_components``
    (what ``vector/clusters.py`` and ``assign/exact_marginals.py`` used); cutting them into clusters costs more."""
    k, m = inside.shape
    rows, cols = np.nonzero(inside)
    graph = coo_matrix((np.ones(len(rows), dtype=np.int8), (rows, k + cols)), shape=(k + m, k + m))
    _, labels = connected_components(graph, directed=False)
    return labels[:k], labels[k:]


def candidates() -> dict[str, Callable[[np.ndarray], object]]:
    return {"scipy connected_components": scipy_components, "union-find (gate_clusters)": gate_clusters}


def median_time_s(fn: Callable[[np.ndarray], object], inside: np.ndarray, repeats: int) -> float:
    times = []
    for _ in range(repeats):
        start = time.perf_counter()
        fn(inside)
        times.append(time.perf_counter() - start)
    return float(np.median(times))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=2000)
    args = parser.parse_args()
    rng = np.random.default_rng(0)
    print(f"{'K':>5} " + " ".join(f"{name:>28}" for name in candidates()))
    for k in SIZES:
        inside = gate_matrix(k, rng)
        row = [median_time_s(fn, inside, args.repeats) for fn in candidates().values()]
        print(f"{k:>5} " + " ".join(f"{1e6 * t:>25.1f} us" for t in row))


if __name__ == "__main__":
    main()
