"""``pmbm.log_sum_exp`` is bit for bit ``scipy.special.logsumexp`` on the 1-D arrays PMBM normalises."""

from __future__ import annotations

import numpy as np
from scipy.special import logsumexp

from gnnpmb.pmb.pmbm import log_sum_exp


def test_equals_scipy_bit_for_bit():
    rng = np.random.default_rng(3)
    cases = [np.array([0.0]), np.array([-3.5, -3.5]), np.array([-np.inf, -1.0]), np.array([-np.inf, -np.inf])]
    for _ in range(500):
        n = int(rng.integers(1, 120))
        a = rng.normal(0.0, float(rng.choice([1e-3, 1.0, 30.0, 1e3])), size=n) + float(rng.uniform(-800, 800))
        if rng.random() < 0.3:
            a[rng.integers(0, n, size=max(1, n // 4))] = a.max()  # ties at the maximum
        if rng.random() < 0.2:
            a[rng.integers(0, n)] = -np.inf
        cases.append(a)
    for a in cases:
        got, want = log_sum_exp(a), logsumexp(a)
        assert type(got) is type(want)
        assert np.array_equal(got, want, equal_nan=True) and got.tobytes() == np.float64(want).tobytes(), a
