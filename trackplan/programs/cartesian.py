"""The Cartesian form of a program: each seam in path moves, the moves between seams as
joint moves (``docs/export.md``).

A seam follows its planned (blended) path, piece by piece: a line is one linear move to
its end; an arc is a circular move through its mid point (an arc of more than
:data:`MAX_ARC_ANGLE` is split into equal arcs, since a via and an end on a half or full
circle define no unique circle); blends, and pieces too short to be moves of their own,
become one spline through points of the path whose polyline keeps within half the seam's
tolerance budget. The budget is the task tolerance minus the plan's own tracking error;
the blend radius between two moves is what the chord error leaves of it, and 0 where the
plan stops.
"""

from __future__ import annotations

import itertools
from dataclasses import dataclass

import numpy as np

from trackplan.case import Case
from trackplan.check_report import CheckReport
from trackplan.paths.planned import Path
from trackplan.planning.result import SEAM, PlanResult, SeamPlan, Span
from trackplan.programs.chords import spline_points
from trackplan.programs.external import interpolate_columns, rated_velocities
from trackplan.programs.model import (
    Budget,
    CircularMove,
    LinearMove,
    Move,
    Section,
    SplineMove,
)
from trackplan.programs.targets import (
    MIN_CHORD,
    MIN_TCP_SPEED,
    START_SPEED,
    joint_move,
    path_targets,
    seam_budget,
    speed_share,
    zone_within,
)
from trackplan.robots.model import Robot

MAX_ARC_ANGLE = 2.0 * np.pi / 3.0
"""Largest angle of one circular move, rad (120°): a longer arc is split into equal arcs."""

MIN_MOVE = 5e-4
"""A piece shorter than this (m) is no move of its own: it joins the spline of its
neighbours."""

_AT = 1e-9  # arc lengths closer than this (m) are the same point


@dataclass(frozen=True)
class _Stretch:
    """A stretch of the planned path written as one kind of move.

    ``kind`` is ``line``, ``arc`` or ``curve``; ``s0``, ``s1`` its ends, m; ``sagitta``
    the chord error of an arc written as a line, m.
    """

    kind: str
    s0: float
    s1: float
    angle: float = 0.0
    sagitta: float = 0.0


@dataclass(frozen=True)
class _MoveSpec:
    """A move before its targets: ``kind`` (line, arc, spline), the arc lengths of its
    targets (an arc: via then end), where it starts, its chord error."""

    kind: str
    s: np.ndarray
    s_start: float
    chord: float


def cartesian_sections(case: Case, plan: PlanResult) -> tuple[tuple[Section, ...], Budget]:
    """The sections of a Cartesian program and its worst tolerance budget.

    Parameters
    ----------
    case
        The case of the run.
    plan
        The run's plan (its spans, seams and trajectory).

    Returns
    -------
    sections
        ``start`` (a joint move to the planned first configuration), then one section per
        span of ``plan.spans``.
    budget
        The seam budget with the smallest slack.
    """
    robot = case.robot
    trajectory = plan.trajectory
    start = joint_move(robot, trajectory.q[0], START_SPEED)
    sections = [Section(kind="start", label="start", moves=(start,))]
    budgets: list[Budget] = []
    seams = iter(plan.seams)
    checks = iter(plan.seam_checks)
    for span in plan.spans:
        if span.kind == SEAM:
            seam = next(seams)
            check = next(checks, seam.plan.check)
            moves, budget = seam_moves(case, seam, check, _span_external(case, plan, span))
            budgets.append(budget)
        else:
            moves = span_joint_moves(robot, plan, span, rated_velocities(case))
        sections.append(Section(kind=span.kind, label=span.label, moves=moves))
    worst = min(budgets, key=lambda budget: budget.slack)
    return tuple(sections), worst


def _span_external(case: Case, plan: PlanResult, span: Span) -> np.ndarray | None:
    """The external axes over a seam's span of the trajectory, shape (K, e), or None for
    an arm alone."""
    n = case.robot.n_dof
    if plan.trajectory.q.shape[1] == n:
        return None
    return plan.trajectory.q[span.first : span.last + 1, n:]


