"""What changed between two runs (``gnnpmb diff A B``): failures fixed, introduced and kept, and the metrics.

A and B are runs (``gnnpmb.runs``: a tracker, a tracker with its own parameters, or a results file) on the same
detections. Per scene, each failure of A is matched with one of B by what it is about, never by track ids (the
two runs number their tracks independently): the same kind, frame and class and the same object (ID switch,
fragmentation, miss, identity theft: the object; coalescence: the objects it missed) or, for a false track, a
false track of B within ``NEAR_M`` (BEV) of its box, nearest first. A failure of A alone was **fixed** by B, one
of B alone **introduced**, a matched pair **kept**. A fixed or introduced failure about objects also names the
other run's failures about the same objects at that frame (``instead``: a fragmentation B "fixed" by losing the
object for good is a miss of B there). Each change has an id per scene, ``diff:<change>:<n>``
(numbered by kind, association errors first, then object and frame: ``scene_diff``), which
``gnnpmb-viz SCENE --tracker A --tracker B --focus diff:introduced:1`` opens with both runs side by side
(``diff_failure``).
"""

from __future__ import annotations

import enum
from collections import Counter, defaultdict
from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import numpy as np

from gnnpmb.errors import GnnpmbError
from gnnpmb.eval.failures import OPEN_FIRST, Failure, FailureKind, FailureReport
from gnnpmb.runs import RunSpec
from gnnpmb.why.findings import NEAR_M

DIFF_METRICS: tuple[str, ...] = ("amota", "amotp", "mota", "recall", "tp", "fp", "fn", "ids", "frag")
"""The devkit metrics a diff reports per class, as named in ``metrics_summary.json``."""
HIGHER_IS_BETTER = frozenset({"amota", "mota", "recall", "tp"})


class Change(enum.Enum):
    FIXED = "fixed"  # A had it, B does not
    INTRODUCED = "introduced"  # B has it, A did not
    KEPT = "kept"  # both


@dataclass(frozen=True, slots=True)
class DiffEntry:
    """One failure's change on one scene: ``diff_id`` (``diff:<change>:<n>``), its kind, class and frame, the
    failure ids in A and B (None where the run does not have it), what it is (B's description, A's for a fixed
    one) and ``instead``: the ids of the other run's failures about the same objects at the same frame (a fixed
    one's in B, an introduced one's in A; () for a kept one or a false track)."""

    scene: str
    diff_id: str
    change: Change
    kind: FailureKind
    class_name: str
    frame: int
    before: str | None
    after: str | None
    what: str
    instead: tuple[str, ...] = ()

    def to_json(self) -> dict[str, object]:
        return {
            "scene": self.scene,
            "id": self.diff_id,
            "change": self.change.value,
            "kind": self.kind.value,
            "class_name": self.class_name,
            "frame": self.frame,
            "a": self.before,
            "b": self.after,
            "what": self.what,
            "instead": list(self.instead),
        }


def _about(f: Failure) -> tuple[str, ...]:
    """The objects a failure is about (module docstring); () for a false track."""
    if f.kind is FailureKind.COALESCENCE:
        return tuple(sorted(f.gt_ids[1:]))
    return tuple(sorted(f.gt_ids))


def _xy(f: Failure) -> np.ndarray:
    return np.asarray(f.boxes[0].translation_m[:2], dtype=np.float64)


def match_failures(
    a: FailureReport, b: FailureReport
) -> list[tuple[tuple[str, Failure] | None, tuple[str, Failure] | None]]:
    """Pairs ((A's id, failure) or None, (B's id, failure) or None) of one scene (module docstring), by frame."""
    if tuple(a.sample_tokens) != tuple(b.sample_tokens):
        raise ValueError(f"the reports are of {a.scene_name} and {b.scene_name}")
    groups: dict[tuple, list[list[tuple[str, Failure]]]] = defaultdict(lambda: [[], []])
    for side, report in enumerate((a, b)):
        for fid, f in zip(report.ids(), report.failures, strict=True):
            groups[(f.frame_index, f.kind, f.class_name, _about(f))][side].append((fid, f))
    pairs = []
    for key, (left, right) in groups.items():
        if key[1] is FailureKind.FALSE_TRACK:
            pairs += _by_place(left, right)
        else:
            pairs += [(x, y) for x, y in zip(left, right, strict=False)]
            longer = left if len(left) > len(right) else right
            rest = longer[min(len(left), len(right)) :]
            pairs += [((x, None) if longer is left else (None, x)) for x in rest]
    return sorted(pairs, key=lambda p: (next(x for x in p if x is not None)[1].frame_index, _order(p)))


