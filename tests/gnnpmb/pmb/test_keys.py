import warnings

import numpy as np

from gnnpmb.pmb.core import combine_keys


def splitmix64_reference(parent: int, outcome: int) -> int:
    """The SplitMix64 finaliser of ``combine_keys`` in Python integers, masked to 63 bits."""
    mask = (1 << 64) - 1
    x = ((parent & mask) * 0x9E3779B97F4A7C15 + (outcome & mask)) & mask
    x ^= x >> 30
    x = (x * 0xBF58476D1CE4E5B9) & mask
    x ^= x >> 27
    x = (x * 0x94D049BB133111EB) & mask
    x ^= x >> 31
    return x & ((1 << 63) - 1)


def test_combine_keys_wraps_silently_and_matches_the_reference():
    parent = np.array([0, 1, -7, 2**62 + 12345, -(2**63)], dtype=np.int64)
    outcome = np.array([0, 3, 1, 40, 2], dtype=np.int64)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        keys = combine_keys(parent, outcome)
    assert keys.dtype == np.int64 and (keys >= 0).all()
    assert keys.tolist() == [splitmix64_reference(int(p), int(o)) for p, o in zip(parent, outcome, strict=True)]
