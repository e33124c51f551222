"""sha256 of every tracker's submission on the demo mini_val scenes x every detector preset.

The submission is what ``gnnpmb track`` writes (``build_submission`` of each scene's ``run_results``, serialised
as ``write_json`` does), built in process. ``tests/gnnpmb/test_submission_digests.py`` compares it with the
committed ``submission_digests.json``; a refactor must leave every digest unchanged.

Regenerate the committed digests deliberately (after a change that is meant to change tracker output, e.g. the
simulated detector), from the code that is to be the reference::

    uv run python -m tests.gnnpmb.submission_digests --write
"""

from __future__ import annotations

import argparse
import hashlib
import json
import sys
import tempfile
import time
from collections.abc import Sequence
from pathlib import Path

from gnnpmb.config import TrackerConfig, paper_config
from gnnpmb.data.nuscenes import load_scene, resolve_dataroot, sample_tokens
from gnnpmb.data.scene import SceneData
from gnnpmb.data.simdet import PRESETS
from gnnpmb.eval.submission import build_submission, run_results
from gnnpmb.pipeline import TrackingRun, get_detections, run_tracker
from gnnpmb.registry import TRACKER_NAMES

DIGESTS_PATH = Path(__file__).with_name("submission_digests.json")
SCENE_NAMES: tuple[str, ...] = ("scene-0103", "scene-0916")
SEED = 0


def load_demo_scenes(dataroot: Path) -> tuple[list[SceneData], list[str]]:
    """The demo mini_val scenes and their sample tokens (the submission's sample list)."""
    location = resolve_dataroot(dataroot, "v1.0-mini")
    return [load_scene(location, name) for name in SCENE_NAMES], sample_tokens(location, SCENE_NAMES)


PAPER_TRACKERS: tuple[str, ...] = ("gnnpmb", "pmbm", "topmb")
"""The trackers whose submissions with ``gnnpmb/params/paper.toml`` are digested too (``paper:`` keys): the
paper's configuration must keep giving the paper's tracker whatever the defaults become."""


def submission_bytes(
    scenes: Sequence[SceneData], tokens: Sequence[str], tracker: str, preset: str, paper: bool = False
) -> bytes:
    """The submission ``gnnpmb track --tracker TRACKER --detector PRESET --seed 0`` writes for ``scenes`` (with
    ``--params gnnpmb/params/paper.toml`` when ``paper``)."""
    config = paper_config() if paper else TrackerConfig()
    runs = [run_tracker(scene, get_detections(scene, None, preset, SEED), tracker, config) for scene in scenes]
    return submission_of(runs, tokens)


def submission_of(runs: Sequence[TrackingRun], tokens: Sequence[str]) -> bytes:
    """The submission bytes of one run per scene (``SEED``'s detections), as ``gnnpmb track`` writes them."""
    submission = build_submission([run_results(run) for run in runs], tokens)
    text = json.dumps(submission, allow_nan=False, separators=(",", ":"))
    return text.encode("utf-8")


def digest_key(tracker: str, preset: str, paper: bool = False) -> str:
    return f"{'paper:' if paper else ''}{tracker}/{preset}"


def all_keys() -> list[tuple[str, str, bool]]:
    """(tracker, preset, paper) of every committed digest."""
    defaults = [(t, p, False) for t in TRACKER_NAMES for p in PRESETS]
    return defaults + [(t, p, True) for t in PAPER_TRACKERS for p in PRESETS]


def compute_digests(dataroot: Path, trackers: Sequence[str] = TRACKER_NAMES) -> dict[str, str]:
    """``{"tracker/preset": sha256 hex}`` for ``trackers`` x every preset; prints each run's wall time."""
    scenes, tokens = load_demo_scenes(dataroot)
    digests: dict[str, str] = {}
    for tracker, preset, paper in all_keys():
        if tracker not in trackers:
            continue
        start = time.perf_counter()
        key = digest_key(tracker, preset, paper)
        digests[key] = hashlib.sha256(submission_bytes(scenes, tokens, tracker, preset, paper)).hexdigest()
        print(f"{key:28s} {time.perf_counter() - start:6.2f} s", file=sys.stderr)
    return digests


def main(argv: Sequence[str] | None = None) -> int:
    from gnnpmb.data.demo import DEMO_SEED, generate_demo_dataset

    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--write", action="store_true", help=f"write {DIGESTS_PATH.name} (else compare with it)")
    args = parser.parse_args(argv)
    with tempfile.TemporaryDirectory() as tmp:
        digests = compute_digests(generate_demo_dataset(Path(tmp) / "nuscenes", seed=DEMO_SEED))
    if args.write:
        DIGESTS_PATH.write_text(json.dumps(digests, indent=1, sort_keys=True) + "\n", encoding="utf-8")
        print(f"wrote {len(digests)} digests to {DIGESTS_PATH}", file=sys.stderr)
        return 0
    committed = json.loads(DIGESTS_PATH.read_text(encoding="utf-8"))
    changed = sorted(k for k in digests if committed.get(k) != digests[k])
    print(f"{len(digests) - len(changed)} of {len(digests)} digests match; changed: {changed}", file=sys.stderr)
    return 1 if changed else 0


if __name__ == "__main__":
    raise SystemExit(main())
