"""Why a tracker failed: typed facts gathered from its events, and findings that explain a failure from them.

The package never draws and never imports the viewer. Its layers, each a module:

* ``facts``: ``FactSink``, an ``EventSink`` that sits beside the viewer's logger (``events.TeeSink``) and keeps
  every event of a run by frame and class; ``TrackerFacts`` answers what the tracker did: how each track's update
  used the frame's detections (``use``: hard assignments, association probabilities, PHD update weights alike),
  where each detection went, each track's frame-by-frame ``TrackStep``, the solver's decisions, PMBM's hypotheses;
* ``story``: the typed story lines of a run (confirmed, missed, ended, close calls) that the logger shows;
* ``evaluation``: what the devkit's evaluation did with an object or a track, as it computed it;
* ``findings``: the frozen dataclasses of an explanation (whose doing, the cause, the deciding choice);
* ``reason``: builds a ``Finding`` for a failure from the facts, the scene and the evaluation;
* ``words``: the one place findings and story lines become text (the viewer and ``gnnpmb failures --why``).
"""
