"""Seven-joint arms plan end to end: the chosen profile is where the samples are, every
sample is re-checked, and the limits hold by the test's own finite differences."""

from __future__ import annotations

import numpy as np
import pytest

import trackplan
from tests.conftest import CASES
from trackplan.robots.families import ik_family
from trackplan.robots.kinematics import forward_kinematics


@pytest.fixture(scope="module")
def sealing():
    """The shipped iiwa case planned at its example placement."""
    case = trackplan.load_case(CASES / "iiwa-sealing.yaml")
    return case, trackplan.plan(case, case.bounds.example)


def test_the_iiwa_plans_feasibly_on_its_chosen_arm_angle(sealing):
    case, result = sealing
    assert result.success, result.message
    traj = result.trajectory
    family = ik_family(case.robot)
    profile = result.joint_path.redundancy
    assert profile is not None
    # each sample's arm angle is the profile's at its arc length (the IK solved for it)
    psi = family.arm_angle(traj.q)
    wanted = profile.value(traj.s)
    gap = (psi - wanted + np.pi) % (2 * np.pi) - np.pi
    assert np.abs(gap).max() < 1e-7
    # every sample's tool point is on the path within the tolerance (our FK, not the checker)
    T = forward_kinematics(case.machine, traj.q)
    np.testing.assert_allclose(T[:, :3, 3], traj.tool_position, atol=1e-9)


def test_finite_differences_of_the_samples_keep_every_joint_limit(sealing):
    case, result = sealing
    traj, robot = result.trajectory, case.robot
    Ts = traj.sample_time
    q = traj.q
    assert np.all(q >= robot.q_min - 1e-9) and np.all(q <= robot.q_max + 1e-9)
    # central differences of the written positions (independent of the time law's own
    # derivatives); a few percent over the limit is the difference quotient's own error
    velocity = np.diff(q, axis=0) / Ts
    acceleration = np.diff(q, 2, axis=0) / Ts**2
    jerk = np.diff(q, 3, axis=0) / Ts**3
    assert np.all(np.abs(velocity) <= robot.v_max * 1.001)
    assert np.all(np.abs(acceleration) <= robot.a_max * 1.01)
    assert np.all(np.abs(jerk) <= robot.j_max * 1.05)


def test_the_checker_given_only_the_joints_agrees(sealing):
    case, result = sealing
    report = trackplan.check(
        case, case.bounds.example, result.trajectory.q, result.trajectory.sample_time
    )
    assert report.success, [v.message for v in report.violations]


def test_a_branch_past_the_familys_is_one_line(tmp_path, capsys):
    from trackplan.cli import main

    case = str(CASES / "iiwa-sealing.yaml")
    code = main(["plan", case, "--branch", "9", "--out", str(tmp_path), "--no-report"])
    err = capsys.readouterr().err.strip().splitlines()
    assert code == 2
    assert len(err) == 1 and "branch" in err[0] and "0…7" in err[0], err
