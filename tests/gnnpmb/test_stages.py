"""The stages are the work behind ``gnnpmb-viz``, usable without the CLI; none imports a later one."""

from __future__ import annotations

import subprocess
import sys

STAGES = ("request", "inputs", "runs", "evaluation", "findings", "diff")


def test_the_stages_import_no_cli_and_no_numpy_until_used() -> None:
    code = (
        "import sys, gnnpmb.stages.findings; "
        "print(sorted({m.split('.')[0] for m in sys.modules} & {'cli', 'typer', 'numpy', 'rerun', 'viz'}))"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    assert out.strip() == "[]"


def test_no_stage_imports_a_later_one() -> None:
    import ast
    from pathlib import Path

    import gnnpmb.stages

    folder = Path(gnnpmb.stages.__file__).parent
    for k, stage in enumerate(STAGES):
        tree = ast.parse((folder / f"{stage}.py").read_text())
        imported = {n.module for n in ast.walk(tree) if isinstance(n, ast.ImportFrom) and n.module}
        later = {f"gnnpmb.stages.{s}" for s in STAGES[k + 1 :]}
        assert not imported & later, (stage, imported & later)
        assert not any(m == "viz" or m.startswith(("viz.", "cli.")) for m in imported), stage
