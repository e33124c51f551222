"""Track score rules of the model-based baselines, hand-computed."""

import numpy as np
import pytest

from gnnpmb.track_scores import decay_on_miss, fuse_confidence, step_down


def test_simpletrack_decay_multiplies_a_missed_track_score():
    assert decay_on_miss(np.array([0.8, 0.5]), 0.01).tolist() == pytest.approx([0.008, 0.005])


def test_cbmot_fuses_the_decayed_track_score_with_the_detection_score():
    """CBMOT eq. 6 after a 0.2 step: track 0.9 -> 0.7, detection 0.6: 1 - 0.3 x 0.4 = 0.88."""
    track = step_down(np.array([0.9, 0.1]), 0.2, clip=True)
    assert track.tolist() == pytest.approx([0.7, 0.0])
    assert fuse_confidence(track, np.array([0.6, 0.6])).tolist() == pytest.approx([0.88, 0.6])
    assert step_down(np.array([0.1]), 0.2, clip=False).tolist() == pytest.approx([-0.1])
