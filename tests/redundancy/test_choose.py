"""choose_redundancy: fixed, best constant, and a profile that travels no more."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from trackplan.io.robot_file import load_robot
from trackplan.profiles import profile_values
from trackplan.redundancy import RedundancySpec, choose_redundancy
from trackplan.redundancy.choose import _travel
from trackplan.robots.kinematics import forward_kinematics
from trackplan.robots.path_ik import solve_path_ik_branches

TILTED7 = Path(__file__).resolve().parents[1] / "io" / "data" / "tilted7.urdf"
LENGTH = 0.1


@pytest.fixture(scope="module")
def arm_and_poses():
    """The 7-joint test arm (numeric family, joint 3 free) and a 0.1 m line of 40 poses."""
    robot = load_robot(TILTED7, assume_limits=True)
    T_mid = forward_kinematics(robot, np.array([0.3, -0.5, 0.8, 0.4, 0.6, -0.3, 0.2]))
    direction = np.array([0.2, 1.0, -0.3]) / np.linalg.norm([0.2, 1.0, -0.3])
    s = np.linspace(0.0, LENGTH, 40)
    T = np.repeat(T_mid[None], len(s), axis=0)
    T[:, :3, 3] += s[:, None] * direction
    return robot, T[None], s


def test_a_fixed_parameter_holds_its_joint_on_every_branch(arm_and_poses):
    robot, T, s = arm_and_poses
    choice = choose_redundancy(
        robot, T, s, LENGTH, RedundancySpec(mode="fixed", value=0.7), np.ones(7)
    )
    np.testing.assert_array_equal(choice.values, 0.7)
    usable = choice.paths.success[0]
    assert usable.any()
    held = choice.paths.q[0][usable][..., 2]
    np.testing.assert_allclose(held, 0.7, atol=1e-12)
    assert len(choice.profile(0, int(np.flatnonzero(usable)[0])).coefficients) == 1


def test_free_picks_the_constant_of_least_travel_among_usable_paths(arm_and_poses):
    robot, T, s = arm_and_poses
    spec = RedundancySpec(mode="free", range=(-1.0, 1.0))
    choice = choose_redundancy(robot, T, s, LENGTH, spec, np.ones(7))
    constants = np.linspace(-1.0, 1.0, 5)  # the tracked family tries five
    each = [solve_path_ik_branches(robot, T, free=np.full((1, len(s)), c)) for c in constants]
    travel = np.stack([_travel(paths, np.ones(7))[0] for paths in each])  # (R, K)
    for k in np.flatnonzero(np.isfinite(travel).any(axis=0)):
        chosen = choice.values[0, k, 0]
        assert chosen in constants
        assert _travel(choice.paths, np.ones(7))[0, k] == pytest.approx(travel[:, k].min())


def test_a_varying_profile_stays_in_bounds_and_rate_and_travels_no_more(arm_and_poses):
    robot, T, s = arm_and_poses
    spec = RedundancySpec(mode="free-varying", range=(-1.0, 1.0), rate=10.0)
    free = choose_redundancy(
        robot, T, s, LENGTH, RedundancySpec(mode="free", range=(-1.0, 1.0)), np.ones(7)
    )
    varying = choose_redundancy(robot, T, s, LENGTH, spec, np.ones(7))
    assert np.all(varying.values >= -1.0 - 1e-12) and np.all(varying.values <= 1.0 + 1e-12)
    rate = np.abs(np.diff(varying.values, axis=-1)) / np.diff(s)
    assert rate.max() <= 10.0 + 1e-9
    ok = free.paths.success
    assert np.all(varying.paths.success[ok])
    weights = np.ones(7)
    assert np.all(_travel(varying.paths, weights)[ok] <= _travel(free.paths, weights)[ok] + 1e-12)
    for k in range(varying.values.shape[1]):  # the values are the profile's
        profile = varying.profile(0, k)
        np.testing.assert_allclose(
            profile_values(profile.coefficients[None], s, LENGTH)[0], varying.values[0, k]
        )


def test_an_arm_without_redundancy_is_refused():
    from trackplan.io.robot_file import builtin_robot

    robot = builtin_robot("puma560")
    with pytest.raises(ValueError, match="no redundancy"):
        choose_redundancy(
            robot, np.eye(4)[None, None], np.zeros(1), 0.0, RedundancySpec(), np.ones(6)
        )
