"""Plan a workpiece with several seams at one placement: the whole welding cycle.

``case → every seam planned at X (both directions when it may be reversed) → approach and
retract configurations → sequence → air moves → one trajectory → checks``.

Each seam is planned by :func:`trackplan.planning.plan.plan_placement` on its own
single-path case (:meth:`trackplan.case.Case.seam_case`), with every guarantee of a single
path; a reversed seam is the same path given end to start (:func:`reversed_segments`).
Each seam end gets an approach (or retract) configuration, the seam's end pose moved back
by ``approach`` metres along the tool axis, solved on the seam's own IK branch along that
straight line, so that the seam and its approach share a branch. The moves between
configurations (home → approach, approach → seam start, seam end → retract, retract →
next approach, last retract → home) are jerk-limited, time-optimal, rest-to-rest joint
moves (:func:`trackplan.timing.airmove.plan_air_move`, ruckig, slowed down where a torque
limit asks for it): the approach and retract
are joint-space moves between two configurations on the tool axis, not straight Cartesian
lines; their largest distance from the straight line is reported
(:attr:`CycleResult.approach_deviation`). The pieces are joined rest to rest into one
trajectory sampled at Ts, and the checker verifies every sample's joint limits and, with a
cell, clearance, and every seam's tracking, orientation and speed on its own samples.

The order and direction of the seams is chosen by :func:`trackplan.planning.sequence.best_sequence`
(``sequence: optimize``) on costs from the planned seams and a fast estimate of every air
move (:func:`trackplan.timing.airmove.air_time_estimate`); then the chosen sequence is
planned exactly. Each seam keeps its own IK branch (the one of its plan): the branch may
differ from seam to seam, the air moves connect them.

A seam whose tool spin is ``free`` or ``free-varying`` is planned with its given spin
(:func:`seam_spin`): spin variables or a profile along the seam as written. A constant
spin is the same in both directions; a profile along s is reversed with the seam, so that
every point of the seam keeps its spin whichever way it is welded.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from trackplan.case import Case
from trackplan.cell.check import check_cell
from trackplan.errors import CaseError
from trackplan.frames import as_placement, placement_transform
from trackplan.paths.nominal import NominalPath
from trackplan.paths.path_geometry import PathGeometry
from trackplan.paths.specs import ArcSpec, LineSpec, PointsSpec, SegmentSpec
from trackplan.planning.checker import check_trajectory
from trackplan.planning.objective import joint_travel
from trackplan.planning.plan import (
    cell_geometry,
    check_task_values,
    make_trajectory,
    plan_placement,
    tracking_reference,
)
from trackplan.planning.result import CheckReport, PlanResult, Trajectory, Violation
from trackplan.planning.sequence import Sequence, best_sequence, given_sequence
from trackplan.robots.kinematics import forward_kinematics
from trackplan.robots.model import Robot
from trackplan.robots.path_ik import solve_path_ik
from trackplan.status import Status
from trackplan.timing import time_law
from trackplan.timing.airmove import AirMove, air_time_estimate, plan_air_move
from trackplan.timing.sample_checks import robot_checks
from trackplan.tool import SpinMode, SpinProfile

APPROACH = "approach"
RETRACT = "retract"
AIR = "air"
MOVE_KINDS = (APPROACH, RETRACT, AIR)
"""Segment labels of the moves between seams (a seam's samples carry its name)."""

APPROACH_POSES = 21
"""Poses along the approach line on which its IK is solved (continuity on the seam's branch)."""
APPROACH_MATCH = 1e-6
"""Largest joint difference, rad, between the seam end and the approach line's IK there."""
VIA_LIFT = 0.1
"""How far beyond the retract pose, along the tool axis, the via of a colliding air move
lies, m."""
UNPLANNED_COST = 1e12
"""Sequencing cost of a seam direction that could not be planned (never chosen)."""


# --------------------------------------------------------------------------- results


@dataclass(frozen=True, eq=False, kw_only=True)
class Piece:
    """One piece of the cycle: a seam or a move between configurations.

    Attributes
    ----------
    kind
        ``seam``, ``approach``, ``retract`` or ``air``.
    label
        The ``segment`` value of its samples: the seam name, or the kind.
    first, last
        Indices of its first and last sample in the cycle trajectory (inclusive; a piece
        shares its first sample with the previous piece's last).
    seam
        Index of the seam (as written) for seam, approach and retract pieces, else None.
    reversed
        For a seam piece: run end to start.
    via
        The via configuration of an air move through one, shape (n,), rad, else None.
    """

    kind: str
    label: str
    first: int
    last: int
    seam: int | None = None
    reversed: bool = False
    via: np.ndarray | None = None


@dataclass(frozen=True, eq=False, kw_only=True)
class SeamPlan:
    """One seam as planned in the cycle.

    Attributes
    ----------
    index
        The seam's index as written.
    name
        Its name.
    reversed
        Welded end to start.
    plan
        Its single-path plan at the cycle's placement (trajectory from rest to rest).
    q_approach, q_retract
        Approach and retract configurations, shape (n,), rad.
    """

    index: int
    name: str
    reversed: bool
    plan: PlanResult
    q_approach: np.ndarray
    q_retract: np.ndarray


@dataclass(frozen=True, eq=False, kw_only=True)
class CycleResult:
    """A whole welding cycle planned at one placement.

    Attributes
    ----------
    case_name
        Name of the case.
    placement
        X, shape (6,), metres and radians.
    success
        True when every seam and every sample passed the checker.
    status, message
        :class:`~trackplan.status.Status` and one line (the first problem, naming the seam).
    timing
        The time law of the seams.
    trajectory
        The cycle, sampled at Ts from rest to rest; ``s`` is the arc length along the seam
        being welded (0 on moves). Empty when some seam could not be planned.
    segment
        Label of every sample, shape (N,), str: the seam's name, or ``approach``,
        ``retract``, ``air``. The sample two pieces share (at rest) carries the earlier
        piece's label.
    pieces
        The pieces in time order.
    seams
        The seams in the order welded (:class:`SeamPlan`).
    sequence
        The order and directions, and their estimated cost.
    check
        The checker's report on the whole cycle: joint limits and clearance at every
        sample, each seam's task checks (violation messages name the seam, times in the
        cycle).
    seam_checks
        Each seam's own check (tracking, orientation, speed, coverage) in welding order.
    objective
        J of Eq. 8 over the whole cycle.
    duration
        Cycle time, s.
    seam_time, air_time
        Time spent welding, and on approach, retract and air moves, s.
    approach_deviation
        Largest distance of the tool point from the tool axis line during approach and
        retract moves, m.
    unplanned
        Seam plans that failed (seam name → plan), when the cycle could not be assembled.
    """

    case_name: str
    placement: np.ndarray
    success: bool
    status: Status
    message: str
    timing: str
    trajectory: Trajectory
    segment: np.ndarray
    pieces: tuple[Piece, ...]
    seams: tuple[SeamPlan, ...]
    sequence: Sequence
    check: CheckReport
    seam_checks: tuple[CheckReport, ...]
    objective: float
    duration: float
    seam_time: float
    air_time: float
    approach_deviation: float
    unplanned: dict[str, PlanResult]

    @property
    def feasible(self) -> bool:
        """Alias of :attr:`success`."""
        return self.success


# --------------------------------------------------------------------------- seams


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
            backwards.append(ArcSpec(segment.center, segment.normal, -segment.angle))
        else:
            through = np.vstack([segment.points[-2::-1], begin[None]])
            backwards.append(PointsSpec(points=through))
    return points[-1].copy(), tuple(backwards)


def _segment_end(begin: np.ndarray, segment: SegmentSpec) -> np.ndarray:
    """End point of a segment starting at ``begin``, shape (3,), m."""
    if isinstance(segment, LineSpec):
        return np.asarray(segment.to, dtype=float)
    if isinstance(segment, PointsSpec):
        return np.asarray(segment.points[-1], dtype=float)
    axis = np.asarray(segment.normal, dtype=float)
    axis = axis / np.linalg.norm(axis)
    radius = begin - segment.center
    c, s = np.cos(segment.angle), np.sin(segment.angle)
    rotated = radius * c + np.cross(axis, radius) * s + axis * (axis @ radius) * (1.0 - c)
    return np.asarray(segment.center + rotated, dtype=float)


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
    """The spin of seam ``index`` in one direction, for :func:`plan_placement`.

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


# --------------------------------------------------------------------------- approach


def approach_configuration(
    robot: Robot, q_end: np.ndarray, distance: float, branch: int
) -> tuple[np.ndarray | None, str]:
    """The configuration ``distance`` metres back along the tool axis from a seam end.

    The straight line from the seam end pose back along its tool axis (orientation kept)
    is solved on :data:`APPROACH_POSES` poses by the path IK on the seam's branch, and
    shifted by whole turns to start at ``q_end``: the seam and its approach share a branch
    and a winding.

    Parameters
    ----------
    robot
        The robot.
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


# --------------------------------------------------------------------------- the cycle


def plan_cycle(
    case: Case,
    X: np.ndarray,
    *,
    timing: str | None = None,
    sequence: Sequence | None = None,
    geometries: SeamGeometries | None = None,
    branches: tuple[int, ...] | None = None,
    spins: tuple[SeamSpin, ...] | None = None,
) -> CycleResult:
    """Plan every seam of the case at placement X, sequence them and join them into one cycle.

    Parameters
    ----------
    case
        A case with several seams (``case.cycle``; a single-path case is one seam with
        no approach, welded as written).
    X
        Placement, shape (6,), metres and radians.
    timing
        A time law of :data:`trackplan.timing.TIME_LAWS`; default each seam's task timing.
    sequence
        Force this order and these directions; default the case's ``sequence`` setting
        (``optimize``: :func:`best_sequence`; ``given``: as written, forward).
    geometries
        The seams' paths when already built for this law (:func:`seam_geometries`).
    branches
        The IK branch of each seam (as written), both directions; default: per seam the
        one with the largest joint-limit margin.
    spins
        The spin of each seam (as written, :data:`SeamSpin`; see :func:`seam_spin`);
        default: each free spin in the middle of its range.

    Returns
    -------
    CycleResult

    Raises
    ------
    CaseError
        When X is not 6 finite numbers, a forced sequence names a seam twice or
        reverses a seam that may not be reversed, ``spins`` does not give one spin per
        seam, or a given spin leaves its tool's range or rate.
    """
    X = as_placement(X)
    cycle = case.cycle
    seams = case.seams
    for index, seam in enumerate(seams):
        check_task_values(seam.task, "task" if cycle is None else f"paths[{index}].task")
    m = len(seams)
    mode = "given" if cycle is None else cycle.sequence
    approach = 0.0 if cycle is None else cycle.approach
    home = None if cycle is None else cycle.home
    if sequence is not None:
        _check_sequence(case, sequence)
    directions = _directions(case, mode, sequence)
    if spins is not None and len(spins) != m:
        raise CaseError(f"give one spin per seam ({m}), got {len(spins)}", key="spin")
    plans: dict[tuple[int, bool], PlanResult] = {}
    ends: dict[tuple[int, bool], tuple[np.ndarray, np.ndarray]] = {}
    failed: dict[str, PlanResult] = {}
    for i, seam in enumerate(seams):
        usable: dict[bool, tuple[PlanResult, np.ndarray, np.ndarray]] = {}
        problems: list[PlanResult] = []
        for reverse in directions[i]:
            geometry = None if geometries is None else geometries.get((i, reverse))
            plan = plan_placement(
                replace(seam_direction_case(case, i, reverse), cell=None),
                X,
                timing=timing,
                branch=None if branches is None else branches[i],
                geometry=geometry,
                spin=seam_spin(case, i, reverse, None if spins is None else spins[i], geometry),
            )
            if not plan.trajectory.n_samples:
                problems.append(plan)
                continue
            q = plan.trajectory.q
            q_in, why_in = approach_configuration(case.robot, q[0], approach, plan.branch)
            q_out, why_out = approach_configuration(case.robot, q[-1], approach, plan.branch)
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
    law_name = next(iter(plans.values())).timing if plans else (timing or case.task.timing)
    if failed:
        return _unplanned_cycle(case, X, str(law_name), failed)
    if sequence is None:
        sequence = (
            _choose_sequence(case, plans, ends, home) if mode == "optimize" else given_sequence(m)
        )
    geometries = {key: plans[key].joint_path.geometry for key in plans}
    return _assemble(case, X, plans, ends, sequence, home, geometries, approach)


def _directions(case: Case, mode: str, sequence: Sequence | None) -> list[tuple[bool, ...]]:
    """The directions to plan each seam in (``reversed`` flags): both for a reversible seam
    whose direction is to be chosen, else the forced or written one."""
    if sequence is not None:
        forced = {visit.seam: visit.reversed for visit in sequence.visits}
        return [(forced[i],) for i in range(len(case.seams))]
    if mode == "optimize":
        return [(False, True) if seam.reversible else (False,) for seam in case.seams]
    return [(False,)] * len(case.seams)


def _check_sequence(case: Case, sequence: Sequence) -> None:
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


def _move_cost(case: Case, q_from: np.ndarray, q_to: np.ndarray) -> np.ndarray:
    """Estimated cost of air moves, shape of the leading axes: seconds, or J + w·T."""
    robot = case.robot
    time = air_time_estimate(q_from, q_to, robot.v_max, robot.a_max, robot.j_max)
    weight = case.objective.time_weight
    if weight == 0.0:
        return np.asarray(time)
    travel = np.sum(case.objective.weights * np.abs(np.asarray(q_to) - q_from), axis=-1)
    return np.asarray(travel + weight * time)


def sequence_costs(
    case: Case,
    plans: dict[tuple[int, bool], PlanResult],
    ends: dict[tuple[int, bool], tuple[np.ndarray, np.ndarray]],
    home: np.ndarray | None,
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Costs of :func:`best_sequence` from planned seams (see ``docs/seams.md``).

    The cost of a piece is its time in seconds when ``objective.time_weight`` is 0 (the
    sequence minimises cycle time), else ``J + time_weight · T`` (the search's objective).
    A seam's cost includes its approach and retract moves (estimated); a direction that
    was not planned costs infinity.

    Returns
    -------
    tuple of numpy.ndarray
        ``seam_cost`` (m, 2), ``air_cost`` (m, 2, m, 2), ``start_cost`` (m, 2),
        ``end_cost`` (m, 2) and ``reversible`` (m,).
    """
    m = len(case.seams)
    n = case.robot.n_dof
    weight = case.objective.time_weight
    seam_cost = np.full((m, 2), np.inf)
    q_in = np.zeros((m, 2, n))
    q_out = np.zeros((m, 2, n))
    for (i, reverse), plan in plans.items():
        d = int(reverse)
        q_in[i, d], q_out[i, d] = ends[i, reverse]
        q = plan.trajectory.q
        own = plan.duration if weight == 0.0 else plan.objective + weight * plan.duration
        seam_cost[i, d] = (
            own + _move_cost(case, q_in[i, d], q[0]) + _move_cost(case, q[-1], q_out[i, d])
        )
    air_cost = _move_cost(case, q_out[:, :, None, None, :], q_in[None, None, :, :, :])
    air_cost = np.where(np.isfinite(seam_cost)[None, None], air_cost, np.inf)
    if home is None:
        start_cost = np.zeros((m, 2))
        end_cost = np.zeros((m, 2))
    else:
        start_cost = _move_cost(case, home, q_in)
        end_cost = _move_cost(case, q_out, home)
    reversible = np.isfinite(seam_cost[:, 1])
    return seam_cost, air_cost, start_cost, end_cost, reversible


def _choose_sequence(
    case: Case,
    plans: dict[tuple[int, bool], PlanResult],
    ends: dict[tuple[int, bool], tuple[np.ndarray, np.ndarray]],
    home: np.ndarray | None,
) -> Sequence:
    """The best order and directions of the planned seams."""
    costs = sequence_costs(case, plans, ends, home)
    seam_cost, air_cost, start_cost, end_cost = (
        np.where(np.isfinite(c), c, UNPLANNED_COST) for c in costs[:4]
    )
    return best_sequence(seam_cost, air_cost, start_cost, end_cost, costs[4])


def _assemble(
    case: Case,
    X: np.ndarray,
    plans: dict[tuple[int, bool], PlanResult],
    ends: dict[tuple[int, bool], tuple[np.ndarray, np.ndarray]],
    sequence: Sequence,
    home: np.ndarray | None,
    geometries: SeamGeometries,
    approach: float,
) -> CycleResult:
    """Join the planned seams in the sequence's order with exact moves, then check.

    With a cell, an air move whose direct path breaks the clearance is planned again
    through a via configuration above the seam it leaves (the tool :data:`VIA_LIFT` beyond
    the retract pose along the tool axis: up, then across); its piece records the via.
    """
    robot = case.robot
    seams = case.seams
    sample_time = case.task.sample_time
    parts: list[_Part] = []
    checks = robot_checks(robot)  # the torque limits too, when the robot has dynamics

    cell = cell_geometry(case)
    T_base_part = placement_transform(X)

    def move(
        kind: str,
        q_from: np.ndarray,
        q_to: np.ndarray,
        seam: int | None,
        lift: tuple[np.ndarray, int] | None = None,
    ) -> None:
        air: AirMove = plan_air_move(
            q_from, q_to, robot.v_max, robot.a_max, robot.j_max, sample_time, checks=checks
        )
        if cell is not None and lift is not None:
            collides = check_cell(cell, robot, air.q, sample_time, T_base_part).violations
            via = approach_configuration(robot, lift[0], approach + VIA_LIFT, lift[1])[0]
            if collides and via is not None:
                air = plan_air_move(
                    q_from,
                    q_to,
                    robot.v_max,
                    robot.a_max,
                    robot.j_max,
                    sample_time,
                    via=via,
                    checks=checks,
                )
        rest = np.zeros(len(air.q))
        parts.append(_Part(kind, kind, air.q, rest, rest, seam, False, air.via))

    chosen: list[SeamPlan] = []
    q_here = home
    lift: tuple[np.ndarray, int] | None = None
    for visit in sequence.visits:
        i, reverse = visit.seam, visit.reversed
        plan = plans[i, reverse]
        q_in, q_out = ends[i, reverse]
        welded = plan.trajectory
        if q_here is not None:
            move(AIR, q_here, q_in, None, lift or (welded.q[0], plan.branch))
        move(APPROACH, q_in, welded.q[0], i)
        spin = welded.spin if len(welded.spin) == welded.n_samples else np.zeros(welded.n_samples)
        parts.append(_Part("seam", seams[i].name, welded.q, welded.s, spin, i, reverse, None))
        move(RETRACT, welded.q[-1], q_out, i)
        q_here = q_out
        lift = (welded.q[-1], plan.branch)
        chosen.append(
            SeamPlan(
                index=i,
                name=seams[i].name,
                reversed=reverse,
                plan=plan,
                q_approach=q_in,
                q_retract=q_out,
            )
        )
    if home is not None and q_here is not None:
        move(AIR, q_here, home, None, lift)

    # pieces meet at rest on a shared sample: keep it once
    q_all = [parts[0].q[:1]] + [part.q[1:] for part in parts]
    s_all = [parts[0].s[:1]] + [part.s[1:] for part in parts]
    spin_all = [parts[0].spin[:1]] + [part.spin[1:] for part in parts]
    labels = [parts[0].label]
    pieces: list[Piece] = []
    first = 0
    for part in parts:
        last = first + len(part.q) - 1
        labels += [part.label] * (last - first)
        pieces.append(
            Piece(
                kind=part.kind,
                label=part.label,
                first=first,
                last=last,
                seam=part.seam,
                reversed=part.reversed,
                via=part.via,
            )
        )
        first = last
    q_cycle = np.concatenate(q_all)
    trajectory = make_trajectory(
        robot, q_cycle, np.concatenate(s_all), sample_time, np.concatenate(spin_all)
    )
    segment = np.asarray(labels, dtype=object)
    seam_pieces = [k for k, piece in enumerate(pieces) if piece.kind == "seam"]
    known = {k: seam.plan.check for k, seam in zip(seam_pieces, chosen, strict=True)}
    check, seam_checks = check_cycle(
        case, X, trajectory.q, sample_time, pieces, geometries, seam_reports=known
    )
    seam_time = sum((p.last - p.first) * sample_time for p in pieces if p.kind == "seam")
    status, message = _cycle_status(check)
    return CycleResult(
        case_name=case.name,
        placement=X,
        success=status is Status.FEASIBLE,
        status=status,
        message=message,
        timing=chosen[0].plan.timing,
        trajectory=trajectory,
        segment=segment,
        pieces=tuple(pieces),
        seams=tuple(chosen),
        sequence=sequence,
        check=check,
        seam_checks=seam_checks,
        objective=float(joint_travel(q_cycle, case.objective.weights)),
        duration=trajectory.duration,
        seam_time=float(seam_time),
        air_time=float(trajectory.duration - seam_time),
        approach_deviation=_approach_deviation(trajectory.tool_position, pieces),
        unplanned={},
    )


@dataclass(frozen=True, eq=False)
class _Part:
    """A piece before joining: its samples (q (K, n), s (K,), spin (K,)) and labels."""

    kind: str
    label: str
    q: np.ndarray
    s: np.ndarray
    spin: np.ndarray
    seam: int | None
    reversed: bool
    via: np.ndarray | None


def _approach_deviation(position: np.ndarray, pieces: list[Piece]) -> float:
    """Largest distance of the tool point from the straight line of each approach or
    retract move, m."""
    worst = 0.0
    for piece in pieces:
        if piece.kind not in (APPROACH, RETRACT):
            continue
        p = position[piece.first : piece.last + 1]
        a, b = p[0], p[-1]
        axis = b - a
        length = float(np.linalg.norm(axis))
        if length == 0.0:
            continue
        along = np.clip((p - a) @ axis / length**2, 0.0, 1.0)
        off = np.linalg.norm(p - a - along[:, None] * axis, axis=1)
        worst = max(worst, float(off.max()))
    return worst


def check_cycle(
    case: Case,
    X: np.ndarray,
    q: np.ndarray,
    sample_time: float,
    pieces: list[Piece] | tuple[Piece, ...],
    geometries: SeamGeometries | None = None,
    seam_reports: dict[int, CheckReport] | None = None,
) -> tuple[CheckReport, tuple[CheckReport, ...]]:
    """Check a cycle trajectory: every sample's joint limits and clearance, every seam's task.

    Parameters
    ----------
    case
        The case.
    X
        Placement, shape (6,), metres and radians.
    q
        The whole cycle, shape (N, n), rad.
    sample_time
        Ts, s.
    pieces
        Where each seam lies in ``q`` (and in which direction).
    geometries
        The seams' paths when already built (:func:`seam_geometries`).
    seam_reports
        Each seam's own report by piece index, when already made on exactly its samples
        (a seam plan's check: the same call on the same samples).

    Returns
    -------
    tuple
        The whole report (joint limits and clearance of every sample, plus each seam's
        task violations, named and timed in the cycle) and each seam's own task report
        in the order of ``pieces``.
    """
    X = as_placement(X)
    q = np.asarray(q, dtype=float)
    whole = check_trajectory(case.robot, q, sample_time)
    cell = cell_geometry(case)
    cell_report = None
    violations = list(whole.violations)
    task_margins: dict[str, float] = {}
    if cell is not None:
        cell_report = check_cell(cell, case.robot, q, sample_time, placement_transform(X))
        violations += list(cell_report.violations)
        task_margins["clearance"] = cell_report.margin
    seam_checks: list[CheckReport] = []
    tracking = 0.0
    orientation = 0.0
    for k, piece in enumerate(pieces):
        if piece.kind != "seam" or piece.seam is None:
            continue
        known = (seam_reports or {}).get(k)
        if known is not None:
            own = known
        else:
            own = _seam_report(case, X, q, sample_time, piece, geometries)
        seam_checks.append(own)
        tracking = max(tracking, own.max_tracking_error)
        orientation = max(orientation, own.max_orientation_error)
        for kind, value in own.task_margins.items():
            task_margins[kind] = min(task_margins.get(kind, np.inf), value)
        offset = piece.first * sample_time
        violations += [
            replace(
                v,
                t_first=v.t_first + offset,
                t_last=v.t_last + offset,
                message=f"seam {piece.label}: {v.message} (seam time; it starts at "
                f"t = {offset:.3f} s)",
            )
            for v in own.violations
            if v.joint is None
        ]
    report = CheckReport(
        success=not violations,
        joint_margins=whole.joint_margins,
        task_margins=task_margins,
        violations=tuple(violations),
        max_tracking_error=tracking,
        max_orientation_error=orientation,
        binding=whole.binding,
        cell=cell_report,
    )
    return report, tuple(seam_checks)


def pieces_from_segments(
    case: Case, X: np.ndarray, q: np.ndarray, segment: np.ndarray
) -> tuple[Piece, ...]:
    """The pieces of a cycle trajectory from its ``segment`` labels (a trajectory.csv read
    back): runs of one label; a seam's direction is the one whose start lies nearer the
    tool point at the run's first sample (for a closed seam, the way the tool runs along it).

    Parameters
    ----------
    case
        The case.
    X
        Placement, shape (6,).
    q
        Joint positions, shape (N, n), rad.
    segment
        Label per sample, shape (N,), str.

    Raises
    ------
    CaseError
        When a label is neither a seam of the case nor a move kind.
    """
    names = [seam.name for seam in case.seams]
    labels = np.asarray(segment).astype(str)
    change = np.flatnonzero(labels[1:] != labels[:-1]) + 1
    starts = np.r_[0, change]
    ends = np.r_[change - 1, len(labels) - 1]
    T_base_part = placement_transform(as_placement(X))
    pieces = []
    for begin, end in zip(starts, ends, strict=True):
        label = str(labels[begin])
        first = max(int(begin) - 1, 0)  # the shared sample carries the earlier label
        if label in MOVE_KINDS:
            pieces.append(Piece(kind=label, label=label, first=first, last=int(end)))
            continue
        if label not in names:
            raise CaseError(
                f"segment {label!r} is neither a seam of the case ({', '.join(names)}) "
                f"nor one of {', '.join(MOVE_KINDS)}",
                key="segment",
            )
        i = names.index(label)
        seam = case.seams[i]
        tool = forward_kinematics(case.robot, q[first])[:3, 3]
        forward = T_base_part[:3, :3] @ seam.start + T_base_part[:3, 3]
        backward_start, _ = reversed_segments(seam.start, seam.segments)
        backward = T_base_part[:3, :3] @ backward_start + T_base_part[:3, 3]
        if np.linalg.norm(forward - backward) > seam.task.tolerance:
            reverse = bool(np.linalg.norm(tool - backward) < np.linalg.norm(tool - forward))
        else:  # a closed seam: the way it runs
            reverse = _runs_backwards(case, i, q[first : int(end) + 1], T_base_part)
        pieces.append(
            Piece(kind="seam", label=label, first=first, last=int(end), seam=i, reversed=reverse)
        )
    return tuple(pieces)


def _runs_backwards(case: Case, index: int, q: np.ndarray, T_base_part: np.ndarray) -> bool:
    """Whether the samples q (K, n) of a closed seam run it end to start: the tool's
    projections on the seam as written at a quarter and at half of the run go backwards."""
    seam = case.seams[index]
    quarter, half = len(q) // 4, len(q) // 2
    frames = forward_kinematics(case.robot, q[[quarter, half]])
    points = (frames[:, :3, 3] - T_base_part[:3, 3]) @ T_base_part[:3, :3]  # part frame
    s, _ = NominalPath.from_specs(seam.start, seam.segments).project(points)
    return bool(s[1] < s[0])


def check_cycle_trajectory(
    case: Case, X: np.ndarray, q: np.ndarray, sample_time: float, segment: np.ndarray
) -> CheckReport:
    """Check any cycle trajectory (``trackplan check`` of a run with several seams).

    Parameters
    ----------
    case
        The case.
    X
        Placement, shape (6,), metres and radians.
    q
        Joint positions, shape (N, n), rad.
    sample_time
        Ts, s.
    segment
        The ``segment`` label of every sample, shape (N,).

    Returns
    -------
    CheckReport
        As :func:`check_cycle`; a seam of the case that no sample welds is a ``coverage``
        violation.
    """
    q = np.asarray(q, dtype=float)
    pieces = pieces_from_segments(case, X, q, segment)
    report, _ = check_cycle(case, X, q, sample_time, pieces)
    welded = {piece.seam for piece in pieces if piece.kind == "seam"}
    missing = [seam.name for i, seam in enumerate(case.seams) if i not in welded]
    if not missing:
        return report
    skipped = tuple(
        Violation(
            limit="coverage",
            joint=None,
            t_first=0.0,
            t_last=0.0,
            worst=float("nan"),
            bound=0.0,
            message=f"seam {name} is not welded: no sample carries its name",
        )
        for name in missing
    )
    return replace(report, success=False, violations=report.violations + skipped)


def _seam_report(
    case: Case,
    X: np.ndarray,
    q: np.ndarray,
    sample_time: float,
    piece: Piece,
    geometries: SeamGeometries | None,
) -> CheckReport:
    """One seam's samples checked against its task (tracking, orientation, speed, coverage)."""
    assert piece.seam is not None
    seam_case = seam_direction_case(case, piece.seam, piece.reversed)
    geometry = (geometries or {}).get((piece.seam, piece.reversed))
    if geometry is None:
        geometry = PathGeometry.from_case(seam_case, time_law(seam_case.task.timing).path_mode)
    reference = tracking_reference(seam_case, geometry, X)
    return check_trajectory(case.robot, q[piece.first : piece.last + 1], sample_time, reference)


def _cycle_status(check: CheckReport) -> tuple[Status, str]:
    if check.success:
        return Status.FEASIBLE, "feasible: every seam and every move meets every limit"
    kinds = {v.limit for v in check.violations}
    status = Status.COLLISION if kinds <= {"collision", "clearance"} else Status.LIMITS_VIOLATED
    return status, check.violations[0].message


def _without_trajectory(plan: PlanResult, message: str) -> PlanResult:
    """A seam plan marked unusable for the cycle (its approach cannot be reached)."""
    return replace(plan, success=False, status=Status.UNREACHABLE, message=message)


def _unplanned_cycle(
    case: Case, X: np.ndarray, timing: str, failed: dict[str, PlanResult]
) -> CycleResult:
    """The result of a placement where some seam cannot be planned."""
    n = case.robot.n_dof
    trajectory = Trajectory.empty(n, case.task.sample_time)
    name, plan = next(iter(failed.items()))
    status = plan.status if plan.status is not Status.FEASIBLE else Status.UNREACHABLE
    check = CheckReport(
        success=False,
        joint_margins={},
        task_margins={},
        violations=(),
        max_tracking_error=float("nan"),
        max_orientation_error=float("nan"),
    )
    return CycleResult(
        case_name=case.name,
        placement=X,
        success=False,
        status=status,
        message=f"seam {name}: {plan.message}",
        timing=timing,
        trajectory=trajectory,
        segment=np.zeros(0, dtype=object),
        pieces=(),
        seams=(),
        sequence=Sequence(visits=(), cost=float("nan"), exact=False),
        check=check,
        seam_checks=(),
        objective=float("nan"),
        duration=float("nan"),
        seam_time=float("nan"),
        air_time=float("nan"),
        approach_deviation=float("nan"),
        unplanned=dict(failed),
    )


__all__ = [
    "AIR",
    "APPROACH",
    "RETRACT",
    "CycleResult",
    "Piece",
    "SeamPlan",
    "approach_configuration",
    "check_cycle",
    "check_cycle_trajectory",
    "pieces_from_segments",
    "plan_cycle",
    "reversed_segments",
    "seam_spin",
]
