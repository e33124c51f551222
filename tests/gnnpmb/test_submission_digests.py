"""Every tracker's submission on the demo mini_val scenes x every detector preset is byte-identical to the
committed digests (``submission_digests.json``; regenerate: ``uv run python -m tests.gnnpmb.submission_digests
--write``). The cells ``test_all_trackers.py`` runs in the default suite (each tracker with one preset) check
their digests there, from the same runs; the rest are checked here."""

from __future__ import annotations

import hashlib
import json

import pytest

from tests.gnnpmb.submission_digests import DIGESTS_PATH, all_keys, digest_key, load_demo_scenes, submission_bytes
from tests.gnnpmb.test_all_trackers import QUICK_CELLS

CHECKED_HERE = [key for key in all_keys() if key[2] or key[:2] not in QUICK_CELLS]
"""Every digest but those of ``test_all_trackers``'s default cells (checked there from the same runs)."""


@pytest.fixture(scope="module")
def scenes_and_tokens(demo_dataroot):
    return load_demo_scenes(demo_dataroot)


@pytest.fixture(scope="module")
def committed() -> dict[str, str]:
    return json.loads(DIGESTS_PATH.read_text(encoding="utf-8"))


def test_every_tracker_and_preset_has_a_digest(committed):
    assert sorted(committed) == sorted(digest_key(*key) for key in all_keys())
    assert len(CHECKED_HERE) + len(QUICK_CELLS) == len(all_keys())  # each digest checked in one place


@pytest.mark.parametrize(("tracker", "preset", "paper"), CHECKED_HERE)
def test_submission_matches_committed_digest(scenes_and_tokens, committed, tracker, preset, paper):
    """Every tracker with the defaults, and the PMB trackers with ``params/paper.toml`` (``paper:`` keys; those
    were recorded before the defaults moved away from the paper and must never change)."""
    scenes, tokens = scenes_and_tokens
    digest = hashlib.sha256(submission_bytes(scenes, tokens, tracker, preset, paper)).hexdigest()
    assert digest == committed[digest_key(tracker, preset, paper)], (
        f"{digest_key(tracker, preset, paper)}: the submission changed (if deliberate, regenerate the digests: "
        "uv run python -m tests.gnnpmb.submission_digests --write)"
    )
