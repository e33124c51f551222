"""The decision view: why the solver chose each association this frame (``gnnpmb.explain``), as text and as a
labelled cost grid.

``decisions_markdown`` lists, per class, each conflict (tracks and detections linked through gates), closest call
first: for every detection the chosen column and its cost, the best alternative and its cost, and the margin
(how much worse the best assignment gets without that pair). ``decision_grid`` lays the same conflicts out as a
2D cost grid: one block per class, rows = detections (``m<idx>``), columns = tracks and one "new" column (each
detection's own birth/clutter cost), each cell labelled with its cost and the chosen cells outlined, so the grid
and the table show exactly the same columns.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from gnnpmb.events import AxisKind, CostMatrix, GlobalHypotheses, label_positions
from gnnpmb.explain import LINK_SLACK, Conflict, Decisions
from gnnpmb.why.words import choice_why, column_name, meas_name, plural

_TRACK = AxisKind.TRACK.value
_NEW = AxisKind.NEW_TRACK.value

MAX_CONFLICTS_PER_CLASS = 6
"""The decision document lists at most this many conflicts per class (closest calls first)."""
MAX_TABLE_CELLS = 400
MAX_HYPOTHESES_LISTED = 5
"""The decision document lists the best this many PMBM global hypotheses per class."""


def _fmt(value: float) -> str:
    return "–" if not math.isfinite(value) else f"{value:.2f}"


def _ids(track_ids: tuple[int, ...], reported: set[int] | None) -> str:
    """Track ids, the reported ones by number and the candidates (never reported) counted."""
    if reported is None:
        return ", ".join(str(t) for t in track_ids) or "none"
    shown = [str(t) for t in track_ids if t in reported]
    hidden = len(track_ids) - len(shown)
    counted = f"{hidden} candidate{'s' if hidden > 1 else ''}"
    if not shown:
        return counted if hidden else "none"
    return ", ".join(shown) + (f" (+{counted})" if hidden else "")


def _tracks_phrase(track_ids: tuple[int, ...], reported: set[int] | None) -> str:
    """``track 26``, ``tracks 26, 123 and 1 candidate``, ``2 candidate tracks`` (candidates: never reported)."""
    shown = [str(t) for t in track_ids if reported is None or t in reported]
    hidden = len(track_ids) - len(shown)
    if not shown:
        return f"{hidden} candidate track{'s' if hidden != 1 else ''}" if hidden else "no track"
    named = f"track{'s' if len(shown) > 1 else ''} {', '.join(shown)}"
    return named + (f" and {plural(hidden, 'candidate')}" if hidden else "")


def conflict_markdown(conflict: Conflict, reported: set[int] | None = None) -> str:
    """One conflict as a heading line and a table (one row per detection). reported: tracks named by id (the
    others, candidates never reported, are counted); None names all."""
    tracks = _tracks_phrase(conflict.track_ids, reported)
    meas = ", ".join(meas_name(m) for m in conflict.meas_indices)
    meas = f"detection{'s' if len(conflict.meas_indices) != 1 else ''} {meas}"
    margin = conflict.closest_margin
    flag = " **close call**" if conflict.close_call else ""
    lines = [
        f"{tracks} · {meas} — closest margin {_fmt(margin)}{flag}",
        "",
        "| detection | chosen | cost | next best | cost | margin |",
        "|---|---|---|---|---|---|",
    ]
    for c in conflict.choices:
        alt = column_name(c.alternative) if c.alternative is not None else "none"
        lines.append(
            f"| {meas_name(c.meas.ref)} | **{column_name(c.chosen)}** | {_fmt(c.chosen_cost)} | {alt} | "
            f"{_fmt(c.alternative_cost)} | {_fmt(c.margin)} |"
        )
    whys = [why for c in conflict.choices if (why := choice_why(c)) is not None]
    if whys:
        lines.append("")
        lines += [f"- {why}" for why in whys]
    if conflict.missed_track_ids:
        lines.append("")
        lines.append(f"missed (no detection, cost 0): {_ids(conflict.missed_track_ids, reported)}")
    return "\n".join(lines) + "\n"


def decisions_markdown(
    tracker: str,
    frame_index: int,
    decisions: Sequence[Decisions],
    fallbacks: Sequence[CostMatrix] = (),
    *,
    focus_tracks: set[int] | None = None,
    reported: set[int] | None = None,
    hypotheses: Sequence[GlobalHypotheses] = (),
) -> str:
    """The frame's decision document: classes with conflicts (closest call first), then matrices that do not
    have the shared layout as plain tables. focus_tracks: list the conflicts involving these tracks first;
    reported: see ``conflict_markdown``; hypotheses: PMBM global hypotheses listed per class (when more than one
    is kept)."""
    head = [
        f"## {tracker} · frame {frame_index}: why each detection went where it did",
        "",
        *_scale_notes(decisions),
        "",
    ]
    body: list[str] = []
    ordered = sorted(decisions, key=lambda d: min((c.closest_margin for c in d.conflicts), default=math.inf))
    for d in ordered:
        conflicts = list(d.conflicts)
        if focus_tracks:
            conflicts.sort(key=lambda c: not c.involves(focus_tracks))
        if not conflicts and not d.births_only:
            continue
        body.append(f"### {d.class_name}")
        if d.births_only:
            body.append(
                f"{plural(len(d.births_only), 'detection')} no track competed for (outside every gate, or dearer "
                f"than a new track by over {LINK_SLACK:g}), so each is a new track or clutter: "
                + ", ".join(meas_name(m) for m in d.births_only)
            )
            body.append("")
        for c in conflicts[:MAX_CONFLICTS_PER_CLASS]:
            body.append(conflict_markdown(c, reported))
        if len(conflicts) > MAX_CONFLICTS_PER_CLASS:
            body.append(f"… {len(conflicts) - MAX_CONFLICTS_PER_CLASS} more conflicts with larger margins\n")
    for m in fallbacks:
        body.append(f"### {m.class_name} ({m.description})")
        body.append(_plain_table(m))
    body += [hypotheses_markdown(event, reported) for event in hypotheses if len(event.members) > 1]
    if not body:
        body.append("No detections and no tracks to decide about in this frame.")
    return "\n".join(head + body) + "\n"


def _scale_notes(decisions: Sequence[Decisions]) -> list[str]:
    """What the costs and margins of the frame's matrices are, once per cost scale (``events.CostScale``)."""
    out = []
    for scale in dict.fromkeys(d.scale for d in decisions):
        if scale.unit == "nats":
            out.append(
                "cost = −log likelihood ratio against *the track was missed* (lower = more likely; **new** = the "
                "detection starts a track or is clutter). margin = how much worse the best assignment gets without "
                f"that pair (a close call below {scale.close_call:g})."
            )
        elif scale.similarity is not None:
            how = "the best assignment gets" if scale.optimal else "the detection's next closest column is"
            never = (
                f" a pair with {scale.similarity} below {1 - scale.threshold:g} is never matched;"
                if (scale.threshold is not None)
                else ""
            )
            new = (
                f"**new** holds the threshold {scale.threshold:g} = 1 − {scale.similarity} {1 - scale.threshold:g}: "
                "the detection starts a track unless a track is cheaper"
                if scale.threshold is not None
                else "**new** = the detection starts a track"
            )
            out.append(
                f"cost = 1 − {scale.similarity} (lower = more overlap;{never} {new}). "
                f"margin = how much worse {how}, in {scale.similarity} (a close call below {scale.close_call:g})."
            )
        else:
            how = "the best assignment gets" if scale.optimal else "the detection's next closest column is"
            new = (
                f"**new** holds the threshold {scale.threshold:g} {scale.unit}: the detection starts a track unless a "
                "track is closer"
                if scale.threshold is not None
                else "**new** = the detection starts a track"
            )
            out.append(
                f"cost = {scale.name} in {scale.unit} (lower = closer; {new}). margin "
                f"= how much worse {how} (a close call below {scale.close_call:g} {scale.unit})."
            )
    return out or [
        "cost = −log likelihood ratio against *the track was missed* (lower = more likely; **new** = the detection "
        "starts a track or is clutter). margin = how much worse the best assignment gets without that pair."
    ]


