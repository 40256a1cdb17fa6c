"""Vector lengths: numpy's norm along the last axis, to a few ULP; RPY rotations: one
angle triple gives the bits of the batch (the same kernel)."""

from __future__ import annotations

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.spatial.transform import Rotation

from tests.tolerances import assert_ulp_close
from trackplan.frames import rpy_from_matrix, rpy_matrix, vector_norms


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


def test_rpy_from_matrix_composes_back_near_and_at_the_gimbal_lock() -> None:
    """20,000 rotations with pitch 1e-17 … 1e-3 rad from ±π/2 (seed 0), each built as a
    rotation matrix from a unit quaternion, as other code makes them (rounded, not
    exactly orthonormal): the angles compose back within 5e-8 (2.0e-8 measured; a
    threshold of 1e-9 leaves 1e-7 errors and fails here)."""
    rng = np.random.default_rng(0)
    n = 20_000
    pitch = rng.choice([-1.0, 1.0], n) * (np.pi / 2 - 10.0 ** rng.uniform(-17, -3, n))
    rpy = np.column_stack([rng.uniform(-np.pi, np.pi, n), pitch, rng.uniform(-np.pi, np.pi, n)])
    xyzw = Rotation.from_matrix(rpy_matrix(rpy)).as_quat()
    w, x, y, z = xyzw[:, 3], xyzw[:, 0], xyzw[:, 1], xyzw[:, 2]
    rounded = np.stack(
        [
            np.stack([w * w + x * x - y * y - z * z, 2 * (x * y - w * z), 2 * (x * z + w * y)], -1),
            np.stack([2 * (x * y + w * z), w * w - x * x + y * y - z * z, 2 * (y * z - w * x)], -1),
            np.stack([2 * (x * z - w * y), 2 * (y * z + w * x), w * w - x * x - y * y + z * z], -1),
        ],
        axis=-2,
    )
    angles = rpy_from_matrix(rounded)
    assert np.all(np.abs(angles[:, 1]) <= np.pi / 2)
    assert np.max(np.abs(rpy_matrix(angles) - rounded)) < 5e-8
