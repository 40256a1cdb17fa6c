"""The one checker: every sample against every limit, with where and how much.

It serves the planner, the optimizer, the tests and ``trackplan check``. It never returns a
bare bool: a :class:`~trackplan.check_report.CheckReport` carries margins per limit and
joint, every violation with its time window and worst value, and the status they amount
to. The checks live in sibling modules: joint limits (:mod:`.check_joints`), the task
(:mod:`.check_task`, :mod:`.check_tool`), shared wording and slack
(:mod:`.check_violations`); the cell check in :mod:`trackplan.cell.check`.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from trackplan.check_report import CheckReport
from trackplan.motion import JointSamples
from trackplan.planning.check_joints import check_joint_limits
from trackplan.planning.check_reference import ORIENTATION_TOLERANCE, TrackingReference
from trackplan.planning.check_task import IK_POSITION_TOLERANCE, check_task, speed_slack
from trackplan.planning.check_violations import RELATIVE_SLACK, UNITS
from trackplan.robots.machine import Machine
from trackplan.robots.model import Robot

if TYPE_CHECKING:
    from trackplan.cell.screening import CellGeometry


def check_trajectory(
    robot: Robot | Machine,
    q: np.ndarray,
    sample_time: float,
    reference: TrackingReference | None = None,
    cell: CellGeometry | None = None,
) -> CheckReport:
    """Check a sampled joint trajectory against the robot's limits and the task.

    Derivatives are backward differences at Ts with the robot at rest before the first and
    after the last sample (docs/conventions.md), exactly what a controller consuming the
    samples sees. A robot with dynamics also has its torques checked, from the same q, q̇,
    q̈ (``docs/dynamics.md``).

    Parameters
    ----------
    robot
        The robot (limits and kinematics), or a machine (``q`` its whole joint vector).
    q
        Joint positions, shape (N, n), rad, one row per controller period.
    sample_time
        Ts, s.
    reference
        The task to check against (tracking, orientation, Cartesian speed, coverage);
        None checks joint limits only.
    cell
        The work cell laid out for the robot (:class:`trackplan.cell.screening.CellGeometry`):
        adds the clearance margin and collision violations (:mod:`trackplan.cell.check`);
        its workpiece is placed at ``reference.T_base_part`` (identity without a reference).

    Returns
    -------
    CheckReport
        Margins, violations and the worst tracking and orientation errors.
    """
    return check_motion(JointSamples(robot, q, sample_time), reference, cell)


def check_motion(
    motion: JointSamples,
    reference: TrackingReference | None = None,
    cell: CellGeometry | None = None,
) -> CheckReport:
    """:func:`check_trajectory` of sampled joints whose derivatives, torques and tool poses
    other readers share (:class:`~trackplan.motion.JointSamples`: each computed once).

    Parameters
    ----------
    motion
        The joint samples at Ts, shape (N, n), rad, and the robot.
    reference, cell
        As :func:`check_trajectory`.

    Returns
    -------
    CheckReport
    """
    q, sample_time = motion.q, motion.sample_time
    t = np.arange(len(q) + 3) * sample_time
    margins, binding, violations = check_joint_limits(motion, t)

    task_margins: dict[str, float] = {}
    downhand = None
    max_tracking = 0.0
    max_orientation = 0.0
    if reference is not None:
        task, max_tracking, max_orientation, downhand = check_task(motion, reference)
        task_margins, task_violations = task
        violations.extend(task_violations)

    cell_report = None
    if cell is not None:
        from trackplan.cell.check import check_cell

        T_base_part = reference.T_base_part if reference is not None else np.eye(4)
        cell_report = check_cell(cell, motion.robot, q, sample_time, T_base_part)
        task_margins["clearance"] = cell_report.margin
        violations.extend(cell_report.violations)

    return CheckReport(
        success=not violations,
        joint_margins=margins,
        task_margins=task_margins,
        violations=tuple(violations),
        max_tracking_error=max_tracking,
        max_orientation_error=max_orientation,
        binding=binding,
        cell=cell_report,
        downhand=downhand,
    )


__all__ = [
    "IK_POSITION_TOLERANCE",
    "ORIENTATION_TOLERANCE",
    "RELATIVE_SLACK",
    "UNITS",
    "TrackingReference",
    "check_motion",
    "check_trajectory",
    "speed_slack",
]
