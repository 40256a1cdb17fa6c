"""The continuous speed curve the smooth law takes near a wrist singularity."""

from __future__ import annotations

import numpy as np
import pytest

from tests.conftest import CASES
from trackplan.io.case_file import load_case
from trackplan.planning.plan import check_case_trajectory, plan_placement
from trackplan.timing import continuous
from trackplan.timing.sample_checks import robot_checks
from trackplan.timing.smooth import LIMIT_SHARE

WRIST_X = np.array([-0.1891, 0.1807, 0.1739, -0.5075, -1.3612, 1.5486])
"""A paper-line placement whose wrist passes near a singularity: joints 4 and 6 cap the speed
at 0.03 m/s over a few centimetres."""
WRIST_TOPP3 = 4.667
"""copp-py's TOPP3 on that joint path, s (``python -m benchmarks plan``'s reference)."""
WINDOWS_ONLY = 7.092
"""The window plan alone on that joint path, s (before the continuous curve)."""


@pytest.fixture(scope="module")
def wrist():
    case = load_case(CASES / "paper-line.yaml")
    return case, plan_placement(case, WRIST_X)


def test_near_a_wrist_singularity_the_law_is_within_4_percent_of_topp3(wrist):
    case, result = wrist
    assert result.feasible, result.message
    assert result.duration <= 1.04 * WRIST_TOPP3
    assert result.duration < 0.7 * WINDOWS_ONLY
    report = check_case_trajectory(case, WRIST_X, result.trajectory.q, case.task.sample_time)
    assert report.success, report.violations[:3]
    assert any("joint 4" in d.limit or "joint 6" in d.limit for d in result.slowdowns)


def test_the_linear_program_meets_its_node_bounds(wrist):
    """x = ṡ² from the LP meets the discretised velocity, acceleration and jerk bounds at
    every node, on both sides of every node, with the jerk bound at the planned speed."""
    case, result = wrist
    robot = case.robot
    stretch = continuous._stretches(result.joint_path, case.task)[0]
    limits = LIMIT_SHARE * np.stack([robot.v_max, robot.a_max, robot.j_max])[:, None, :]
    limits = np.broadcast_to(limits, (3, len(stretch.s), robot.n_dof))
    x = continuous._solve(stretch, limits, np.ones(len(stretch.s)))
    assert x is not None
    h = stretch.s[1] - stretch.s[0]
    v = np.sqrt(x)
    assert v.max() <= case.task.rated_speed
    assert np.all(np.abs(stretch.d1 * v[None, :, None]) <= limits[0] * (1 + 1e-6))
    slope = (x[2:] - x[:-2]) / (2 * h)
    bend = (x[2:] - 2 * x[1:-1] + x[:-2]) / h**2
    d1, d2, d3 = (d[:, 1:-1] for d in (stretch.d1, stretch.d2, stretch.d3))
    accel = d1 * slope[None, :, None] / 2 + d2 * x[None, 1:-1, None]
    jerk = v[None, 1:-1, None] * (
        d1 * bend[None, :, None] / 2 + 1.5 * d2 * slope[None, :, None] + d3 * x[None, 1:-1, None]
    )
    assert np.all(np.abs(accel) <= limits[1, 1:-1] * (1 + 1e-6) + 1e-9)
    assert np.all(np.abs(jerk) <= limits[2, 1:-1] * (1 + 1e-6) + 1e-9)
    # the curve rises above the constant-speed cap somewhere (signed demand cancels)
    cap, _ = continuous._joint_caps(stretch, robot, LIMIT_SHARE)
    assert np.any(v > 1.2 * cap)


def test_rest_envelope_is_a_start_at_constant_path_jerk():
    s = np.linspace(0.0, 0.01, 101)
    d1 = np.full((2, len(s), 1), 2.0)  # q' = 2 rad/m: path jerk J = j_max / 2
    jerk = np.full((len(s), 1), 8.0)
    x = continuous._rest_envelope(s, d1, jerk)
    J = continuous.REST_JERK_SHARE * 4.0
    t = np.cbrt(6 * s / J)  # s = J t³/6
    near_start = s <= 0.005
    assert np.allclose(x[near_start], (J * t[near_start] ** 2 / 2) ** 2, rtol=1e-12)
    assert x[0] == 0.0 and x[-1] == 0.0
    assert np.allclose(x, x[::-1], rtol=1e-12)  # the stop mirrors the start


def test_a_curve_that_cannot_beat_the_windows_is_given_up(wrist):
    """Given the window plan's duration to beat, the curve is planned when it is faster and
    given up (None) when even the nodes' own timing cannot beat a shorter one."""
    case, result = wrist
    checks = robot_checks(case.robot)
    curve = continuous.plan_speed_curve(
        result.joint_path, case.task, checks, LIMIT_SHARE, to_beat=WINDOWS_ONLY
    )
    assert curve is not None and curve.duration < WINDOWS_ONLY
    unbeatable = 0.5 * curve.duration
    assert (
        continuous.plan_speed_curve(
            result.joint_path, case.task, checks, LIMIT_SHARE, to_beat=unbeatable
        )
        is None
    )
