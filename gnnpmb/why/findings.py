"""An explanation of one failure as data: ``Finding`` and its parts (frozen dataclasses, no text).

A finding says whose doing the failure was by stated tests (``Blame``), what the tracker did to each track
involved, frame by frame, in its own terms (``facts.TrackStep``: an assignment, association probabilities, PHD
weights), the solver's deciding choice with its cost taken apart (``Deciding``), a PMBM hypothesis switch
(``HypothesisSwitch``), what the evaluation did (``eval.evaluated``) and how other trackers on the same detections
fared (``OtherRun``). ``reason.explain_failure`` builds it; ``words`` renders it; ``claims`` lists what it asserts
so a test can check every assertion against independent facts.

The tests of ``Blame`` (``Rule``) are stated once, here:

* **the detector's**: in a frame that decided the failure, no detection of a tracked class (any score) within
  ``NEAR_M`` of the object while it had LiDAR or radar points, or only detections that lie nearer another annotated
  object (``NO_DETECTION``: they are that object's, ``Near.on_other``), only detections of its own of another
  class (``OTHER_CLASS``), or the false
  track was output on a detection that lies within ``NEAR_M`` of no object (``DETECTION_OF_NOTHING``), or a false
  track was a second one on an object the detector gave two or more kept detections of its class within ``NEAR_M``,
  each nearer it than any other annotated object (``TWO_DETECTIONS``: a detector without NMS, audit truth50);
* **the tracker's**: a detection of the object's class was within ``NEAR_M`` and the update of the track that had
  the object did not use it (``DETECTION_UNUSED``, naming where it went, or that preprocessing dropped it), or the
  track that had the object (or took its detection) was not output (``NOT_OUTPUT``: over a gap in the
  detections, the tracker could have carried it), or it was output
  ``NEAR_M`` or more from the object (``OFF_OBJECT``; a false track: on a detection within ``NEAR_M`` of an object,
  its box ``NEAR_M`` or more from every object, ``FalseOutput.detection_near``), or a track on the object was
  output but not counted (``NOT_COUNTED``), or two tracks were output on one object (``TWO_TRACKS``), or a track
  was output without a detection on no object (``COASTED``), or one track was matched to an object while covering
  another (``COVERED_TWO``), or the object had no LiDAR or radar points, so no detector could see it, and no track
  carried it (``UNSEEN``);
* **the evaluation's**: the box the object was scored against is an interpolation ``EVALUATED_OFFSET_M`` or more
  from the annotation (for a miss ``NEAR_M`` or more: a nearer box would still match a track on the object), or one
  that put a counted track output within ``NEAR_M`` of the annotation out of the
  devkit's ``NEAR_M`` (``INTERPOLATED``), or the evaluation has no box of the object there, beyond its range or
  for want of points (``NO_EVAL_BOX``), or the false track's box is one the evaluation interpolated between two of
  the track's boxes, at a frame the tracker did not output it (``TRACK_INTERPOLATED``), or a track output on the
  object was dropped there by the evaluation's range or bike-rack filter (``TRACK_DROPPED``), or the object had no
  annotation at all at the failure's frame (it left view and came back) and the evaluation scored a box it
  interpolated between its annotations (``UNANNOTATED``).

The frames that decide a failure: for a miss, a false track and a coalescence, the failure's frame; for a
fragmentation, an ID switch and an identity theft, the frames from the one after the lost track last lay within
``NEAR_M`` of the object to the failure's frame.
"""

from __future__ import annotations

import enum
from dataclasses import dataclass

from gnnpmb.eval.evaluated import GtFrame, TrackEval
from gnnpmb.eval.failures import FailureKind
from gnnpmb.explain import PairChoice
from gnnpmb.foreign import BoxOn
from gnnpmb.why.counterfactual import WouldTake
from gnnpmb.why.facts import Destination, TrackStep, Use

NEAR_M = 2.0
"""A detection or track within this BEV distance of an object is on it: the devkit's match distance
(``tracking_nips_2019`` dist_th_tp), which ``reason`` reads from the devkit config and checks against this."""
EVALUATED_OFFSET_M = 0.5
"""An interpolated box this far or farther from the annotation makes a failure the evaluation's doing."""
FRAMES_BEFORE = 8
"""A finding looks back this many keyframes before its failure (and a focus recording starts there)."""
OFF_NEAR_M = 6.5
"""How far from an object with no detection within ``NEAR_M`` a detection of its class, nearer it than any other
annotated object, is named beside the miss: it may be the object's box placed that far off (audit truth51)."""