def hypotheses_markdown(event: GlobalHypotheses, reported: set[int] | None = None) -> str:
    """The kept PMBM global hypotheses of one class: probability, and what tells each apart from the best one
    (tracks only it holds, tracks only the best holds, tracks it explains with another association history)."""
    weights = np.exp(np.asarray(event.log_weights, dtype=np.float64))
    n = len(event.members)
    lines = [
        f"### {event.class_name}: {n} global hypotheses kept",
        "",
        "| hypothesis | probability | differs from h0 by |",
        "|---|---|---|",
    ]
    best = dict(zip(event.members[0], event.local[0], strict=True)) if n else {}
    for h in range(min(n, MAX_HYPOTHESES_LISTED)):
        mine = dict(zip(event.members[h], event.local[h], strict=True))
        if h == 0:
            diff = "(the best, shown in the views)"
        else:
            added = sorted(set(mine) - set(best))
            dropped = sorted(set(best) - set(mine))
            other = sorted(t for t in set(mine) & set(best) if mine[t] != best[t])
            parts = []
            if other:
                parts.append("other association for " + _ids(tuple(other), reported))
            if added:
                parts.append("also " + _ids(tuple(added), reported))
            if dropped:
                parts.append("without " + _ids(tuple(dropped), reported))
            diff = "; ".join(parts) or "nothing visible (same tracks, same associations)"
        lines.append(f"| h{h} | {weights[h]:.3f} | {diff} |")
    if n > MAX_HYPOTHESES_LISTED:
        lines.append(f"| … | {weights[MAX_HYPOTHESES_LISTED:].sum():.3f} | {n - MAX_HYPOTHESES_LISTED} more |")
    return "\n".join(lines) + "\n"


