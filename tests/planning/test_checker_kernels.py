"""The checker's compiled kernels against the numpy expressions they replace, and its
screens of the arccos and arctan2 against evaluating every sample."""

from __future__ import annotations

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from trackplan.planning._kernels import peak_use, task_frames
from trackplan.planning.checker import _largest_spin_errors, _smallest, _spin_error


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


@settings(max_examples=30, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), n=st.integers(1, 50))
def test_task_frames_are_the_numpy_products_to_round_off(seed, n):
    rng = np.random.default_rng(seed)
    T = rng.normal(size=(n, 4, 4))
    T_base_part = rng.normal(size=(4, 4))
    R, origin = T_base_part[:3, :3], T_base_part[:3, 3]
    points, velocity, speed, x_axis, z_axis = task_frames(T, T_base_part, 1e-3)
    p = (T[:, :3, 3] - origin) @ R
    v = np.diff(p, axis=0, prepend=p[:1]) / 1e-3
    np.testing.assert_allclose(points, p, rtol=0, atol=1e-14)
    np.testing.assert_allclose(velocity, v, rtol=0, atol=1e-10)
    np.testing.assert_allclose(speed, np.linalg.norm(velocity, axis=1), rtol=1e-15, atol=0)
    np.testing.assert_allclose(x_axis, T[:, :3, 0] @ R, rtol=0, atol=1e-14)
    np.testing.assert_allclose(z_axis, T[:, :3, 2] @ R, rtol=0, atol=1e-14)
    assert not velocity[0].any()


@settings(max_examples=80, deadline=None)
@given(
    seed=st.integers(0, 2**32 - 1),
    n=st.integers(1, 300),
    scale=st.sampled_from([1e-16, 1e-12, 1e-6, 1e-2, 1.0, 3.0]),
    ties=st.booleans(),
)
def test_screened_arccos_is_the_largest_of_all_to_the_bit(seed, n, scale, ties):
    rng = np.random.default_rng(seed)
    angles = np.abs(rng.normal(scale=scale, size=n))
    if ties:
        angles[rng.integers(n, size=n // 2)] = angles.max()
    cosines = np.clip(np.cos(angles) + rng.normal(scale=1e-16, size=n), -1.0, 1.0)
    assert np.arccos(_smallest(cosines)).max() == np.arccos(cosines).max()


@settings(max_examples=80, deadline=None)
@given(
    seed=st.integers(0, 2**32 - 1),
    n=st.integers(1, 300),
    scale=st.sampled_from([1e-16, 1e-12, 1e-6, 1e-2, 0.5, 3.0]),
    value=st.sampled_from([0.0, 0.3, -2.5, np.pi, 40.0]),
    length=st.sampled_from([1.0, 0.3, 1e-6]),
)
def test_screened_spin_error_is_the_largest_of_all_to_the_bit(seed, n, scale, value, length):
    rng = np.random.default_rng(seed)
    spin = value + rng.normal(scale=scale, size=n)
    x_cos, x_sin = length * np.cos(spin), length * np.sin(spin)
    every = _spin_error(np.arctan2(x_sin, x_cos), value)
    rows = _largest_spin_errors(x_cos, x_sin, value)
    screened = _spin_error(np.arctan2(x_sin[rows], x_cos[rows]), value)
    assert screened.max() == every.max()
    if scale <= 1e-6 and value == 0.0:  # small errors about a zero spin: a few rows only
        assert len(rows) <= 3
