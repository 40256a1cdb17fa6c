"""The seam stage of :func:`trackplan.planning.plan.plan`: one seam planned at one placement.

``seam case → path geometry → joint path (poses and IK, once) → time law → trajectory →
checks``. The time law is looked up by name (:data:`trackplan.timing.TIME_LAWS`); nothing
here depends on which law runs.
"""

from __future__ import annotations

import math
from dataclasses import replace
from typing import TYPE_CHECKING

import numpy as np

from trackplan.axes.choose import AxesFailure, choose_axes
from trackplan.axes.profile import AxesProfile
from trackplan.case import Case
from trackplan.derived import derived
from trackplan.errors import CaseError
from trackplan.frames import as_placement, placement_transform, vector_norms
from trackplan.jointpath import JointPath, placed_tool_poses
from trackplan.motion import JointSamples
from trackplan.paths.path_geometry import PathGeometry, PathMode
from trackplan.paths.screening_grid import screening_grid
from trackplan.planning.checker import TrackingReference, check_motion
from trackplan.planning.energy import motion_energy
from trackplan.planning.objectives import joint_travel
from trackplan.planning.result import CheckReport, PlanResult, Trajectory
from trackplan.planning.tool_zones import transition_zones
from trackplan.profiles import Profile
from trackplan.redundancy import choose_redundancy
from trackplan.robots.families import ik_family
from trackplan.robots.machine import Machine, arm_of, machine_of
from trackplan.robots.model import Robot
from trackplan.status import Status
from trackplan.task import Task
from trackplan.timing import TimedPath, TimeLaw, time_law
from trackplan.tool import (
    SpinMode,
    SpinProfile,
    ToolOrientation,
    ToolSpec,
    tool_axis_twist,
)
from trackplan.tool.weave import WeaveReached, WeaveTrack, WovenPath, weave_reached

if TYPE_CHECKING:  # the cell's compiled screening only for cases with a cell
    from trackplan.cell.screening import CellGeometry

CELL_KINDS = ("collision", "clearance")
"""Violation kinds of the cell check."""


def case_geometry(case: Case, mode: PathMode = "g2") -> PathGeometry:
    """The case's paths in a path mode (:meth:`PathGeometry.from_case`), built once per case.

    The case is immutable: every plan of it shares one geometry (and the planning grid
    cached on it).
    """
    return derived(case, ("paths", mode), lambda: PathGeometry.from_case(case, mode))


def _transition_zones(spec: ToolSpec, geometry: PathGeometry, tolerance: float) -> np.ndarray:
    """:func:`~trackplan.planning.tool_zones.transition_zones`, computed once per geometry,
    tool spec and tolerance (read-only)."""

    def build() -> tuple[ToolSpec, np.ndarray]:
        zones = transition_zones(spec, geometry, tolerance)
        zones.flags.writeable = False
        return spec, zones  # the spec kept alive with its zones: its id stays its own

    # the spec by identity (a frozen ToolSpec compares its arrays), the tolerance by value
    return derived(geometry, ("tool zones", id(spec), tolerance), build)[1]


def tracking_reference(case: Case, geometry: PathGeometry, X: np.ndarray) -> TrackingReference:
    """What the checker holds a trajectory of this case at placement X to."""
    return TrackingReference(
        nominal=geometry.nominal,
        T_base_part=placement_transform(as_placement(X)),
        tool=case.task.tool,
        tolerance=case.task.tolerance,
        rated_speed=case.task.rated_speed,
        corner_speed=case.task.corner_speed,
        corner_intervals=geometry.corner_intervals(),
        tool_zones=_transition_zones(case.task.tool, geometry, case.task.tolerance),
        downhand=case.downhand,
        weave=woven_path(case.task.tool, geometry),
    )


def woven_path(spec: ToolSpec, geometry: PathGeometry) -> WovenPath | None:
    """The geometry's weave (``task.weave``) over its planned path, or None; built once per
    geometry and tool spec."""
    weave = geometry.weave
    if not isinstance(weave, WeaveTrack):
        return None
    return derived(
        geometry,
        ("woven path", id(spec)),
        lambda: WovenPath(weave, geometry.planned, ToolOrientation.choose(spec, geometry)),
    )