def span_joint_moves(
    robot: Robot, plan: PlanResult, span: Span, v_max: np.ndarray | None = None
) -> tuple[Move, ...]:
    """An approach, retract or air span as joint moves to its end (through its via, when
    it has one), each at the span's peak joint rate share (of ``v_max``, every axis's
    rated velocity; default the arm's) and stopping at its end."""
    q = plan.trajectory.q
    qd = plan.trajectory.qd
    rated = np.asarray(robot.v_max if v_max is None else v_max, dtype=float)
    ends = [span.last]
    if span.via is not None:
        via = np.asarray(span.via, dtype=float)
        distance = np.linalg.norm(q[span.first : span.last + 1, : len(via)] - via, axis=1)
        ends.insert(0, span.first + int(np.argmin(distance)))
    moves: list[Move] = []
    before = span.first
    for end in ends:
        share = speed_share(rated[: qd.shape[1]], qd[before + 1 : end + 1])
        moves.append(joint_move(robot, q[end], share))
        before = end
    return tuple(moves)


def seam_moves(
    case: Case, seam: SeamPlan, check: CheckReport, external: np.ndarray | None = None
) -> tuple[tuple[Move, ...], Budget]:
    """The path moves of one seam and its tolerance budget.

    Parameters
    ----------
    case
        The case.
    seam
        The seam as planned (its own plan holds the planned path in the welding
        direction: a reversed seam's runs end to start).
    check
        The seam's check (its largest tracking error).
    external
        The external axes over the seam's span of the trajectory, shape (K, e), one row
        per sample of the seam's own trajectory, or None (an arm alone): each target
        carries them interpolated at its arc length.

    Returns
    -------
    moves
        Linear, circular and spline moves from the seam's start to its end.
    budget
        Tolerance, tracking error, chord error and largest zone of the seam.
    """
    robot = case.robot
    joint_path = seam.plan.joint_path
    path = joint_path.geometry.planned
    tolerance, tracking = seam_budget(case, seam.index, check)
    room = tolerance - tracking
    chord_limit = max(0.5 * room, MIN_CHORD)
    specs = [
        spec
        for stretch in _stretches(path, chord_limit)
        for spec in _specs(path, stretch, chord_limit)
    ]
    chord = max((spec.chord for spec in specs), default=0.0)
    zone = zone_within(room - chord)
    all_s = np.concatenate([spec.s for spec in specs])
    targets = path_targets(
        robot, joint_path, all_s, _external_at(seam, robot.n_dof, external, all_s)
    )
    speeds = _speeds(seam, specs)
    stops = np.asarray(path.stops, dtype=float)
    moves: list[Move] = []
    k = 0
    for n, (spec, speed) in enumerate(zip(specs, speeds, strict=True)):
        own = targets[k : k + len(spec.s)]
        k += len(spec.s)
        end = float(spec.s[-1])
        stops_here = n == len(specs) - 1 or bool(np.any(np.abs(stops - end) <= _AT))
        move_zone = 0.0 if stops_here else zone
        if spec.kind == "line":
            moves.append(LinearMove(target=own[0], speed=speed, zone=move_zone))
        elif spec.kind == "arc":
            moves.append(CircularMove(via=own[0], target=own[1], speed=speed, zone=move_zone))
        elif stops_here and len(own) > 1:
            # a spline written as blended linear moves blends between its points with its
            # zone: one that ends where the plan stops runs through its points before the
            # last with the seam's zone, then stops on the last
            moves.append(SplineMove(targets=tuple(own[:-1]), speed=speed, zone=zone))
            moves.append(SplineMove(targets=tuple(own[-1:]), speed=speed, zone=0.0))
        else:
            moves.append(SplineMove(targets=tuple(own), speed=speed, zone=move_zone))
    written_zone = max((float(move.zone) for move in moves), default=0.0)
    budget = Budget(
        tolerance=tolerance, tracking_error=tracking, chord_error=chord, zone=written_zone
    )
    return tuple(moves), budget


