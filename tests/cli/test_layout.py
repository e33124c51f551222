"""The command-line modules only parse and print: ``cli.study`` does not import ``cli.batch`` (no cycle), and the
tracking entry point lives in ``gnnpmb``; every module stays short."""

from __future__ import annotations

import subprocess
import sys


def _modules_after(statement: str) -> set[str]:
    code = f"import sys; {statement}; print(' '.join(sorted(sys.modules)))"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    return set(out.split())


def test_cli_study_does_not_import_cli_batch() -> None:
    assert "cli.batch" not in _modules_after("import cli.study")


def test_track_and_failures_use_the_gnnpmb_entry_point() -> None:
    import inspect

    import cli.batch
    import cli.failures

    source = inspect.getsource(cli.batch)
    assert "track_to_file(" in source
    stages = inspect.getsource(cli.failures)
    assert "load_inputs(" in stages and "run_all(" in stages and "find_reports(" in stages
    for module in (source, stages):
        assert "run_tracker(" not in module and "load_scene(" not in module


def test_every_cli_module_only_parses_and_prints_in_at_most_250_lines() -> None:
    from pathlib import Path

    import cli

    for path in Path(cli.__file__).parent.glob("*.py"):
        assert len(path.read_text().splitlines()) <= 250, path.name
