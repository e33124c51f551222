"""The truth oracle (``tools.oracle``): every claim of every failure's finding, for every tracker on each of the
demo's evaluation scenes and staged scene and with each detector preset, holds against the submission, the raw
events and the devkit."""

from __future__ import annotations

import dataclasses
from pathlib import Path

import pytest

from gnnpmb.data.demo import DEMO_SCENES
from gnnpmb.data.demo_staged import STAGED_SCENES
from gnnpmb.data.simdet_presets import PRESETS
from gnnpmb.registry import TRACKER_NAMES
from gnnpmb.stages.findings import explain_all
from gnnpmb.why.findings import Blame, Rule
from tests.pipeline import evidence_of_all, prepare
from tools import oracle

SCENES = DEMO_SCENES + STAGED_SCENES


def checked_here(scene: str, detector: str) -> list[str]:
    """The trackers checked on one scene and preset by hand (``-m exhaustive``): a Latin square, so every tracker is
    checked on every scene and with every preset once (a third of the full matrix, which
    ``uv run python -m tools.oracle`` runs)."""
    s, p = SCENES.index(scene), list(PRESETS).index(detector)
    return [t for i, t in enumerate(TRACKER_NAMES) if (i + s + p) % 3 == 0]


def checked_in_ci(scene: str, detector: str) -> list[str]:
    """The trackers checked on one scene and preset in the suite: each tracker once, the cells taken in turn, so
    every scene and preset is checked and the suite does not grow with the square."""
    cell = SCENES.index(scene) * len(PRESETS) + list(PRESETS).index(detector)
    return [t for i, t in enumerate(TRACKER_NAMES) if i % (len(SCENES) * len(PRESETS)) == cell]


def _check(demo_dataroot: Path, scene: str, detector: str, trackers: list[str]) -> None:
    findings = 0
    for tracker in trackers:
        others = ("gnnpmb",) if tracker != "gnnpmb" else ("greedy",)  # another tracker's evidence is claimed too
        request = prepare(scene, [tracker, *others], dataroot=demo_dataroot, detector=detector)
        verdict, n = oracle.run_one(request, tracker, others)
        assert verdict.contradictions == [], verdict.contradictions[:5]
        assert verdict.checked > 10 * n  # every finding makes claims
        findings += n
    assert findings > 0


@pytest.mark.slow
@pytest.mark.parametrize("scene", SCENES)
@pytest.mark.parametrize("detector", list(PRESETS))
def test_no_finding_of_any_tracker_contradicts_the_facts(demo_dataroot: Path, scene: str, detector: str) -> None:
    _check(demo_dataroot, scene, detector, checked_in_ci(scene, detector))


@pytest.mark.exhaustive
@pytest.mark.parametrize("scene", SCENES)
@pytest.mark.parametrize("detector", list(PRESETS))
def test_the_latin_square_contradicts_no_fact(demo_dataroot: Path, scene: str, detector: str) -> None:
    _check(demo_dataroot, scene, detector, checked_here(scene, detector))


def test_ci_and_the_square_cover_every_tracker_scene_and_preset() -> None:
    cells = [(t, s, p) for s in SCENES for p in PRESETS for t in checked_here(s, p)]
    for tracker in TRACKER_NAMES:
        mine = [(s, p) for t, s, p in cells if t == tracker]
        assert sorted(s for s, _ in mine) == sorted(SCENES) and sorted(p for _, p in mine) == sorted(PRESETS)
    ci = [t for s in SCENES for p in PRESETS for t in checked_in_ci(s, p)]
    assert sorted(ci) == sorted(TRACKER_NAMES)
    assert all(checked_in_ci(s, p) for s in SCENES for p in PRESETS)


def test_the_oracle_catches_a_false_claim(demo_dataroot: Path) -> None:
    """A finding made to say something untrue (a detector gap where the object had a detection, a track output
    where it was not) is caught."""
    request = prepare("scene-0103", ["jpda"], dataroot=demo_dataroot, detector="megvii")
    evidence, _, _ = evidence_of_all(request)
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


def test_no_finding_of_a_results_file_contradicts_the_file(demo_dataroot: Path, cv_results: Path) -> None:
    """Another tracker's results (a constant-velocity tracker outside the registry): every claim of every finding
    holds against the file itself, the detections and the devkit; the claims name only what its output shows."""
    request = prepare("scene-0103", ["gnnpmb"], results=[f"cv={cv_results}"], dataroot=demo_dataroot)
    verdict, n = oracle.run_one(request, "cv", ("gnnpmb",))
    assert verdict.contradictions == [], verdict.contradictions[:5]
    assert n > 50 and verdict.checked > 10 * n


def test_the_oracle_catches_a_false_claim_about_a_results_file(demo_dataroot: Path, cv_results: Path) -> None:
    from gnnpmb.foreign import OnHow
    from gnnpmb.why.claims import claims

    request = prepare("scene-0103", [], results=[f"cv={cv_results}"], dataroot=demo_dataroot)
    evidence, _, _ = evidence_of_all(request)
    findings = explain_all(request, evidence)["cv"]
    src = oracle.sources(request, "cv", evidence)
    finding = next(f for f in findings if f.boxes_on)
    assert oracle.check(finding, src).contradictions == []
    assert {c.what for f in findings for c in claims(f)} >= {"output on", "first output"}
    frame, track, on = finding.boxes_on[0]
    how = OnHow.NEAREST if on.how is OnHow.SAME_BOX else OnHow.SAME_BOX
    lie = dataclasses.replace(finding, boxes_on=((frame, track, dataclasses.replace(on, how=how)),))
    assert any("output on" in c for c in oracle.check(lie, src).contradictions)
    moved = dataclasses.replace(on, meas=on.meas + 1)
    lie = dataclasses.replace(finding, boxes_on=((frame, track, moved),))
    assert oracle.check(lie, src).contradictions
