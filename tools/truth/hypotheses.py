"""PMBM's global hypotheses as the Why states them, checked against the raw ``GlobalHypotheses`` (after each
frame's update, sorted best first, weights normalised), ``Assignment`` and ``CostMatrix`` events.

* "at frame x the best hypothesis switched: it descends from prior hypothesis H (probability P after frame x-1,
  against Q for the best)": the frame's assignment (the best posterior hypothesis) was solved in prior hypothesis
  H, H is not 0, and after frame x-1 hypothesis H had probability P and hypothesis 0 Q;
* "track T: held by a kept hypothesis since frame F" (also "track T had existed since frame F in a hypothesis
  other than the best"): F is the first frame whose kept hypotheses hold T;
* "predicted existence E in hypothesis H": T's predicted existence in the matrix of prior hypothesis H at x;
  "E' in the previous best": in the matrix of prior hypothesis 0; "absent from the previous best": hypothesis 0
  after frame x-1 does not hold T;
* "after the update A in the chosen hypothesis, M over all kept ones": T's existence in hypothesis 0 after frame
  x, and its existence summed over the kept hypotheses weighted by their probabilities.
"""

from __future__ import annotations

import re

import numpy as np

from gnnpmb.events import Assignment, CostMatrix, GlobalHypotheses
from tools.truth.printing import NUMBER, printed

_P = r"\d+\.\d+"
SWITCHED = re.compile(
    rf"at frame (\d+) the best hypothesis switched: it descends from prior hypothesis (\d+) \(probability ({_P}) "
    rf"after frame (\d+), against ({_P}) for the best\), not from a cost choice within the best(?: \(([^\n]*?)\))?"
    r"(?=; |\.$|\.\n|$)"
)
TRACK_ROW = re.compile(r"track (\d+): ([^;]*)")
SINCE = re.compile(r"track (\d+)(?::| had existed) (?:held by a kept hypothesis )?since frame (\d+)")
IN_PARENT = re.compile(rf"predicted existence ({NUMBER}) in hypothesis (\d+)")
IN_BEST = re.compile(rf"({NUMBER}) in the previous best")
AFTER = re.compile(rf"after the update ({NUMBER}) in the chosen hypothesis, ({NUMBER}) over all kept ones")


def _first_held(raw, c: str, t: int, upto: int) -> int | None:
    for y in range(upto + 1):
        h = raw.last(y, c, GlobalHypotheses)
        if h is not None and any(t in ids for ids in h.members):
            return y
    return None


def _predicted(raw, x: int, c: str, hypothesis: int, t: int) -> float | None:
    for mat in raw.of_kind(x, c, CostMatrix):
        if mat.hypothesis == hypothesis and mat.terms is not None and mat.terms.existence is not None:
            k = mat.terms.column_of(t)
            if k is not None:
                return float(mat.terms.existence[k])
    return None


def check_hypotheses(text: str, c: str, raw, out, bad) -> None:
    for m in SINCE.finditer(text):
        t, since = int(m[1]), int(m[2])
        out.checked["hypothesis"] += 1
        first = _first_held(raw, c, t, since)
        if first != since:
            bad("hypothesis", m[0], f"the kept hypotheses first hold track {t} at frame {first}")
    for m in SWITCHED.finditer(text):
        _check_switch(m, c, raw, out, bad)


def _check_switch(m: re.Match, c: str, raw, out, bad) -> None:
    x, parent, p, before, q = int(m[1]), int(m[2]), m[3], int(m[4]), m[5]
    out.checked["hypothesis"] += 1
    a = raw.last(x, c, Assignment)
    prior = raw.last(before, c, GlobalHypotheses)
    if a is None or prior is None or before != x - 1:
        bad("hypothesis", m[0][:120], f"no assignment at frame {x} or no hypotheses after frame {x - 1}")
        return
    w = np.exp(np.asarray(prior.log_weights, dtype=float))
    if a.hypothesis != parent or parent == 0 or parent >= len(w):
        bad(
            "hypothesis",
            m[0][:120],
            f"the best hypothesis of frame {x} was solved in prior hypothesis {a.hypothesis}",
        )
        return
    if f"{w[parent]:.2f}" != p or f"{w[0]:.2f}" != q:
        bad("hypothesis", m[0][:120], f"after frame {before}: hypothesis {parent} {w[parent]:.3f}, best {w[0]:.3f}")
    post = raw.last(x, c, GlobalHypotheses)
    for row in TRACK_ROW.finditer(m[6] or ""):
        t, said = int(row[1]), row[2]
        out.checked["hypothesis"] += 1
        wrong = []
        e = IN_PARENT.search(said)
        if e is not None:
            got = _predicted(raw, x, c, int(e[2]), t)
            if got is None or printed(got) != e[1]:
                wrong.append(f"predicted existence in hypothesis {e[2]}: {got}")
        e = IN_BEST.search(said)
        if e is not None:
            got = _predicted(raw, x, c, 0, t)
            if got is None or printed(got) != e[1]:
                wrong.append(f"predicted existence in the previous best: {got}")
        if "absent from the previous best" in said and t in prior.members[0]:
            wrong.append("the previous best held it")
        e = AFTER.search(said)
        if e is not None and post is not None:
            pw = np.exp(np.asarray(post.log_weights, dtype=float))
            best = dict(zip(post.members[0], post.existence[0], strict=True)).get(t)
            marginal = sum(
                float(pw[h]) * dict(zip(ids, post.existence[h], strict=True)).get(t, 0.0)
                for h, ids in enumerate(post.members)
            )
            if best is None or printed(float(best)) != e[1] or printed(marginal) != e[2]:
                wrong.append(f"after the update: {best} in the best, {marginal:.4f} over all")
        if wrong:
            bad("hypothesis", row[0], "; ".join(wrong))
