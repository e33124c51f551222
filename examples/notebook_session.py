"""A viewer session from Python, cell by cell as in a notebook: what ``gnnpmb-viz`` does, without its CLI.

Usage: uv run python examples/notebook_session.py [OUT.rrd]   (default: session.rrd; demo data, scene-0103)

Each block below is one notebook cell: the stages of ``gnnpmb.stages``. ``check_request`` checks every argument,
``load_inputs`` loads the scene and detections, ``run_view`` tracks and writes the recording (open it with
``uv run rerun OUT.rrd``); the request, the inputs and the result are plain objects to look into.
"""

from __future__ import annotations

import sys
from pathlib import Path

from gnnpmb.stages.inputs import load_inputs
from gnnpmb.stages.request import check_request
from gnnpmb.stages.runs import run_all, run_digests
from viz.view import run_view

out = Path(sys.argv[1] if len(sys.argv) > 1 else "session.rrd")

# %% check the arguments, load scene-0103 and the simulated CenterPoint detections (keyframes 0 to 19)
request = check_request("scene-0103", ["gnnpmb", "pmbm"], frames="0:20", classes="car,pedestrian", save=out)
inputs = load_inputs(request)
print(f"{inputs.scene.name}: {len(inputs.frame_range)} keyframes, detections {inputs.source.describe()}")

# %% track with both trackers into one recording, with their comparison and failures
result = run_view(inputs)
for tracker, ms in result.ms_per_frame.items():
    print(f"{tracker}: {ms:.1f} ms per frame")
if result.comparison is not None:
    print(f"{len(result.comparison.disagreements)} disagreements between the trackers")

# %% the runs are deterministic: running again without logging gives the same tracks
again = run_digests(run_all(inputs, record=False))
print("same tracks again:", all(again[t] == result.digests[t] for t in inputs.trackers))
print(f"saved {out}; open it with: uv run rerun {out}")
