"""The sample checks' compiled rate ratios against the backward differences the checker
reads, to the bit."""

from __future__ import annotations

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from trackplan.derivatives import backward_derivatives
from trackplan.timing._kernels import rate_ratios


@settings(max_examples=60, deadline=None)
@given(
    seed=st.integers(0, 2**32 - 1),
    n_samples=st.integers(1, 60),
    n_dof=st.integers(1, 7),
    nan=st.booleans(),
)
def test_rate_ratios_are_the_largest_backward_difference_ratios(seed, n_samples, n_dof, nan):
    rng = np.random.default_rng(seed)
    q = np.cumsum(rng.normal(scale=1e-3, size=(n_samples, n_dof)), axis=0)
    if nan:
        q[rng.integers(n_samples), rng.integers(n_dof)] = np.nan
    Ts = 1e-3
    limits = rng.uniform(0.5, 5.0, size=(3, n_dof)) * [[1.0], [10.0], [100.0]]
    ratio = rate_ratios(q, np.array([Ts, Ts**2, Ts**3]), limits)
    derivatives = backward_derivatives(q, Ts, pad_end=True)
    for order, values in enumerate(derivatives):
        use = np.abs(values) / limits[order]
        # the running maximum from 0 over the joints in order, as Python's max(a, b):
        # b only where b > a (a NaN b is passed over)
        expected = np.zeros(len(use))
        for j in range(n_dof):
            expected = np.where(use[:, j] > expected, use[:, j], expected)
        np.testing.assert_array_equal(ratio[:, order], expected)
