"""Every Rerun entity path of the recording, in one place.

Spatial entities live under ``world/`` and mirror the transform tree: ``world`` (static, Z-up), ``world/ego_vehicle``
(ego pose per frame), ``world/ego_vehicle/LIDAR_TOP`` (static calibration; points in the sensor frame). Boxes, gates
and tracks are in the nuScenes global frame, so they hang directly under ``world``. Each tracker gets its own
subtree (``world/trackers/<tracker>/...`` for 3D things, ``trackers/<tracker>/...`` for plots, tensors and logs),
so several trackers fit in one recording and a view can show one of them with a ``/**`` filter.
"""

from __future__ import annotations

from dataclasses import dataclass

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


# Non-spatial, per tracker.
def tracker_root(tracker: str) -> str:
    return f"{TRACKERS}/{_name(tracker)}"


@dataclass(frozen=True, slots=True)
class Family:
    """A tracker's entities of one kind: ``root(tracker)`` holds them all (a view's origin, or one entity alone),
    one per class (``family(tracker, class_name)``) or per class and track (``family.track(tracker, class_name,
    track_id)``); under ``tracker_world`` (spatial, global frame) or ``tracker_root`` (plots, tensors, logs)."""

    part: str
    spatial: bool = False

    def root(self, tracker: str) -> str:
        return f"{tracker_world(tracker) if self.spatial else tracker_root(tracker)}/{self.part}"

    def __call__(self, tracker: str, class_name: str) -> str:
        return f"{self.root(tracker)}/{_name(class_name)}"

    def track(self, tracker: str, class_name: str, track_id: int) -> str:
        return f"{self(tracker, class_name)}/{int(track_id)}"


focus_callouts = Family("focus/callouts", spatial=True).root
"""Points3D labels and leader lines of a focus recording's involved objects in one tracker's views."""
tracks = Family("tracks", spatial=True)
"""Parent of the extracted tracks of one class (one entity per track, ``track``)."""
track = tracks.track
"""One extracted track: its Boxes3D (while it is reported) and its trail (LineStrips3D of recent positions); one
entity per track, so a click selects it and hover names it."""
predicted = Family("predicted", spatial=True)
"""Points3D of the predicted means (prior) of the tracks of one class worth a gate (not candidates)."""


def predicted_focus(tracker: str, class_name: str) -> str:
    """Points3D of the predicted means of the focused tracks of a focus recording (their labels are shown by
    the focus callouts, ``viz.callouts``)."""
    return f"{predicted(tracker, class_name)}/focus"


candidates_world = Family("candidates", spatial=True)
"""Points3D of the predicted means of candidate Bernoullis (low existence, e.g. born on clutter); hidden by default
in the views, one click away."""
associations = Family("associations", spatial=True)
"""LineStrips3D: one line per chosen (track, detection) pair, from the track's predicted position to the detection,
in the track's colour."""
weak_associations = Family("associations_weak", spatial=True)
"""LineStrips3D: dimmed lines for (track, detection) pairs a soft update used with a share below one half (an
association probability or PHD weight, in the label)."""
gated_pairs = Family("gated_pairs", spatial=True)
"""LineStrips3D: dimmed lines for (track, detection) pairs inside the gate that the solver did not choose."""
gates = Family("gates", spatial=True)
"""LineStrips3D of the gate ellipses of one class."""
failures_world = Family("failures", spatial=True)
"""3D markers of one kind of tracking failure (e.g. id switches, false tracks), one entity per kind."""
failure_index_doc = Family("failure_index").root
"""TextDocument: a run's failures with their ``--focus`` ids (``viz.opening``; static)."""
decisions = Family("decisions").root
"""TextDocument: the frame's conflicts per class, chosen pairs, best alternatives and margins."""
decision_matrix = Family("decision_matrix").root
"""2D: the conflicts' cost cells (Boxes2D labelled with their cost), row and column labels, chosen cells."""
involved_story = Family("involved_story").root
"""TextLog of a focus recording: the story lines of one tracker that name an involved track."""
_EXISTENCE = Family("existence")
existence_root = _EXISTENCE.root
existence = _EXISTENCE.track
"""Scalars: the existence probability of one track over time."""


def extraction_threshold(tracker: str, class_name: str) -> str:
    """Scalars: the existence a Bernoulli of this class needs to be reported, drawn beside the existence lines."""
    return f"{_EXISTENCE(tracker, class_name)}/threshold"


_NIS = Family("nis")
nis_root = _NIS.root
nis = _NIS.track
"""Scalars: normalised innovation squared (z - H m)^T S^-1 (z - H m) of the detection a track was given."""
_CHOSEN_COST = Family("chosen_cost")
chosen_cost_root = _CHOSEN_COST.root
chosen_cost = _CHOSEN_COST.track
"""Scalars: the assignment cost of the pair chosen for a track (lower = more likely)."""
candidate_count = Family("candidates")
"""Scalars: how many candidate Bernoullis (never output as tracks) a class holds per frame; their individual series
would be thousands of short lines (and chunks)."""
events = Family("events")
"""TextLog of births, prunings, assignments, confirmations and merges of one class."""
hypothesis_weights = Family("hypotheses")
"""Scalars: log weights of the best PMBM global hypotheses of one class, one line per rank (h0, h1, ...)."""
marginals = Family("marginals")
"""Tensor of marginal association probabilities (TO-PMB, JPDA)."""
cardinality_pmf = Family("cardinality/pmf")
"""BarChart of the CPHD cardinality distribution."""
cardinality_mean = Family("cardinality/expected")
"""Scalars: expected number of targets under the CPHD cardinality distribution."""
intensity_weights = Family("intensity/weights")
"""BarChart of GM-PHD / CPHD component weights."""
intensity_total = Family("intensity/total")
"""Scalars: total intensity weight (the PHD's expected number of targets)."""
failure_count = Family("failures")
"""Scalars: number of failures of one kind per frame, one entity per kind."""
