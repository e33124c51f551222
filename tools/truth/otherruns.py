"""Sentences about how another tracker on the same detections fared at the failure, checked against the devkit
bookkeeping of that other run (``devkit.EvalFacts`` of its results, built the same way as the first run's).

By failure kind, at the failure's frame x, for the object: a miss is the devkit's MISS of it (no match at x); an
ID switch or identity theft is a SWITCH event of it at x; a fragmentation is a match at x after none at x - 1 and
one before that. "Did not fail here: its track T was output on the object and counted" holds when the devkit matched
the object to one of the named tracks at x. "Did not have this failure" said of a run that had no track matched to
the object at x is the issue's class 4: that run lost the object too.
"""

from __future__ import annotations

import re
from collections.abc import Mapping

from tools.truth.devkit import EvalFacts

OTHER = re.compile(
    r"(\w+) on the same detections (failed here too|did not have this failure|had no counted track on the object "
    r"here either|did not fail here: its tracks? ([\d, ]+) (?:was|were) output on the object and counted)"
)
LOST_KINDS = ("id_switch", "identity_theft", "fragmentation")


def _failed(ev: EvalFacts, kind: str, c: str, x: int, gt: str) -> bool | None:
    """Whether the other run had a failure of ``kind`` on ``gt`` at ``x`` by the devkit's events (None: unknown)."""
    here = ev.gt_to_track.get((c, x), {})
    if gt not in here:
        return None
    if kind == "miss":
        return here[gt] is None
    if kind in ("id_switch", "identity_theft"):
        return gt in ev.switches.get((c, x), set())
    if kind == "fragmentation":
        before = [ev.matched_track(c, y, gt) for y in range(x)]
        return here[gt] is not None and bool(before) and before[-1] is None and any(before)
    return None


def check_others(text: str, kind: str, c: str, x: int, gt: str | None, others: Mapping[str, EvalFacts], out, bad):
    """Each other-run sentence of ``text`` about object ``gt`` (``out``: the ``Tally``; ``bad``)."""
    if gt is None:
        return
    for m in OTHER.finditer(text):
        ev = others.get(m[1])
        if ev is None:
            continue
        matched = ev.matched_track(c, x, gt)
        failed = _failed(ev, kind, c, x, gt)
        out.checked["other run"] += 1
        said = m[2]
        if said == "failed here too":
            if failed is False:
                bad("other run", m[0], f"the devkit's events of {m[1]} have no {kind} of the object at frame {x}")
        elif said.startswith("had no counted track"):
            if matched is not None:
                bad("other run", m[0], f"the devkit matched the object at frame {x} to {m[1]}'s track {matched}")
        elif said.startswith("did not fail here"):
            named = {t.strip() for t in m[3].split(",")}
            if matched not in named or failed:
                bad("other run", m[0], f"the devkit matched the object at frame {x} to {m[1]}'s track {matched}")
        else:  # did not have this failure
            if failed:
                bad("other run", m[0], f"the devkit's events of {m[1]} have a {kind} of the object at frame {x}")
            elif matched is None and kind in LOST_KINDS:
                out.checked["misleading"] += 1
                bad("misleading", m[0], f"{m[1]} had no track matched to the object at frame {x}: it lost it too")