class Party(enum.Enum):
    """Whose doing (part of) a failure was."""

    DETECTOR = "the detector"
    TRACKER = "the tracker"
    EVALUATION = "the evaluation"


class Rule(enum.Enum):
    """The stated tests of the module docstring; each held test is one ``Blame``."""

    NO_DETECTION = "no detection"
    OTHER_CLASS = "another class"
    DETECTION_OF_NOTHING = "detection of nothing"
    DETECTION_UNUSED = "detection unused"
    NOT_OUTPUT = "not output"
    OFF_OBJECT = "off the object"
    NOT_COUNTED = "not counted"
    TWO_TRACKS = "two tracks"
    TWO_DETECTIONS = "two detections"
    COASTED = "coasted"
    COVERED_TWO = "covered two"
    UNSEEN = "unseen"
    INTERPOLATED = "interpolated"
    NO_EVAL_BOX = "no evaluated box"
    TRACK_INTERPOLATED = "track interpolated"
    TRACK_DROPPED = "track dropped"
    UNANNOTATED = "not annotated"

    @property
    def party(self) -> Party:
        return _PARTY[self]


_PARTY = {
    Rule.NO_DETECTION: Party.DETECTOR,
    Rule.OTHER_CLASS: Party.DETECTOR,
    Rule.DETECTION_OF_NOTHING: Party.DETECTOR,
    Rule.DETECTION_UNUSED: Party.TRACKER,
    Rule.NOT_OUTPUT: Party.TRACKER,
    Rule.OFF_OBJECT: Party.TRACKER,
    Rule.NOT_COUNTED: Party.TRACKER,
    Rule.TWO_TRACKS: Party.TRACKER,
    Rule.TWO_DETECTIONS: Party.DETECTOR,
    Rule.COASTED: Party.TRACKER,
    Rule.COVERED_TWO: Party.TRACKER,
    Rule.UNSEEN: Party.TRACKER,
    Rule.INTERPOLATED: Party.EVALUATION,
    Rule.NO_EVAL_BOX: Party.EVALUATION,
    Rule.TRACK_INTERPOLATED: Party.EVALUATION,
    Rule.TRACK_DROPPED: Party.EVALUATION,
    Rule.UNANNOTATED: Party.EVALUATION,
}


@dataclass(frozen=True, slots=True)
class Blame:
    """One stated test that held (``Rule``), at ``frames``."""

    rule: Rule
    frames: tuple[int, ...]

    @property
    def party(self) -> Party:
        return self.rule.party


@dataclass(frozen=True, slots=True)
class Near:
    """A detection near an object: its source index, class, score, BEV distance (m) and whether preprocessing
    kept it (score threshold, NMS); on_other: the annotated object (id, class, BEV distance m) the detection lies
    nearer than this one, when it does: then it is that object's detection, not a sight of this one (dev set
    scene-1094 centerpoint ab3dmot: a car detection 1.8 m from a bicycle and 0.1 m from a car was said to be the
    bicycle seen as a car). A detection of another class within ``NEAR_M`` of an object of its own class is that
    object's too (audit truth51, world7: a rider's bicycle box, on the spot of the pedestrian annotated with it)."""

    meas: int
    class_name: str
    score: float
    distance_m: float
    kept: bool
    on_other: tuple[str, str, float] | None = None

    @property
    def of_it(self) -> bool:
        """Whether the detection is this object's: no other annotated object lies nearer it."""
        return self.on_other is None


@dataclass(frozen=True, slots=True)
class OnObject:
    """A track output within ``NEAR_M`` of an object: its id, distance, output score, the detection its box sits
    on (-1: none this frame) and how the evaluation took it (``TrackEval``; None: not evaluated) against the
    class's threshold (None: every box counts); false_here: the evaluation matched it to no object at this frame
    (a false track there); xy_m: its box's BEV centre (global); matched_m: its distance to the annotation of the
    object the evaluation matched it to at this frame (None: matched to none, or that object not annotated here).
    Two parked cars 1.7 m apart (world4): a track within 2 m of one is often the other's."""

    track_id: int
    distance_m: float
    score: float
    meas: int
    evaluated: TrackEval | None
    threshold: float | None
    false_here: bool = False
    xy_m: tuple[float, float] | None = None
    matched_m: float | None = None

    @property
    def counted(self) -> bool:
        """Whether the evaluation counted the track (its averaged score reaches the threshold)."""
        if self.evaluated is None or self.evaluated.averaged_score is None:
            return False
        return self.threshold is None or self.evaluated.averaged_score >= self.threshold


