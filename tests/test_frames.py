"""Vector lengths: the same bits as numpy's norm along the last axis."""

from __future__ import annotations

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from trackplan.frames import vector_norms


@settings(max_examples=40, deadline=None, derandomize=True)
@given(st.integers(0, 2**31), st.integers(0, 300), st.sampled_from([1e-12, 1e-3, 1.0, 1e150]))
def test_vector_norms_are_numpys_to_the_bit(seed, n, scale):
    v = np.random.default_rng(seed).normal(size=(n, 3)) * scale
    np.testing.assert_array_equal(vector_norms(v), np.linalg.norm(v, axis=1))


def test_vector_norms_of_special_values_are_numpys():
    v = np.array([[0.0, 0.0, 0.0], [np.inf, 1.0, 0.0], [np.nan, 0.0, 0.0], [-3.0, 4.0, 0.0]])
    np.testing.assert_array_equal(vector_norms(v), np.linalg.norm(v, axis=1))
    strided = np.arange(48.0).reshape(4, 4, 3)[:, 1, :]  # rows of a larger array
    np.testing.assert_array_equal(vector_norms(strided), np.linalg.norm(strided, axis=1))
