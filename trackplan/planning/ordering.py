"""The sequence stage of :func:`trackplan.planning.plan.plan`: the order and directions of
the planned seams.

With ``sequence: optimize``, :func:`~trackplan.planning.sequence.best_sequence` runs on
costs from the planned seams and a fast estimate of every approach, retract and air move
(:func:`trackplan.timing.airmove.air_time_estimate`); with ``given``, the seams run as
written, forward (``docs/seams.md``).
"""

from __future__ import annotations

import numpy as np

from trackplan.case import Case
from trackplan.planning.result import PlanResult
from trackplan.planning.seams import SeamStage
from trackplan.planning.sequence import Sequence, best_sequence, given_sequence

UNPLANNED_COST = 1e12
"""Sequencing cost of a seam direction that could not be planned (never chosen)."""


def order_seams(case: Case, stage: SeamStage) -> Sequence:
    """The case's sequence of the planned seams: the best one (``optimize``) or as written
    (``given``)."""
    if case.sequencing.sequence == "optimize":
        return choose_sequence(case, stage.plans, stage.ends, case.sequencing.home)
    return given_sequence(len(case.seams))


def _move_cost(case: Case, q_from: np.ndarray, q_to: np.ndarray) -> np.ndarray:
    """Estimated cost of air moves, shape of the leading axes: seconds, or J + w·T."""
    robot = case.machine
    from trackplan.timing.airmove import air_time_estimate  # ruckig: only with moves

    time = air_time_estimate(q_from, q_to, robot.v_max, robot.a_max, robot.j_max)
    weight = case.objective.time_weight
    if weight == 0.0:
        return np.asarray(time)
    travel = np.sum(case.travel_weights * np.abs(np.asarray(q_to) - q_from), axis=-1)
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
    n = case.machine.n_dof
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


def choose_sequence(
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


__all__ = ["UNPLANNED_COST", "choose_sequence", "order_seams", "sequence_costs"]