@dataclass(frozen=True, slots=True)
class Sighting:
    """The object at one frame: its LiDAR + radar points, how the evaluation saw it, the nearest detection of any
    class (within ``NEAR_M``, kept or not), the nearest kept detection of its class and where that went, the
    tracks of its class output on it, the nearest detection of its class within ``NEAR_M`` that preprocessing
    removed (score threshold or NMS), and how many of ``points`` are radar returns (a box with no LiDAR return
    and a few radar ones is nothing a LiDAR detector can see)."""

    frame: int
    points: int
    evaluated: GtFrame | None
    nearest_any: Near | None
    nearest_own: Near | None
    """The nearest kept detection of its class within ``NEAR_M`` that is its own (``Near.of_it``)."""
    went: Destination | None
    on_it: tuple[OnObject, ...]
    removed_own: Near | None = None
    radar_points: int = 0
    in_box: Near | None = None
    """With no detection of any class within ``NEAR_M``: the nearest one whose centre lies inside the object's box
    (a long truck seen as two boxes, world6: a sight of part of it, not no sight)."""
    off: Near | None = None
    """With no detection of any class within ``NEAR_M`` nor inside its box: the nearest detection of its class
    within ``OFF_NEAR_M`` that lies nearer it than any other annotated object (world7: a car's box placed 3-6 m
    off for one frame was told as "the detector missed it")."""
    neighbours_own: Near | None = None
    """The nearest kept detection of its class within ``NEAR_M`` that lies nearer another annotated object: that
    one's, not this one's (``nearest_own`` never is such a detection; two pedestrians given one box)."""
    untracked_name: tuple[str, float, float] | None = None
    """With no detection of a tracked class within ``NEAR_M`` nor inside its box: the nearest box of a detection
    name the evaluation does not track (``construction_vehicle``, ``traffic_cone``, ``barrier``) within ``NEAR_M``:
    name, score, m (audit truth52, world8: a car detected only as a construction vehicle was "missed")."""

    @property
    def lidar_points(self) -> int:
        return self.points - self.radar_points

    @property
    def seen(self) -> Near | None:
        """The nearest detection of any class that is this object's (``Near.of_it``); None where every detection
        within ``NEAR_M`` lies nearer another annotated object, or none does."""
        n = self.nearest_any
        return n if n is not None and n.of_it else None

    @property
    def undetected(self) -> bool:
        """No detection of it: none of its class kept within ``NEAR_M`` and none of any class that is its own."""
        return self.nearest_own is None and self.seen is None


@dataclass(frozen=True, slots=True)
class OffObject:
    """The lost track output ``NEAR_M`` or more from the object at the failure's frame: how far, on which
    detection (-1: none), and the earlier frames whose detection it used lay that far from the object
    ((frame, detection) pairs); scored_m: how far from the box the evaluation interpolated for the object there
    (None: it scored the annotation, or no box)."""

    distance_m: float
    meas: int
    earlier: tuple[tuple[int, int], ...]
    scored_m: float | None = None


@dataclass(frozen=True, slots=True)
class MatchedAway:
    """An object other than the finding's to which the evaluation matched the lost track after its last match on
    the finding's object, up to the failure's frame (the devkit's MATCH or SWITCH events, ``TrackEval.matches``):
    its id and the frames of those matches."""

    gt_id: str
    frames: tuple[int, ...]


