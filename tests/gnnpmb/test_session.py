"""The session module is the work behind ``gnnpmb-viz``, usable without the CLI."""

from __future__ import annotations

import subprocess
import sys


def test_the_session_imports_no_cli_and_no_numpy_until_used() -> None:
    code = (
        "import sys, gnnpmb.session; "
        "print(sorted({m.split('.')[0] for m in sys.modules} & {'cli', 'typer', 'numpy', 'rerun'}))"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    assert out.strip() == "[]"