def make_trajectory(
    robot: Robot | Machine,
    q: np.ndarray,
    s: np.ndarray,
    sample_time: float,
    spin: np.ndarray | None = None,
) -> Trajectory:
    """Sampled trajectory with derivatives exactly as the checker computes them.

    Parameters
    ----------
    robot
        The robot (for the tool point by FK).
    q
        Joint positions, shape (N, n), rad.
    s
        Arc length on the planned path per sample, shape (N,), m.
    sample_time
        Ts, s.
    spin
        Spin about the tool axis per sample, shape (N,), rad; default 0.
    """
    return motion_trajectory(JointSamples(robot, q, sample_time), s, spin)


def motion_trajectory(
    motion: JointSamples, s: np.ndarray, spin: np.ndarray | None = None
) -> Trajectory:
    """:func:`make_trajectory` reading the derivatives and tool poses of a
    :class:`~trackplan.motion.JointSamples` (shared with the checker).

    Parameters
    ----------
    motion
        Joint samples at Ts, shape (N, n), rad, and the robot.
    s
        Arc length on the planned path per sample, shape (N,), m.
    spin
        Spin about the tool axis per sample, shape (N,), rad; default 0.
    """
    q, sample_time, n = motion.q, motion.sample_time, motion.n_samples
    position = motion.T_base_tool[:, :3, 3]  # relative to the part's carrier
    step = np.empty(position.shape)  # np.diff(position, axis=0, prepend=position[:1])
    np.subtract(position[:1], position[:1], out=step[:1])
    np.subtract(position[1:], position[:-1], out=step[1:])
    speed = vector_norms(step) / sample_time
    if isinstance(motion.robot, Machine):  # the tool point in the cell frame
        position = motion.robot.T_cell_tool(q)[:, :3, 3]
    return Trajectory(
        sample_time=sample_time,
        t=np.arange(n) * sample_time,
        s=s,
        q=q,
        qd=motion.qd[:n],
        qdd=motion.qdd[:n],
        qddd=motion.qddd[:n],
        tool_position=position,
        speed=speed,
        spin=np.zeros(n) if spin is None else np.asarray(spin, dtype=float),
    )


def plan_seam(
    case: Case,
    X: np.ndarray,
    *,
    timing: str | None = None,
    branch: int | None = None,
    geometry: PathGeometry | None = None,
    spin: np.ndarray | SpinProfile | None = None,
) -> PlanResult:
    """Plan the one path of a single-seam case at placement X and check it.

    Parameters
    ----------
    case
        A single-seam case (its ``start``, ``segments`` and ``task``).
    X
        Placement (x, y, z, roll, pitch, yaw), shape (6,), metres and radians.
    timing
        A time law of :data:`trackplan.timing.TIME_LAWS` (``smooth`` or ``paper``);
        default: the case's ``task.timing``.
    branch
        Force an IK branch; default: the one with the largest joint-limit margin.
    geometry
        The case's paths when already built in the law's path mode.
    spin
        Spin variables of the case's tool spec, shape (n_spin,) (:meth:`ToolSpec.profile`),
        or a given :class:`~trackplan.tool.SpinProfile`; default: the middle of the spin
        range.

    Returns
    -------
    PlanResult
        Feasible or not, with the trajectory (empty when the path is unreachable) and the
        checker's report (the case's cell included); no cycle fields.

    Raises
    ------
    CaseError
        When X is not 6 finite numbers or the timing names no law.
    """
    X = as_placement(X)
    check_task_values(case.task)
    law = time_law(timing or case.task.timing)
    if geometry is None or geometry.mode != law.path_mode:
        geometry = case_geometry(case, law.path_mode)
    tool = ToolOrientation.choose(case.task.tool, geometry, spin)
    machine = case.machine
    axes = None
    failure = None
    if isinstance(machine, Machine) or case.downhand is not None:
        # the external axes' motion, and whether the weld can be held downhand at all
        chosen = choose_axes(machine_of(machine), geometry, case.task.tool, X, case.downhand)
        if isinstance(chosen, AxesFailure):  # planned with the axes held, to show it
            failure = chosen
            chosen = choose_axes(machine_of(machine), geometry, case.task.tool, X, None)
            assert isinstance(chosen, AxesProfile)
        axes = chosen if isinstance(machine, Machine) else None
    redundancy = None
    if ik_family(arm_of(machine)).redundancy is not None:
        redundancy, branch = choose_seam_redundancy(case, geometry, X, tool, axes, branch)
    joint_path = JointPath.solve(machine, geometry, X, tool, branch, axes, redundancy)
    if failure is not None:
        planned = _planned(case, joint_path, law, geometry)
        return replace(planned, success=False, status=failure.status, message=failure.message)
    return _planned(case, joint_path, law, geometry)


