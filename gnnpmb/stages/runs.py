"""Stage 3, the runs: every run of the inputs, once. A built-in tracker tracks (with its own parameters and
detections when it has them); a results file is replayed (``gnnpmb.foreign.replay``).

With ``record`` the run keeps its events in order (``Run.events``) and what they say (``Run.facts``,
``why.facts``): the later stages explain from the facts, and the recording replays the events into its logger, so
no tracker runs twice for one command. Without it the tracker emits nothing (``NullSink``), as for a failure list
or a digest.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass, replace
from typing import TYPE_CHECKING

from gnnpmb.stages.inputs import Inputs, recorded_spelling

if TYPE_CHECKING:
    from gnnpmb.events import Event, EventSink
    from gnnpmb.pipeline import TrackingRun
    from gnnpmb.provenance import Provenance, TrackDigest
    from gnnpmb.why.facts import TrackerFacts


@dataclass(frozen=True, slots=True)
class Run:
    """One run of the inputs: its output per keyframe (``tracking``), and, when recorded, its events in emission
    order and the facts gathered from them (``events`` empty and ``facts`` None otherwise)."""

    tracking: TrackingRun
    events: tuple[Event, ...] = ()
    facts: TrackerFacts | None = None

    @property
    def name(self) -> str:
        return self.tracking.tracker

    def replay(self, sink: EventSink) -> None:
        """Emit the recorded events, in order, to ``sink`` (e.g. the recording's logger)."""
        for event in self.events:
            sink.emit(event)


def run_one(inputs: Inputs, name: str, *, record: bool, on_frame: Callable[[], None] | None = None) -> Run:
    """Run ``name`` of ``inputs`` once over its frames (a results file replayed, a tracker tracking with its own
    parameters and detections when it has them); with ``record`` its events and facts are kept (module
    docstring). on_frame: called after each frame."""
    from gnnpmb.events import ListSink, TeeSink
    from gnnpmb.foreign import replay
    from gnnpmb.pipeline import run_tracker
    from gnnpmb.why.facts import FactSink

    spec, foreign, caps = inputs.spec(name), inputs.foreign.get(name), inputs.caps[name]
    facts = FactSink(name, has_existence=caps.has_existence, output_only=caps.output_only) if record else None
    events = ListSink()
    sink = TeeSink(facts, events) if facts is not None else None
    if foreign is not None:
        tracking = replay(
            foreign, inputs.scene, inputs.frame_detections, inputs.classes, inputs.frame_range, sink, on_frame
        )
    else:
        tracking = run_tracker(
            inputs.scene,
            inputs.own_frames.get(name, inputs.frame_detections),
            str(spec.tracker),
            inputs.configs.get(name, inputs.config),
            sink=sink,
            classes=inputs.classes,
            frame_range=inputs.frame_range,
            on_frame=on_frame,
        )
        tracking = tracking if tracking.tracker == name else replace(tracking, tracker=name)
    return Run(tracking, tuple(events.events), facts.facts) if facts is not None else Run(tracking)


def run_all(
    inputs: Inputs, *, record: bool, on_frame: Callable[[str], Callable[[], None] | None] = lambda name: None
) -> list[Run]:
    """Every run of ``inputs`` once, in order; on_frame(name): the callback run ``name`` calls after each frame."""
    return [run_one(inputs, name, record=record, on_frame=on_frame(name)) for name in inputs.trackers]


def run_digest(run: TrackingRun) -> TrackDigest:
    """The track digest of one tracker run."""
    from gnnpmb.provenance import track_digest

    return track_digest([f.keyframe.index for f in run.frames], [f.estimates for f in run.frames])


def run_digests(runs: Sequence[Run]) -> dict[str, TrackDigest]:
    """Each run's track digest, by name."""
    return {run.name: run_digest(run.tracking) for run in runs}


def provenance_of(inputs: Inputs, digests: dict[str, TrackDigest]) -> Provenance:
    """The provenance of the runs of ``inputs`` whose tracks have ``digests``."""
    from gnnpmb.provenance import Provenance, recorded_versions

    return Provenance(
        argv=inputs.argv,
        versions=recorded_versions(),
        config=inputs.config.as_dict(),
        dataroot=str(inputs.location.dataroot),
        version=inputs.location.version,
        synthetic=inputs.scene.synthetic,
        scene_name=inputs.scene.name,
        scene_token=inputs.scene.token,
        detections=inputs.source,
        seed=inputs.seed,
        frame_start=inputs.frame_range.start,
        frame_end=inputs.frame_range.stop,
        classes=inputs.classes,
        trackers=tuple(recorded_spelling(inputs.spec(t)) for t in inputs.trackers),
        track_digests=digests,
    )