def _plain_table(matrix: CostMatrix) -> str:
    """A matrix without the shared layout, without its all-impossible columns; row per line when large."""
    cost = np.asarray(matrix.cost, dtype=np.float64)
    keep = np.flatnonzero(np.isfinite(cost).any(axis=0)) if cost.size else np.zeros(0, dtype=np.int64)
    cols = [column_name(matrix.cols[j]) for j in keep]
    rows = [column_name(r) for r in matrix.rows]
    if cost.size == 0:
        return "(empty)\n"
    if len(rows) * len(cols) <= MAX_TABLE_CELLS:
        lines = ["| | " + " | ".join(cols) + " |", "|---" * (len(cols) + 1) + "|"]
        for name, row in zip(rows, cost[:, keep], strict=True):
            lines.append(f"| **{name}** | " + " | ".join(_fmt(v) for v in row) + " |")
        return "\n".join(lines) + "\n"
    out = []
    for name, row in zip(rows, cost[:, keep], strict=True):
        ok = np.isfinite(row)
        entries = ", ".join(f"{c} {_fmt(v)}" for c, v, o in zip(cols, row, ok, strict=True) if o)
        out.append(f"- **{name}**: {entries or 'nothing possible'}")
    return "\n".join(out) + "\n"


@dataclass(frozen=True, slots=True)
class Grid:
    """A 2D cost grid: cells (N) with centres (N, 2), cost (N,), labels; chosen (N,) bool; axis labels at
    positions (L, 2). One unit per cell; y grows downward (rows), blocks of classes stacked."""

    centers: np.ndarray
    costs: np.ndarray
    labels: list[str]
    chosen: np.ndarray
    axis_positions: np.ndarray
    axis_labels: list[str]


