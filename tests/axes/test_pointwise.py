"""The closed-form positioner angles that turn a weld normal straight up."""

from __future__ import annotations

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from tests.axes.cells import tilt_rotate_chain, turntable_chain
from trackplan.axes.pointwise import (
    crossed_branches,
    fill_undetermined,
    hold_values,
    upright_branches,
)
from trackplan.robots.model import Robot

UP_TOL = 1e-9
"""Largest |R(p) m − z| of an exact closed-form solution (rounding only)."""


def _rodrigues(axis: np.ndarray, angle: float) -> np.ndarray:
    """Own rotation about a unit axis (not the module's)."""
    x, y, z = axis / np.linalg.norm(axis)
    c, s, v = np.cos(angle), np.sin(angle), 1.0 - np.cos(angle)
    return np.array(
        [
            [x * x * v + c, x * y * v - z * s, x * z * v + y * s],
            [y * x * v + z * s, y * y * v + c, y * z * v - x * s],
            [z * x * v - y * s, z * y * v + x * s, z * z * v + c],
        ]
    )


def _flange_rotation(chain: Robot, R_pose: np.ndarray, p: np.ndarray) -> np.ndarray:
    """Own forward kinematics of the chain's rotation, one configuration."""
    R = R_pose.copy()
    for i in range(chain.n_dof):
        R = R @ chain.origins[i, :3, :3] @ _rodrigues(chain.axes[i], p[i])
    return R @ chain.T_tip[:3, :3]


