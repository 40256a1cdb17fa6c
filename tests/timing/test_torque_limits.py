"""The torque sample check: the speed factor it asks for brings the torque under the limit."""

from __future__ import annotations

import dataclasses

import numpy as np

from trackplan.robots.dynamics_parameters import Payload
from trackplan.timing.sample_checks import TorqueLimits

TS = 1e-3


def swing(robot, omega: float, amplitude: float = 0.5) -> np.ndarray:
    """Joint 2 swings out and back, ``q2 = A (1 - cos ω t)`` over one whole period (at rest
    at both ends, the last sample exactly at the period), the other joints still."""
    n = round(2 * np.pi / omega / TS)
    t = np.arange(n + 1) * TS
    q = np.tile([0.3, -0.4, 0.2, 0.1, 0.5, 0.0], (len(t), 1))
    q[:, 1] += amplitude * (1.0 - np.cos(2 * np.pi * t / t[-1]))
    return q


def peak_torque_ratio(robot, q: np.ndarray) -> float:
    from trackplan.planning.energy import energy_figures

    return energy_figures(robot, q, TS).peak_torque_ratio


def test_slowing_by_the_ratio_meets_the_limit(puma):
    fast = swing(puma, omega=12.0)
    assert peak_torque_ratio(puma, fast) > 1.5
    sample, order, ratio = TorqueLimits(puma)(fast, TS)
    assert sample.size and np.all(order == 2) and np.all(ratio > 1.0)
    # the worst sample's factor applied to the whole motion: speed × ratio^(-1/2)
    slowed = swing(puma, omega=12.0 * ratio.max() ** -0.5)
    assert peak_torque_ratio(puma, slowed) <= 1.0 + 1e-2
    # and it is not needlessly slow: a bit faster breaks the limit again
    faster = swing(puma, omega=12.0 * 1.05 * ratio.max() ** -0.5)
    assert peak_torque_ratio(puma, faster) > 1.0


def test_nothing_to_do_within_the_limits(puma):
    sample, order, ratio = TorqueLimits(puma)(swing(puma, omega=1.0), TS)
    assert sample.size == order.size == ratio.size == 0


def test_gravity_only_excess_is_left_to_the_checker(puma):
    """A load joint 2 cannot hold at any speed: no slow-down is asked for it."""
    heavy = dataclasses.replace(
        puma, dynamics=dataclasses.replace(puma.dynamics, payload=Payload(60.0))
    )
    q = swing(heavy, omega=1.0, amplitude=0.05)
    assert peak_torque_ratio(heavy, q) > 1.0
    sample, _, _ = TorqueLimits(heavy)(q, TS)
    assert sample.size == 0


def test_robot_without_dynamics(ur):
    sample, order, ratio = TorqueLimits(ur)(np.zeros((5, 6)), TS)
    assert sample.size == order.size == ratio.size == 0


def test_the_smooth_law_slows_down_where_torque_binds():
    """Joint 1 of the PUMA560 limited to 35 N·m (|G|·Tc− = 27.2 N·m of it is Coulomb
    friction): the corner case's plan at the paper's placement would break it; the smooth law
    slows down until it holds, and the plan is feasible."""
    from tests.conftest import CASES
    from trackplan.io.case_file import load_case
    from trackplan.planning.checker import check_trajectory
    from trackplan.planning.plan import plan

    case = load_case(CASES / "paper-corner.yaml")
    X = case.bounds.example
    base = plan(case, X)
    torque_max = np.array(case.robot.dynamics.torque_max)
    torque_max[0] = 35.0
    robot = dataclasses.replace(
        case.robot, dynamics=dataclasses.replace(case.robot.dynamics, torque_max=torque_max)
    )
    weak = dataclasses.replace(case, robot=robot)
    before = check_trajectory(robot, base.trajectory.q, TS)
    assert [v.joint for v in before.violations if v.limit == "torque"] == [1]
    planned = plan(weak, X)
    assert planned.success, planned.message
    assert 0.0 <= planned.check.joint_margins["torque"][0] < 0.05
    assert planned.duration > base.duration + 0.1