def decision_grid(
    decisions: Sequence[Decisions],
    matrices: dict[str, CostMatrix],
    max_blocks: int = 4,
    reported: set[int] | None = None,
    focus_tracks: set[int] | None = None,
) -> Grid:
    """Lay the conflicts out as stacked blocks, closest call first (at most ``max_blocks``): per block the rows
    are its detections, the columns its tracks then "new" (each detection's own birth/clutter cost). reported:
    only these tracks, and candidates a detection was given, get a column (None: every track). Conflicts
    involving ``focus_tracks`` come first."""
    centers: list[tuple[float, float]] = []
    costs: list[float] = []
    labels: list[str] = []
    chosen: list[bool] = []
    axis_pos: list[tuple[float, float]] = []
    axis_lab: list[str] = []
    blocks = sorted(
        ((c, d.class_name) for d in decisions for c in d.conflicts[:MAX_CONFLICTS_PER_CLASS]),
        key=lambda b: (not b[0].involves(focus_tracks or set()), b[0].closest_margin),
    )[:max_blocks]
    y0 = 0.0
    lookups: dict[str, tuple[dict[int, int], dict[int, int], dict[int, int]]] = {}
    for conflict, class_name in blocks:
        m = matrices[class_name]
        cost = np.asarray(m.cost, dtype=np.float64)
        if class_name not in lookups:  # one class may give several blocks
            rows_by_kind, cols_by_kind = label_positions(m.rows), label_positions(m.cols)
            lookups[class_name] = (
                rows_by_kind.get(AxisKind.MEASUREMENT, {}),
                cols_by_kind.get(AxisKind.TRACK, {}),
                cols_by_kind.get(AxisKind.NEW_TRACK, {}),
            )
        row_of, track_col_of, new_col_of = lookups[class_name]
        picked = {(c.meas.ref, c.chosen.kind.value, c.chosen.ref) for c in conflict.choices}
        given = {c.chosen.ref for c in conflict.choices if c.chosen.kind is AxisKind.TRACK}
        track_ids = [t for t in conflict.track_ids if reported is None or t in reported or t in given]
        track_cells = [(k, _TRACK, t, track_col_of[t]) for k, t in enumerate(track_ids)]
        axis_pos.append((-0.6, y0 - 1.1))
        axis_lab.append(f"{class_name}, margin {_fmt(conflict.closest_margin)}")
        for k, t in enumerate(track_ids):
            axis_pos.append((k + 0.5, y0 - 0.35))
            axis_lab.append(str(t))
        axis_pos.append((len(track_ids) + 0.5, y0 - 0.35))
        axis_lab.append("new")
        for i, ref in enumerate(conflict.meas_indices):
            y = y0 + i + 0.5
            axis_pos.append((-0.6, y))
            axis_lab.append(meas_name(ref))
            r = row_of[ref]
            for k, kind, col_ref, col in [*track_cells, (len(track_ids), _NEW, ref, new_col_of[ref])]:
                v = cost[r, col]
                if not math.isfinite(v):
                    continue
                centers.append((k + 0.5, y))
                costs.append(float(v))
                labels.append(f"{v:.1f}")
                chosen.append((ref, kind, col_ref) in picked)
        y0 += len(conflict.meas_indices) + 2.2
    return Grid(
        np.array(centers, dtype=np.float64).reshape(-1, 2),
        np.array(costs, dtype=np.float64),
        labels,
        np.array(chosen, dtype=bool),
        np.array(axis_pos, dtype=np.float64).reshape(-1, 2),
        axis_lab,
    )


def cost_colors(costs: np.ndarray) -> np.ndarray:
    """(N, 4) uint8 colours of costs: more likely (lower cost) = brighter blue, less likely = darker; a fixed
    map over [-10, +10] so colours mean the same thing in every frame."""
    t = np.clip((np.asarray(costs, dtype=np.float64) + 10.0) / 20.0, 0.0, 1.0)[:, None]
    likely = np.array([60.0, 150.0, 255.0])
    unlikely = np.array([70.0, 50.0, 60.0])
    rgb = (1.0 - t) * likely + t * unlikely
    out = np.empty((t.shape[0], 4), dtype=np.uint8)
    out[:, :3] = rgb.round().astype(np.uint8)
    out[:, 3] = 255
    return out
