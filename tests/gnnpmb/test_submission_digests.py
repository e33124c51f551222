"""Every tracker's submission on the demo mini_val scenes x every detector preset is byte-identical to the
committed digests (``submission_digests.json``; regenerate: ``uv run python -m tests.gnnpmb.submission_digests
--write``)."""

from __future__ import annotations

import hashlib
import json

import pytest

from gnnpmb.data.simdet import PRESETS
from gnnpmb.registry import TRACKER_NAMES
from tests.gnnpmb.submission_digests import DIGESTS_PATH, digest_key, load_demo_scenes, submission_bytes


@pytest.fixture(scope="module")
def scenes_and_tokens(demo_dataroot):
    return load_demo_scenes(demo_dataroot)


@pytest.fixture(scope="module")
def committed() -> dict[str, str]:
    return json.loads(DIGESTS_PATH.read_text(encoding="utf-8"))


def test_every_tracker_and_preset_has_a_digest(committed):
    assert sorted(committed) == sorted(digest_key(t, p) for t in TRACKER_NAMES for p in PRESETS)


@pytest.mark.parametrize("preset", list(PRESETS))
@pytest.mark.parametrize("tracker", TRACKER_NAMES)
def test_submission_matches_committed_digest(scenes_and_tokens, committed, tracker, preset):
    scenes, tokens = scenes_and_tokens
    digest = hashlib.sha256(submission_bytes(scenes, tokens, tracker, preset)).hexdigest()
    assert digest == committed[digest_key(tracker, preset)], (
        f"{tracker} on {preset}: the submission changed (if deliberate, regenerate the digests: "
        "uv run python -m tests.gnnpmb.submission_digests --write)"
    )
