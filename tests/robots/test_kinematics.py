"""FK and Jacobian against roboticstoolbox-python and finite differences."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from tests.oracles import oracle
from trackplan.robots._ik_kernels import fk_jacobian_into
from trackplan.robots.ik_numeric import chain_arrays
from trackplan.robots.kinematics import forward_kinematics, jacobian

N_CONFIGS = 1000


def rtb_robot(robot):
    """roboticstoolbox DHRobot with exactly our DH table (no pedestal, no tool)."""
    rtb = oracle("roboticstoolbox")
    links = [
        rtb.RevoluteDH(d=d, a=a, alpha=alpha, offset=offset) for d, a, alpha, offset in robot.dh
    ]
    return rtb.DHRobot(links, name=robot.name)


@pytest.mark.parametrize("name", ["puma", "ur"])
def test_fk_and_jacobian_match_roboticstoolbox(name, request, rng):
    robot = request.getfixturevalue(name)
    oracle = rtb_robot(robot)
    q = rng.uniform(-np.pi, np.pi, (N_CONFIGS, robot.n_dof))
    T = forward_kinematics(robot, q)
    J = jacobian(robot, q)
    T_rtb = np.array([oracle.fkine(qk).A for qk in q])
    J_rtb = np.array([oracle.jacob0(qk) for qk in q])
    assert np.abs(T - T_rtb).max() < 1e-9
    assert np.abs(J - J_rtb).max() < 1e-9


@pytest.mark.parametrize("name", ["puma", "ur"])
def test_jacobian_matches_finite_differences(name, request, rng):
    robot = request.getfixturevalue(name)
    q = rng.uniform(-np.pi, np.pi, (200, robot.n_dof))
    h = 1e-6
    J = jacobian(robot, q)
    for i in range(robot.n_dof):
        step = np.zeros(robot.n_dof)
        step[i] = h
        T_plus, T_minus = forward_kinematics(robot, q + step), forward_kinematics(robot, q - step)
        v = (T_plus[:, :3, 3] - T_minus[:, :3, 3]) / (2 * h)
        dR = (T_plus[:, :3, :3] - T_minus[:, :3, :3]) / (2 * h)
        W = dR @ np.swapaxes(forward_kinematics(robot, q)[:, :3, :3], -1, -2)  # [ω]×
        omega = np.stack([W[:, 2, 1], W[:, 0, 2], W[:, 1, 0]], axis=-1)
        assert np.abs(J[:, :3, i] - v).max() < 1e-8
        assert np.abs(J[:, 3:, i] - omega).max() < 1e-8


@pytest.mark.parametrize("name", ["puma", "ur"])
def test_compiled_fk_jacobian_matches_numpy(name, request, rng):
    robot = request.getfixturevalue(name)
    tool = np.eye(4)
    tool[:3, 3] = (0.01, -0.02, 0.1)  # a tool offset exercises the last transform
    robot_with_tool = replace(robot, T_flange_tool=tool)
    chain, tail = chain_arrays(robot_with_tool)
    T = np.empty((4, 4))
    J = np.empty((6, robot.n_dof))
    axes = np.empty((robot.n_dof, 6))
    for q in rng.uniform(-np.pi, np.pi, (50, robot.n_dof)):
        fk_jacobian_into(chain, tail, q, T, J, axes)
        assert np.abs(T - forward_kinematics(robot_with_tool, q)).max() < 1e-14
        assert np.abs(J - jacobian(robot_with_tool, q)).max() < 1e-14


def test_a_missing_oracle_skips_with_its_reason():
    """An oracle test skips, naming the missing package, instead of failing."""
    with pytest.raises(pytest.skip.Exception, match="optional oracle no_such_oracle"):
        oracle("no_such_oracle")


def test_reach_is_the_farthest_tool_point_of_the_sampled_configurations(puma):
    """Robot.reach: the largest |p_tool| over REACH_SAMPLES configurations drawn with seed 0
    inside the limits, as forward_kinematics computes them (to 1e-12 m)."""
    from trackplan.robots.model import REACH_SAMPLES

    q = np.random.default_rng(0).uniform(puma.q_min, puma.q_max, (REACH_SAMPLES, puma.n_dof))
    expected = np.linalg.norm(forward_kinematics(puma, q)[:, :3, 3], axis=1).max()
    fresh = replace(puma)  # a new Robot: reach not yet cached
    assert abs(fresh.reach - expected) < 1e-12
