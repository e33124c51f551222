"""Costs as printed, checked against the deciding cost matrix of the frame (the one its assignment indexes) and
the detection file.

* a breakdown, "Track T's C = a for … + b for its predicted existence E + c for … (±S m) + d for the distance to
  mN (d² D) + e for mN's score S'" (also "Track T, which had the object, would have cost C = …"): C is the
  matrix's entry (mN, track T); the parts add up to C (as printed); E is the matrix's predicted existence of T
  (its ``CostTerms``), D its d²[T, mN], S' the detection file's score of mN;
* a choice, "frame x: mN (score S) → track T (cost C) over track U (C' at existence E, ±S m, d² D)": C is the
  entry of the column the assignment gave mN, C' the entry (mN, U), E and D U's terms, S the file's score;
* a new-track column said as a threshold, "→ new track T (the K threshold V)" / "over a new track (the K threshold
  V)" (also in a close call): the row's new-track entry is the matrix's cost threshold (its scale's, the value
  every track entry beyond it was set +inf against) and V prints it (1 - it for a similarity such as 3D IoU); a
  new-track column that holds the threshold said as a cost ("over new (3D IoU 0.10)") is ``misleading`` (it reads
  as a new track's IoU).

Printed values are compared as printed: two decimals for costs, existences and scores, one for d².
"""

from __future__ import annotations

import math
import re
from collections.abc import Iterator

from gnnpmb.events import Assignment, CostMatrix
from tools.truth import replay
from tools.truth.printing import BECAUSE, NUMBER, printed

_N = r"-?\d+\.\d+"
BREAKDOWN = re.compile(
    rf"Track (\d+)(?:'s|, which had the object, would have cost) ({_N}) = ({_N} for .+?)(?=\. [A-Z]|\.$|$)"
)
PART = re.compile(rf"({_N}) for ")
EXISTENCE = re.compile(rf"for its predicted existence ({NUMBER})")
DISTANCE = re.compile(rf"for the distance to m(\d+) \(d² ({_N})\)")
SCORE = re.compile(rf"for m(\d+)'s score ({_N})")
CHOICE = re.compile(
    rf"frame (\d+): m(\d+)(?: \(score ({_N})\))? → (?:new track \d+|track \d+|new|missed \d+) \(cost ({_N})\) "
    rf"over track (\d+) \(({_N})(?: at (?:existence ({NUMBER}), )?±[\d.]+ m, d² ({_N}))?\)"
)


HELD = re.compile(
    rf"frame (\d+): (?:close call: )?m(\d+)(?: \(score {_N}\))? → [^(\n]*?(?:\(([^()\n]*)\) )?over "
    rf"(?:a new track \(the ([^()\n]+?) threshold ({_N})(?: m)?\)|new \(([^()\n]*)\)|track \d+)"
)
CHOSEN_HELD = re.compile(rf"the ([^()\n]+?) threshold ({_N})(?: m)?")


def check_costs(text: str, c: str, raw, scene, out, bad) -> None:
    for b in BECAUSE.finditer(text):
        x = int(b[1])
        for m in BREAKDOWN.finditer(b[2]):
            _check_breakdown(m, x, c, raw, scene, out, bad)
    for m in CHOICE.finditer(text):
        _check_choice_costs(m, c, raw, scene, out, bad)
    check_thresholds(text, c, raw, out, bad)
    check_choice_values(text, c, raw, out, bad)


VALUES = re.compile(
    rf"frame (\d+): (?:close call: )?m(\d+)(?: \(score {_N}\))? → \**(?:new track \d+|track \d+|new|missed \d+)\** "
    rf"\((?:cost |the [^()\n]+? threshold |[\w ]*?[A-Za-z] )?({_N})(?: m)?[^()\n]*\) over (?:track (\d+)|new|a new "
    rf"track) \((?:the [^()\n]+? threshold |[\w ]*?[A-Za-z] )?({_N})"
)


def check_choice_values(text: str, c: str, raw, out, bad) -> None:
    """Every choice line's two values ("→ X (V) over Y (W)", on any scale: nats, metres, a similarity such as
    3D IoU, a threshold) against the deciding matrix: V the entry of the column the assignment gave the
    detection, W that of track Y or of the row's new-track column; a similarity prints 1 - the entry."""
    for m, mat, a in _decided(VALUES, text, c, raw):
        meas = int(m[2])
        row, chosen = replay.row_of(mat, meas), replay.chosen_col(mat, a, meas)
        if row is None or chosen is None:
            continue
        alt = replay.track_col(mat, int(m[4])) if m[4] else None
        other = float(mat.cost[row, alt]) if alt is not None else None if m[4] else _new_entry(mat, row, meas)
        similar = mat.scale is not None and mat.scale.similarity is not None
        out.checked["cost"] += 1
        entry, after = _as_printed(float(mat.cost[row, chosen]), similar), _as_printed(other, similar)
        if entry != m[3] or after != m[5]:
            bad("cost", m[0][:160], f"the deciding matrix gives {entry} for the chosen, {after} for the other")


def _decided(
    pattern: re.Pattern[str], text: str, c: str, raw
) -> Iterator[tuple[re.Match[str], CostMatrix, Assignment]]:
    """Each match of ``pattern`` (its group 1 a frame) with the frame's deciding matrix and assignment of class
    ``c`` (``raw.deciding``); none without raw events."""
    if raw is None:
        return
    for m in pattern.finditer(text):
        found = raw.deciding(int(m[1]), c)
        if found is not None:
            yield m, *found


def _as_printed(value: float | None, similar: bool) -> str | None:
    """A matrix entry as a choice line prints it: two decimals, of 1 - it for a similarity (None: no entry)."""
    return None if value is None else f"{1.0 - value:.2f}" if similar else f"{value:.2f}"


