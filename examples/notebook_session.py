"""A viewer session from Python, cell by cell as in a notebook: what ``gnnpmb-viz`` does, without its CLI.

Usage: uv run python examples/notebook_session.py [OUT.rrd]   (default: session.rrd; demo data, scene-0103)

Each block below is one notebook cell. ``prepare`` checks everything and loads the scene and detections,
``run_view`` tracks and writes the recording (open it with ``uv run rerun OUT.rrd``); the request and the result
are plain objects to look into.
"""

from __future__ import annotations

import sys
from pathlib import Path

from gnnpmb.session import prepare, rerun_digests
from viz.view import run_view

out = Path(sys.argv[1] if len(sys.argv) > 1 else "session.rrd")

# %% check the arguments, load scene-0103 and the simulated CenterPoint detections (keyframes 0 to 19)
request = prepare("scene-0103", ["gnnpmb", "pmbm"], frames="0:20", classes="car,pedestrian", save=out)
print(f"{request.scene.name}: {len(request.frame_range)} keyframes, detections {request.source.describe()}")

# %% track with both trackers into one recording, with their comparison and failures
result = run_view(request)
for tracker, ms in result.ms_per_frame.items():
    print(f"{tracker}: {ms:.1f} ms per frame")
if result.comparison is not None:
    print(f"{len(result.comparison.disagreements)} disagreements between the trackers")

# %% the runs are deterministic: running again without logging gives the same tracks
again = rerun_digests(request)
print("same tracks again:", all(again[t] == result.digests[t] for t in request.trackers))
print(f"saved {out}; open it with: uv run rerun {out}")