def choose_seam_redundancy(
    case: Case,
    geometry: PathGeometry,
    X: np.ndarray,
    tool: ToolOrientation,
    axes: AxesProfile | None,
    branch: int | None,
) -> tuple[Profile, int]:
    """A redundant arm's free parameter along a seam at placement X, and the branch.

    Chosen on the seam's screening grid as the placement search chooses it
    (:func:`~trackplan.redundancy.choose_redundancy`), for the case's steering
    (``task.redundancy``) and travel weights. Without a given branch, the branch whose
    path is usable with the largest margin (else the one whose first problem comes
    latest), as :func:`~trackplan.robots.path_ik.solve_path_ik` chooses one.

    Returns
    -------
    tuple
        The profile (rad over the seam's arc length) and the branch.

    Raises
    ------
    CaseError
        When the branch given is none of the family's.
    """
    arm = arm_of(case.machine)
    s = screening_grid(geometry)
    poses = placed_tool_poses(case.machine, geometry, X, tool, axes, s)
    weights = case.travel_weights[: arm.n_dof]
    length = geometry.planned.length
    choice = choose_redundancy(arm, poses[None], s, length, case.task.redundancy, weights)
    paths = choice.paths
    if branch is None:
        order = np.lexsort(
            (
                -paths.margin[0],
                np.where(paths.success[0], 0, -paths.first_problem[0]),
                ~paths.success[0],
            )
        )
        column = int(order[0])
    else:
        if branch not in paths.branches:
            last = int(paths.branches[-1])
            raise CaseError(f"branch must be in 0…{last}, got {branch}", key="branch")
        column = int(np.flatnonzero(paths.branches == branch)[0])
    return choice.profile(0, column), int(paths.branches[column])


def _planned(case: Case, joint_path: JointPath, law: TimeLaw, geometry: PathGeometry) -> PlanResult:
    """The seam timed by ``law`` along its joint path, checked; or why it has no trajectory."""
    if not joint_path.success:
        message = joint_path.message + _twist_note(joint_path)
        return _unplanned(case, joint_path, law.timing, joint_path.status, message)
    timed = law.plan(joint_path, case.task)
    if not timed.s.size:
        return _unplanned(case, joint_path, law.timing, timed.status, timed.message)
    return _checked(case, joint_path, timed)


def check_task_values(task: Task, key: str = "task") -> None:
    """Refuse a task no time law can run (a Task built in code; the case loader checks
    files the same way): speeds, tolerance and sample time must be finite and > 0.

    Raises
    ------
    CaseError
        Naming the value, e.g. ``task.rated_speed: must be a finite number > 0 (m/s),
        got 0.0``.
    """
    for name, unit in (
        ("rated_speed", "m/s"),
        ("corner_speed", "m/s"),
        ("tolerance", "m"),
        ("sample_time", "s"),
    ):
        value = getattr(task, name)
        if not (
            isinstance(value, int | float | np.floating) and math.isfinite(value) and value > 0
        ):
            raise CaseError(
                f"must be a finite number > 0 ({unit}), got {value!r}", key=f"{key}.{name}"
            )


def _twist_note(joint_path: JointPath) -> str:
    """Why a fixed spin may run a joint out of range: the turn of the tool about its axis."""
    tool = joint_path.tool
    if tool.spec.spin is not SpinMode.FIXED:
        return ""
    twist = tool_axis_twist(joint_path.R_part_tool(np.unique(joint_path.s)))
    turn = float(twist[-1])
    if abs(turn) < np.pi:
        return ""
    return (
        f"; with spin: fixed the tool turns {turn:.3f} rad ({turn / (2 * np.pi):.2f} turns) "
        "about its own axis along the path, and the wrist must follow; spin: free-varying "
        "lets the spin counter-rotate"
    )


