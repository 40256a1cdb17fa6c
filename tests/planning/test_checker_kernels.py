"""The checker's compiled kernels against the numpy expressions they replace, and its
screens of the arccos and arctan2 against evaluating every sample."""

from __future__ import annotations

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from trackplan.frames import placement_transform
from trackplan.planning._kernels import peak_use, task_frames
from trackplan.planning.check_tool import _largest_spin_errors, _smallest, _spin_error
from trackplan.planning.tracking import BETWEEN_STEP, MAX_BETWEEN_PER_PERIOD
from trackplan.robots.builtin import puma560
from trackplan.robots.kinematics import forward_kinematics


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


def _between_samples(
    q: np.ndarray, points: np.ndarray, tolerance: float
) -> tuple[np.ndarray, np.ndarray]:
    """The joints inside each period where the tool path is checked, and their times in
    periods, in numpy (the split of :data:`trackplan.planning.tracking.BETWEEN_STEP`)."""
    if len(q) < 2:
        return np.zeros((0, q.shape[1])), np.zeros(0)
    chord = np.linalg.norm(np.diff(points, axis=0), axis=1)
    parts = np.ceil(chord / (BETWEEN_STEP * tolerance))
    parts = np.clip(np.nan_to_num(parts, nan=2.0), 2, MAX_BETWEEN_PER_PERIOD).astype(int)
    period = np.repeat(np.arange(len(parts)), parts - 1)
    first = np.cumsum(parts - 1) - (parts - 1)
    j = np.arange(len(period)) - np.repeat(first, parts - 1) + 1
    fraction = j / parts[period]
    q_between = q[period] + fraction[:, None] * (q[period + 1] - q[period])
    return q_between, period + fraction


def _frames(robot, q: np.ndarray, T_base_part: np.ndarray, tolerance: float = 1e-3):  # type: ignore[no-untyped-def]
    chain, tail = robot.kernel_chain
    return task_frames(
        forward_kinematics(robot, q),
        T_base_part,
        1e-3,
        chain,
        tail,
        q,
        BETWEEN_STEP * tolerance,
        MAX_BETWEEN_PER_PERIOD,
    )


@settings(max_examples=30, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), n=st.integers(1, 50))
def test_task_frames_are_the_numpy_products_to_round_off(seed, n):
    rng = np.random.default_rng(seed)
    robot = puma560()
    q = rng.uniform(-3.0, 3.0, size=(n, robot.n_dof))
    T = forward_kinematics(robot, q)
    T_base_part = rng.normal(size=(4, 4))
    R, origin = T_base_part[:3, :3], T_base_part[:3, 3]
    points, velocity, speed, x_axis, z_axis, _, _ = _frames(robot, q, T_base_part)
    p = (T[:, :3, 3] - origin) @ R
    v = np.diff(p, axis=0, prepend=p[:1]) / 1e-3
    np.testing.assert_allclose(points, p, rtol=0, atol=1e-14)
    np.testing.assert_allclose(velocity, v, rtol=0, atol=1e-10)
    np.testing.assert_allclose(speed, np.linalg.norm(velocity, axis=1), rtol=1e-15, atol=0)
    np.testing.assert_allclose(x_axis, T[:, :3, 0] @ R, rtol=0, atol=1e-14)
    np.testing.assert_allclose(z_axis, T[:, :3, 2] @ R, rtol=0, atol=1e-14)
    assert not velocity[0].any()


@settings(max_examples=40, deadline=None)
@given(
    seed=st.integers(0, 2**32 - 1),
    n=st.integers(1, 120),
    step=st.sampled_from([1e-5, 1e-4, 3e-3]),
    odd=st.sampled_from([None, "nan", "far", "jump"]),
)
def test_points_between_samples_are_fk_of_the_split_joints_to_the_bit(seed, n, step, odd):
    """The task frames' points between samples: the FK of the joints of the numpy split,
    placed as the samples' points, to the bit (periods in halves, periods in many parts, a
    NaN chord, an angle beyond the sine kernel's reduction, a jump of MAX parts)."""
    rng = np.random.default_rng(seed)
    robot = puma560()
    q = np.cumsum(rng.normal(scale=step, size=(n, robot.n_dof)), axis=0)
    if odd == "nan" and n > 1:
        q[rng.integers(n), rng.integers(robot.n_dof)] = np.nan
    elif odd == "far":
        q[rng.integers(n), rng.integers(robot.n_dof)] = 3e5
    elif odd == "jump" and n > 1:
        q[rng.integers(1, n) :] += 2.0
    T_base_part = placement_transform(rng.uniform(-0.5, 0.5, size=6))
    points, *_, between, t_between = _frames(robot, q, T_base_part)
    q_between, t_expected = _between_samples(q, points, 1e-3)
    expected = task_frames(
        forward_kinematics(robot, q_between),
        T_base_part,
        1e-3,
        *robot.kernel_chain,
        q_between,
        1.0,
        2,
    )[0]
    np.testing.assert_array_equal(t_between, t_expected)
    np.testing.assert_array_equal(between, expected)


def test_periods_in_halves_are_their_midpoints_whatever_the_other_periods():
    """When no period needs more than its midpoint, the points between samples are the FK of
    the midpoints ``q_k + (q_k+1 − q_k) / 2``; one long period adds its parts and leaves the
    others' points as they were."""
    rng = np.random.default_rng(3)
    robot = puma560()
    q = np.cumsum(rng.normal(scale=1e-4, size=(400, robot.n_dof)), axis=0)
    T_base_part = placement_transform(np.array([0.4, 0.1, 0.2, 0.1, -0.2, 0.3]))
    *_, between, t_between = _frames(robot, q, T_base_part)
    np.testing.assert_array_equal(t_between, np.arange(399) + 0.5)
    midpoints = q[:-1] + 0.5 * (q[1:] - q[:-1])
    fk = forward_kinematics(robot, midpoints)
    np.testing.assert_allclose(
        between, (fk[:, :3, 3] - T_base_part[:3, 3]) @ T_base_part[:3, :3], atol=1e-15
    )
    jump = np.vstack([q, q[-1] + 0.05])  # a long last period: many parts
    *_, far, t_far = _frames(robot, jump, T_base_part)
    assert len(far) > 399 + 1
    np.testing.assert_array_equal(far[:399], between)
    np.testing.assert_array_equal(t_far[:399], t_between)


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
