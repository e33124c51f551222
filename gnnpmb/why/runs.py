"""Runs of alike findings, so ``gnnpmb failures --why`` says a repeated story once.

A track output falsely for twelve frames running, or an object missed the same way frame after frame, gives one
finding per frame whose sentences differ only in that frame's numbers. This module groups such findings after
``words`` has written them (it reads the finished sentences and never changes what they claim):

* a finding's sentences (``Said``) are cut into literal text and per-frame values (``Slot``): the frame number
  (only where it is the finding's own frame), a detection's id (``m12``), a score (``score 0.54``), a distance
  (``0.3 m``) and a count of points in a box (never a zero count: no points is a claim of its own);
* consecutive findings of one subject (the same kind, class, object and tracks: a track or object id is never a
  per-frame value) at consecutive frames join a ``Run`` only when their whose-doing and every sentence are equal
  with those values taken out; the values that differ within the run are shown as ``<detection>``, ``<score 1>``
  ... and given per frame on a line of their own, the values that do not stay in the text;
* a comparison with another run (the clause that starts with its name, ``immortal on the same detections ...``)
  that is word for word the one the same subject's previous run gave is not repeated: ``immortal: as for miss:11``
  names the finding where it was written out.

``--json`` keeps every finding as data, and every id stays openable with ``gnnpmb-viz --focus ID``.
"""

from __future__ import annotations

import enum
import re
from collections.abc import Sequence
from dataclasses import dataclass

from gnnpmb.why.findings import Finding
from gnnpmb.why.words import consecutive_runs, plain, whose_text, why_lines


class Slot(enum.Enum):
    """A per-frame value a run's sentences may differ in."""

    FRAME = "frame"
    DETECTION = "detection"
    SCORE = "score"
    DISTANCE = "distance"
    POINTS = "points"


_VALUES = re.compile(
    r"(?P<frame>(?<=\bframe )\d+\b)"
    r"|(?P<detection>\bm\d+\b)"
    r"|(?P<score>(?<=\bscore )\d+\.\d+\b)"
    r"|(?P<distance>(?<![\d.])\d+\.\d+(?= m\b))"
    r"|(?P<points>(?<![\d,–-])[1-9][\d,]*(?= LiDAR and| radar points))"
)
"""Where each ``Slot``'s values stand in a sentence (``words`` prints them so: ``at frame 7``, ``m6``,
``(score 0.69)``, ``0.1 m``, ``25 LiDAR and radar points``); a whole number of metres (``within 2 m``, the
evaluation's ``40 m`` range) is a constant of the text, not a measurement."""


@dataclass(frozen=True, slots=True)
class Cut:
    """A sentence cut at its per-frame values: ``texts`` has one more item than ``slots``; the sentence is
    ``texts[0] + values[0] + texts[1] + ...``."""

    texts: tuple[str, ...]
    slots: tuple[Slot, ...]
    values: tuple[str, ...]

    @property
    def shape(self) -> tuple[tuple[str, ...], tuple[Slot, ...]]:
        """What two sentences must share to be alike: everything but the values."""
        return self.texts, self.slots

    def text(self, shown: Sequence[str] | None = None) -> str:
        """The sentence with ``shown`` in place of the values (default: its own values)."""
        values = self.values if shown is None else shown
        out = [self.texts[0]]
        for value, text in zip(values, self.texts[1:], strict=True):
            out += [value, text]
        return "".join(out)


def cut(sentence: str, frame: int) -> Cut:
    """``sentence`` cut at its per-frame values (``_VALUES``); a frame number other than ``frame`` (the finding's
    own) stays text: ``frames 31 and 33`` or an earlier frame of the story are claims, not the run's clock."""
    texts: list[str] = []
    slots: list[Slot] = []
    values: list[str] = []
    start = 0
    for m in _VALUES.finditer(sentence):
        slot = Slot(m.lastgroup)
        if slot is Slot.FRAME and int(m.group()) != frame:
            continue
        texts.append(sentence[start : m.start()])
        slots.append(slot)
        values.append(m.group())
        start = m.end()
    texts.append(sentence[start:])
    return Cut(tuple(texts), tuple(slots), tuple(values))