def check_thresholds(text: str, c: str, raw, out, bad) -> None:
    """The choice lines (and a story's close calls) whose new-track column is said as a threshold, or said as a
    cost where it holds one (module docstring)."""
    for m, mat, _ in _decided(HELD, text, c, raw):
        row = replay.row_of(mat, int(m[2]))
        entry = _new_entry(mat, row, int(m[2])) if row is not None else None
        if entry is None:
            continue
        threshold = mat.scale.threshold if mat.scale is not None else None
        holds = threshold is not None and math.isclose(entry, threshold, rel_tol=1e-9, abs_tol=1e-12)
        similar = mat.scale is not None and mat.scale.similarity is not None
        shown = f"{1.0 - entry:.2f}" if similar else f"{entry:.2f}"
        said = [(m[4], m[5])] if m[4] else []
        chosen = CHOSEN_HELD.fullmatch(m[3] or "")
        if chosen is not None:
            said.append((chosen[1], chosen[2]))
        for _, value in said:
            out.checked["cost"] += 1
            if not holds or value != shown:
                bad("cost", m[0], f"m{m[2]}'s new-track entry is {entry:.4f}, the matrix's threshold {threshold}")
        if m[6] is not None:  # "over new (V)": a cost, or a threshold said as one
            out.checked["misleading"] += 1
            if holds:
                bad("misleading", m[0], f"the new-track entry {entry:.4f} is the matrix's threshold, not a cost")


def _new_entry(mat, row: int, meas: int) -> float | None:
    """The entry of detection ``meas``'s new-track column in ``row`` (its own, else the row's finite one)."""
    from gnnpmb.events import AxisKind

    cols = [k for k, col in enumerate(mat.cols) if col.kind is AxisKind.NEW_TRACK]
    own = [k for k in cols if int(mat.cols[k].ref) == meas]
    finite = [k for k in own or cols if math.isfinite(float(mat.cost[row, k]))]
    return float(mat.cost[row, finite[0]]) if finite else None


def _terms_of(mat, row: int, t: int) -> tuple[float | None, float | None]:
    """(predicted existence, d²) of track ``t`` for the matrix's ``row`` (None: its terms do not say)."""
    terms = mat.terms
    k = terms.column_of(t) if terms is not None else None
    if k is None:
        return None, None
    existence = None if terms.existence is None else float(terms.existence[k])
    return existence, float(terms.d2[k, row])


def _check_breakdown(m: re.Match, x: int, c: str, raw, scene, out, bad) -> None:
    t, total, parts = int(m[1]), m[2], m[3]
    dist = DISTANCE.search(parts)
    found = raw.deciding(x, c)
    if dist is None or found is None:
        return
    meas = int(dist[1])
    mat, _ = found
    row, col = replay.row_of(mat, meas), replay.track_col(mat, t)
    out.checked["cost"] += 1
    if row is None or col is None:
        bad("cost", m[0], f"the deciding matrix of frame {x} has no entry (m{meas}, track {t})")
        return
    entry = float(mat.cost[row, col])
    summed = sum(float(v) for v in PART.findall(parts))
    existence, d2 = _terms_of(mat, row, t)
    wrong = []
    if not math.isfinite(entry) or f"{entry:.2f}" != total:
        wrong.append(f"the matrix's entry is {entry:.4f}")
    if abs(summed - float(total)) > 0.005 + 1e-9:
        wrong.append(f"the parts add up to {summed:.2f}")
    e = EXISTENCE.search(parts)
    if e is not None and (existence is None or printed(existence) != e[1]):
        wrong.append(f"its predicted existence is {existence}")
    if d2 is not None and f"{d2:.1f}" != dist[2]:
        wrong.append(f"its d² is {d2:.3f}")
    s = SCORE.search(parts)
    if s is not None and scene is not None and f"{scene.detections[x][int(s[1])].score:.2f}" != s[2]:
        wrong.append(f"m{s[1]}'s score is {scene.detections[x][int(s[1])].score}")
    if wrong:
        bad("cost", m[0][:160], "; ".join(wrong))


def _check_choice_costs(m: re.Match, c: str, raw, scene, out, bad) -> None:
    x, meas, alt = int(m[1]), int(m[2]), int(m[5])
    found = raw.deciding(x, c)
    if found is None:
        return
    mat, a = found
    row, chosen, other = replay.row_of(mat, meas), replay.chosen_col(mat, a, meas), replay.track_col(mat, alt)
    if row is None or chosen is None:
        return
    out.checked["cost"] += 1
    wrong = []
    if f"{float(mat.cost[row, chosen]):.2f}" != m[4]:
        wrong.append(f"the chosen entry is {float(mat.cost[row, chosen]):.4f}")
    if other is None or f"{float(mat.cost[row, other]):.2f}" != m[6]:
        wrong.append(f"track {alt}'s entry is {None if other is None else float(mat.cost[row, other])}")
    elif m[8] is not None:
        existence, d2 = _terms_of(mat, row, alt)
        if m[7] is not None and (existence is None or printed(existence) != m[7]):
            wrong.append(f"track {alt}'s predicted existence is {existence}")
        if d2 is None or f"{d2:.1f}" != m[8]:
            wrong.append(f"track {alt}'s d² is {d2}")
    dets = scene.detections[x] if scene is not None and x < len(scene.detections) else []
    if m[3] is not None and meas < len(dets) and f"{dets[meas].score:.2f}" != m[3]:
        wrong.append(f"m{meas}'s score is {dets[meas].score}")
    if wrong:
        bad("cost", m[0], "; ".join(wrong))
