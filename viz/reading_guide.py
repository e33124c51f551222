"""The reading guide of a focus recording (``focus/how_to_read``): what every box, line, colour and panel means."""

from __future__ import annotations

from gnnpmb.why.words import SHOW_MIN_EXISTENCE

READING_GUIDE = f"""# How to read the views

**Bird's-eye and 3D views** (one pair per tracker; with several trackers the 3D view is the tab behind the
bird's-eye view)

- **Detections**: thin boxes in class colours, labelled `m<idx> <score>` (the same `m<idx>` everywhere: lines,
  tables, logs).
- **Ground truth**: translucent boxes.
- **Tracks**: boxes labelled with their id; the trail behind a track shows its last positions.
- **Gates**: the circles around each track's predicted position.
- **Association lines**: a solid line joins a track's prediction to each detection its update used: the one it
  was given (GNN-PMB, PMBM, GNN, greedy), or each with half or more of an association probability (JPDA, TO-PMB) or
  of its PHD weight (PHD, CPHD), labelled with that share; a dimmed line, a detection it used with a smaller
  share; a faint line, a detection inside its gate that its update did not use.
- **Failures**: enlarged boxes: magenta ID switch, orange fragmentation, red false track, green coalescence,
  yellow identity theft, grey miss. This failure's box encloses the others on the same objects; failures of
  other objects at the same frame are pale.
- **Disagreements** (several trackers): boxes around the object in sky blue where only one tracker shows a track
  on it (one track an object: the other's track between two objects counts on the nearer, and the line says
  so), violet where one changed its id and the other kept it, pink around a track only one shows. Shown means
  an existence of {SHOW_MIN_EXISTENCE:g} or more (output, for GNN, JPDA and greedy, which have no existences):
  an involved track below that is drawn here all the same, but counts as not shown in the comparison (and is
  not drawn in the full recording).
- **Involved objects**: drawn enlarged; their labels stand in a column beside them, with a line to each object.
  A detection's label says where it went (`m2 0.75 → track 26`, `→ new track 212`, `→ track 62 (p 1.00)`); a
  track's label, at its predicted position, its predicted existence (for PMBM, in the hypothesis its detection was
  decided in when that differs, with the best hypothesis's beside it: `26 predicted r=0.40`) and `missed`, or the
  detection its update used most unless that detection's label already says it went to this track
  (`26 predicted r=0.40 → m5`); a PHD's track always names it, with its share of the weight
  (`8 predicted weight 0.79 → m1 (78 % of its weight)`).
  An involved track kept but not output this frame is a pale box at its predicted position, in the shape of its
  last output box: where the tracker expected the object.
  The involved tracks take distinct colours (blue, green, black, light blue, lime, … in order of their ids,
  skipping a colour close to their class's own), the same in every view and plot; the others are pale.
- **GT … as evaluated**: where the evaluation put an object that had no LiDAR or radar points at this frame (it
  interpolates a box between the frames where the object had points); the failure is scored against that box.
  It is drawn thin in the class colour, with a line to the annotated box and a circle of 2 m around it: a track
  outside that circle is not matched to the object.
- **evaluation range**: when the failure lies near it, the circle around the ego vehicle beyond which the
  evaluation drops boxes of the class (50 m for vehicles, 40 m for pedestrians and two-wheelers), ground truth
  and tracks alike: an object just beyond it with a track just inside makes a false track.

**Panels**

- **focus**: the failure in words: **Why** opens with whose doing it was (the detector's, the tracker's, the
  evaluation's: each by a stated test, see *whose doing* below), then the facts: the object's detections, what
  the lost track's update did with them in the tracker's terms, how it ended, the choice or the hypothesis switch
  that gave the object away, where the new track came from; for a false track, what it was output on and why no
  object matched it; for a miss, whether the detector or the tracker missed it. **Because** takes the deciding
  choice's costs apart; then the key decisions, and per tracker what happened to each involved track.
- **story**: each frame's events of the involved class (confirmed, missed, ended, close calls).
- **decisions** and **cost grid**: per conflict the chosen pair, its cost, the next best and the margin (lower
  cost = more likely). When the next best was a track, the line under the table takes both costs apart (GNN-PMB,
  PMBM, TO-PMB): a track's cost is what its predicted existence adds (low existence, high cost), plus the
  uncertainty of its predicted position (a track not seen for a while is spread wide), plus the distance to the
  detection, plus the detection's score; and it gives the existence at which that track would have won the
  detection. GNN has no existence or score in its cost, but a constant (a detection against clutter); it gives
  the distance at which the track would have won.
- **existence**, **NIS**, **chosen cost**: the involved tracks' series up to the failure; the grey line is the
  existence from which a Bernoulli is shown as a track (PHD, CPHD: a component's weight, capped at 1). The NIS is
  that of the detection that dominated the update. GNN, JPDA and greedy have no existence plot: their tracks have
  no existence probability (track logic keeps a track or deletes it); greedy has no gates, so no NIS.

**Terms**

- **r, existence**: the filter's probability that a track's object exists (a Bernoulli's existence); it falls
  each frame the track gets no detection. **Predicted** values are before this frame's detections are used.
- **candidate**: a track (Bernoulli) never shown, because its existence never reached the line above.
- **d², NIS**: the squared Mahalanobis distance between a detection and a track's predicted position (normalised
  innovation squared); the gate keeps detections with d² ≤ 40.
- **uncertainty of the predicted position (± m)**: the spread of the track's predicted position plus the
  detection noise (the fourth root of det S); it grows while a track gets no detection.
- **cost**: −log of how much more likely a pairing is than the track being missed; the solver picks the set of
  pairings of least total cost. **new**: the cost of a detection starting a track (or being clutter), about the
  same for every detection (the birth weight against the clutter rate, −log(clutter + birth weight × score ×
  birth density)).
- **margin**: how much the best total cost rises without a chosen pair; shown up to 5.00 (larger is no contest).
- **identity theft** (the paper's cascading identity theft): a track whose first frames were false (matched to
  no object) takes over a real object another track held, an ID switch; the victim, left without its object,
  may steal the next one in turn.
- **counted**: the evaluation keeps a track only if its score averaged over the whole track reaches the class's
  threshold (chosen for the best MOTA), at all its frames or at none.
- **whose doing**: the detector's when, in a frame that decided the failure, no detection of a tracked class lay
  within 2 m of an object that had LiDAR or radar points (a detection nearer another object is that one's), or
  only one of another class, or a false track sat on a
  detection of nothing; the tracker's when a detection was there and the update of the track that had the object
  did not use it, the track was not output, output 2 m or more away, not counted, or covered two objects; the
  evaluation's when it scored the object at an interpolated box 0.5 m or more from the annotation (2 m for a
  miss), had no box for it, or made the false box up between two of the track's. Several can hold at once.
- **p**, **% of its weight**: a JPDA or TO-PMB association probability; the share of a PHD component's weight the
  update took from a detection.
"""
