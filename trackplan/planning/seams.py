"""The seam stage of :func:`trackplan.planning.plan.plan`: every seam planned at X.

Each seam is planned by :func:`~trackplan.planning.seam_plan.plan_seam` on its own
single-seam case (:meth:`trackplan.case.Case.seam_case`), with every guarantee of a single
path; a reversed seam is the same path given end to start (:func:`reversed_segments`).
Each seam end gets an approach (or retract) configuration, the seam's end pose moved back
by ``approach`` metres along the tool axis, solved on the seam's own IK branch along that
straight line, so that the seam and its approach share a branch
(:func:`approach_configuration`).

A seam whose tool spin is ``free`` or ``free-varying`` is planned with its given spin
(:func:`seam_spin`): spin variables or a profile along the seam as written. A constant
spin is the same in both directions; a profile along s is reversed with the seam, so that
every point of the seam keeps its spin whichever way it is welded.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from trackplan.case import Case
from trackplan.errors import CaseError
from trackplan.paths.path_geometry import PathGeometry
from trackplan.paths.specs import ArcSpec, LineSpec, PointsSpec, SegmentSpec
from trackplan.planning.result import PlanResult
from trackplan.planning.seam_plan import plan_seam
from trackplan.planning.sequence import Sequence
from trackplan.robots.kinematics import forward_kinematics
from trackplan.robots.machine import Machine
from trackplan.robots.model import Robot
from trackplan.robots.path_ik import solve_path_ik
from trackplan.status import Status
from trackplan.timing import time_law
from trackplan.tool import SpinMode, SpinProfile
from trackplan.tool.weld_normal import PointsNormal

APPROACH_POSES = 21
"""Poses along the approach line on which its IK is solved (continuity on the seam's branch)."""
APPROACH_MATCH = 1e-6
"""Largest joint difference, rad, between the seam end and the approach line's IK there."""


def reversed_segments(
    start: np.ndarray, segments: tuple[SegmentSpec, ...]
) -> tuple[np.ndarray, tuple[SegmentSpec, ...]]:
    """The same path given end to start.

    Parameters
    ----------
    start
        First point, shape (3,), m.
    segments
        The segments in order.

    Returns
    -------
    tuple
        The new first point (the old last one), shape (3,), and the reversed segments:
        lines to the previous points, arcs about the same axis by the opposite angle,
        sampled curves through their points in reverse order.
    """
    points = [np.asarray(start, dtype=float)]
    for segment in segments:
        points.append(_segment_end(points[-1], segment))
    backwards: list[SegmentSpec] = []
    for k in range(len(segments) - 1, -1, -1):
        segment, begin = segments[k], points[k]
        if isinstance(segment, LineSpec):
            backwards.append(LineSpec(to=begin.copy()))
        elif isinstance(segment, ArcSpec):
            weld = segment.weld_normal
            if weld is not None:  # the normal at the arc's end
                weld = _rotated(np.asarray(weld, dtype=float), segment.normal, segment.angle)
            backwards.append(ArcSpec(segment.center, segment.normal, -segment.angle, weld))
        else:
            through = np.vstack([segment.points[-2::-1], begin[None]])
            if segment.normals is None:
                backwards.append(PointsSpec(points=through))
                continue
            normals = np.asarray(segment.normals, dtype=float)
            first = segment.start_normal
            if first is None:  # the normal the forward segment has at its start
                first = PointsNormal.from_points(begin, segment)(begin[None], np.zeros(1))[0]
            along = np.vstack([normals[-2::-1], np.asarray(first, dtype=float)[None]])
            backwards.append(PointsSpec(through, along, normals[-1].copy()))
    return points[-1].copy(), tuple(backwards)


def _segment_end(begin: np.ndarray, segment: SegmentSpec) -> np.ndarray:
    """End point of a segment starting at ``begin``, shape (3,), m."""
    if isinstance(segment, LineSpec):
        return np.asarray(segment.to, dtype=float)
    if isinstance(segment, PointsSpec):
        return np.asarray(segment.points[-1], dtype=float)
    return np.asarray(
        segment.center + _rotated(begin - segment.center, segment.normal, segment.angle),
        dtype=float,
    )


def _rotated(vector: np.ndarray, axis: np.ndarray, angle: float) -> np.ndarray:
    """``vector`` (3,) turned by ``angle`` (rad) about ``axis`` (3,, any length), (3,)."""
    axis = np.asarray(axis, dtype=float)
    axis = axis / np.linalg.norm(axis)
    c, s = np.cos(angle), np.sin(angle)
    turned = vector * c + np.cross(axis, vector) * s + axis * (axis @ vector) * (1.0 - c)
    return np.asarray(turned, dtype=float)


def seam_direction_case(case: Case, index: int, reverse: bool) -> Case:
    """The single-path case of seam ``index``, run forward or end to start."""
    seam_case = case.seam_case(index)
    if not reverse:
        return seam_case
    start, segments = reversed_segments(seam_case.start, seam_case.segments)
    return replace(seam_case, start=start, segments=segments)


SeamGeometries = dict[tuple[int, bool], PathGeometry]
"""Paths of each seam direction ``(seam index, reversed)`` for one time law's path mode."""


def seam_geometries(case: Case, timing: str | None = None) -> SeamGeometries:
    """Build the paths of every seam in both directions once (the search shares them).

    Parameters
    ----------
    case
        The case.
    timing
        The time law whose path mode to build; default the case's.
    """
    mode = time_law(timing or case.task.timing).path_mode
    return {
        (i, reverse): PathGeometry.from_case(seam_direction_case(case, i, reverse), mode)
        for i, seam in enumerate(case.seams)
        for reverse in ((False, True) if seam.reversible else (False,))
    }


SeamSpin = np.ndarray | SpinProfile | None
"""The spin of one seam: its tool's spin variables (n_spin,), a profile along the seam as
written, or None (the middle of the spin range)."""


def seam_spin(
    case: Case,
    index: int,
    reverse: bool,
    spin: SeamSpin,
    geometry: PathGeometry | None = None,
) -> SpinProfile | None:
    """The spin of seam ``index`` in one direction, for :func:`plan_seam`.

    Parameters
    ----------
    case
        The case.
    index
        The seam (as written).
    reverse
        Welded end to start.
    spin
        Spin variables of the seam's tool (n_spin,), rad (and rad/m steps for
        ``free-varying``, :meth:`trackplan.tool.ToolSpec.spin_coefficients`), or a profile
        over the seam as written, or None.
    geometry
        The seam's path in this direction, when built (its length lays out the profile).

    Returns
    -------
    SpinProfile or None
        The profile along the direction welded: reversed (``c(L − s)``, the coefficients
        in reverse order on the clamped uniform knots) for a reversed seam, unchanged
        otherwise; None for a fixed spin or no spin given.
    """
    tool = case.seams[index].task.tool
    if spin is None or tool.spin is SpinMode.FIXED:
        return None
    if isinstance(spin, SpinProfile):
        profile = spin
    else:
        if geometry is None:
            seam_case = seam_direction_case(case, index, reverse)
            mode = time_law(seam_case.task.timing).path_mode
            geometry = PathGeometry.from_case(seam_case, mode)
        profile = tool.profile(np.asarray(spin, dtype=float), geometry.planned.length)
    if not reverse:
        return profile
    return SpinProfile(np.asarray(profile.coefficients, dtype=float)[::-1].copy(), profile.length)


def approach_configuration(
    robot: Robot | Machine, q_end: np.ndarray, distance: float, branch: int
) -> tuple[np.ndarray | None, str]:
    """The configuration ``distance`` metres back along the tool axis from a seam end.

    The straight line from the seam end pose back along its tool axis (orientation kept)
    is solved on :data:`APPROACH_POSES` poses by the path IK on the seam's branch, and
    shifted by whole turns to start at ``q_end``: the seam and its approach share a branch
    and a winding.

    Parameters
    ----------
    robot
        The robot, or a machine (its external axes held where they are at the seam end).
    q_end
        The seam's first or last configuration, shape (n,), rad.
    distance
        Approach distance, m (0: ``q_end`` itself).
    branch
        The seam's IK branch.

    Returns
    -------
    tuple
        The configuration, shape (n,), rad (None when the line is not reachable
        continuously inside the limits on that branch), and a message saying why not.
    """
    q_end = np.asarray(q_end, dtype=float)
    if distance == 0.0:
        return q_end.copy(), ""
    if isinstance(robot, Machine):
        arm = robot.arm
        q_arm, why = approach_configuration(arm, q_end[: arm.n_dof], distance, branch)
        if q_arm is None:
            return None, why
        return np.concatenate([q_arm, q_end[arm.n_dof :]]), ""
    T_end = forward_kinematics(robot, q_end)
    back = np.linspace(0.0, distance, APPROACH_POSES)
    T_line = np.repeat(T_end[None], APPROACH_POSES, axis=0)
    T_line[:, :3, 3] -= back[:, None] * T_end[:3, 2]
    ik = solve_path_ik(robot, T_line[None], branch)
    line = ik.q[0] + 2.0 * np.pi * np.round((q_end - ik.q[0, 0]) / (2.0 * np.pi))
    continuous = bool(ik.reachable[0].all() and not ik.switch[0, 1:].any())
    inside = bool(np.all((line >= robot.q_min) & (line <= robot.q_max)))
    if continuous and inside and np.max(np.abs(line[0] - q_end)) < APPROACH_MATCH:
        return line[-1], ""
    where = "outside the joint limits" if continuous else "not reachable continuously"
    return None, f"the approach line of {distance:g} m along the tool axis is {where}"


def directions(case: Case, mode: str, sequence: Sequence | None) -> list[tuple[bool, ...]]:
    """The directions to plan each seam in (``reversed`` flags): both for a reversible seam
    whose direction is to be chosen, else the forced or written one."""
    if sequence is not None:
        forced = {visit.seam: visit.reversed for visit in sequence.visits}
        return [(forced[i],) for i in range(len(case.seams))]
    if mode == "optimize":
        return [(False, True) if seam.reversible else (False,) for seam in case.seams]
    return [(False,)] * len(case.seams)


def check_sequence(case: Case, sequence: Sequence) -> None:
    """A forced sequence visits every seam once, reversing only reversible ones."""
    seams = case.seams
    order = sorted(v.seam for v in sequence.visits)
    if order != list(range(len(seams))):
        raise CaseError(
            f"a sequence must visit each of the {len(seams)} seams once, got seams "
            f"{[v.seam for v in sequence.visits]}",
            key="sequence",
        )
    for visit in sequence.visits:
        if visit.reversed and not seams[visit.seam].reversible:
            raise CaseError(
                f"seam {seams[visit.seam].name} is not reversible (reversible: false)",
                key="sequence",
            )


Direction = tuple[int, bool]
"""A seam direction: ``(seam index as written, reversed)``."""


@dataclass(frozen=True, eq=False)
class SeamStage:
    """Every seam planned at one placement, in the directions that may be welded.

    Attributes
    ----------
    plans
        The usable plan of each direction (a direction that breaks a limit is kept only
        when no direction of its seam passes).
    ends
        The approach and retract configurations of each direction, shape (n,) each, rad.
    failed
        Seam name → the plan of a seam that no direction could be planned for (its first
        problem).
    """

    plans: dict[Direction, PlanResult]
    ends: dict[Direction, tuple[np.ndarray, np.ndarray]]
    failed: dict[str, PlanResult]


def plan_seams(
    case: Case,
    X: np.ndarray,
    ways: list[tuple[bool, ...]],
    *,
    timing: str | None,
    geometries: SeamGeometries | None,
    branches: tuple[int, ...] | None,
    spins: tuple[SeamSpin, ...] | None,
    spin: np.ndarray | SpinProfile | None,
    with_cell: bool,
) -> SeamStage:
    """Plan every seam of the case at X in the given directions, with its approach ends.

    Parameters
    ----------
    case
        The case.
    X
        Placement, shape (6,), metres and radians.
    ways
        Per seam (as written) the directions to plan (:func:`directions`).
    timing
        The time law; default each seam's task timing.
    geometries
        The seams' paths when already built for this law (:func:`seam_geometries`).
    branches
        The IK branch of each seam, or None for the largest joint-limit margin.
    spins
        The spin of each seam as written (:func:`seam_spin`), or None.
    spin
        One spin passed as given to the seam planner (a single seam), or None.
    with_cell
        Check each seam against the case's cell (when the seam is the whole trajectory);
        else the cell is checked on the joined trajectory.
    """
    approach = case.sequencing.approach
    plans: dict[Direction, PlanResult] = {}
    ends: dict[Direction, tuple[np.ndarray, np.ndarray]] = {}
    failed: dict[str, PlanResult] = {}
    for i, seam in enumerate(case.seams):
        usable: dict[bool, tuple[PlanResult, np.ndarray, np.ndarray]] = {}
        problems: list[PlanResult] = []
        for reverse in ways[i]:
            geometry = None if geometries is None else geometries.get((i, reverse))
            seam_case = seam_direction_case(case, i, reverse)
            if spin is not None:
                own_spin: np.ndarray | SpinProfile | None = spin
            else:
                own_spin = seam_spin(
                    case, i, reverse, None if spins is None else spins[i], geometry
                )
            plan = plan_seam(
                seam_case if with_cell else replace(seam_case, cell=None),
                X,
                timing=timing,
                branch=None if branches is None else branches[i],
                geometry=geometry,
                spin=own_spin,
            )
            if not plan.trajectory.n_samples:
                problems.append(plan)
                continue
            q = plan.trajectory.q
            q_in, why_in = approach_configuration(case.machine, q[0], approach, plan.branch)
            q_out, why_out = approach_configuration(case.machine, q[-1], approach, plan.branch)
            if q_in is None or q_out is None:
                problems.append(_without_trajectory(plan, why_in or why_out))
                continue
            usable[reverse] = (plan, q_in, q_out)
        if not usable:
            failed[seam.name] = problems[0]
            continue
        # a direction that breaks a limit is kept only when no direction passes
        passing = {d: u for d, u in usable.items() if u[0].success} or usable
        for reverse, (plan, q_in, q_out) in passing.items():
            plans[i, reverse] = plan
            ends[i, reverse] = (q_in, q_out)
    return SeamStage(plans=plans, ends=ends, failed=failed)


def _without_trajectory(plan: PlanResult, message: str) -> PlanResult:
    """A seam plan marked unusable (its approach cannot be reached)."""
    return replace(plan, success=False, status=Status.UNREACHABLE, message=message)


__all__ = [
    "Direction",
    "SeamGeometries",
    "SeamSpin",
    "SeamStage",
    "approach_configuration",
    "check_sequence",
    "directions",
    "plan_seams",
    "reversed_segments",
    "seam_direction_case",
    "seam_geometries",
    "seam_spin",
]
