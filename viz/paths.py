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
SWEEPS = f"{WORLD}/sweeps"
SWEEP_EGO = f"{SWEEPS}/ego_vehicle"
"""The ego pose at each LiDAR sweep between keyframes (on the timestamp timeline only)."""
SWEEP_LIDAR = f"{SWEEP_EGO}/LIDAR_TOP"


def _name(part: str) -> str:
    """An entity-path segment; tracker and class names are plain identifiers, ids are integers."""
    if not part or "/" in part or part.strip() != part:
        raise ValueError(f"invalid entity path segment {part!r}")
    return part


def camera(channel: str) -> str:
    """One camera (``CAM_FRONT`` ...): its pose in the keyframe's ego frame, static pinhole and JPEG images."""
    return f"{EGO}/{_name(channel)}"


def camera_boxes(channel: str, layer: str) -> str:
    """LineStrips2D in one camera's image: the boxes of ``layer`` (``gt``, ``detections``, a tracker's name,
    ``failures``) projected and clipped to the image (``viz.camera_boxes``)."""
    return f"{camera(channel)}/boxes/{_name(layer)}"


def camera_labels(channel: str) -> str:
    """Points2D in one camera's image carrying the labels of the frame's failures (``viz.camera_boxes``)."""
    return f"{camera(channel)}/labels"


# Spatial, per tracker (global frame).
def tracker_world(tracker: str) -> str:
    return f"{WORLD_TRACKERS}/{_name(tracker)}"


def focus_callouts(tracker: str) -> str:
    """Points3D labels and leader lines of a focus recording's involved objects in one tracker's views."""
    return f"{tracker_world(tracker)}/focus/callouts"


def tracks(tracker: str, class_name: str) -> str:
    """Parent of the extracted tracks of one class (one entity per track, ``track``)."""
    return f"{tracker_world(tracker)}/tracks/{_name(class_name)}"


def track(tracker: str, class_name: str, track_id: int) -> str:
    """One extracted track: its Boxes3D (while it is reported) and its trail (LineStrips3D of recent
    positions); one entity per track, so a click selects it and hover names it."""
    return f"{tracks(tracker, class_name)}/{int(track_id)}"


def predicted(tracker: str, class_name: str) -> str:
    """Points3D of the predicted means (prior) of the tracks of one class worth a gate (not candidates)."""
    return f"{tracker_world(tracker)}/predicted/{_name(class_name)}"


def predicted_focus(tracker: str, class_name: str) -> str:
    """Points3D of the predicted means of the focused tracks of a focus recording (their labels are shown by
    the focus callouts, ``viz.callouts``)."""
    return f"{predicted(tracker, class_name)}/focus"


def candidates_world(tracker: str, class_name: str) -> str:
    """Points3D of the predicted means of candidate Bernoullis (low existence, e.g. born on clutter); hidden by
    default in the views, one click away."""
    return f"{tracker_world(tracker)}/candidates/{_name(class_name)}"


def associations(tracker: str, class_name: str) -> str:
    """LineStrips3D: one line per chosen (track, detection) pair, from the track's predicted position to the
    detection, in the track's colour."""
    return f"{tracker_world(tracker)}/associations/{_name(class_name)}"


def weak_associations(tracker: str, class_name: str) -> str:
    """LineStrips3D: dimmed lines for (track, detection) pairs a soft update used with a share below one half
    (an association probability or PHD weight, in the label)."""
    return f"{tracker_world(tracker)}/associations_weak/{_name(class_name)}"


def gated_pairs(tracker: str, class_name: str) -> str:
    """LineStrips3D: dimmed lines for (track, detection) pairs inside the gate that the solver did not choose."""
    return f"{tracker_world(tracker)}/gated_pairs/{_name(class_name)}"


def gates(tracker: str, class_name: str) -> str:
    """LineStrips3D of the gate ellipses of one class."""
    return f"{tracker_world(tracker)}/gates/{_name(class_name)}"


def failures_world(tracker: str, kind: str) -> str:
    """3D markers of one kind of tracking failure (e.g. id switches, false tracks)."""
    return f"{tracker_world(tracker)}/failures/{_name(kind)}"


# Non-spatial, per tracker.
def tracker_root(tracker: str) -> str:
    return f"{TRACKERS}/{_name(tracker)}"


def failure_index_doc(tracker: str) -> str:
    """TextDocument: a run's failures with their ``--focus`` ids (``viz.opening``; static)."""
    return f"{tracker_root(tracker)}/failure_index"


def decisions(tracker: str) -> str:
    """TextDocument: the frame's conflicts per class, chosen pairs, best alternatives and margins."""
    return f"{tracker_root(tracker)}/decisions"


def decision_matrix(tracker: str) -> str:
    """2D: the conflicts' cost cells (Boxes2D labelled with their cost), row and column labels, chosen cells."""
    return f"{tracker_root(tracker)}/decision_matrix"


def existence_root(tracker: str) -> str:
    return f"{tracker_root(tracker)}/existence"


def existence(tracker: str, class_name: str, track_id: int) -> str:
    """Scalars: the existence probability of one track over time."""
    return f"{existence_root(tracker)}/{_name(class_name)}/{int(track_id)}"


def extraction_threshold(tracker: str, class_name: str) -> str:
    """Scalars: the existence a Bernoulli of this class needs to be reported, drawn beside the existence lines."""
    return f"{existence_root(tracker)}/{_name(class_name)}/threshold"


def nis_root(tracker: str) -> str:
    return f"{tracker_root(tracker)}/nis"


def nis(tracker: str, class_name: str, track_id: int) -> str:
    """Scalars: normalised innovation squared (z - H m)^T S^-1 (z - H m) of the detection a track was given."""
    return f"{nis_root(tracker)}/{_name(class_name)}/{int(track_id)}"


def chosen_cost_root(tracker: str) -> str:
    return f"{tracker_root(tracker)}/chosen_cost"


def chosen_cost(tracker: str, class_name: str, track_id: int) -> str:
    """Scalars: the assignment cost of the pair chosen for a track (lower = more likely)."""
    return f"{chosen_cost_root(tracker)}/{_name(class_name)}/{int(track_id)}"


def candidates_root(tracker: str) -> str:
    return f"{tracker_root(tracker)}/candidates"


def candidate_count(tracker: str, class_name: str) -> str:
    """Scalars: how many candidate Bernoullis (never output as tracks) a class holds per frame; their
    individual series would be thousands of short lines (and chunks)."""
    return f"{candidates_root(tracker)}/{_name(class_name)}"


def events_root(tracker: str) -> str:
    return f"{tracker_root(tracker)}/events"


def involved_story(tracker: str) -> str:
    """TextLog of a focus recording: the story lines of one tracker that name an involved track."""
    return f"{tracker_root(tracker)}/involved_story"


def events(tracker: str, class_name: str) -> str:
    """TextLog of births, prunings, assignments, confirmations and merges of one class."""
    return f"{events_root(tracker)}/{_name(class_name)}"


def hypotheses_root(tracker: str) -> str:
    return f"{tracker_root(tracker)}/hypotheses"


def hypothesis_weights(tracker: str, class_name: str) -> str:
    """Scalars: log weights of the best PMBM global hypotheses of one class, one line per rank (h0, h1, ...)."""
    return f"{hypotheses_root(tracker)}/{_name(class_name)}"


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