@dataclass(frozen=True, slots=True)
class LostTrack:
    """The track that had the object: ``held_until`` the last frame it was output within ``NEAR_M`` of it (None:
    never in the window); steps: its ``TrackStep`` per frame of the window; off: output away from the object at the
    failure's frame; evaluated: how the evaluation took it; shown_min: the existence from which the viewer shows a
    track (for a track never shown that the evaluation still counted); elsewhere: the frames of the window at which
    it has no step of its own but a cost matrix of a hypothesis other than the chosen one had its column (PMBM: it
    was held only by hypotheses the tracker did not choose, so it was not gone); finite_elsewhere: (frame,
    detection) pairs its column could not take in the chosen hypothesis's matrix but another hypothesis's matrix
    gave a finite cost (PMBM); matched_until: the last frame before the failure at which the evaluation matched
    the object to a track (the devkit's memory of its last match, which for a lost object is this track: None if
    none); matched_away: the other objects the evaluation matched this track to after that frame, up to the
    failure's (``MatchedAway``, by first frame)."""

    track_id: int
    held_until: int | None
    steps: tuple[TrackStep, ...]
    off: OffObject | None
    evaluated: TrackEval | None
    threshold: float | None
    elsewhere: tuple[int, ...] = ()
    finite_elsewhere: tuple[tuple[int, int], ...] = ()
    matched_until: int | None = None
    matched_away: tuple[MatchedAway, ...] = ()
    used_of_no_object: tuple[tuple[int, int], ...] = ()
    """(frame, detection) pairs its updates in the window used that lay within ``NEAR_M`` of no annotated object
    and inside none's box (audit truth50: world5's false bus pulled the real bus's JPDA / CPHD track)."""

    def step(self, frame: int) -> TrackStep | None:
        return next((s for s in self.steps if s.frame == frame), None)


@dataclass(frozen=True, slots=True)
class Origin:
    """Where the track that took the object came from: born at ``frame`` from detection ``meas`` (frame -1: before
    the window), and the frames it was a false track before the failure (identity theft); victim_held: at each of those
    frames the evaluation matched the object to the victim (no miss of it, the victim no false track), so the victim
    held it; of_no_object: no annotated object of a tracked class lay within ``NEAR_M`` of that detection at ``frame``
    (a false detection started the track)."""

    track_id: int
    frame: int
    meas: int
    false_frames: tuple[int, ...] = ()
    victim_held: bool = False
    of_no_object: bool = False
    part_of: tuple[str, str, float] | None = None
    """Of no object, but inside this object's box (id, class, m from its centre): see ``Reasoner.part_of``."""


@dataclass(frozen=True, slots=True)
class Deciding:
    """A solver's choice that decided where the object's detection went: at ``frame``, ``choice`` (the chosen
    column, its cost, the next best, the margin, and the cost terms when the tracker gives them); went: the id of
    the track the detection went to (-1: none), or that it started (``born``); lost: the track that had the object
    when it is neither of the compared columns and had a column in the frame's matrix (None otherwise: a track
    without a column is not said to be outside a gate), and whether its column could take the detection (a finite
    cost); would / lost_would: what change of the next best's / the lost track's cost would have given it the
    detection, re-solved (``counterfactual.WouldTake``; None: nothing is said); alternative_took: the detection
    the next best (a track) took in the same assignment (None: none), as ``KeyDecision`` has it; meas_of_no_object:
    the detection lay farther than ``NEAR_M`` from every annotated object of a tracked class."""

    frame: int
    choice: PairChoice
    went: int
    born: bool
    lost: int | None = None
    lost_in_gate: bool = False
    would: WouldTake | None = None
    lost_would: WouldTake | None = None
    alternative_took: int | None = None
    meas_of_no_object: bool = False
    meas_part_of: tuple[str, str, float] | None = None
    """Of no object, but inside this object's box (id, class, m from its centre)."""


@dataclass(frozen=True, slots=True)
class HypothesisSwitch:
    """PMBM: at ``frame`` the best posterior hypothesis descends from prior hypothesis ``parent`` (not the previous
    best, 0), of weight ``parent_weight`` against the previous best's ``best_weight`` (both as kept after the
    previous frame); in it, each track of ``tracks`` has existed since a frame, with its existence in the chosen
    hypothesis beside its marginal existence (``HypothesisTrack``)."""

    frame: int
    parent: int
    parent_weight: float
    best_weight: float
    tracks: tuple[HypothesisTrack, ...]


@dataclass(frozen=True, slots=True)
class HypothesisTrack:
    """One track in a hypothesis switch: since: the first frame any kept hypothesis held it (None: never before);
    decided: its predicted existence in the parent hypothesis (None: not there); predicted: in the previous best
    (None: not there); chosen / marginal: after the update, in the chosen hypothesis and over all kept ones."""

    track_id: int
    since: int | None
    decided: float | None
    predicted: float | None
    chosen: float | None
    marginal: float | None


