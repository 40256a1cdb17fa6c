"""The joint form of a program: the verified joint trajectory replayed, every k-th sample
(``docs/export.md``).

Each timed joint move ends on a sample: every k-th from the first and always the last,
its duration the time since the sample before, its speed the share of the rated joint
rates it reaches. Moves stop (zone 0) where the plan rests (the end of every span); between,
the blend radius lets the controller run through the sample: in a seam, at most what the
seam's tolerance budget leaves after the TCP's largest distance from the chords between
the written samples; on moves between seams, half the shorter of the two TCP steps.
"""

from __future__ import annotations

import math

import numpy as np

from trackplan.case import Case
from trackplan.errors import CaseError
from trackplan.planning.result import SEAM, PlanResult
from trackplan.programs.external import rated_velocities
from trackplan.programs.model import JointMove, Move, Section
from trackplan.programs.targets import (
    MIN_SPEED_SHARE,
    START_SPEED,
    joint_move,
    seam_budget,
    zones_within,
)

PERIOD_TOLERANCE = 1e-9
"""How far (s) a period may be from a multiple of the sample time."""


def sample_step(period: float | None, sample_time: float) -> int:
    """How many samples one timed move spans.

    Parameters
    ----------
    period
        The asked time per move, s, or None for every sample.
    sample_time
        The trajectory's sample time, s.

    Raises
    ------
    CaseError
        When ``period`` is not a positive multiple of the sample time (within
        :data:`PERIOD_TOLERANCE`), key ``--period``.
    """
    if period is None:
        return 1
    k = round(period / sample_time) if math.isfinite(period) else 0
    if not (period > 0.0 and k >= 1 and abs(k * sample_time - period) <= PERIOD_TOLERANCE):
        raise CaseError(
            f"must be a positive multiple of the sample time {sample_time:g} s "
            f"(e.g. {sample_time:g} or {2 * sample_time:g}), got {period!r}",
            key="--period",
        )
    return k


def sample_indices(n_samples: int, step: int) -> np.ndarray:
    """Samples the program passes through: every ``step``-th from the first, and the last
    (shape (M,), increasing)."""
    index = np.arange(0, n_samples, step)
    if index[-1] != n_samples - 1:
        index = np.append(index, n_samples - 1)
    return index


def joint_sections(case: Case, plan: PlanResult, step: int) -> tuple[Section, ...]:
    """The sections of a joint-form program.

    Parameters
    ----------
    case
        The case of the run.
    plan
        The run's plan.
    step
        Samples per timed move (:func:`sample_step`).

    Returns
    -------
    tuple of Section
        ``start`` (an untimed joint move to the first sample), then one section per span
        of ``plan.spans`` holding the timed moves that end in it.
    """
    robot = case.robot
    trajectory = plan.trajectory
    q, qd, t = trajectory.q, trajectory.qd, trajectory.t
    index = sample_indices(trajectory.n_samples, step)
    zones = _zones(case, plan, index)
    n = robot.n_dof
    q_written = q[index]  # a copy: the moves' rows are their own
    theta = robot.convention.to_controller(q_written[:, :n])
    outside = q_written[:, n:]  # the external axes (none for an arm alone)
    # each move's peak joint rate share (external axes included) over the samples after
    # the one before it
    rates = np.max(np.abs(qd) / rated_velocities(case)[: qd.shape[1]], axis=1)
    peaks = np.maximum.reduceat(rates, index[:-1] + 1) if len(index) > 1 else np.zeros(0)
    shares = np.clip(np.concatenate([[0.0], peaks]), MIN_SPEED_SHARE, 1.0)
    durations = np.concatenate([[0.0], np.diff(t[index])])
    start = joint_move(robot, q[0], START_SPEED)
    sections = [Section(kind="start", label="start", moves=(start,))]
    for span in plan.spans:
        inside = np.flatnonzero((index > span.first) & (index <= span.last))
        moves: tuple[Move, ...] = tuple(
            JointMove(
                joints=theta[m],
                model_joints=q_written[m, :n],
                speed=float(shares[m]),
                duration=float(durations[m]),
                zone=float(zones[m]),
                external=outside[m],
            )
            for m in inside.tolist()
        )
        if moves:
            sections.append(Section(kind=span.kind, label=span.label, moves=moves))
    return tuple(sections)


def _zones(case: Case, plan: PlanResult, index: np.ndarray) -> np.ndarray:
    """Blend radius at each written sample, shape (M,), m (the first is unused)."""
    trajectory = plan.trajectory
    points = trajectory.tool_position
    n = trajectory.n_samples
    # each sample's chord: the written samples around it; its distance from that chord
    move = np.clip(np.searchsorted(index, np.arange(n), side="left"), 1, len(index) - 1)
    a, b = points[index[move - 1]], points[index[move]]
    chord = b - a
    length2 = np.maximum(np.sum(chord * chord, axis=1), 1e-300)
    along = np.clip(np.sum((points - a) * chord, axis=1) / length2, 0.0, 1.0)
    off = np.linalg.norm(points - a - along[:, None] * chord, axis=1)
    chord_error = np.zeros(len(index))
    np.maximum.at(chord_error, move, off)
    step = np.zeros(len(index))
    step[1:] = np.linalg.norm(np.diff(points[index], axis=0), axis=1)
    room = np.full(n, np.inf)  # each sample's tolerance budget (seams only)
    seams = iter(plan.seams)
    checks = iter(plan.seam_checks)
    for span in plan.spans:
        if span.kind == SEAM:
            seam = next(seams)
            tolerance, tracking = seam_budget(case, seam.index, next(checks, seam.plan.check))
            room[span.first : span.last + 1] = tolerance - tracking
    rest = np.zeros(n, dtype=bool)
    rest[[span.last for span in plan.spans] + [n - 1]] = True
    zones = np.zeros(len(index))
    if len(index) > 2:
        inner = index[1:-1]
        half = 0.5 * np.minimum(step[1:-1], step[2:])
        worst = np.maximum(chord_error[1:-1], chord_error[2:])
        allowed = np.minimum(half, room[inner] - worst)
        zones[1:-1] = np.where(rest[inner], 0.0, zones_within(allowed))
    return zones


__all__ = ["PERIOD_TOLERANCE", "joint_sections", "sample_indices", "sample_step"]
