"""A run's story: typed lines per frame and class (confirmed, missed, no longer shown, ended, close calls).

``Storyteller`` reads a tracker's facts frame by frame, in order, and keeps what a story needs to remember (the
tracks shown so far, those shown the frame before). Each ``StoryLine`` names its tracks (``track_ids``), so a
view picks the lines about some tracks without reading the text; the text is made here, once.
"""

from __future__ import annotations

import enum
from dataclasses import dataclass

import numpy as np

from gnnpmb.events import AxisKind, TrackLogicAction
from gnnpmb.why.facts import ClassFrame, TrackerFacts, Went
from gnnpmb.why.words import (
    SHOW_MIN_EXISTENCE,
    column_name,
    cost_named,
    cost_value,
    destination_text,
    existence_text,
    hits_text,
    margin_value,
    meas_name,
    threshold_held,
    undercut_text,
    use_text,
)

MAX_NAMED = 12
"""A line about new candidates names at most this many detections."""


class StoryKind(enum.Enum):
    CONFIRMED = "confirmed"  # first shown
    SHOWN_AGAIN = "shown again"  # shown after frames it was not
    MISSED = "missed"  # shown without a detection this frame
    HIDDEN = "hidden"  # an involved track below the show floor, every frame
    NO_LONGER_SHOWN = "no longer shown"
    ENDED = "ended"
    DELETED = "deleted"  # by track logic
    MERGED = "merged"
    CANDIDATES = "candidates"
    SUMMARY = "summary"
    CLOSE_CALL = "close call"
    DROPPED_PAIR = "dropped pair"  # a choice undercut by a solve before the threshold (``explain``)
    BUDGET = "budget"


@dataclass(frozen=True, slots=True)
class StoryLine:
    """One line of the story: its frame, class, kind, level (``TextLog`` level), the tracks it is about and its
    text."""

    frame: int
    class_name: str
    kind: StoryKind
    level: str
    track_ids: tuple[int, ...]
    text: str


