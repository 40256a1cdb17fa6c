"""Plan results for the report tests.

The paper's corner case (Case 3: (0, 0, 0) → (0.5, 0, 0) → (0.3, 0, 0.5), the paper's
placement X) planned by trackplan at a 5 ms period, with one planted jerk violation on
joint 6 re-checked by the checker, a planted slow-down and reference durations.
"""

from __future__ import annotations

import dataclasses
import math
from pathlib import Path

import numpy as np
import pytest

from trackplan.case import Case, Objective, OptimizerSettings, PlacementBounds, Task
from trackplan.derivatives import backward_derivatives
from trackplan.paths.path_geometry import PathGeometry
from trackplan.paths.specs import LineSpec
from trackplan.planning.checker import check_trajectory
from trackplan.planning.plan import make_trajectory, plan, tracking_reference
from trackplan.planning.result import LIMIT_KINDS, CheckReport, PlanResult, Trajectory
from trackplan.robots.builtin import puma560
from trackplan.robots.model import Robot
from trackplan.status import Status
from trackplan.timing import SlowDown
from trackplan.tool import ToolSpec

SAMPLE_TIME = 0.005  # s
TOLERANCE = 0.001  # ρ, m
RATED_SPEED = 0.15  # v_r, m/s
CORNER_SPEED_CAP = 0.05  # v_t^max, m/s
SLOW_SPEED = 0.10  # plateau of the planted slow-down on the second line, m/s
PAPER_PLACEMENT = np.array([0.0902, 0.2090, 0.2020, 0.3263, 0.3016, -0.2522])
PAPER_WEIGHTS = np.array([0.3, 0.2, 0.2, 0.1, 0.1, 0.1])
TOOL_RPY = np.array([-np.pi / 2, 0.0, 0.0])
CORNER = np.array([[0.0, 0.0, 0.0], [0.5, 0.0, 0.0], [0.3, 0.0, 0.5]])  # m
UNREACHABLE_PLACEMENT = np.array([0.8, 0.0, 0.4, 0.0, 0.0, 0.0])  # beyond the PUMA's reach
PLANTED_JOINT = 6
PLANTED_TIME = 2.0  # s
PLANTED_JERK = 31.2  # rad/s³, against the limit of 20


def corner_case(robot: Robot) -> Case:
    """The paper's corner case (Section 4, Case 3) as a Case."""
    reach = (math.sqrt(0.0226), math.sqrt(0.7289))
    lower = np.array([-0.87, -0.87, -0.87, -1.57, -1.57, -1.57])
    return Case(
        name="paper-corner",
        robot=robot,
        start=CORNER[0],
        segments=(LineSpec(to=CORNER[1]), LineSpec(to=CORNER[2])),
        task=Task(
            rated_speed=RATED_SPEED,
            corner_speed=CORNER_SPEED_CAP,
            tolerance=TOLERANCE,
            sample_time=SAMPLE_TIME,
            tool=ToolSpec.part(TOOL_RPY),
        ),
        bounds=PlacementBounds(lower=lower, upper=-lower, reach=reach, example=PAPER_PLACEMENT),
        objective=Objective(weights=PAPER_WEIGHTS),
        optimizer=OptimizerSettings(method="ga", population=30, seed=1),
    )


def plan_corner(case: Case) -> PlanResult:
    """``case`` planned by trackplan at the paper's placement, with planted findings.

    A jerk violation is planted on joint 6 (it turns the tool about its own axis, so the tool
    point and the tracking error are unaffected) and re-checked by the checker; a slow-down
    and reference durations are added so that every part of the report has content.
    """
    robot = case.robot
    planned = plan(case, PAPER_PLACEMENT)
    t, q = planned.trajectory.t, planned.trajectory.q.copy()
    bump = np.exp(-0.5 * ((t - PLANTED_TIME) / 0.02) ** 2)
    bump_jerk = backward_derivatives(bump, SAMPLE_TIME)[2]
    base_jerk = backward_derivatives(q, SAMPLE_TIME)[2][:, PLANTED_JOINT - 1]
    k_peak = np.argmax(np.abs(bump_jerk))
    q[:, PLANTED_JOINT - 1] += bump * (PLANTED_JERK - base_jerk[k_peak]) / bump_jerk[k_peak]
    trajectory = make_trajectory(robot, q, planned.trajectory.s, SAMPLE_TIME)
    geometry = PathGeometry.from_case(case)
    check = check_trajectory(
        robot, q, SAMPLE_TIME, tracking_reference(case, geometry, PAPER_PLACEMENT)
    )
    slow_start = 0.65
    return dataclasses.replace(
        planned,
        trajectory=trajectory,
        check=check,
        success=check.success,
        status=Status.FEASIBLE if check.success else Status.LIMITS_VIOLATED,
        message=check.violations[0].message if check.violations else "feasible",
        objective=float(np.sum(PAPER_WEIGHTS * np.abs(np.diff(q, axis=0)))),
        slowdowns=(
            SlowDown(slow_start, slow_start + 0.1, SLOW_SPEED, RATED_SPEED, "joint 4 velocity"),
        ),
        references={
            "toppra_duration": 0.97 * planned.duration,
            "topp3_duration": 0.985 * planned.duration,
        },
    )


