"""Percentages of a GM-PHD / CPHD update, checked against its raw ``UpdateWeights`` event.

"Track T took P % of its weight from mN" is label T's updated weight from detection N over its whole updated
weight, detected[T, N] / (missed[T] + sum_j detected[T, j]); "→ track T (P % of mN)" is the share of detection N's
unit weight that went to label T, detected[T, N]. A bare "(P %)" after a track does not say which of the two it is:
the issue's "(99 %)" in the Why and "97 %" below it for the same association, class 4.
"""

from __future__ import annotations

import re

import numpy as np

from gnnpmb.events import UpdateWeights

TOOK = re.compile(r"at frame (\d+) it took (\d+) % of its weight from m(\d+)")
WENT = re.compile(
    r"at frame (\d+) (?:detection )?m(\d+) \([^()]*\)(?: lay [\d.]+ m from \w+ GT \w+ and went to| →) "
    r"track (\d+) \((\d+) %( of m\d+)?\)"
)


def check_shares(text: str, c: str, lost: int | None, raw, out, bad) -> None:
    """Each percentage of ``text`` (``out``: the ``Tally``; ``bad``); ``lost``: the track the Why follows."""
    for m in TOOK.finditer(text):
        w = raw.last(int(m[1]), c, UpdateWeights)
        if w is None or lost is None:
            continue
        out.checked["share"] += 1
        labels, refs = np.asarray(w.labels).tolist(), np.asarray(w.meas_indices).tolist()
        if lost not in labels or int(m[3]) not in refs:
            bad("share", m[0], f"no weight of track {lost} from m{m[3]} in the frame's update")
            continue
        k, j = labels.index(lost), refs.index(int(m[3]))
        total = float(np.asarray(w.missed)[k] + np.asarray(w.detected)[k].sum())
        share = 100.0 * float(np.asarray(w.detected)[k, j]) / total
        if abs(share - int(m[2])) > 0.5 + 1e-9:
            bad("share", m[0], f"track {lost} took {share:.2f} % of its weight from m{m[3]}")
    for m in WENT.finditer(text):
        w = raw.last(int(m[1]), c, UpdateWeights)
        if w is None:
            continue
        out.checked["share"] += 1
        if m[5] is None:
            out.checked["misleading"] += 1
            bad("misleading", m[0], "a bare percentage: of the detection's weight or of the track's, not said")
            continue
        labels, refs = np.asarray(w.labels).tolist(), np.asarray(w.meas_indices).tolist()
        t, meas = int(m[3]), int(m[2])
        if t not in labels or meas not in refs:
            bad("share", m[0], f"no weight of track {t} from m{meas} in the frame's update")
            continue
        share = 100.0 * float(np.asarray(w.detected)[labels.index(t), refs.index(meas)])
        if abs(share - int(m[4])) > 0.5 + 1e-9:
            bad("share", m[0], f"{share:.2f} % of m{meas}'s weight went to track {t}")