@dataclass(frozen=True, slots=True)
class KeyDecision:
    """A choice up to the failure that sent a detection away from an involved track that was its next best, or
    gave one to an involved track by a close call: the frame, the choice, and where the detection went
    (track id, -1: none; born: it started that track); alternative_took: the detection the next best (a track)
    took in the same assignment, when it took one (its lower cost then did not decide alone: the lower total
    did), else None."""

    frame: int
    choice: PairChoice
    went: int
    born: bool
    alternative_took: int | None = None


@dataclass(frozen=True, slots=True)
class FalseOutput:
    """A false track's box at the failure frame: the detection it was output on (None: none, it was predicted, or
    not output at all), where the box lies, the frames of the track's own boxes the evaluation interpolated this
    one between (None: the tracker output it), the nearest object of its class (gt id, distance, how the evaluation
    saw it), the nearest of any class, and the track the evaluation matched to that object instead (None: none);
    object_missed: the evaluation matched that object to no track at this frame; use: how the track's update used
    the frame's detections there (None: not known)."""

    track_id: int
    on: Near | None
    output_xy_m: tuple[float, float]
    between: tuple[int, int] | None
    nearest_own: tuple[str, float, GtFrame | None] | None
    nearest_any: tuple[str, str, float] | None
    matched_instead: int | None
    evaluated: TrackEval | None
    threshold: float | None
    object_missed: bool = False
    use: Use | None = None
    part_of: tuple[str, str, float] | None = None
    """No object within ``NEAR_M``, but the box's centre lies inside this object's box (id, class, m from its
    centre): the track was on part of it."""
    twins: tuple[int, ...] = ()
    """The kept detections of its class the detector gave the object within ``NEAR_M`` when two or more
    (``Rule.TWO_DETECTIONS``)."""
    coasted_from: tuple[int, int] | None = None
    """A predicted box on an object of another class: the frame and detection of the track's last box, when that
    detection was the object's own (the detector gave it the track's class there; ``Rule.OTHER_CLASS``)."""
    drifted_from: tuple[str, float, int, GtFrame | None] | None = None
    """A box on no detection (predicted, or interpolated by the evaluation) with no object within ``NEAR_M``: the
    object of its class the track's box was last output within ``NEAR_M`` of (id, its distance now in m, that
    frame, how the evaluation saw it now), when it is annotated here, less than ``OFF_NEAR_M`` away (dev set
    scene-0916 centerpoint false_track:14: a track that followed a bicycle with no sensor points ran 2.1 m past
    it, told as "a box where no tracked object was")."""
    beside_untracked: tuple[str, str, float] | None = None
    """Near an object of its class: the annotation of an untracked category (id, category, m) the box lies nearer
    than that object (a stroller beside its pusher: the track was on the stroller; audit truth52, world8)."""
    detection_near: tuple[str, str, float, float] | None = None
    """No object within ``NEAR_M`` of the box, which sat on a detection: the object of a tracked class that
    detection lay within ``NEAR_M`` of (id, class, the detection's distance m, the box's distance m; audit truth54,
    dev set scene-0103 pointpillars jpda false_track:19: "a detection of no tracked object" of a bicycle detection
    1.98 m from a bicycle, the track's box 2.0 m or more from it)."""
    kept_around: tuple[int | None, int | None] | None = None
    """The nearest object of its class has no box the evaluation scored here (``Rule.NO_EVAL_BOX``): the last frame
    before and the first after this one at which the evaluation kept its box (None: none on that side), the ends an
    interpolation would join (audit truth54, dev set: "no box of it both before and after" of one it kept after)."""


@dataclass(frozen=True, slots=True)
class EvaluatedReach:
    """Where the evaluation scored the object at the failure frame, against where it was annotated: the tracks
    of the failure's tracker output within ``NEAR_M`` of the evaluated box and of the annotated box."""

    offset_m: float
    near_evaluated: tuple[int, ...]
    near_annotated: tuple[int, ...]


def covering(s: Sighting, reach: EvaluatedReach | None) -> tuple[OnObject, ...]:
    """The counted tracks on the object (``s``) that the evaluation matched to another object: no false track
    there, their box kept by the evaluation (one it dropped was matched to nothing), and within reach of the box it
    scored the object at (``reach``: where that box is an interpolation; a track out of its reach could not have
    had the object, so its match elsewhere is not one track for two objects: dev set scene-0061 megvii gnnpmb
    miss at frame 9, track 72 0.3 m from the annotation and 2.9 m from the box the devkit interpolated)."""
    away = set(reach.near_annotated) - set(reach.near_evaluated) if reach is not None else set()
    return tuple(
        o
        for o in s.on_it
        if o.counted
        and not o.false_here
        and o.evaluated is not None
        and s.frame in o.evaluated.kept
        and o.track_id not in away
    )