def empty_result(case: Case) -> PlanResult:
    """An unreachable placement: no trajectory at all."""
    n = case.robot.n_dof
    empty = np.zeros((0, n))
    trajectory = Trajectory(
        sample_time=SAMPLE_TIME,
        t=np.zeros(0),
        s=np.zeros(0),
        q=empty,
        qd=empty,
        qdd=empty,
        qddd=empty,
        tool_position=np.zeros((0, 3)),
        speed=np.zeros(0),
    )
    check = CheckReport(
        success=False,
        joint_margins={kind: np.full(n, np.nan) for kind in LIMIT_KINDS},
        task_margins={"coverage": -1.0},
        violations=(),
        max_tracking_error=float("nan"),
        max_orientation_error=float("nan"),
    )
    return PlanResult(
        case_name=case.name,
        placement=UNREACHABLE_PLACEMENT,
        success=False,
        status=Status.UNREACHABLE,
        message="path pose 12 at s = 0.061 m is out of reach",
        timing="smooth",
        branch=-1,
        trajectory=trajectory,
        check=check,
        objective=float("inf"),
        duration=float("nan"),
        path_length=1.0385,
        rated_speed_fraction=0.0,
        min_corner_speed=0.0,
        slowdowns=(),
        references={},
        joint_path=plan(case, UNREACHABLE_PLACEMENT).joint_path,
    )


def optimizer_history(rng: np.random.Generator) -> dict[str, dict[str, np.ndarray]]:
    """A plausible optimize history for two methods."""
    history = {}
    for method, population, n_gen in (("ga", 30, 25), ("cmaes", 12, 40)):
        generation = np.arange(1, n_gen + 1)
        best = 0.9 + 4.0 * np.exp(-generation / 6.0) + 0.02 * rng.random(n_gen)
        history[method] = {
            "generation": generation,
            "evaluations": generation * population,
            "best": np.minimum.accumulate(best),
            "mean": best * 3.0 + 1e3 * np.exp(-generation / 3.0),
            "feasible_share": np.clip(1.0 - np.exp(-generation / 8.0), 0.0, 1.0),
            "wall_time": generation * 0.05 * population,
        }
    return history


@pytest.fixture(scope="session")
def corner() -> Case:
    """The paper's corner case with the built-in PUMA560."""
    return corner_case(puma560())


@pytest.fixture(scope="session")
def corner_result(corner: Case) -> PlanResult:
    """The corner case planned at the paper's placement, one planted jerk violation."""
    return plan_corner(corner)


@pytest.fixture(scope="session")
def unreachable_result(corner: Case) -> PlanResult:
    """An unreachable placement of the corner case: empty trajectory."""
    return empty_result(corner)


@pytest.fixture
def history() -> dict[str, dict[str, np.ndarray]]:
    """Optimizer history of two methods (ga, cmaes)."""
    return optimizer_history(np.random.default_rng(7))


REPORT_FRAMES = 60  # animation frames of the 3D view in the report tests
REPORT_INFO = {"method": "ga", "evaluations": 750, "wall_time": 37.5, "best_X": PAPER_PLACEMENT}
"""The optimizer table of the report tests."""


@pytest.fixture(scope="session")
def report_file(tmp_path_factory, corner: Case, corner_result: PlanResult):
    """report.html of the corner result with an optimizer history (written once, as a run
    writes it: :func:`~trackplan.report.run_report.write_run_report`)."""
    from trackplan.report.run_report import write_run_report

    history = optimizer_history(np.random.default_rng(7))
    out_dir = tmp_path_factory.mktemp("report")
    _, report = write_run_report(
        corner_result, corner, out_dir, history, REPORT_INFO, n_frames=REPORT_FRAMES
    )
    return report


BRACKET_CASE = Path(__file__).resolve().parents[2] / "cases" / "bracket-4-fillets.yaml"
"""A case of four seams joined by approach, retract and air moves, with a cell."""


@pytest.fixture(scope="session")
def bracket() -> Case:
    from trackplan.io.case_file import load_case

    return load_case(BRACKET_CASE)


@pytest.fixture(scope="session")
def bracket_result(bracket: Case) -> PlanResult:
    """The four seams planned once at the case's example placement."""
    return plan(bracket, bracket.bounds.example)


@pytest.fixture(scope="session")
def bracket_report(tmp_path_factory, bracket: Case, bracket_result: PlanResult):
    """The bracket's report files, written as a run writes them: (plots, report.html)."""
    from trackplan.report.run_report import write_run_report

    out_dir = tmp_path_factory.mktemp("bracket-report")
    return write_run_report(
        bracket_result, bracket, out_dir, parallel=False, n_frames=REPORT_FRAMES
    )
