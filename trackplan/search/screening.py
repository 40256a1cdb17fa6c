"""The one fitness of a case: each seam's screening summed, plus the moves between seams.

A case is a set of seams (one seam is a set of one). :func:`evaluate_seams` screens every
seam of a batch of candidates with its own screener
(:class:`~trackplan.search.fitness.PlacementFitness`), sums the seams' objectives and
duration bounds, adds the estimated cost of the moves between them (``air``; zero for one
seam and no home), and, where the time law must run (paper timing, or a time weight),
plans every seam of the candidates that can still beat the incumbent. A candidate is
feasible only if every seam is; an infeasible one carries the worst seam's graded
violation and outcome.

Outcomes are :class:`trackplan.status.Status` members; the batched arrays hold their
integer codes, indices into :data:`OUTCOMES` (:func:`code`, :func:`outcome`).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Protocol

import numpy as np

from trackplan.case import Case
from trackplan.planning.objectives import plan_objective
from trackplan.planning.result import PlanResult
from trackplan.search.space import N_VAR, SearchSpace
from trackplan.status import Status

OUTCOMES: tuple[Status, ...] = tuple(Status)
"""Every outcome; a batched array holds the index of a member here."""


def code(status: Status) -> int:
    """The integer code of ``status`` in the batched arrays (its index in :data:`OUTCOMES`)."""
    return OUTCOMES.index(status)


def outcome(value: int | np.integer) -> Status:
    """The :class:`Status` of an integer code of the batched arrays."""
    return OUTCOMES[int(value)]


FEASIBLE = code(Status.FEASIBLE)
"""Code of a feasible candidate."""
REACH_LEVEL = 4.0
"""Graded violation of a placement outside the reach interval, before its excess."""
REACH_SCALE = 0.1
"""Reach excess that adds 1 to the graded violation, m."""
GEOMETRY_LEVEL = 0.5
"""Graded violation of a geometrically infeasible placement, before its shares."""


@dataclass(frozen=True, eq=False)
class Screening:
    """Fitness of a batch of B candidates.

    Attributes
    ----------
    X
        Variables, shape (B, 6 + k): placements (metres and radians), then the k spin
        variables of the seams' tools (:meth:`trackplan.tool.ToolSpec.spin_coefficients`).
    fitness
        Eq. 30 (see :mod:`trackplan.search.fitness`), shape (B,).
    objective
        The case's objective (``objective.kind``, Eq. 8 by default) summed over the seams
        on their screening grids on the chosen branches (paper timing: of the planned
        trajectories), shape (B,), NaN when infeasible.
    duration
        Duration of the planned seams, s, shape (B,); NaN when not planned.
    duration_bound
        Lower bound of the seams' duration from the screening grids, s, shape (B,); NaN
        when the candidate is infeasible before timing.
    feasible
        Shape (B,), bool.
    branch
        The first seam's IK branch, shape (B,), int: the feasible branch with the smallest
        J, or the branch with the smallest violation.
    violation
        Graded violation v, shape (B,), 0 when feasible (the worst seam's).
    finding
        Outcome code per candidate (:func:`outcome`), shape (B,), int.
    """

    X: np.ndarray
    fitness: np.ndarray
    objective: np.ndarray
    duration: np.ndarray
    duration_bound: np.ndarray
    feasible: np.ndarray
    branch: np.ndarray
    violation: np.ndarray
    finding: np.ndarray


@dataclass(frozen=True, eq=False)
class SeamScreen:
    """Seams of B candidates on their chosen branches (m seams; one seam: m = 1).

    Attributes
    ----------
    ok
        Shape (m, B), bool: the seam has a feasible branch clear of the cell.
    objective
        The objective of each seam on its branch, shape (m, B) (inf where not ``ok``).
    bound
        Duration bound of each seam, shape (m, B), s.
    branch
        Chosen branch, shape (m, B), int.
    violation, finding
        Graded violation and outcome code per seam, shape (m, B).
    q_first, q_last
        The seam's first and last configuration on the screening grid, shape (m, B, n), rad.
    """

    ok: np.ndarray
    objective: np.ndarray
    bound: np.ndarray
    branch: np.ndarray
    violation: np.ndarray
    finding: np.ndarray
    q_first: np.ndarray
    q_last: np.ndarray

    @classmethod
    def stack(cls, seams: Sequence[SeamScreen]) -> SeamScreen:
        """The screens of single seams (m = 1 each) stacked along the seam axis."""
        return cls(
            *(
                np.concatenate([getattr(seam, name) for seam in seams])
                for name in cls.__dataclass_fields__
            )
        )


class _Law(Protocol):
    """What the screening needs of a time law."""

    @property
    def follows_joint_path(self) -> bool:
        """Whether the law meets the rate limits by following the joint path."""
        ...


class SeamScreener(Protocol):
    """What :func:`evaluate_seams` needs of one seam's screener
    (:class:`~trackplan.search.fitness.PlacementFitness`)."""

    @property
    def case(self) -> Case:
        """The seam's single-path case."""
        ...

    @property
    def law(self) -> _Law:
        """The time law."""
        ...

    @property
    def penalty(self) -> float:
        """M, the fitness of an infeasible candidate before its violation."""
        ...

    @property
    def flat(self) -> bool:
        """Whether every infeasible candidate gets M alone."""
        ...

    @property
    def time_weight(self) -> float:
        """The objective's weight of the duration, 1/s."""
        ...

    def screen_seam(self, X: np.ndarray) -> SeamScreen:
        """The seam of candidates (B, 6 + k) inside the reach interval, m = 1."""
        ...

    def plan_candidates(self, X: np.ndarray, branch: np.ndarray) -> list[PlanResult]:
        """The seam planned with the time law at candidates (B, 6 + k) on ``branch`` (B,)."""
        ...


AirCost = Callable[[SeamScreen, np.ndarray], np.ndarray]
"""The estimated cost of the moves between the seams of screened candidates: a function
of their :class:`SeamScreen` and which of them are feasible on every seam (B,), giving
shape (B,) (0 where not feasible)."""


def evaluate_seams(
    space: SearchSpace,
    seams: Sequence[SeamScreener],
    slices: Sequence[slice] | Sequence[np.ndarray],
    X: np.ndarray,
    incumbent: float = np.inf,
    air: AirCost | None = None,
) -> tuple[Screening, SeamScreen | None]:
    """The fitness of a batch of candidates over every seam of a case.

    Parameters
    ----------
    space
        The search space (its reach interval).
    seams
        One screener per seam, as written.
    slices
        Where each seam's own variables (its spin, the positioner pose) lie in a candidate:
        a slice or column indices (empty for none).
    X
        Candidates, shape (B, n_var): placements (metres and radians), then the spin
        variables.
    incumbent
        Best fitness so far: where the time law follows the joint path, only the
        candidates whose lower bound is below it are timed.
    air
        Estimated cost of the moves between the seams (:data:`AirCost`); None: no moves.

    Returns
    -------
    tuple
        The :class:`Screening`, and the seams' :class:`SeamScreen` of the candidates inside
        the reach interval (None when none is).
    """
    first = seams[0]
    n = len(X)
    fitness = np.full(n, np.nan)
    objective = np.full(n, np.nan)
    duration = np.full(n, np.nan)
    bound = np.full(n, np.nan)
    branch = np.zeros(n, dtype=int)
    excess = space.reach_excess(X)
    violation = REACH_LEVEL + excess / REACH_SCALE
    finding = np.full(n, code(Status.REACH))
    inside = np.flatnonzero(excess == 0.0)
    parts = [np.hstack([X[:, :N_VAR], X[:, part]]) for part in slices]
    screens = None
    if len(inside):
        screens = SeamScreen.stack(
            [seam.screen_seam(part[inside]) for seam, part in zip(seams, parts, strict=True)]
        )
        all_ok = screens.ok.all(axis=0)
        worst = np.argmax(screens.violation, axis=0)
        violation[inside] = screens.violation.max(axis=0)
        finding[inside] = np.where(all_ok, FEASIBLE, screens.finding[worst, np.arange(len(inside))])
        branch[inside] = screens.branch[0]
        objective[inside] = screens.objective.sum(axis=0)
        bound[inside] = screens.bound.sum(axis=0)
        moves = np.zeros(len(inside)) if air is None else air(screens, np.asarray(all_ok))
        fitness[inside] = objective[inside] + first.time_weight * bound[inside] + moves
    feasible = finding == FEASIBLE
    violation[feasible] = 0.0
    if screens is not None and (not first.law.follows_joint_path or first.time_weight > 0.0):
        timed = (
            np.logical_and(feasible, fitness < incumbent)
            if first.law.follows_joint_path
            else feasible
        )
        index = np.flatnonzero(timed)
        if len(index):
            where = np.searchsorted(inside, index)
            moves = fitness[index] - objective[index] - first.time_weight * bound[index]
            _time(
                seams,
                [part[index] for part in parts],
                screens,
                where,
                moves,
                index,
                (fitness, objective, duration, violation, finding),
            )
            feasible = finding == FEASIBLE
    infeasible = ~feasible
    fitness[infeasible] = first.penalty + (0.0 if first.flat else violation[infeasible])
    objective[infeasible] = np.nan
    bound[~np.isin(finding, [FEASIBLE, code(Status.LIMITS_VIOLATED)])] = np.nan
    screening = Screening(
        X, fitness, objective, duration, bound, feasible, branch, violation, finding
    )
    return screening, screens


def _time(
    seams: Sequence[SeamScreener],
    parts: list[np.ndarray],
    screens: SeamScreen,
    where: np.ndarray,
    moves: np.ndarray,
    index: np.ndarray,
    arrays: tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray],
) -> None:
    """Plan every seam of the candidates ``index`` (positions ``where`` in ``screens``) with
    the time law; update fitness, objective, duration, violation and finding in place.

    A candidate whose seams all pass the checker gets ``Σ (J + w·T) + moves``; one that
    fails gets the outcome ``LIMITS_VIOLATED`` and the graded violation
    ``0.5 L / (1 + L)``, ``L = ln(1 + x)``, ``x`` the worst excess over a limit of its
    failing seams (see :mod:`trackplan.search.fitness`)."""
    fitness, objective, duration, violation, finding = arrays
    first = seams[0]
    total_objective = np.zeros(len(index))
    total_duration = np.zeros(len(index))
    passed = np.ones(len(index), dtype=bool)
    worst = np.zeros(len(index))
    for s, (seam, part) in enumerate(zip(seams, parts, strict=True)):
        plans = seam.plan_candidates(part, screens.branch[s, where])
        for j, plan in enumerate(plans):
            total_duration[j] += plan.duration
            if plan.success:
                total_objective[j] += (
                    screens.objective[s, where[j]]
                    if first.law.follows_joint_path
                    else plan_objective(seam.case.objective, plan)
                )
            else:
                passed[j] = False
                excess = -plan.check.worst_margin() if plan.check.joint_margins else 1.0
                worst[j] = max(worst[j], np.log1p(max(excess, 1e-9)))
    duration[index] = total_duration
    good, bad = index[passed], index[~passed]
    objective[good] = total_objective[passed]
    fitness[good] = (
        total_objective[passed] + first.time_weight * total_duration[passed] + moves[passed]
    )
    finding[bad] = code(Status.LIMITS_VIOLATED)
    level = worst[~passed]
    violation[bad] = GEOMETRY_LEVEL * level / (1.0 + level)