def _external_at(
    seam: SeamPlan, n_arm: int, external: np.ndarray | None, s: np.ndarray
) -> np.ndarray | None:
    """The external axes at arc lengths ``s`` (M,) of a seam, shape (M, e), or None.

    From the seam's own trajectory when it carries the external axes, else from its span
    of the run's trajectory (``external``), sample for sample."""
    if external is None:
        return None
    trajectory = seam.plan.trajectory
    columns = trajectory.q[:, n_arm:] if trajectory.q.shape[1] > n_arm else external
    if len(columns) != len(trajectory.s):
        raise ValueError(
            f"the seam's trajectory has {len(trajectory.s)} samples and its span "
            f"{len(columns)}: the external axes cannot be placed on its targets"
        )
    return interpolate_columns(trajectory.s, columns, s)


def _stretches(path: Path, chord_limit: float) -> list[_Stretch]:
    """The planned path cut into lines, arcs and curves (runs of blends and short pieces,
    never across a stop)."""
    stops = np.asarray(path.stops, dtype=float)
    out: list[_Stretch] = []
    for piece in path.pieces:
        s0, s1 = float(piece.s_start), float(piece.s_end)
        kind, angle, sagitta = "curve", 0.0, 0.0
        if piece.length >= MIN_MOVE and piece.kind == "line":
            kind = "line"
        elif piece.length >= MIN_MOVE and piece.kind == "arc":
            radius = float(piece.curve.radius)  # type: ignore[union-attr]
            angle = piece.length / radius
            sagitta = radius * (1.0 - np.cos(0.5 * angle))
            kind = "line" if sagitta <= chord_limit and angle < MAX_ARC_ANGLE else "arc"
            sagitta = sagitta if kind == "line" else 0.0
        joins = (
            kind == "curve"
            and out
            and out[-1].kind == "curve"
            and not np.any(np.abs(stops - s0) <= _AT)
        )
        if joins:
            out[-1] = _Stretch("curve", out[-1].s0, s1)
        else:
            out.append(_Stretch(kind, s0, s1, angle, sagitta))
    return out


def _specs(path: Path, stretch: _Stretch, chord_limit: float) -> list[_MoveSpec]:
    """The moves of one stretch, with the arc lengths of their targets."""
    s0, s1 = stretch.s0, stretch.s1
    if stretch.kind == "line":
        return [_MoveSpec("line", np.array([s1]), s0, stretch.sagitta)]
    if stretch.kind == "arc":
        n = max(1, int(np.ceil(stretch.angle / MAX_ARC_ANGLE - 1e-9)))
        edges = np.linspace(s0, s1, n + 1)
        return [
            _MoveSpec("arc", np.array([0.5 * (a + b), b]), float(a), 0.0)
            for a, b in itertools.pairwise(edges)
        ]
    s, error = spline_points(path, s0, s1, chord_limit)
    return [_MoveSpec("spline", s, s0, error)]


def _speeds(seam: SeamPlan, specs: list[_MoveSpec]) -> list[float]:
    """Each move's speed: the plan's highest TCP speed over its stretch of path, m/s."""
    trajectory = seam.plan.trajectory
    s, speed = trajectory.s, trajectory.speed
    out = []
    for spec in specs:
        a, b = spec.s_start, float(spec.s[-1])
        lo = int(np.searchsorted(s, a - _AT, side="left"))
        hi = int(np.searchsorted(s, b + _AT, side="right"))
        inside = speed[lo:hi]
        ends = np.interp([a, b], s, speed)
        peak = max(float(inside.max()) if len(inside) else 0.0, float(ends.max()))
        out.append(max(peak, MIN_TCP_SPEED))
    return out


__all__ = ["MAX_ARC_ANGLE", "MIN_MOVE", "cartesian_sections", "seam_moves", "span_joint_moves"]
