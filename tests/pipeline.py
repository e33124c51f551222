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
