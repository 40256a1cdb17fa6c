"""The assembly stage of :func:`trackplan.planning.plan.plan`: seams and moves joined into
one trajectory, then checked.

The moves between configurations (home → approach, approach → seam start, seam end →
retract, retract → next approach, last retract → home) are jerk-limited, time-optimal,
rest-to-rest joint moves (:func:`trackplan.timing.airmove.plan_air_move`, ruckig, slowed
down where a torque limit asks for it): the approach and retract are joint-space moves
between two configurations on the tool axis, not straight Cartesian lines; their largest
distance from the straight line is reported (:attr:`PlanResult.approach_deviation`). The
spans are joined rest to rest into one trajectory sampled at Ts, and the checker verifies
every sample's joint limits and, with a cell, clearance, and every seam's tracking,
orientation and speed on its own samples. Each seam keeps its own IK branch: the branch
may differ from seam to seam, the air moves connect them.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from trackplan.case import Case
from trackplan.frames import placement_transform
from trackplan.motion import JointSamples
from trackplan.planning.energy import motion_energy
from trackplan.planning.objectives import joint_travel
from trackplan.planning.result import (
    AIR,
    APPROACH,
    RETRACT,
    SEAM,
    CheckReport,
    PlanResult,
    SeamPlan,
    Span,
    Trajectory,
)
from trackplan.planning.seam_plan import CELL_KINDS, cell_geometry, motion_trajectory
from trackplan.planning.seams import SeamStage, approach_configuration
from trackplan.planning.sequence import Sequence, given_sequence
from trackplan.planning.trajectory_check import check_spans
from trackplan.status import Status
from trackplan.timing.sample_checks import robot_checks

VIA_LIFT = 0.1
"""How far beyond the retract pose, along the tool axis, the via of a colliding air move
lies, m."""


def join_seams(case: Case, X: np.ndarray, stage: SeamStage, sequence: Sequence) -> PlanResult:
    """Join the planned seams in the sequence's order with exact moves, then check.

    Without moves (one seam, no approach, no home) the plan is the seam's own, the cell
    checked with it. Else every move is planned (home → approach, approach → seam start,
    seam end → retract, retract → next approach, last retract → home) and the whole
    trajectory is checked (:func:`~trackplan.planning.trajectory_check.check_spans`).

    With a cell, an air move whose direct path breaks the clearance is planned again
    through a via configuration above the seam it leaves (the tool :data:`VIA_LIFT` beyond
    the retract pose along the tool axis: up, then across); its span records the via.
    """
    if not has_moves(case, sequence):
        return _one_seam(case, stage, sequence)
    # the moves' planner (ruckig) and the cell's exact check only where there are moves
    from trackplan.cell.check import check_cell
    from trackplan.timing.airmove import AirMove, plan_air_move

    plans, ends = stage.plans, stage.ends
    approach, home = case.sequencing.approach, case.sequencing.home
    geometries = {key: plans[key].joint_path.geometry for key in plans}
    robot = case.machine
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
        parts.append(_Part(SEAM, seams[i].name, welded.q, welded.s, spin, i, reverse, None))
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

    # spans meet at rest on a shared sample: keep it once
    q_all = [parts[0].q[:1]] + [part.q[1:] for part in parts]
    s_all = [parts[0].s[:1]] + [part.s[1:] for part in parts]
    spin_all = [parts[0].spin[:1]] + [part.spin[1:] for part in parts]
    labels = [parts[0].label]
    spans: list[Span] = []
    first = 0
    for part in parts:
        last = first + len(part.q) - 1
        labels += [part.label] * (last - first)
        spans.append(
            Span(
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
    motion = JointSamples(robot, q_cycle, sample_time)
    trajectory = motion_trajectory(motion, np.concatenate(s_all), np.concatenate(spin_all))
    seam_spans = [k for k, span in enumerate(spans) if span.kind == SEAM]
    known = {k: seam.plan.check for k, seam in zip(seam_spans, chosen, strict=True)}
    check, seam_checks = check_spans(
        case, X, trajectory.q, sample_time, spans, geometries, seam_reports=known
    )
    seam_time = sum((p.last - p.first) * sample_time for p in spans if p.kind == SEAM)
    status, message = _status(check)
    first_plan = chosen[0].plan
    lengths = np.array([seam.plan.path_length for seam in chosen])
    fractions = np.array([seam.plan.rated_speed_fraction for seam in chosen])
    return PlanResult(
        case_name=case.name,
        placement=X,
        success=status is Status.FEASIBLE,
        status=status,
        message=message,
        timing=first_plan.timing,
        branch=first_plan.branch,
        trajectory=trajectory,
        check=check,
        objective=float(joint_travel(q_cycle, case.travel_weights)),
        duration=trajectory.duration,
        path_length=float(lengths.sum()),
        rated_speed_fraction=float(fractions @ lengths / lengths.sum()),
        min_corner_speed=min(seam.plan.min_corner_speed for seam in chosen),
        slowdowns=tuple(d for seam in chosen for d in seam.plan.slowdowns),
        references={},
        joint_path=first_plan.joint_path,
        energy=None if robot.dynamics is None else motion_energy(motion),
        segment=np.asarray(labels, dtype=object),
        spans=tuple(spans),
        seams=tuple(chosen),
        sequence=sequence,
        seam_checks=seam_checks,
        seam_time=float(seam_time),
        air_time=float(trajectory.duration - seam_time),
        approach_deviation=_approach_deviation(trajectory.tool_position, spans),
        unplanned={},
    )


def has_moves(case: Case, sequence: Sequence) -> bool:
    """Whether the plan joins its seams with moves: several seams, an approach or a home."""
    sequencing = case.sequencing
    return len(sequence.visits) > 1 or sequencing.approach > 0.0 or sequencing.home is not None


def _one_seam(case: Case, stage: SeamStage, sequence: Sequence) -> PlanResult:
    """The plan of one seam without moves: the seam's own plan, with its one span."""
    visit = sequence.visits[0]
    plan = stage.plans[visit.seam, visit.reversed]
    q_in, q_out = stage.ends[visit.seam, visit.reversed]
    name = case.seams[visit.seam].name
    n = plan.trajectory.n_samples
    seam = SeamPlan(
        index=visit.seam,
        name=name,
        reversed=visit.reversed,
        plan=plan,
        q_approach=q_in,
        q_retract=q_out,
    )
    span = Span(
        kind=SEAM, label=name, first=0, last=n - 1, seam=visit.seam, reversed=visit.reversed
    )
    return replace(
        plan,
        case_name=case.name,
        segment=np.full(n, name),
        spans=(span,),
        seams=(seam,),
        sequence=sequence,
        seam_checks=(plan.check,),
        seam_time=plan.duration,
        air_time=0.0,
        approach_deviation=0.0,
        unplanned={},
    )