class Storyteller:
    """Tells a run's story from its facts (module docstring). has_existence: whether tracks have existences
    (else nothing is said of them); show_min: the existence from which a track counts as shown; involved: tracks
    that get a line every frame even while not shown."""

    def __init__(
        self,
        facts: TrackerFacts,
        *,
        show_min: float = SHOW_MIN_EXISTENCE,
        involved: frozenset[int] = frozenset(),
    ) -> None:
        self.facts = facts
        self.show_min = show_min
        self.involved = involved
        self.shown_ever: set[int] = set()
        self._shown_before: dict[str, set[int]] = {}
        self._output_before: dict[str, set[int]] = {}

    @property
    def has_existence(self) -> bool:
        return self.facts.has_existence

    def frame_lines(self, frame: int) -> list[StoryLine]:
        """The lines of ``frame`` (call once per frame, in order): per class, then the frame's close calls."""
        out: list[StoryLine] = []
        for class_name, cf in self.facts.frames.get(frame, {}).items():
            out += self._class_lines(frame, class_name, cf)
        return out

    def _class_lines(self, frame: int, class_name: str, cf: ClassFrame) -> list[StoryLine]:
        lines: list[StoryLine] = []

        def say(kind: StoryKind, level: str, ids: tuple[int, ...], text: str) -> None:
            lines.append(StoryLine(frame, class_name, kind, level, ids, text))

        r = "w" if cf.intensity is not None else "r"  # the symbol: a GM-PHD / CPHD label's weight, else an existence
        posterior_r: dict[int, float] = {}
        if cf.posterior is not None:  # a GM-PHD / CPHD label has a row per component: its heaviest one's weight
            ids, rs = np.asarray(cf.posterior.track_ids).tolist(), np.asarray(cf.posterior.existence).tolist()
            for t, value in zip(ids, rs, strict=True):
                posterior_r[t] = max(value, posterior_r.get(t, value))
        if cf.intensity is not None:  # uncapped (the Posterior and the estimates hold min(w, 1))
            ids, ws = np.asarray(cf.intensity.labels).tolist(), np.asarray(cf.intensity.weights).tolist()
            for t, value in zip(ids, ws, strict=True):
                posterior_r[t] = max(value, posterior_r.get(t, value))
        extracted = cf.extracted.estimates if cf.extracted is not None else ()
        now = {e.track_id: e for e in extracted if e.existence >= self.show_min}
        known = self.shown_ever
        shown_last, output_last = self._shown_before.get(class_name, set()), self._output_before.get(class_name, set())
        hyp = self.facts.hypotheses(frame, class_name)
        output_only = self.facts.output_only
        for t, e in now.items():
            via = f"from {meas_name(e.meas_index)}" if e.meas_index >= 0 else "without a detection"
            weight = posterior_r.get(t, e.existence) if cf.intensity is not None else e.existence
            if output_only:  # a results file: only where its boxes were is known
                if t not in known:
                    on = f"on {meas_name(e.meas_index)}" if e.meas_index >= 0 else "on no detection"
                    say(StoryKind.CONFIRMED, "INFO", (t,), f"track {t} first output ({on})")
                elif e.meas_index < 0:
                    say(StoryKind.MISSED, "INFO", (t,), f"track {t} output with no detection under its box")
                continue
            if t not in known:
                since = self.facts.existed_since(t, class_name, frame) if hyp is not None else None
                why = ""
                if hyp is not None and hyp.switched and since is not None and since < frame:
                    why = (
                        f": the best hypothesis now descends from prior hypothesis {hyp.best_parent}, in which it "
                        f"has existed since frame {since}"
                    )
                copy_of = _copied(e, extracted, posterior_r) if cf.intensity is not None else None
                if copy_of is not None:  # Vo & Ma's round(w) copies of a heavy component: no weight of its own
                    said = (
                        f"track {t} confirmed (a copy of track {copy_of}'s component, {r}={posterior_r[copy_of]:.2f}, "
                        f"which the extraction outputs round({r}) times; {via})"
                    )
                    say(StoryKind.CONFIRMED, "INFO", (t,), said)
                    continue
                say(StoryKind.CONFIRMED, "INFO", (t,), f"track {t} confirmed ({self._r(weight, r)}{via}){why}")
            elif t not in shown_last:  # back after a gap the story reported ("no longer output", "fell below")
                back = "back above the display threshold" if t in output_last else "output again"
                say(StoryKind.SHOWN_AGAIN, "INFO", (t,), f"track {t} {back} ({self._r(weight, r)}{via})")
            elif e.meas_index < 0:
                copy_of = _copied(e, extracted, posterior_r) if cf.intensity is not None else None
                value = (
                    f" (a copy of track {copy_of}'s component, {r}={posterior_r[copy_of]:.2f})"
                    if copy_of is not None
                    else self._r_in(weight, r)
                )
                say(StoryKind.MISSED, "INFO", (t,), f"track {t} missed this frame, still reported{value}")
        output_ids = {e.track_id for e in extracted}  # the submission's tracks: down to the output threshold
        for t in sorted((self.involved & set(posterior_r)) - known - set(now)):
            step = self.facts.steps(t, class_name).get(frame)
            if step is None:
                continue
            via = f"started by {meas_name(step.born_from)}" if step.born_from is not None else use_text(step)
            value = f"{r}={existence_text(posterior_r[t])}"
            if not self.has_existence:
                text = f"track {t} (not output): {via}"
            elif t in output_ids:  # below the viewer's line, but in the submission: the evaluation may match it
                text = f"track {t} (output; {r} below the display threshold {self.show_min:g}): {via}, {value}"
            else:
                text = f"track {t} (not output): {via}, {value}"
            say(StoryKind.HIDDEN, "INFO", (t,), text)
        pruned_ids = {p.track_id for p in cf.pruned}
        limit = max(cf.extracted.threshold if cf.extracted is not None else 0.0, self.show_min)
        before = self._shown_before.get(class_name, set())
        for t in sorted(before - set(now) - pruned_ids):
            if output_only:
                say(StoryKind.NO_LONGER_SHOWN, "WARN", (t,), f"track {t} no longer output")
            elif t in posterior_r:
                if not self.has_existence:
                    text = f"track {t} no longer output"
                elif t in output_ids:  # "not shown" would read as not output: the evaluation still scores it
                    text = (
                        f"track {t} fell below the display threshold ({r}={posterior_r[t]:.2f} < "
                        f"{self.show_min:.2f}), still output"
                    )
                elif cf.cardinality is not None:  # CPHD: the n^ heaviest are output, no fixed threshold
                    text = f"track {t} no longer output ({r}={posterior_r[t]:.2f}; {_map_cardinality(cf)})"
                else:
                    text = f"track {t} no longer output ({r}={posterior_r[t]:.2f} fell below {limit:.2f})"
                say(StoryKind.NO_LONGER_SHOWN, "WARN", (t,), text)
        candidates_pruned = 0
        for p in cf.pruned:
            if p.track_id in known:
                last = f" (last {r}={p.last_existence:.3g})" if self.has_existence else ""
                say(StoryKind.ENDED, "WARN", (p.track_id,), f"track {p.track_id} ended: {p.reason.value}{last}")
            else:
                candidates_pruned += 1
        born = cf.born_of()
        if born or candidates_pruned:
            named = ", ".join(meas_name(m) for m in list(born)[:MAX_NAMED]) + (" …" if len(born) > MAX_NAMED else "")
            say(
                StoryKind.CANDIDATES,
                "DEBUG",
                tuple(born.values()),
                f"{len(born)} new candidates{' from ' + named if born else ''}; {candidates_pruned} candidates pruned",
            )
        for m in cf.merged:
            if m.into_id in known or any(f in known for f in m.from_ids):
                weights = ", ".join(f"{w:.3g}" for w in m.weights)
                ids = ", ".join(str(i) for i in m.from_ids)
                say(StoryKind.MERGED, "INFO", (m.into_id,), f"merged {ids} into track {m.into_id} (weights {weights})")
        for ev in cf.logic:
            if ev.action is TrackLogicAction.DELETED:
                say(
                    StoryKind.DELETED,
                    "WARN",
                    (ev.track_id,),
                    f"track {ev.track_id} deleted ({hits_text(ev.hits, ev.window)})",
                )
        use = self.facts.use(frame, class_name)
        if use is not None and cf.meas is not None and output_only:
            under = sum(1 for d in use.destinations.values() if d.went is Went.TRACK)
            say(
                StoryKind.SUMMARY,
                "DEBUG",
                (),
                f"{len(cf.meas.meas_indices)} detections: {under} under an output box",
            )
        elif use is not None and cf.meas is not None:
            to_tracks = sum(1 for d in use.destinations.values() if d.went is Went.TRACK)
            missed = [t for t, u in use.tracks.items() if t in known and not u.shares]
            say(
                StoryKind.SUMMARY,
                "DEBUG",
                tuple(missed),
                f"{len(cf.meas.meas_indices)} detections: {to_tracks} updated tracks, "
                f"{len(use.destinations) - to_tracks} new or clutter; reported tracks missed: "
                f"{', '.join(map(str, missed)) or 'none'}",
            )
        for b in cf.budgets:
            say(
                StoryKind.BUDGET,
                "WARN",
                (),
                f"budget {b.budget} = {b.limit} reached (this frame needed {b.needed}); work was cut",
            )
        lines += self._close_calls(frame, class_name, cf)
        self.shown_ever |= set(now)
        self._shown_before[class_name] = set(now)
        self._output_before[class_name] = output_ids
        return lines

    def _close_calls(self, frame: int, class_name: str, cf: ClassFrame) -> list[StoryLine]:
        """Close calls (on the tracker's own cost scale) that involve a shown track (between candidates they are
        routine)."""
        d = self.facts.decisions(frame, class_name)
        if d is None:
            return []
        born = cf.born_of()
        out = []
        for conflict in d.conflicts:
            for c in conflict.choices:
                tracks = {
                    label.ref
                    for label in (c.chosen, c.alternative)
                    if label is not None and label.kind is AxisKind.TRACK
                }
                if not (c.close_call or c.undercut) or not tracks & self.shown_ever:
                    continue
                b = born.get(int(c.meas.ref))
                if c.chosen.kind is AxisKind.TRACK:
                    went = column_name(c.chosen)
                else:
                    went = destination_text(b if b is not None else -1, True, c.chosen)
                chosen = threshold_held(c.chosen, c.chosen_cost, c) or cost_named(c.chosen_cost, c)
                if c.undercut:  # no close call: a solve before the threshold decided it (``explain``)
                    taken = {int(o.meas.ref) for o in conflict.choices if o is not c and o.chosen == c.alternative}
                    out.append(
                        StoryLine(
                            frame,
                            class_name,
                            StoryKind.DROPPED_PAIR,
                            "INFO",
                            tuple(sorted(tracks | ({b} if b is not None else set()))),
                            f"{meas_name(c.meas.ref)} → {went} ({chosen}), "
                            + undercut_text(c, next(iter(taken), None)),
                        )
                    )
                    continue
                held = threshold_held(c.alternative, c.alternative_cost, c)
                other = (
                    f"a new track ({held})"
                    if held is not None
                    else f"{column_name(c.alternative)} ({cost_value(c.alternative_cost, c)})"
                )
                pairs = cf.assignment.pairs if cf.assignment is not None else ()
                took = [int(r.ref) for r, k in pairs if k == c.alternative and int(r.ref) != int(c.meas.ref)]
                if held is None and took and c.alternative_cost < c.chosen_cost:  # the cheaper one had its own
                    other += f", which took {meas_name(took[0])} (the lower total wins)"  # world4's parked pair
                out.append(
                    StoryLine(
                        frame,
                        class_name,
                        StoryKind.CLOSE_CALL,
                        "INFO",
                        tuple(sorted(tracks | ({b} if b is not None else set()))),
                        f"close call: {meas_name(c.meas.ref)} → {went} ({chosen}) over {other}, margin "
                        f"{margin_value(c.margin, c)}",
                    )
                )
        return out

    def _r(self, existence: float, symbol: str = "r") -> str:
        return f"{symbol}={existence:.2f}, " if self.has_existence else ""

    def _r_in(self, existence: float, symbol: str = "r") -> str:
        return f" ({symbol}={existence:.2f})" if self.has_existence else ""