def _unplanned(
    case: Case, joint_path: JointPath, timing: str, status: Status, message: str
) -> PlanResult:
    """The result of a placement that has no trajectory."""
    n_dof = case.machine.n_dof
    trajectory = Trajectory.empty(n_dof, case.task.sample_time)
    check = CheckReport.of_nothing(status)
    return PlanResult(
        case_name=case.name,
        placement=joint_path.placement,
        success=False,
        status=status,
        message=message,
        timing=timing,
        branch=joint_path.branch,
        trajectory=trajectory,
        check=check,
        objective=float("nan"),
        duration=float("nan"),
        path_length=joint_path.geometry.nominal.length,
        rated_speed_fraction=0.0,
        min_corner_speed=0.0,
        slowdowns=(),
        references={},
        joint_path=joint_path,
    )


def _checked(case: Case, joint_path: JointPath, timed: TimedPath) -> PlanResult:
    """Check the sampled trajectory and assemble the result."""
    geometry = joint_path.geometry
    spin = joint_path.tool.spin.value(timed.s)
    motion = timed.motion
    if motion is None or motion.q is not timed.q or motion.robot is not case.machine:
        motion = JointSamples(case.machine, timed.q, timed.sample_time)
    trajectory = motion_trajectory(motion, timed.s, spin)
    check = check_motion(
        motion, tracking_reference(case, geometry, joint_path.placement), cell_geometry(case)
    )
    if not check.success:
        status = Status.LIMITS_VIOLATED
        if all(v.limit in CELL_KINDS for v in check.violations):
            status = Status.COLLISION
        message = check.violations[0].message
    elif not timed.success:
        status, message = timed.status, timed.message
    else:
        status, message = Status.FEASIBLE, "feasible: every limit met"
    fraction, corner_speed = _speed_summary(case, geometry, trajectory, timed)
    return PlanResult(
        case_name=case.name,
        placement=joint_path.placement,
        success=status is Status.FEASIBLE,
        status=status,
        message=message,
        timing=timed.timing,
        branch=joint_path.branch,
        trajectory=trajectory,
        check=check,
        objective=float(joint_travel(timed.q, case.travel_weights)),
        duration=trajectory.duration,
        path_length=geometry.nominal.length,
        rated_speed_fraction=fraction,
        min_corner_speed=corner_speed,
        slowdowns=timed.slowdowns,
        references={},
        joint_path=joint_path,
        energy=None if motion.torque is None else motion_energy(motion),
        weave=_weave_reached(case, geometry, joint_path, motion),
    )


def _weave_reached(
    case: Case, geometry: PathGeometry, joint_path: JointPath, motion: JointSamples
) -> WeaveReached | None:
    """The weave the samples reached (:func:`trackplan.tool.weave.weave_reached`), or None."""
    woven = woven_path(case.task.tool, geometry)
    if woven is None or not len(motion.q):
        return None
    T_part_tool = np.linalg.inv(joint_path.T_base_part) @ motion.T_base_tool
    return weave_reached(
        woven,
        T_part_tool[:, :3, 3],
        T_part_tool[:, :3, :3],
        motion.sample_time,
        case.task.rated_speed,
    )


def _speed_summary(
    case: Case, geometry: PathGeometry, trajectory: Trajectory, timed: TimedPath
) -> tuple[float, float]:
    """Share of the path run at the rated speed, and the lowest corner speed.

    The rated share is measured on the samples (path speed ``Δs / Ts``), so it holds for
    every law; the corner speed is the law's own figure where it gives one, else the lowest
    sampled path speed on arcs and blends.
    """
    rated = case.task.rated_speed
    ds = np.diff(trajectory.s)
    path_speed = ds / trajectory.sample_time
    at_rated = np.abs(path_speed - rated) <= 1e-4 * rated  # paper mode: projection noise
    fraction = float(ds[at_rated].sum() / geometry.planned.length)
    if np.isfinite(timed.corner_speed):
        return fraction, timed.corner_speed
    curved = geometry.on_curved_zone(0.5 * (trajectory.s[1:] + trajectory.s[:-1]))
    corner = float(path_speed[curved].min()) if curved.any() else rated
    return fraction, corner


def cell_geometry(case: Case) -> CellGeometry | None:
    """The case's cell laid out for its robot, or None without a cell."""
    if case.cell is None:
        return None
    from trackplan.cell.screening import CellGeometry

    return CellGeometry.from_cell(case.cell, case.machine)
