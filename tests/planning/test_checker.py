"""The checker catches what it must: planted faults on a real, feasible trajectory."""

from __future__ import annotations

import numpy as np
import pytest

from trackplan.frames import placement_transform, tool_poses
from trackplan.paths.path_geometry import PathGeometry
from trackplan.planning.checker import check_trajectory
from trackplan.planning.plan import plan, tracking_reference
from trackplan.robots.path_ik import solve_path_ik
from trackplan.status import Status


def _check(case, geometry, q, X):
    return check_trajectory(
        case.robot, q, case.task.sample_time, tracking_reference(case, geometry, X)
    )


def _kinds(report):
    return {(v.limit, v.joint) for v in report.violations}


def test_feasible_plan_passes_every_check(corner_case, corner_geometry, corner_plan):
    report = _check(corner_case, corner_geometry, corner_plan.trajectory.q, corner_plan.placement)
    assert report.success, [v.message for v in report.violations]
    assert report.status is Status.FEASIBLE
    assert report.max_tracking_error <= corner_case.task.tolerance
    for kind, margins in report.joint_margins.items():
        assert np.all(margins >= 0), kind
    assert set(report.task_margins) == {"orientation", "spin", "tracking", "speed", "coverage"}


def test_planted_acceleration_step_is_caught(corner_case, corner_geometry, corner_plan):
    q = corner_plan.trajectory.q.copy()
    Ts = corner_case.task.sample_time
    k0, m, a = len(q) // 3, 100, 2.0
    # joint 1 acceleration steps to +a at k0, to -a at k0 + m and back to 0 at k0 + 2m
    accel = np.zeros(len(q))
    accel[k0 : k0 + m] = a
    accel[k0 + m : k0 + 2 * m] = -a
    q[:, 0] += np.cumsum(np.cumsum(accel) * Ts) * Ts
    report = _check(corner_case, corner_geometry, q, corner_plan.placement)
    jerk = [v for v in report.violations if v.limit == "jerk" and v.joint == 1]
    assert jerk, [v.message for v in report.violations]
    assert report.status is Status.LIMITS_VIOLATED and not report.success
    assert jerk[0].t_first == pytest.approx(k0 * Ts, abs=3 * Ts)
    # an acceleration step Δa between two samples is a jerk of Δa / Ts: worst at k0 + m
    assert abs(jerk[0].worst) == pytest.approx(2 * a / Ts, rel=0.05)
    assert "joint 1 jerk" in jerk[0].message and "exceeds 30" in jerk[0].message


def test_planted_tracking_deviation_is_caught(corner_case, corner_geometry, corner_plan):
    rho = corner_case.task.tolerance
    X = corner_plan.placement
    s = corner_plan.trajectory.s
    window = (s > 0.2) & (s < 0.3)
    bump = np.where(window, np.sin(np.pi * (s - 0.2) / 0.1) ** 2, 0.0)
    positions = corner_geometry.planned.sample(s).position
    positions[:, 1] += 2 * rho * bump  # y is normal to the x–z plane of the path
    poses = tool_poses(X, positions, corner_case.task.tool.base_rotations(np.zeros((1, 3)))[0])
    q = solve_path_ik(corner_case.robot, poses[None], branch=corner_plan.branch).q[0]
    report = _check(corner_case, corner_geometry, q, X)
    tracking = [v for v in report.violations if v.limit == "tracking"]
    assert len(tracking) == 1
    assert report.max_tracking_error == pytest.approx(2 * rho, rel=1e-3)
    t = corner_plan.trajectory.t
    assert t[window][0] <= tracking[0].t_first <= tracking[0].t_last <= t[window][-1]


def test_path_run_backwards_is_caught(corner_case, corner_geometry, corner_plan):
    q = corner_plan.trajectory.q[::-1].copy()
    report = _check(corner_case, corner_geometry, q, corner_plan.placement)
    coverage = [v.message for v in report.violations if v.limit == "coverage"]
    assert coverage and any("backwards" in m or "starts" in m for m in coverage), coverage
    assert not any(v.limit in ("velocity", "acceleration", "jerk") for v in report.violations)


def test_skipped_segment_is_caught(three_segment_case):
    case = three_segment_case
    geometry = PathGeometry.from_case(case)
    X = case.bounds.example
    result = plan(case, X, geometries={(0, False): geometry})
    assert result.feasible, result.message
    nominal = geometry.nominal
    s_nominal, _ = nominal.project(
        (result.trajectory.tool_position - X[:3]) @ placement_transform(X)[:3, :3]
    )
    middle = (s_nominal > nominal.pieces[1].s_start - 0.005) & (
        s_nominal < nominal.pieces[1].s_end + 0.005
    )
    q = result.trajectory.q[~middle]
    report = _check(case, geometry, q, X)
    messages = [v.message for v in report.violations if v.limit == "coverage"]
    assert any("segment 2 skipped" in m for m in messages), messages
    part = result.trajectory.q[~((s_nominal > 0.55) & (s_nominal < 0.6))]
    messages = [v.message for v in _check(case, geometry, part, X).violations]
    assert any("part of segment 2 skipped" in m for m in messages), messages


def test_orientation_error_is_caught(corner_case, corner_geometry, corner_plan):
    q = corner_plan.trajectory.q.copy()
    q[:, 4] += 0.01  # a constant tilt of the tool axis (the PUMA's tool point is on joint 5)
    report = _check(corner_case, corner_geometry, q, corner_plan.placement)
    assert ("orientation", None) in _kinds(report)
    assert report.max_orientation_error == pytest.approx(0.01, rel=1e-6)


def test_a_twist_about_the_tool_axis_is_a_spin_error(corner_case, corner_geometry, corner_plan):
    q = corner_plan.trajectory.q.copy()
    q[:, 5] += 0.01  # the tool axis stays, the spin (fixed at 0) moves
    report = _check(corner_case, corner_geometry, q, corner_plan.placement)
    assert _kinds(report) == {("spin", None)}
    assert report.task_margins["spin"] == pytest.approx(1.0 - 0.01 / 1e-3, rel=1e-6)


def test_joint_limits_only_without_reference(corner_case, corner_plan):
    report = check_trajectory(corner_case.robot, corner_plan.trajectory.q, 1e-3)
    assert report.success and report.task_margins == {}