def _order(pair: tuple) -> tuple[int, str]:
    f = next(x for x in pair if x is not None)[1]
    return list(FailureKind).index(f.kind), f.class_name


def _by_place(left: list, right: list) -> list:
    """False tracks of one frame and class matched by place: closest pairs within ``NEAR_M`` first."""
    d = [(float(np.hypot(*(_xy(x[1]) - _xy(y[1])))), i, j) for i, x in enumerate(left) for j, y in enumerate(right)]
    used_l, used_r, pairs = set(), set(), []
    for dist, i, j in sorted(d):
        if dist < NEAR_M and i not in used_l and j not in used_r:
            used_l.add(i)
            used_r.add(j)
            pairs.append((left[i], right[j]))
    pairs += [(x, None) for i, x in enumerate(left) if i not in used_l]
    pairs += [(None, y) for j, y in enumerate(right) if j not in used_r]
    return pairs


def scene_diff(scene: str, a: FailureReport, b: FailureReport) -> list[DiffEntry]:
    """The changes from A's failures to B's on one scene, numbered per change in the order worth a look: by kind
    (``eval.failures.OPEN_FIRST``: association errors first), then class, what the failure is about and frame (so
    one object's misses over consecutive frames take consecutive numbers)."""
    changed = []
    for x, y in match_failures(a, b):
        change = Change.KEPT if x is not None and y is not None else Change.FIXED if y is None else Change.INTRODUCED
        changed.append((change, x, y, (y or x)[1]))
    changed.sort(key=lambda c: (OPEN_FIRST.index(c[3].kind), c[3].class_name, _subject(c[3]), c[3].frame_index))
    seen: Counter[Change] = Counter()
    out = []
    for change, x, y, f in changed:
        seen[change] += 1
        other = b if change is Change.FIXED else a
        instead = () if change is Change.KEPT else _about_same(other, f)
        out.append(
            DiffEntry(
                scene,
                f"diff:{change.value}:{seen[change]}",
                change,
                f.kind,
                f.class_name,
                f.frame_index,
                x[0] if x is not None else None,
                y[0] if y is not None else None,
                f.describe(),
                instead,
            )
        )
    return out


def _about_same(report: FailureReport, f: Failure) -> tuple[str, ...]:
    """The ids of ``report``'s failures at ``f``'s frame about any object ``f`` is about (none for a false
    track)."""
    objects = set(_about(f))
    return tuple(
        fid
        for fid, g in zip(report.ids(), report.failures, strict=True)
        if g.frame_index == f.frame_index and objects & set(_about(g))
    )


def _subject(f: Failure) -> tuple[str, ...]:
    """What a failure is about, for ordering: its objects, or a false track's id."""
    return _about(f) or tuple(f.track_ids)


def grouped(entries: Sequence[DiffEntry]) -> list[list[DiffEntry]]:
    """Runs of entries of one scene, change, kind and class about the same thing (the same description) at
    consecutive frames with consecutive ids: one object missed over ten frames is one group."""
    out: list[list[DiffEntry]] = []
    for e in entries:
        last = out[-1][-1] if out else None
        if (
            last is not None
            and (last.scene, last.change, last.kind, last.class_name, _plain(last.what))
            == (e.scene, e.change, e.kind, e.class_name, _plain(e.what))
            and e.frame == last.frame + 1
            and _number(e) == _number(last) + 1
        ):
            out[-1].append(e)
        else:
            out.append([e])
    return out


def _plain(what: str) -> str:
    return what.split(" (", 1)[0]


def _number(e: DiffEntry) -> int:
    return int(e.diff_id.rsplit(":", 1)[1])