@dataclass(frozen=True, slots=True)
class Said:
    """One finding as ``failures --why`` prints it: id, frame, class, whose doing, the subject it is about (kind,
    class, object, tracks), its **Why** sentence without its comparisons (``why``, without the closing full stop),
    the comparisons with other runs (``comparisons``, one per other run, each starting with that run's name in
    ``others``; empty when the sentence does not end in them) and its other lines (``Because``)."""

    failure_id: str
    frame: int
    class_name: str
    whose: str
    subject: tuple[str, str, str | None, tuple[int, ...]]
    why: str
    comparisons: tuple[str, ...]
    others: tuple[str, ...]
    rest: tuple[str, ...]

    def cuts(self) -> tuple[Cut, ...]:
        """Every sentence of the finding, cut: the Why, each comparison, each other line."""
        return tuple(cut(s, self.frame) for s in (self.why, *self.comparisons, *self.rest))


def said(f: Finding) -> Said:
    """``f`` as ``words`` writes it (``whose_text``, ``why_lines`` made plain), its comparisons split off."""
    lines = [plain(line) for line in why_lines(f) if line]
    why, rest = (lines[0], tuple(lines[1:])) if lines else ("", ())
    others = tuple(o.tracker for o in f.others)
    comparisons = split_comparisons(why, others)
    if comparisons:
        why = why.removesuffix(".").rsplit("; ", len(others))[0]
    return Said(
        f.failure_id,
        f.frame,
        f.class_name,
        whose_text(f),
        (f.kind.value, f.class_name, f.gt_id, f.track_ids),
        why,
        comparisons,
        others if comparisons else (),
        rest,
    )


def split_comparisons(why: str, others: Sequence[str]) -> tuple[str, ...]:
    """The last ``len(others)`` clauses of a **Why** sentence (``; ``-separated, full stop dropped) when each
    starts with its run's name (``words`` ends the sentence with one clause per other run, in order, none holding
    ``; ``); () when the sentence does not end so (then nothing is shortened)."""
    if not others:
        return ()
    head, *clauses = why.removesuffix(".").rsplit("; ", len(others))
    if len(clauses) != len(others) or ": " not in head:
        return ()
    if not all(c.startswith((f"{name} ", f"{name}'s ")) for c, name in zip(clauses, others, strict=True)):
        return ()
    return tuple(clauses)


@dataclass(frozen=True, slots=True)
class Run:
    """Findings of one subject at consecutive frames whose sentences are alike (``Cut.shape`` equal): printed
    once. ``members`` in frame order; ``as_for``: per comparison, the id(s) of the run that wrote it out when it
    is word for word the one the subject's previous run gave (None: written out here)."""

    members: tuple[Said, ...]
    as_for: tuple[str | None, ...]

    @property
    def first(self) -> Said:
        return self.members[0]


def group(findings: Sequence[Said]) -> list[Run]:
    """``findings`` (in printed order) as runs, each placed where its first member was."""
    open_runs: dict[tuple, int] = {}
    members: list[list[int]] = []
    for n, f in enumerate(findings):
        key = (f.subject, f.others)
        run = open_runs.get(key)
        if run is not None:
            last = findings[members[run][-1]]
            if last.frame + 1 == f.frame and _alike(last, f):
                members[run].append(n)
                continue
        open_runs[key] = len(members)
        members.append([n])
    runs: list[Run] = []
    spelled: dict[tuple, tuple[tuple[str, ...], tuple[str | None, ...]]] = {}
    for indices in members:
        said_ = tuple(findings[i] for i in indices)
        first = said_[0]
        key = (first.subject, first.others)
        previous = spelled.get(key)
        texts = _fixed_comparisons(said_)
        as_for: list[str | None] = []
        where: list[str | None] = []
        for k, text in enumerate(texts):
            if text is not None and previous is not None and previous[0][k] == text:
                as_for.append(previous[1][k])
                where.append(previous[1][k])
            else:
                as_for.append(None)
                where.append(ids_text([m.failure_id for m in said_]) if text is not None else None)
        spelled[key] = (texts, tuple(where))
        runs.append(Run(said_, tuple(as_for)))
    return runs


