"""Every tracker on both demo mini_val scenes with every detector preset (PMBM: the most cluttered one): valid
numbers throughout, and the submission of the same runs byte-identical to its committed digest (these cells'
digests are checked here rather than in ``test_submission_digests.py``: one run for both checks).

Checks what the viewer would show: no NaN anywhere, probabilities (existence, marginals, cardinality, hypothesis
weights) within [0, 1] and normalised where they should be, covariances symmetric positive-definite, and track
ids unique per frame.
"""

from __future__ import annotations

import hashlib
import json

import numpy as np
import pytest

from gnnpmb.config import TrackerConfig
from gnnpmb.events import (
    Cardinality,
    Extracted,
    GlobalHypotheses,
    IntensityWeights,
    ListSink,
    Marginals,
    Posterior,
    Predicted,
)
from gnnpmb.pipeline import get_detections, run_tracker
from gnnpmb.registry import TRACKER_NAMES
from tests.gnnpmb.submission_digests import DIGESTS_PATH, SEED, digest_key, load_demo_scenes, submission_of

PRESETS = ("centerpoint", "megvii", "pointpillars")


@pytest.fixture(scope="module")
def scenes_and_tokens(demo_dataroot):
    """The demo mini_val scenes and their sample tokens, as ``test_submission_digests`` loads them."""
    return load_demo_scenes(demo_dataroot)


def assert_spd(cov: np.ndarray, what: str) -> None:
    if len(cov) == 0:
        return
    assert np.isfinite(cov).all(), f"{what}: non-finite covariance"
    np.testing.assert_allclose(cov, np.swapaxes(cov, -1, -2), atol=1e-9, err_msg=f"{what}: not symmetric")
    assert np.linalg.eigvalsh(cov).min() > 0, f"{what}: not positive-definite"


def assert_probability(p: np.ndarray, what: str) -> None:
    p = np.asarray(p, dtype=float)
    assert np.isfinite(p).all(), f"{what}: NaN"
    assert (p >= 0).all() and (p <= 1 + 1e-9).all(), f"{what}: outside [0, 1]"


def quick_preset(tracker: str) -> str:
    """The preset ``tracker`` is checked with in the default run: the presets taken in turn, so each is used;
    PMBM, the slow one at 2 s per preset and scene, with the most cluttered one."""
    return "pointpillars" if tracker == "pmbm" else PRESETS[TRACKER_NAMES.index(tracker) % len(PRESETS)]


QUICK_CELLS = frozenset((tracker, quick_preset(tracker)) for tracker in TRACKER_NAMES)
"""(tracker, preset) of the default run's cells, whose submissions' digests are checked here."""


def _cases() -> list:
    """Every tracker with its ``quick_preset`` in the default run; every other pair is marked ``exhaustive``
    (``-m exhaustive``). Whatever a tracker outputs on any preset is also held byte for byte by
    ``test_submission_digests``."""
    cases = []
    for tracker in TRACKER_NAMES:
        quick = quick_preset(tracker)
        for preset in PRESETS:
            marks = () if preset == quick else (pytest.mark.exhaustive,)
            cases.append(pytest.param(tracker, preset, marks=marks, id=f"{tracker}-{preset}"))
    return cases


CASES = _cases()


@pytest.mark.parametrize(("tracker", "preset"), CASES)
def test_tracker_outputs_are_valid(scenes_and_tokens, tracker, preset):
    config = TrackerConfig()
    scenes, tokens = scenes_and_tokens
    runs = []
    for scene in scenes:
        sink = ListSink()
        run = run_tracker(scene, get_detections(scene, None, preset, seed=SEED), tracker, config, sink=sink)
        runs.append(run)
        assert len(run.frames) == len(scene.keyframes)
        n_tracks = 0
        for frame in run.frames:
            ids = [e.track_id for e in frame.estimates]
            assert len(ids) == len(set(ids)), f"duplicate track ids in frame {frame.keyframe.index}"
            for e in frame.estimates:
                values = [*e.translation_m, *e.size_wlh_m, *e.quat_wxyz, *e.velocity_mps, e.score, e.existence]
                assert np.isfinite(values).all()
                assert_probability([e.score, e.existence], "estimate")
            n_tracks += len(ids)
        assert n_tracks > 0, f"{tracker} extracted no track on {scene.name}"
        for ev in sink.events:
            where = f"{tracker}/{preset}/{scene.name}/{type(ev).__name__}"
            if isinstance(ev, Predicted | Posterior):
                assert np.isfinite(ev.mean).all(), where
                assert_spd(ev.cov, where)
                assert_probability(ev.existence, where)
            elif isinstance(ev, Marginals):
                assert_probability(ev.probs, where)
                if ev.probs.size:
                    np.testing.assert_allclose(ev.probs.sum(axis=1), 1.0, atol=1e-6, err_msg=where)
            elif isinstance(ev, Cardinality):
                assert_probability(ev.pmf, where)
                assert abs(ev.pmf.sum() - 1.0) < 1e-6, where
            elif isinstance(ev, GlobalHypotheses):
                assert np.isfinite(ev.log_weights).all() and (ev.log_weights <= 1e-9).all(), where
                assert abs(np.logaddexp.reduce(ev.log_weights) if len(ev.log_weights) else 0.0) < 1e-6, where
            elif isinstance(ev, IntensityWeights):
                assert np.isfinite(ev.weights).all() and (ev.weights >= 0).all(), where
            elif isinstance(ev, Extracted):
                assert all(e.class_name == ev.class_name for e in ev.estimates), where
    # The same runs (the sink only listens) give the committed submission, byte for byte.
    digest = hashlib.sha256(submission_of(runs, tokens)).hexdigest()
    assert digest == json.loads(DIGESTS_PATH.read_text(encoding="utf-8"))[digest_key(tracker, preset)], (
        f"{digest_key(tracker, preset)}: the submission changed (if deliberate, regenerate the digests: "
        "uv run python -m tests.gnnpmb.submission_digests --write)"
    )
