"""The joint path's tool poses: a tool held in one orientation along the whole path (part
frame, constant spin) takes its one rotation once; the poses equal those from the rotation
at every point; the joints at any arc lengths are the IK of those poses."""

from __future__ import annotations

import numpy as np

import trackplan
from tests.conftest import CASES
from trackplan.frames import tool_poses
from trackplan.jointpath import _rotations
from trackplan.planning.plan import plan
from trackplan.robots.path_ik import branch_joints
from trackplan.tool import SpinProfile, ToolOrientation


def test_poses_of_a_tool_in_one_orientation_equal_those_of_every_point():
    case = trackplan.load_case(CASES / "paper-corner.yaml")
    joint_path = plan(case, case.bounds.example).joint_path
    s = np.linspace(0.0, joint_path.length, 501)
    sample = joint_path.geometry.planned.sample(s)
    every = joint_path.tool.rotations(sample.s, sample.tangent)
    once = _rotations(joint_path.tool, sample.s, sample.tangent)
    assert once.shape == (3, 3)
    np.testing.assert_array_equal(every, np.broadcast_to(once, every.shape))
    expected = tool_poses(joint_path.placement, sample.position, every)
    np.testing.assert_allclose(joint_path.poses(s), expected, rtol=0, atol=1e-15)


def test_a_held_rotation_is_computed_once_per_spec_and_spin():
    """Plans of a case with a tool held in the part frame read one rotation; another spin
    value has its own, that of a rotation computed at every point with that spin."""
    case = trackplan.load_case(CASES / "paper-corner.yaml")
    first = plan(case, case.bounds.example).joint_path
    second = plan(case, case.bounds.example + 0.01).joint_path
    s = np.linspace(0.0, first.length, 11)
    sample = first.geometry.planned.sample(s)
    held = _rotations(first.tool, sample.s, sample.tangent)
    assert _rotations(second.tool, sample.s[::-1], sample.tangent[::-1]) is held
    assert not held.flags.writeable
    turned = ToolOrientation(case.task.tool, SpinProfile(np.array([0.3]), first.length))
    other = _rotations(turned, sample.s, sample.tangent)
    assert other is not held
    every = turned.rotations(sample.s, sample.tangent)
    np.testing.assert_array_equal(every, np.broadcast_to(other, every.shape))


def test_a_seam_frame_tool_turns_with_the_path():
    case = trackplan.load_case(CASES / "paper-circle-seam-fixed.yaml")
    joint_path = plan(case, case.bounds.example).joint_path
    s = np.linspace(0.0, joint_path.length, 101)
    sample = joint_path.geometry.planned.sample(s)
    rotations = _rotations(joint_path.tool, sample.s, sample.tangent)
    assert rotations.shape == (101, 3, 3)
    np.testing.assert_array_equal(rotations, joint_path.tool.rotations(sample.s, sample.tangent))


def test_joints_are_the_branch_ik_of_the_poses():
    """JointPath.joints solves the IK from the poses' rotations and positions without
    building them: bit for bit the joints of branch_joints on :meth:`JointPath.poses`
    wound near the interpolated grid, for a tool in one orientation and a turning one."""
    for name in ("paper-corner", "paper-circle-seam-fixed"):
        case = trackplan.load_case(CASES / f"{name}.yaml")
        joint_path = plan(case, case.bounds.example).joint_path
        s = np.linspace(0.0, joint_path.length, 777)[::-1]
        expected = branch_joints(
            case.robot, joint_path.poses(s), joint_path.branch, joint_path.interpolate(s)
        )
        np.testing.assert_array_equal(joint_path.joints(s), expected)
