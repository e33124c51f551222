"""Every Rerun entity path of the recording, in one place.

Spatial entities live under ``world/`` and mirror the transform tree: ``world`` (static, Z-up), ``world/ego_vehicle``
(ego pose per frame), ``world/ego_vehicle/LIDAR_TOP`` (static calibration; points in the sensor frame). Boxes, gates
and tracks are in the nuScenes global frame, so they hang directly under ``world``. Each tracker gets its own
subtree (``world/trackers/<tracker>/...`` for 3D things, ``trackers/<tracker>/...`` for plots, tensors and logs),
so several trackers fit in one recording and a view can show one of them with a ``/**`` filter.
"""

from __future__ import annotations

ROOT = "/"
WORLD = "world"
EGO = f"{WORLD}/ego_vehicle"
EGO_BODY = f"{EGO}/body"
LIDAR = f"{EGO}/LIDAR_TOP"
GT = f"{WORLD}/gt"
DETECTIONS = f"{WORLD}/detections"
DETECTIONS_KEPT = f"{DETECTIONS}/kept"
DETECTIONS_SUPPRESSED = f"{DETECTIONS}/suppressed"
WORLD_TRACKERS = f"{WORLD}/trackers"
TRACKERS = "trackers"
SCENE_INFO = "scene/info"


def _name(part: str) -> str:
    """An entity-path segment; tracker and class names are plain identifiers, ids are integers."""
    if not part or "/" in part or part.strip() != part:
        raise ValueError(f"invalid entity path segment {part!r}")
    return part


# Spatial, per tracker (global frame).
def tracker_world(tracker: str) -> str:
    return f"{WORLD_TRACKERS}/{_name(tracker)}"


def tracks(tracker: str, class_name: str) -> str:
    """Boxes3D of the extracted tracks of one class."""
    return f"{tracker_world(tracker)}/tracks/{_name(class_name)}"


def predicted(tracker: str, class_name: str) -> str:
    """Points3D of the predicted track means (prior) of one class."""
    return f"{tracker_world(tracker)}/predicted/{_name(class_name)}"


def gates(tracker: str, class_name: str) -> str:
    """LineStrips3D of the gate ellipses of one class."""
    return f"{tracker_world(tracker)}/gates/{_name(class_name)}"


def failures_world(tracker: str, kind: str) -> str:
    """3D markers of one kind of tracking failure (e.g. id switches, false tracks)."""
    return f"{tracker_world(tracker)}/failures/{_name(kind)}"


# Non-spatial, per tracker.
def tracker_root(tracker: str) -> str:
    return f"{TRACKERS}/{_name(tracker)}"


def cost_matrix(tracker: str, class_name: str, hypothesis: int = 0) -> str:
    """Tensor of the assignment cost of one class; hypothesis 0 (the best) has the short path."""
    if hypothesis == 0:
        return f"{tracker_root(tracker)}/cost/{_name(class_name)}"
    return f"{tracker_root(tracker)}/cost_hypotheses/{_name(class_name)}/{int(hypothesis)}"


def cost_axes(tracker: str, class_name: str) -> str:
    """TextDocument naming the rows and columns of the cost matrix of hypothesis 0, with its values."""
    return f"{tracker_root(tracker)}/cost_axes/{_name(class_name)}"


def existence_root(tracker: str) -> str:
    return f"{tracker_root(tracker)}/existence"


def existence(tracker: str, class_name: str, track_id: int) -> str:
    """Scalars: the existence probability of one track over time."""
    return f"{existence_root(tracker)}/{_name(class_name)}/{int(track_id)}"


def candidates_root(tracker: str) -> str:
    return f"{tracker_root(tracker)}/candidates"


def candidate_existence(tracker: str, class_name: str, track_id: int) -> str:
    """Scalars: the existence probability over time of a Bernoulli that was never output as a track (a candidate
    that stayed below the extraction threshold); kept apart so the default existence plot shows real tracks."""
    return f"{candidates_root(tracker)}/{_name(class_name)}/{int(track_id)}"


def events_root(tracker: str) -> str:
    return f"{tracker_root(tracker)}/events"


def events(tracker: str, class_name: str) -> str:
    """TextLog of births, prunings, assignments, confirmations and merges of one class."""
    return f"{events_root(tracker)}/{_name(class_name)}"


def hypotheses_root(tracker: str) -> str:
    return f"{tracker_root(tracker)}/hypotheses"


def hypothesis_weight(tracker: str, class_name: str, rank: int) -> str:
    """Scalars: log weight of the rank-th best PMBM global hypothesis."""
    return f"{hypotheses_root(tracker)}/{_name(class_name)}/{int(rank)}"


def marginals(tracker: str, class_name: str) -> str:
    """Tensor of marginal association probabilities (TO-PMB, JPDA)."""
    return f"{tracker_root(tracker)}/marginals/{_name(class_name)}"


def cardinality_pmf_root(tracker: str) -> str:
    return f"{tracker_root(tracker)}/cardinality/pmf"


def cardinality_pmf(tracker: str, class_name: str) -> str:
    """BarChart of the CPHD cardinality distribution."""
    return f"{cardinality_pmf_root(tracker)}/{_name(class_name)}"


def cardinality_mean_root(tracker: str) -> str:
    return f"{tracker_root(tracker)}/cardinality/expected"


def cardinality_mean(tracker: str, class_name: str) -> str:
    """Scalars: expected number of targets under the CPHD cardinality distribution."""
    return f"{cardinality_mean_root(tracker)}/{_name(class_name)}"


def intensity_weights_root(tracker: str) -> str:
    return f"{tracker_root(tracker)}/intensity/weights"


def intensity_weights(tracker: str, class_name: str) -> str:
    """BarChart of GM-PHD / CPHD component weights."""
    return f"{intensity_weights_root(tracker)}/{_name(class_name)}"


def intensity_total_root(tracker: str) -> str:
    return f"{tracker_root(tracker)}/intensity/total"


def intensity_total(tracker: str, class_name: str) -> str:
    """Scalars: total intensity weight (the PHD's expected number of targets)."""
    return f"{intensity_total_root(tracker)}/{_name(class_name)}"


def failure_count(tracker: str, kind: str) -> str:
    """Scalars: number of failures of one kind per frame."""
    return f"{tracker_root(tracker)}/failures/{_name(kind)}"
