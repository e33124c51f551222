"""Issue 33 case 9 through the installed script in a real process: a parameter past the limit where the model's
float64 arithmetic overflows is refused with exit 2 and one ``error:`` line naming the key, the value and the
allowed range, and the output already at ``--out`` is left as it was (``gnnpmb.param``)."""

from __future__ import annotations

import os
import subprocess
import sys
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

BIN = Path(sys.executable).parent
GOOD = b"a good output from an earlier run\n"

CASES = (
    ("[models]\nbirth_pos_std_m = 1e308\n", "[models] birth_pos_std_m must be in (0, 3.40282e+38] ("),
    ("[classes.car]\nr_x = 1e308\n", "[classes.car] r_x must be in (0, 1.15792e+77] ("),
    ("[classes.car]\nq_x = 1e308\n", "[classes.car] q_x must be in [0, 1.15792e+77] ("),
)


def _track(params: Path, out: Path, demo: Path) -> subprocess.CompletedProcess[str]:
    env = {k: v for k, v in os.environ.items() if k not in ("DISPLAY", "WAYLAND_DISPLAY")}
    env["NUSCENES_DATAROOT"] = str(demo)
    argv = [str(BIN / "gnnpmb"), "track", "--out", str(out), "--params", str(params), "--no-progress"]
    return subprocess.run(argv, capture_output=True, text=True, env=env, timeout=300)


def test_a_parameter_past_the_models_overflow_limit_is_one_error_line(demo_dataroot: Path, tmp_path: Path) -> None:
    for i, (text, _) in enumerate(CASES):
        (tmp_path / f"p{i}.toml").write_text(text)
        (tmp_path / f"out{i}.json").write_bytes(GOOD)
    before = sorted(p.name for p in tmp_path.iterdir())

    def one(i: int) -> list[str]:
        text, expected = CASES[i]
        proc = _track(tmp_path / f"p{i}.toml", tmp_path / f"out{i}.json", demo_dataroot)
        lines = proc.stderr.strip().splitlines()
        problems = [] if proc.returncode == 2 else [f"exit {proc.returncode}"]
        if len(lines) != 1 or not lines[0].startswith("error: ") or expected not in lines[0]:
            problems.append(f"stderr {proc.stderr[-400:]!r}")
        elif not lines[0].endswith("got 1e+308"):
            problems.append(f"the value is not named: {lines[0]!r}")
        if (tmp_path / f"out{i}.json").read_bytes() != GOOD:
            problems.append("--out changed")
        return [f"{text.strip()!r}: {p}" for p in problems]

    with ThreadPoolExecutor(len(CASES)) as pool:
        problems = [p for found in pool.map(one, range(len(CASES))) for p in found]
    assert not problems, problems
    assert sorted(p.name for p in tmp_path.iterdir()) == before