def _random_rotation(rng: np.random.Generator) -> np.ndarray:
    q = rng.normal(size=4)
    w, x, y, z = q / np.linalg.norm(q)
    return np.array(
        [
            [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
            [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
            [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
        ]
    )


def _chain(rng: np.random.Generator) -> Robot:
    """Two revolute axes in general position with random origins and a random tip."""
    origins = np.tile(np.eye(4), (2, 1, 1))
    tip = np.eye(4)
    for T in (*origins, tip):
        T[:3, :3] = _random_rotation(rng)
        T[:3, 3] = rng.normal(size=3)
    axes = rng.normal(size=(2, 3))
    return Robot(
        name="random",
        origins=origins,
        axes=axes,
        q_min=[-10.0, -10.0],
        q_max=[10.0, 10.0],
        v_max=[1.0, 1.0],
        a_max=[1.0, 1.0],
        j_max=[1.0, 1.0],
        T_tip=tip,
    )


@settings(max_examples=25, deadline=None)
@given(seed=st.integers(0, 2**32 - 1))
def test_two_axes_in_general_position_turn_a_reachable_normal_exactly_up(seed):
    """For random chains and random angles p, the normal m = R(p)ᵀ z is reachable: both
    branches put it straight up (own forward kinematics), and one of them is p (mod 2π)."""
    rng = np.random.default_rng(seed)
    chain = _chain(rng)
    R_pose = _random_rotation(rng)
    p = rng.uniform(-np.pi, np.pi, (12, 2))
    m = np.stack([_flange_rotation(chain, R_pose, row).T @ [0, 0, 1.0] for row in p])
    branches, _ = upright_branches(chain, R_pose, m)
    assert branches.shape == (2, 12, 2)
    for branch in branches:
        up = np.stack(
            [_flange_rotation(chain, R_pose, row) @ v for row, v in zip(branch, m, strict=True)]
        )
        np.testing.assert_allclose(up, np.tile([0.0, 0.0, 1.0], (12, 1)), atol=UP_TOL)
    wrapped = np.angle(np.exp(1j * (branches - p[None])))
    assert np.all(np.min(np.abs(wrapped).max(axis=2), axis=0) < 1e-7)


def test_the_tilt_rotate_positioner_turns_a_45_degree_normal_up_with_a_45_degree_tilt():
    chain = tilt_rotate_chain()
    phi = np.linspace(0.0, 2 * np.pi, 9)
    m = np.column_stack([np.cos(phi), np.sin(phi), np.ones(9)]) / np.sqrt(2.0)
    branches, gamma = upright_branches(chain, np.eye(3), m)
    np.testing.assert_allclose(gamma, np.sin(np.pi / 4), atol=1e-12)  # far from meeting
    np.testing.assert_allclose(np.abs(branches[..., 0]), np.pi / 4, atol=1e-12)
    assert np.all(np.sign(branches[0, :, 0]) == -np.sign(branches[1, :, 0]))


def test_one_axis_comes_as_near_to_up_as_its_turn_allows():
    """A turntable tilted by 20° about x: its angle brings the normal nearest to straight
    up: at least as near as the best of a brute-force search over a 0.1° grid."""
    chain = turntable_chain()
    tilt = _rodrigues(np.array([1.0, 0, 0]), np.radians(20.0))
    rng = np.random.default_rng(3)
    m = rng.normal(size=(20, 3))
    m /= np.linalg.norm(m, axis=1, keepdims=True)
    (best,), _ = upright_branches(chain, tilt, m)
    grid = np.radians(np.arange(-180.0, 180.0, 0.1))
    z_of = np.array([(_flange_rotation(chain, tilt, [g]) @ m.T)[2] for g in grid])  # (G, 20)
    ours = np.array(
        [(_flange_rotation(chain, tilt, row) @ v)[2] for row, v in zip(best, m, strict=True)]
    )
    assert np.all(ours >= z_of.max(axis=0) - 1e-8)


def test_an_angle_that_does_not_matter_is_nan_and_filled_from_its_neighbours():
    """A normal along the rotate axis leaves the rotation free: NaN, then the nearest
    determined angle (or the hold value when none is)."""
    chain = tilt_rotate_chain()
    m = np.array([[0.0, 0.0, 1.0], [0.0, 0.0, 1.0], [0.6, 0.0, 0.8]])
    (first, _), _ = upright_branches(chain, np.eye(3), m)
    assert np.isnan(first[:2, 1]).all() and np.isfinite(first[2]).all()
    filled = fill_undetermined(first, hold_values(chain))
    np.testing.assert_array_equal(filled[:2, 1], first[2, 1])
    never = fill_undetermined(np.full((3, 2), np.nan), np.array([0.1, 0.2]))
    np.testing.assert_array_equal(never, np.tile([0.1, 0.2], (3, 1)))


def test_hold_values_are_zero_inside_the_range_else_the_middle():
    chain = tilt_rotate_chain()
    np.testing.assert_array_equal(hold_values(chain), [0.0, 0.0])
    shifted = Robot(
        name="shifted",
        origins=chain.origins,
        axes=chain.axes,
        q_min=[0.5, -1.0],
        q_max=[1.5, 1.0],
        v_max=chain.v_max,
        a_max=chain.a_max,
        j_max=chain.j_max,
    )
    np.testing.assert_array_equal(hold_values(shifted), [1.0, 0.0])


def test_crossed_branches_swap_where_the_branches_meet():
    """|γ| dips to 0 at sample 4 and again at 8: the crossed paths swap there."""
    gamma = np.array([0.5, 0.3, 0.1, 0.03, 0.0, 0.04, 0.2, 0.04, 0.01, 0.3])
    branches = np.stack([np.zeros((10, 1)), np.ones((10, 1))])
    crossed = crossed_branches(branches, gamma)
    np.testing.assert_array_equal(crossed[0, :, 0], [0, 0, 0, 0, 1, 1, 1, 1, 0, 0])
    np.testing.assert_array_equal(crossed[1, :, 0], 1 - crossed[0, :, 0])
    np.testing.assert_array_equal(crossed_branches(branches, gamma + 1.0), branches)


def test_two_parallel_axes_act_as_one():
    """Two parallel vertical axes (not in general position): one branch, the second axis
    held, and the first as near to up as a turntable gets (brute force over 0.1°)."""
    tilt = _rodrigues(np.array([1.0, 0, 0]), np.radians(20.0))
    offset = np.eye(4)
    offset[:3, 3] = 0.3, 0.0, 0.0
    chain = Robot(
        name="parallel",
        origins=np.stack([np.eye(4), offset]),
        axes=np.array([[0.0, 0, 1], [0.0, 0, 1]]),
        q_min=[-4.0, -4.0],
        q_max=[4.0, 4.0],
        v_max=[1.0, 1.0],
        a_max=[1.0, 1.0],
        j_max=[1.0, 1.0],
    )
    m = np.random.default_rng(5).normal(size=(10, 3))
    m /= np.linalg.norm(m, axis=1, keepdims=True)
    branches, _ = upright_branches(chain, tilt, m)
    assert branches.shape == (1, 10, 2) and np.all(branches[0, :, 1] == 0.0)
    grid = np.radians(np.arange(-180.0, 180.0, 0.1))
    best = np.array([(_flange_rotation(chain, tilt, [g, 0.0]) @ m.T)[2] for g in grid])
    ours = np.array(
        [(_flange_rotation(chain, tilt, row) @ v)[2] for row, v in zip(branches[0], m, strict=True)]
    )
    assert np.all(ours >= best.max(axis=0) - 1e-8)
