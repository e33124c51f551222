"""The truth oracle (``tools.oracle``): every claim of every failure's finding, for every tracker on the demo's
evaluation scenes and staged scene and every detector preset, holds against the submission, the raw events and
the devkit."""

from __future__ import annotations

import dataclasses
from pathlib import Path

import pytest

from gnnpmb.data.demo import DEMO_SCENES
from gnnpmb.data.demo_staged import STAGED_SCENES
from gnnpmb.data.simdet_presets import PRESETS
from gnnpmb.registry import TRACKER_NAMES
from gnnpmb.session import explain_all, gather_evidence, prepare
from gnnpmb.why.findings import Blame, Rule
from tools import oracle


@pytest.mark.slow
@pytest.mark.parametrize("scene", DEMO_SCENES + STAGED_SCENES)
@pytest.mark.parametrize("detector", list(PRESETS))
def test_no_finding_of_any_tracker_contradicts_the_facts(demo_dataroot: Path, scene: str, detector: str) -> None:
    findings = 0
    for tracker in TRACKER_NAMES:
        others = ("gnnpmb",) if tracker != "gnnpmb" else ("greedy",)  # another tracker's evidence is claimed too
        request = prepare(scene, [tracker, *others], dataroot=demo_dataroot, detector=detector)
        verdict, n = oracle.run_one(request, tracker, others)
        assert verdict.contradictions == [], verdict.contradictions[:5]
        assert verdict.checked > 10 * n  # every finding makes claims
        findings += n
    assert findings > 0


def test_the_oracle_catches_a_false_claim(demo_dataroot: Path) -> None:
    """A finding made to say something untrue (a detector gap where the object had a detection, a track output
    where it was not) is caught."""
    request = prepare("scene-0103", ["jpda"], dataroot=demo_dataroot, detector="megvii")
    evidence, _ = gather_evidence(request)
    (fid, finding) = next(
        (i, f)
        for i, f in zip(evidence["jpda"].report.ids(), explain_all(request, evidence)["jpda"], strict=True)
        if f.lost is not None and f.lost.output_frames
    )
    src = oracle.sources(request, "jpda", evidence)
    assert oracle.check(finding, src).contradictions == []
    detected = [s.frame for s in finding.sightings if s.nearest_any is not None]
    lie = dataclasses.replace(finding, blame=(*finding.blame, Blame(Rule.NO_DETECTION, (detected[0],))))
    assert any("NO_DETECTION" in c or "no detection" in c for c in oracle.check(lie, src).contradictions)
    step = next(s for s in finding.lost.steps if s.output is not None)
    moved = dataclasses.replace(step, output=dataclasses.replace(step.output, meas_index=10_000))
    steps = tuple(moved if s is step else s for s in finding.lost.steps)
    lie = dataclasses.replace(finding, lost=dataclasses.replace(finding.lost, steps=steps))
    assert oracle.check(lie, src).contradictions
    assert oracle.check(finding, src, "m5 → ?").contradictions  # a placeholder in the text
    assert fid
