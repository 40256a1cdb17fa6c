"""Paper mode (Section 3.1 as written) on the paper's line, corner and circle."""

from __future__ import annotations

import numpy as np
import pytest

from tests.conftest import CASES
from trackplan.io.case_file import load_case
from trackplan.jointpath import JointPath
from trackplan.paths.path_geometry import PathGeometry
from trackplan.planning.plan import plan
from trackplan.status import Status
from trackplan.timing import paper
from trackplan.tool import ToolOrientation

LINE_PUBLISHED = np.array([-0.1322, 0.0610, 0.1829, 0.0312, -0.4124, 0.5020])
LINE_MOVED_OUT = np.array([-0.2230, 0.1029, 0.1829, 0.0312, -0.4124, 0.5020])
"""Case 1's placement with (x, y) moved 0.1 m away from joint 1's axis (reachable)."""
CORNER_PUBLISHED = np.array([0.0902, 0.2090, 0.2020, 0.3263, 0.3016, -0.2522])
CIRCLE = np.array([0.3922, 0.4626, 0.1924, -0.799, 0.8431, -0.9053])


@pytest.fixture(scope="module")
def line_case():
    return load_case(CASES / "paper-line.yaml")


@pytest.fixture(scope="module")
def corner_case():
    return load_case(CASES / "paper-corner.yaml")


@pytest.fixture(scope="module")
def line_result(line_case):
    return plan(line_case, LINE_MOVED_OUT, timing="paper")


@pytest.fixture(scope="module")
def corner_result(corner_case):
    return plan(corner_case, CORNER_PUBLISHED, timing="paper")


def kinds(result) -> set[str]:
    return {v.limit for v in result.check.violations}


def test_published_line_placement_is_out_of_reach(line_case):
    # The start (x, y) is 0.146 m from joint 1's axis, inside the 0.15 m shoulder offset d3.
    assert np.hypot(*LINE_PUBLISHED[:2]) < line_case.robot.dh[2, 0]
    result = plan(line_case, LINE_PUBLISHED, timing="paper")
    assert result.status is Status.UNREACHABLE
    assert result.trajectory.n_samples == 0
    assert "out of reach" in result.message


def test_line_produces_a_checked_trajectory(line_result, line_case):
    assert line_result.trajectory.n_samples > 0
    assert line_result.status is Status.LIMITS_VIOLATED
    # the paper's Fig. 5b finding: acceleration and jerk limits broken, velocities within
    assert {"acceleration", "jerk"} <= kinds(line_result)
    assert "velocity" not in kinds(line_result)
    assert np.all(line_result.check.joint_margins["velocity"] > 0.0)
    # rest to rest, whole path, at most about L / v_r plus the ramps
    s = line_result.trajectory.s
    assert s[0] == pytest.approx(0.0, abs=1e-6)
    assert s[-1] == pytest.approx(line_result.path_length, abs=1e-6)
    assert line_result.duration < 1.05 * line_result.path_length / line_case.task.rated_speed


def test_line_resolved_rate_tracking_error_is_small(line_result):
    assert line_result.check.max_tracking_error < 2e-5
    assert line_result.check.max_orientation_error < 1e-4
    assert "tracking" not in kinds(line_result)


def test_line_middle_piece_runs_at_rated_speed(line_result, line_case):
    speed = np.diff(line_result.trajectory.s) / line_case.task.sample_time
    at_rated = np.abs(speed - line_case.task.rated_speed) <= 1e-3 * line_case.task.rated_speed
    assert at_rated.mean() > 0.9
    assert speed.max() <= line_case.task.rated_speed * (1 + 1e-3)


def test_corner_tracking_error_is_two_rho(corner_result, corner_case):
    # Eq. 10's tangent arc lies 2ρ from the sharp corner: the checker flags it.
    rho = corner_case.task.tolerance
    assert corner_result.trajectory.n_samples > 0
    assert corner_result.check.max_tracking_error == pytest.approx(2 * rho, rel=0.02)
    tracking = [v for v in corner_result.check.violations if v.limit == "tracking"]
    assert tracking and tracking[0].worst == pytest.approx(2 * rho, rel=0.02)
    # it happens on the arc, half-way through the path
    assert 0.3 * corner_result.duration < tracking[0].t_first < 0.7 * corner_result.duration


