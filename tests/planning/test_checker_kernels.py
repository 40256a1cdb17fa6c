"""The checker's compiled peak search against the numpy expressions it replaces."""

from __future__ import annotations

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from trackplan.planning._kernels import peak_use


@settings(max_examples=60, deadline=None)
@given(
    seed=st.integers(0, 2**32 - 1),
    n_rows=st.integers(1, 40),
    n_cols=st.integers(1, 7),
    ties=st.booleans(),
    nan=st.booleans(),
    odd_scale=st.sampled_from([None, np.inf, 1e-300]),
)
def test_peak_use_is_numpy_max_and_argmax_to_the_bit(seed, n_rows, n_cols, ties, nan, odd_scale):
    rng = np.random.default_rng(seed)
    values = rng.normal(size=(n_rows, n_cols))
    if ties:  # repeated peaks: the first one counts
        values = np.round(values)
    if nan:
        values[rng.integers(n_rows), rng.integers(n_cols)] = np.nan
    centre = rng.normal(size=n_cols)
    scale = rng.uniform(0.1, 3.0, size=n_cols)
    if odd_scale is not None:  # an infinite scale, or quotients that overflow
        scale[0] = odd_scale
    with np.errstate(over="ignore"):
        use = np.abs(values - centre) / scale
    peak, row = peak_use(values, centre, scale)
    np.testing.assert_array_equal(peak, use.max(axis=0))
    np.testing.assert_array_equal(row, use.argmax(axis=0))
