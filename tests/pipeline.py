"""The stages (``gnnpmb.stages``) as tests call them most: load a checked request, run, evaluate, explain."""

from __future__ import annotations

from pathlib import Path
from typing import Any

from gnnpmb.stages.evaluation import find_reports
from gnnpmb.stages.findings import all_evidence
from gnnpmb.stages.inputs import Inputs, load_inputs
from gnnpmb.stages.request import check_request
from gnnpmb.stages.runs import Run, run_all


def prepare(*args: Any, **kwargs: Any) -> Inputs:
    """``load_inputs(check_request(...))``: what ``gnnpmb-viz`` does with its options."""
    return load_inputs(check_request(*args, **kwargs))


def reports_of(inputs: Inputs) -> tuple[dict, list[str]]:
    """Every run once (not recorded) and their failure reports, with notices."""
    return find_reports(inputs, run_all(inputs, record=False))


def evidence_of_all(inputs: Inputs) -> tuple[dict, list[str], list[Run]]:
    """Every run once, recorded, its failures found: the evidence per run, notices and the runs."""
    runs = run_all(inputs, record=True)
    reports, notices = find_reports(inputs, runs)
    return all_evidence(inputs, runs, reports), notices, runs


POSITION_ONLY = Path(__file__).resolve().parents[1] / "gnnpmb" / "params" / "position_only.toml"
"""The PMB family's model set before issue 32: the tests that open a GNN-PMB ID switch on the demo pin it (the
defaults make none on scene-0103)."""

PMBM_ALL = "pmbm-all"
PMBM_NO_NSCAN = f"{PMBM_ALL}=pmbm:{POSITION_ONLY.with_name('pmbm_no_nscan.toml')}"
"""A PMBM run without N-scan pruning (``gnnpmb/params/pmbm_no_nscan.toml``, the README's example): it parts
from GNN-PMB at the first ID switch; the default PMBM (N-scan 1) loses the bicycle too."""


def focus_comparison_args(focus: str) -> list[str]:
    """``gnnpmb-viz``'s arguments (but ``--dataroot`` and ``--save``) for the focus recording on ``focus`` of GNN-PMB
    beside PMBM without N-scan pruning on scene-0103 (pointpillars, ``POSITION_ONLY``), without camera views:
    ``tests/cli/test_focus.py`` reads it and ``tests/viz/test_browser.py`` opens it in Chromium, one recording
    for both (``viz_recording``, ``tests/conftest.py``)."""
    argv = ["scene-0103", "--detector", "pointpillars", "--params", str(POSITION_ONLY), "--focus", focus]
    return [*argv, "--no-cameras", "--tracker", "gnnpmb", "--tracker", PMBM_NO_NSCAN]