def test_corner_arc_is_a_whole_number_of_periods(corner_case):
    geometry = PathGeometry.from_case(corner_case, "paper")
    tool = ToolOrientation.choose(corner_case.task.tool, geometry)
    joint_path = JointPath.solve(corner_case.robot, geometry, CORNER_PUBLISHED, tool, branch=3)
    planner = paper._PaperPlanner(corner_case.robot, corner_case.task, joint_path)
    arc = next(k for k, piece in enumerate(geometry.planned.pieces) if not piece.straight)
    steps = planner._arc_steps(arc)
    speed = planner._arc_speed(arc)
    assert speed <= corner_case.task.corner_speed
    assert steps * corner_case.task.sample_time * speed == pytest.approx(
        geometry.planned.pieces[arc].length
    )


def test_arc_started_at_constant_speed_steps_the_velocity():
    case = load_case(CASES / "paper-circle.yaml")
    result = plan(case, CIRCLE, timing="paper")
    assert result.trajectory.n_samples > 0
    first = [v for v in result.check.violations if v.limit == "acceleration"]
    assert first, "the step from rest to v_t at the start must break the acceleration limit"
    assert min(v.t_first for v in first) == pytest.approx(case.task.sample_time)
    # the circle itself is tracked closely by resolved rate
    assert result.check.max_tracking_error < 1e-5


def test_forced_branch_is_used_or_refused(corner_case):
    geometry = PathGeometry.from_case(corner_case, "paper")
    joint_path = JointPath.solve(
        corner_case.robot,
        geometry,
        CORNER_PUBLISHED,
        ToolOrientation.choose(corner_case.task.tool, geometry),
        branch=3,
    )
    law = paper.plan_paper_trajectory(joint_path, corner_case.task)
    assert joint_path.branch == 3 and law.success and law.message == ""
    assert law.q.shape == (len(law.s), 6)
    assert np.all(np.diff(law.s) >= -1e-6)
    refused = plan(corner_case, CORNER_PUBLISHED, timing="paper", branch=0)
    assert refused.branch == 0 and refused.status is Status.POSITION_LIMITS
    assert refused.trajectory.q.shape == (0, 6) and refused.message


def test_via_spacing_keeps_the_ramp_from_stalling(line_case):
    # With 1 mm vias at Ts = 1 ms, rounding each interval up to whole periods cancels the
    # acceleration: the forward piece stalls at 1 mm / (m Ts) below v_r.
    geometry = PathGeometry.from_case(line_case, "paper")
    tool = ToolOrientation.choose(line_case.task.tool, geometry)
    joint_path = JointPath.solve(line_case.robot, geometry, LINE_MOVED_OUT, tool, branch=2)
    planner = paper._PaperPlanner(line_case.robot, line_case.task, joint_path)
    piece = geometry.planned.pieces[0]
    q_start = plan(line_case, LINE_MOVED_OUT, timing="paper").trajectory.q[0]
    rated = line_case.task.rated_speed
    _, fine = planner._via_points(piece, paper.MIN_VIA_SPACING, q_start)
    stalled = planner._ramp(fine, np.zeros(6), rated)
    end = stalled.reached if stalled.reached is not None else -1
    assert stalled.via_speed[end] < 0.9 * rated
    spacing = planner.via_spacing(fine, piece.length / (len(fine) - 1))
    assert spacing > paper.MIN_VIA_SPACING
    _, coarse = planner._via_points(piece, spacing, q_start)
    ramp = planner._ramp(coarse, np.zeros(6), rated)
    assert ramp.reached is not None
    assert ramp.via_speed[ramp.reached] == pytest.approx(rated, rel=0.05)
    assert ramp.via_speed.max() <= rated * (1 + 1e-9)
