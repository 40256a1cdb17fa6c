"""The CRX cobot plans end to end on a tracked branch: one solution followed, every limit kept."""

from __future__ import annotations

import numpy as np
import pytest

import trackplan
from tests.conftest import CASES
from trackplan.robots.families import ik_family
from trackplan.robots.kinematics import forward_kinematics


@pytest.fixture(scope="module")
def weld():
    """The shipped CRX case planned at its example placement."""
    case = trackplan.load_case(CASES / "crx-weld.yaml")
    return case, trackplan.plan(case, case.bounds.example)


def test_the_crx_follows_one_solution_of_its_first_pose(weld):
    case, result = weld
    assert result.success, result.message
    family = ik_family(case.robot)
    assert family.name == "crx" and not family.closed_form
    q = result.trajectory.q
    T0 = forward_kinematics(case.robot, q[:1])
    solutions = family.solutions(T0)
    # the first sample is one of the first pose's solutions (the branch the plan follows)
    found = solutions[0][0][solutions[1][0]]
    gaps = np.abs((found - q[0] + np.pi) % (2 * np.pi) - np.pi).max(axis=1)
    assert gaps.min() < 1e-6
    # and the samples never jump to another solution: no joint step above 10 mrad
    assert np.abs(np.diff(q, axis=0)).max() < 0.01


def test_the_crx_samples_keep_every_limit_and_the_checker_agrees(weld):
    case, result = weld
    traj, robot = result.trajectory, case.robot
    Ts = traj.sample_time
    assert np.all(traj.q >= robot.q_min) and np.all(traj.q <= robot.q_max)
    assert np.all(np.abs(np.diff(traj.q, axis=0) / Ts) <= robot.v_max * 1.001)
    assert np.all(np.abs(np.diff(traj.q, 2, axis=0) / Ts**2) <= robot.a_max * 1.01)
    assert np.all(np.abs(np.diff(traj.q, 3, axis=0) / Ts**3) <= robot.j_max * 1.05)
    report = trackplan.check(case, case.bounds.example, traj.q, Ts)
    assert report.success, [v.message for v in report.violations]


def test_a_branch_the_first_pose_does_not_have_says_so(weld):
    case, _ = weld
    result = trackplan.plan(case, case.bounds.example, branch=15)
    assert not result.success
    assert "first pose has no such solution inside the joint limits" in result.message
