"""Gated clusters: connected components of the bipartite track-measurement gate graph.

Tracks k and measurements j are the nodes; (k, j) is an edge iff j is inside k's gate. Data-association events
of different components are independent, so JPDA's marginal association probabilities factorise over them
(Fortmann, Bar-Shalom & Scheffe 1983, cluster decomposition) and each cluster can be solved on its own.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import connected_components


@dataclass(frozen=True, slots=True)
class Cluster:
    """One connected component with at least one gated pair: tracks (K_c,) and meas (M_c,) are the sorted row
    and column indices of its members in the (K, M) gate matrix."""

    tracks: np.ndarray
    meas: np.ndarray


def gate_clusters(inside: np.ndarray) -> list[Cluster]:
    """Connected components of the gate graph of a (K, M) bool matrix that contain at least one gated pair.

    Tracks and measurements with no gated partner belong to no cluster. Clusters are ordered by their smallest
    track index, so the same gate matrix always gives the same list.
    """
    k, m = inside.shape
    rows, cols = np.nonzero(inside)
    if len(rows) == 0:
        return []
    graph = coo_matrix((np.ones(len(rows), dtype=np.int8), (rows, k + cols)), shape=(k + m, k + m))
    _, labels = connected_components(graph, directed=False)
    track_label, meas_label = labels[:k], labels[k:]
    used = np.unique(track_label[rows])  # components with at least one edge
    t_order = np.argsort(track_label, kind="stable")  # stable: indices ascending within a component
    m_order = np.argsort(meas_label, kind="stable")
    t_sorted, m_sorted = track_label[t_order], meas_label[m_order]
    t_lo, t_hi = np.searchsorted(t_sorted, used, "left"), np.searchsorted(t_sorted, used, "right")
    m_lo, m_hi = np.searchsorted(m_sorted, used, "left"), np.searchsorted(m_sorted, used, "right")
    clusters = [
        Cluster(tracks=t_order[a:b], meas=m_order[c:d])
        for a, b, c, d in zip(t_lo.tolist(), t_hi.tolist(), m_lo.tolist(), m_hi.tolist(), strict=True)
    ]
    clusters.sort(key=lambda c: int(c.tracks[0]))
    return clusters
