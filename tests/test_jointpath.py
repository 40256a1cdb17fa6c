"""The joint path's tool poses: a tool held in one orientation along the whole path (part
frame, constant spin) takes its one rotation once; the poses equal those from the rotation
at every point."""

from __future__ import annotations

import numpy as np

import trackplan
from tests.conftest import CASES
from trackplan.frames import tool_poses
from trackplan.jointpath import _rotations


def test_poses_of_a_tool_in_one_orientation_equal_those_of_every_point():
    case = trackplan.load_case(CASES / "paper-corner.yaml")
    joint_path = trackplan.plan_placement(case, case.bounds.example).joint_path
    s = np.linspace(0.0, joint_path.length, 501)
    sample = joint_path.geometry.planned.sample(s)
    every = joint_path.tool.rotations(sample.s, sample.tangent)
    once = _rotations(joint_path.tool, sample.s, sample.tangent)
    assert once.shape == (3, 3)
    np.testing.assert_array_equal(every, np.broadcast_to(once, every.shape))
    expected = tool_poses(joint_path.placement, sample.position, every)
    np.testing.assert_allclose(joint_path.poses(s), expected, rtol=0, atol=1e-15)


def test_a_seam_frame_tool_turns_with_the_path():
    case = trackplan.load_case(CASES / "paper-circle-seam-fixed.yaml")
    joint_path = trackplan.plan_placement(case, case.bounds.example).joint_path
    s = np.linspace(0.0, joint_path.length, 101)
    sample = joint_path.geometry.planned.sample(s)
    rotations = _rotations(joint_path.tool, sample.s, sample.tangent)
    assert rotations.shape == (101, 3, 3)
    np.testing.assert_array_equal(rotations, joint_path.tool.rotations(sample.s, sample.tangent))