def diff_failure(ref: str, reports: Mapping[str, FailureReport]) -> tuple[Failure, str, str, DiffEntry]:
    """The failure ``diff:<ref>`` (``ref``: e.g. ``introduced:3``) names between the first two runs of ``reports``
    (A, then B): (failure, the run it is of, its id in that run, the entry). Raises a one-line error when there are
    not two runs or no such change."""
    names = list(reports)
    if len(names) < 2:
        raise GnnpmbError(f"--focus diff:{ref} compares two runs: give two (--tracker A --tracker B)")
    a, b = names[:2]
    entries = scene_diff(reports[a].scene_name, reports[a], reports[b])
    entry = next((e for e in entries if e.diff_id == f"diff:{ref}"), None)
    if entry is None:
        counts = Counter(e.change.value for e in entries)
        have = ", ".join(f"{n} {c}" for c, n in counts.items()) or "no change"
        raise GnnpmbError(
            f"--focus diff:{ref}: no such change from {a} to {b} on {reports[a].scene_name} ({have}); "
            f"gnnpmb diff {a} {b} --scene {reports[a].scene_name} lists them"
        )
    run, fid = (a, entry.before) if entry.change is Change.FIXED else (b, entry.after)
    failure = reports[run].by_id(str(fid))
    if failure is None:
        raise AssertionError(fid)
    return failure, run, str(fid), entry


def counts_table(entries: Sequence[DiffEntry]) -> list[tuple[str, str, int, int, int]]:
    """(kind, class, fixed, introduced, kept) per kind and class with any failure, in kind order."""
    counts: dict[tuple[FailureKind, str], Counter[Change]] = defaultdict(Counter)
    for e in entries:
        counts[(e.kind, e.class_name)][e.change] += 1
    order = list(FailureKind)
    return [
        (kind.value, cls, c[Change.FIXED], c[Change.INTRODUCED], c[Change.KEPT])
        for (kind, cls), c in sorted(counts.items(), key=lambda kv: (order.index(kv[0][0]), kv[0][1]))
    ]


@dataclass(frozen=True, slots=True)
class MetricDelta:
    """One metric of one class (or "overall") in A and in B; better: whether B's is the better value (None: equal
    or not comparable)."""

    class_name: str
    metric: str
    a: float
    b: float

    @property
    def delta(self) -> float:
        return self.b - self.a

    @property
    def better(self) -> bool | None:
        if not np.isfinite(self.delta) or self.delta == 0:
            return None
        return (self.delta > 0) == (self.metric in HIGHER_IS_BETTER)


def metric_deltas(
    a: tuple[Mapping[str, Mapping[str, float]], Mapping[str, float]],
    b: tuple[Mapping[str, Mapping[str, float]], Mapping[str, float]],
) -> list[MetricDelta]:
    """Per class (those with ground truth in A or B), then overall, each of ``DIFF_METRICS`` in A and B (the
    ``eval.scene_scores`` pairs of per-class and overall metrics)."""
    out = []
    for cls in a[0]:
        if np.isnan(a[0][cls].get("amota", np.nan)) and np.isnan(b[0][cls].get("amota", np.nan)):
            continue  # no ground truth of the class
        out += [MetricDelta(cls, m, a[0][cls].get(m, np.nan), b[0][cls].get(m, np.nan)) for m in DIFF_METRICS]
    out += [MetricDelta("overall", m, a[1].get(m, np.nan), b[1].get(m, np.nan)) for m in DIFF_METRICS]
    return out


@dataclass(frozen=True, slots=True)
class DiffResult:
    """A diff of run ``a`` to run ``b`` over ``scenes`` (``where``: "scene-0103" or "split mini_val"): every
    change (``DiffEntry``, scene by scene), the metric deltas and notices (e.g. boxes of a results file left
    out)."""

    a: RunSpec
    b: RunSpec
    where: str
    scenes: tuple[str, ...]
    entries: tuple[DiffEntry, ...]
    metrics: tuple[MetricDelta, ...]
    notices: tuple[str, ...]

    def of(self, change: Change) -> list[DiffEntry]:
        return [e for e in self.entries if e.change is change]
