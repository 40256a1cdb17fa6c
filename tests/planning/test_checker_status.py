"""A check report's status: derived from its violations, one vocabulary with plans."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from tests.conftest import CASES
from trackplan.check_report import CellReport, CheckReport, Violation, violations_status
from trackplan.io.case_file import load_case
from trackplan.planning.plan import plan
from trackplan.status import Status


def _violation(limit: str, joint: int | None = None) -> Violation:
    return Violation(
        limit=limit, joint=joint, t_first=0.1, t_last=0.2, worst=2.0, bound=1.0, message=limit
    )


def _report(*violations: Violation, success: bool | None = None, **extra) -> CheckReport:
    return CheckReport(
        success=not violations if success is None else success,
        joint_margins={"velocity": np.array([0.5, -1.0 if violations else 0.2])},
        task_margins={},
        violations=violations,
        max_tracking_error=0.0,
        max_orientation_error=0.0,
        **extra,
    )


@pytest.mark.parametrize(
    ("limits", "status"),
    [
        ((), Status.FEASIBLE),
        (("jerk",), Status.LIMITS_VIOLATED),
        (("tracking", "speed"), Status.LIMITS_VIOLATED),
        (("collision",), Status.COLLISION),
        (("clearance", "collision"), Status.COLLISION),
        (("clearance", "torque"), Status.LIMITS_VIOLATED),  # a limit broken comes first
    ],
)
def test_status_follows_the_violations(limits: tuple[str, ...], status: Status) -> None:
    found = tuple(_violation(limit) for limit in limits)
    report = _report(*found)
    assert report.status is status is violations_status(found)
    assert report.success is status.success


def test_each_violation_carries_its_status() -> None:
    assert _violation("jerk", 3).status is Status.LIMITS_VIOLATED
    assert _violation("clearance").status is Status.COLLISION


def test_a_report_of_no_trajectory_says_why() -> None:
    """Nothing checked (no trajectory): the status is the reason given, not FEASIBLE."""
    assert _report(success=False).status is Status.UNREACHABLE
    report = _report(success=False, unchecked=Status.BRANCH_SWITCH)
    assert report.status is Status.BRANCH_SWITCH and not report.status.success


def test_cell_report_status() -> None:
    def cell(*found: Violation) -> CellReport:
        return CellReport(
            min_clearance=0.0,
            closest=("link 2", "ball"),
            t_closest=0.1,
            point=10,
            clearance=0.01,
            margin=-1.0 if found else 0.5,
            distance=np.zeros(3),
            violations=found,
        )

    assert cell().status is Status.FEASIBLE
    assert cell(_violation("collision")).status is Status.COLLISION


def test_result_module_re_exports_the_moved_classes() -> None:
    from trackplan.planning import result

    assert result.CheckReport is CheckReport and result.Violation is Violation
    assert result.CellReport is CellReport


def test_a_plan_and_its_check_say_the_same(corner_plan) -> None:
    assert corner_plan.check.status is corner_plan.status is Status.FEASIBLE


def test_an_infeasible_plan_and_its_check_say_the_same() -> None:
    """The paper's line in paper timing breaks the acceleration and jerk limits
    (docs/paper.md): the plan, its check and each violation say LIMITS_VIOLATED."""
    case = load_case(CASES / "paper-line.yaml")
    X = np.array([-0.2230, 0.1029, 0.1829, 0.0312, -0.4124, 0.5020])
    planned = plan(case, X, timing="paper")
    assert planned.status is planned.check.status is Status.LIMITS_VIOLATED
    assert planned.check.violations
    assert {v.status for v in planned.check.violations} == {Status.LIMITS_VIOLATED}


def test_a_plan_without_trajectory_carries_its_status_into_its_check():
    case = load_case(CASES / "paper-corner.yaml")
    # joints held within ±0.05 rad: every IK branch leaves the range (not "unreachable")
    narrow = dataclasses.replace(case.robot, q_min=np.full(6, -0.05), q_max=np.full(6, 0.05))
    planned = plan(dataclasses.replace(case, robot=narrow), case.bounds.example)
    assert not planned.trajectory.n_samples
    assert planned.check.status is planned.status is Status.POSITION_LIMITS