def _map_cardinality(cf: ClassFrame) -> str:
    """What a CPHD output this frame (``phd.cphd``: the MAP cardinality n^, then the n^ heaviest components):
    ``the MAP cardinality 3 kept the 3 heaviest components, the lightest at w=1.20`` / ``the MAP cardinality was
    0``. Its ``Extracted.threshold`` is that lightest weight, no threshold fixed beforehand (dev set scene-0916
    pointpillars cphd, track 15: "w=0.14 fell below 1.20" a frame after it was output at w=0.72)."""
    extracted = cf.extracted
    if extracted is None or not extracted.estimates:
        return "the MAP cardinality was 0"
    n = len(extracted.estimates)
    return f"the MAP cardinality {n} kept the {n} heaviest components, the lightest at w={extracted.threshold:.2f}"


def _copied(e, extracted, weights: dict[int, float]) -> int | None:
    """The label whose component estimate ``e`` copies (a GM-PHD extraction outputs a component round(w) times, the
    extra copies under ids of their own: Vo & Ma 2006, Table III), None when ``e`` has a component of its own or
    no estimate at its place has one."""
    if e.track_id in weights:
        return None
    at = np.asarray(e.translation_m, dtype=np.float64)
    for other in extracted:
        if other.track_id in weights and np.allclose(np.asarray(other.translation_m, dtype=np.float64), at):
            return other.track_id
    return None