def _alike(a: Said, b: Said) -> bool:
    return a.whose == b.whose and [c.shape for c in a.cuts()] == [c.shape for c in b.cuts()]


def _fixed_comparisons(members: Sequence[Said]) -> tuple[str | None, ...]:
    """Each comparison's words when every member has the same (None where they differ)."""
    first = members[0].comparisons
    return tuple(c if all(m.comparisons[k] == c for m in members) else None for k, c in enumerate(first))


def ids_text(ids: Sequence[str]) -> str:
    """``miss:12`` / ``miss:12-14`` / ``false_track:2, 5, 8`` (one kind; consecutive numbers as ranges)."""
    kind = ids[0].split(":")[0]
    spans = consecutive_runs(int(i.split(":")[1]) for i in ids)
    return f"{kind}:" + ", ".join(str(s[0]) if len(s) == 1 else f"{s[0]}-{s[-1]}" for s in spans)


def run_lines(run: Run) -> list[str]:
    """The run as printed: a heading (ids, frames, class, whose doing), the **Why** (with ``<slot>`` for a value
    that differs per frame and ``T: as for ID`` for a comparison given before), its other lines, then, when any
    value besides the frame differs, ``per frame (frame: <detection>, ...): 7: m6, ...; 8: ...``."""
    first = run.first
    frames = [m.frame for m in run.members]
    when = f"frame {frames[0]}" if len(frames) == 1 else f"frames {frames[0]}-{frames[-1]}"
    head = f"{ids_text([m.failure_id for m in run.members])} ({when}, {first.class_name}): {first.whose}"
    per_member = [m.cuts() for m in run.members]
    cuts = per_member[0]
    varying = [[len({c[k].values[i] for c in per_member}) > 1 for i in range(len(x.slots))] for k, x in enumerate(cuts)]
    names = _slot_names(cuts, varying)
    shown = [tuple(names[(k, i)] if varying[k][i] else v for i, v in enumerate(c.values)) for k, c in enumerate(cuts)]
    texts = [c.text(s) for c, s in zip(cuts, shown, strict=True)]
    n_comp = len(first.comparisons)
    why, comparisons, rest = texts[0], texts[1 : 1 + n_comp], texts[1 + n_comp :]
    said_ = [
        text if as_for is None else f"{name}: as for {as_for}"
        for text, as_for, name in zip(comparisons, run.as_for, first.others, strict=True)
    ]
    lines = [head, "; ".join([why, *said_]) + ("." if n_comp else "")]
    lines += rest
    columns = [
        (k, i) for k, row in enumerate(varying) for i, v in enumerate(row) if v and cuts[k].slots[i] is not Slot.FRAME
    ]
    if columns:
        rows = [
            f"{m.frame}: " + ", ".join(c[k].values[i] for k, i in columns)
            for m, c in zip(run.members, per_member, strict=True)
        ]
        lines.append(f"per frame (frame: {', '.join(names[c] for c in columns)}): " + "; ".join(rows))
    return lines


def _slot_names(cuts: Sequence[Cut], varying: Sequence[Sequence[bool]]) -> dict[tuple[int, int], str]:
    """``<detection>`` for each varying value, numbered where a run has several of one slot (``<score 2>``)."""
    at = [(k, i) for k, row in enumerate(varying) for i, v in enumerate(row) if v]
    count: dict[Slot, int] = {}
    for k, i in at:
        count[cuts[k].slots[i]] = count.get(cuts[k].slots[i], 0) + 1
    seen: dict[Slot, int] = {}
    names = {}
    for k, i in at:
        slot = cuts[k].slots[i]
        seen[slot] = seen.get(slot, 0) + 1
        names[(k, i)] = f"<{slot.value}>" if count[slot] == 1 or slot is Slot.FRAME else f"<{slot.value} {seen[slot]}>"
    return names
