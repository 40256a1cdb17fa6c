"""Torque limits in the checker and the search, and the shipped payload case."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from tests.oracles import rtb_robot_from
from trackplan.io.case_file import load_case
from trackplan.paths.path_geometry import PathGeometry
from trackplan.planning.checker import check_trajectory
from trackplan.planning.plan import plan
from trackplan.search.fitness import PlacementFitness
from trackplan.search.screening import code
from trackplan.search.space import SearchSpace
from trackplan.status import Status

from .conftest import CASES

rtb = pytest.importorskip("roboticstoolbox")


@pytest.fixture(scope="module")
def payload_case():
    return load_case(CASES / "puma-payload.yaml")


def test_torque_margins_from_backward_differences(corner_case, corner_plan):
    """Margins are 1 - max|τ|/τmax with τ from rtb's rne on np.diff derivatives, robot at
    rest before and after."""
    q = corner_plan.trajectory.q
    Ts = corner_case.task.sample_time
    padded = np.concatenate([np.repeat(q[:1], 3, 0), q, np.repeat(q[-1:], 3, 0)])
    qd = np.diff(padded, 1, axis=0)[2:] / Ts
    qdd = np.diff(padded, 2, axis=0)[1:] / Ts**2
    tau = rtb_robot_from(corner_case.robot).rne(padded[3:], qd, qdd)
    expected = 1.0 - np.abs(tau).max(axis=0) / corner_case.robot.dynamics.torque_max
    report = check_trajectory(corner_case.robot, q, Ts)
    np.testing.assert_allclose(report.joint_margins["torque"], expected, rtol=0, atol=1e-9)
    assert report.success and "torque" in report.binding


def test_fast_motion_breaks_torque_but_not_at_any_speed(corner_case, corner_plan):
    """A joint-2 swing peaking at 30 rad/s² breaks its torque limit; holding still would not."""
    robot = dataclasses.replace(
        corner_case.robot, a_max=np.full(6, 1e3), j_max=np.full(6, 1e6), v_max=np.full(6, 1e3)
    )
    Ts = 1e-3
    t = np.arange(0, 0.5, Ts)
    q = np.tile(corner_plan.trajectory.q[0], (len(t), 1))
    q[:, 1] += 0.5 * (1 - np.cos(2 * np.pi * t / 0.5)) * 60 / (2 * np.pi / 0.5) ** 2
    report = check_trajectory(robot, q, Ts)
    torque = [v for v in report.violations if v.limit == "torque"]
    assert [v.joint for v in torque] == [2]
    assert "exceeds 186.4" in torque[0].message and "any speed" not in torque[0].message
    assert report.joint_margins["torque"][1] < 0


def test_robot_without_dynamics_has_no_torque_check(ur):
    q = np.zeros((10, 6))
    assert "torque" not in check_trajectory(ur, q, 1e-3).joint_margins


def test_payload_case_is_infeasible_at_the_papers_optimum(payload_case):
    """The 5 kg end effector: joint 5 cannot hold it at the paper's placement."""
    planned = plan(payload_case, payload_case.bounds.example)
    assert not planned.feasible
    torque = [v for v in planned.check.violations if v.limit == "torque"]
    assert [v.joint for v in torque] == [5]
    assert torque[0].message.startswith("joint 5 torque")
    assert "infeasible at any speed" in torque[0].message
    assert "joint 5 torque" in planned.message


def test_search_screens_holding_torque(payload_case, corner_case):
    """The paper's optimum screens out for holding torque with the payload, not without."""
    X = payload_case.bounds.example[None, :]
    found = []
    for case in (payload_case, corner_case):
        geometry = PathGeometry.from_case(case)
        fitness = PlacementFitness(case, SearchSpace.from_case(case), geometry, "smooth")
        found.append(fitness.evaluate(X))
    assert found[0].finding[0] == code(Status.HOLDING_TORQUE) and not found[0].feasible[0]
    assert found[1].feasible[0]
    assert 0.5 < found[0].violation[0] < 1.5
