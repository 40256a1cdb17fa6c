"""Vector lengths: numpy's norm along the last axis, to a few ULP; RPY rotations: one
angle triple gives the bits of the batch (the same kernel)."""

from __future__ import annotations

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from tests.tolerances import assert_ulp_close
from trackplan.frames import rpy_matrix, vector_norms


@settings(max_examples=40, deadline=None, derandomize=True)
@given(st.integers(0, 2**31), st.integers(0, 300), st.sampled_from([1e-12, 1e-3, 1.0, 1e150]))
def test_vector_norms_are_numpys(seed, n, scale):
    v = np.random.default_rng(seed).normal(size=(n, 3)) * scale
    assert_ulp_close(vector_norms(v), np.linalg.norm(v, axis=1))


def test_vector_norms_of_special_values_are_numpys():
    v = np.array([[0.0, 0.0, 0.0], [np.inf, 1.0, 0.0], [np.nan, 0.0, 0.0], [-3.0, 4.0, 0.0]])
    assert_ulp_close(vector_norms(v), np.linalg.norm(v, axis=1))
    strided = np.arange(48.0).reshape(4, 4, 3)[:, 1, :]  # rows of a larger array
    assert_ulp_close(vector_norms(strided), np.linalg.norm(strided, axis=1))


@settings(max_examples=30, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), n=st.integers(1, 20))
def test_one_rpy_rotation_is_the_batch_one_to_the_bit(seed, n):
    angles = np.random.default_rng(seed).uniform(-7.0, 7.0, size=(n, 3))
    batch = rpy_matrix(angles)
    for rpy, R in zip(angles, batch, strict=True):
        np.testing.assert_array_equal(rpy_matrix(rpy), R)