@dataclass(frozen=True, slots=True)
class OtherRun:
    """Another tracker on the same detections at the failure: whether it has a failure of the same kind on the
    same object (without an object: within ``NEAR_M`` of ``place_xy_m``) at the same frame, and the tracks it
    output on the object there (counted or not); output_only: it is a results file (what detections it was given is
    not known); missed: its evaluation counted the object missed at that frame (the devkit's MISS, whatever lay
    near the annotated box: the evaluation may have scored an interpolated box elsewhere); matched: the track its
    evaluation matched the object to there (None: none), and each of ``on_it`` carries its own matches
    (``OnObject.evaluated``), so a track on the object that the evaluation matched elsewhere is not said to have
    kept it; switched: its evaluation switched the object's track at that frame (an ID switch or identity theft, a
    failure of another kind than a fragmentation's, a miss's or a coalescence's), so it is not said not to fail;
    unscored: no score threshold of its reached the evaluation's lowest recall in the class, so the evaluation
    counted none of its tracks of the class (its failures there are outside the devkit's counts)."""

    tracker: str
    failed_same: bool
    on_it: tuple[OnObject, ...]
    place_xy_m: tuple[float, float] | None = None
    output_only: bool = False
    missed: bool = False
    matched: int | None = None
    switched: bool = False
    unscored: bool = False


@dataclass(frozen=True, slots=True)
class Finding:
    """The explanation of one failure (module docstring).

    failure_id, kind, tracker, frame, class_name: the failure; gt_id: its object (a false track's nearest object
    of its class within ``NEAR_M``, or None); track_ids: its own tracks; window: the frames looked at; deciding:
    the frames that decided it; blame: the tests that held, in order (evaluation, detector, tracker); sightings:
    the object per frame of the window; lost: the track that had it; taker: where the track that took it came
    from; decision: the solver's deciding choice; switch: a PMBM hypothesis switch that decided it; false_output:
    a false track's box; covered: a coalescence's other objects; key_decisions: choices that sent detections away
    from involved tracks; others: other trackers on the same detections; reach: where the evaluation scored an
    interpolated object against its annotation; mode: how the tracker's update uses detections (``facts.UseMode``
    value; "output only" for a results file: nothing is said of its update), has_existence: whether its tracks have
    existences; boxes_on: for a results file, how each output box named was placed on a detection (frame, track
    id, ``foreign.BoxOn``); unscored: no score threshold of this run reached the evaluation's lowest recall in the
    class, so the devkit counted none of its tracks of the class (every object missed, no false track, switch or
    fragmentation): a failure other than a miss is what matching every box finds, outside the devkit's counts.
    """

    failure_id: str
    kind: FailureKind
    tracker: str
    frame: int
    class_name: str
    gt_id: str | None
    track_ids: tuple[int, ...]
    window: tuple[int, int]
    deciding: tuple[int, ...]
    blame: tuple[Blame, ...]
    sightings: tuple[Sighting, ...]
    mode: str
    has_existence: bool
    lost: LostTrack | None = None
    taker: Origin | None = None
    decision: Deciding | None = None
    switch: HypothesisSwitch | None = None
    false_output: FalseOutput | None = None
    covered: tuple[str, ...] = ()
    key_decisions: tuple[KeyDecision, ...] = ()
    others: tuple[OtherRun, ...] = ()
    reach: EvaluatedReach | None = None
    boxes_on: tuple[tuple[int, int, BoxOn], ...] = ()
    unscored: bool = False

    @property
    def output_only(self) -> bool:
        """Whether only the run's output is known (a results file)."""
        return self.mode == "output only"

    def box_on(self, frame: int, track_id: int) -> BoxOn | None:
        """How track ``track_id``'s box at ``frame`` was placed on a detection (a results file; else None)."""
        return next((b for f, t, b in self.boxes_on if (f, t) == (frame, track_id)), None)

    @property
    def parties(self) -> tuple[Party, ...]:
        """Whose doing, in order, each once."""
        return tuple(dict.fromkeys(b.party for b in self.blame))

    def sighting(self, frame: int) -> Sighting | None:
        return next((s for s in self.sightings if s.frame == frame), None)