@dataclass(frozen=True, eq=False)
class _Part:
    """A span before joining: its samples (q (K, n), s (K,), spin (K,)) and labels."""

    kind: str
    label: str
    q: np.ndarray
    s: np.ndarray
    spin: np.ndarray
    seam: int | None
    reversed: bool
    via: np.ndarray | None


def _approach_deviation(position: np.ndarray, spans: list[Span]) -> float:
    """Largest distance of the tool point from the straight line of each approach or
    retract move, m."""
    worst = 0.0
    for span in spans:
        if span.kind not in (APPROACH, RETRACT):
            continue
        p = position[span.first : span.last + 1]
        a, b = p[0], p[-1]
        axis = b - a
        length = float(np.linalg.norm(axis))
        if length == 0.0:
            continue
        along = np.clip((p - a) @ axis / length**2, 0.0, 1.0)
        off = np.linalg.norm(p - a - along[:, None] * axis, axis=1)
        worst = max(worst, float(off.max()))
    return worst


def _status(check: CheckReport) -> tuple[Status, str]:
    if check.success:
        return Status.FEASIBLE, "feasible: every seam and every move meets every limit"
    kinds = {v.limit for v in check.violations}
    status = Status.COLLISION if kinds <= set(CELL_KINDS) else Status.LIMITS_VIOLATED
    return status, check.violations[0].message


def unplanned(case: Case, X: np.ndarray, failed: dict[str, PlanResult]) -> PlanResult:
    """The result of a placement where some seam cannot be planned: without moves, the
    seam's own failed plan; else an empty trajectory whose message names the seam."""
    name, plan = next(iter(failed.items()))
    if not has_moves(case, given_sequence(len(case.seams))):
        return replace(plan, case_name=case.name, unplanned=dict(failed))
    n = case.machine.n_dof
    trajectory = Trajectory.empty(n, case.task.sample_time)
    status = plan.status if plan.status is not Status.FEASIBLE else Status.UNREACHABLE
    check = CheckReport.of_nothing(status)
    return replace(
        plan,
        case_name=case.name,
        placement=X,
        success=False,
        status=status,
        message=f"seam {name}: {plan.message}",
        trajectory=trajectory,
        segment=np.zeros(0, dtype=object),
        spans=(),
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


__all__ = ["VIA_LIFT", "has_moves", "join_seams", "unplanned"]
