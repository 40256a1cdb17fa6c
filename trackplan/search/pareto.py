"""A Pareto front of two objectives over the placement (NSGA-II, pymoo).

Each candidate is screened like the single-objective search (:mod:`trackplan.search.fitness`):
every IK branch on the screening grid, the reach, the joint range, the holding torque. Both
objectives (:mod:`trackplan.planning.objectives`) are estimated on the same branch: the
feasible one with the smallest first objective. Infeasible candidates carry the graded
violation as pymoo's inequality constraint (``G <= 0`` feasible). At the end every placement
of the front is planned at the full sample time, checked, and its objectives taken from
the planned trajectory.
"""

from __future__ import annotations

import time
from concurrent.futures import Executor
from dataclasses import dataclass

import numpy as np
from pymoo.algorithms.moo.nsga2 import NSGA2
from pymoo.core.problem import Problem
from pymoo.optimize import minimize

from trackplan.case import Case, Objective
from trackplan.choices import Timing
from trackplan.errors import CaseError
from trackplan.paths.path_geometry import PathGeometry
from trackplan.planning.objectives import OBJECTIVES
from trackplan.planning.result import PlanResult
from trackplan.search.fitness import PlacementFitness, plan_candidate
from trackplan.search.screening import REACH_LEVEL, REACH_SCALE
from trackplan.search.space import N_VAR, SearchSpace
from trackplan.status import Status
from trackplan.timing import time_law

GENERATIONS = 40
"""Default number of NSGA-II generations."""


def parse_objective_pair(text: str, case: Case | None = None) -> tuple[str, str]:
    """The two objective names of ``--pareto A,B``.

    Raises
    ------
    CaseError
        When there are not exactly two distinct registered names, or one needs dynamics the
        robot does not have.
    """
    names = tuple(name.strip() for name in text.split(","))
    known = ", ".join(OBJECTIVES)
    if len(names) != 2 or names[0] == names[1]:
        raise CaseError(
            f"expected two different objectives A,B (of {known}), got {text!r}", key="--pareto"
        )
    for name in names:
        if name not in OBJECTIVES:
            raise CaseError(f"unknown objective {name!r}: use {known}", key="--pareto")
        if case is not None and OBJECTIVES[name].needs_dynamics and case.robot.dynamics is None:
            raise CaseError(
                f"{name} needs joint torques, but robot {case.robot.name} has no dynamic "
                "parameters",
                key="--pareto",
            )
    return names[0], names[1]


@dataclass(frozen=True, eq=False)
class ParetoResult:
    """The front and its re-planned points.

    Attributes
    ----------
    success
        True when at least one front point passes the checker after re-planning.
    status
        ``FEASIBLE`` when ``success``; ``LIMITS_VIOLATED`` when every re-planned point fails
        the checker; ``UNREACHABLE`` when no candidate passed the screening.
    message
        One line on the outcome.
    objectives
        The two objective names.
    X
        Front placements, shape (P, 6), sorted by the first screened objective.
    branch
        IK branch of each, shape (P,), int.
    screened
        Objectives estimated on the screening grid, shape (P, 2).
    values
        Objectives of the planned trajectories, shape (P, 2) (NaN where none was built).
    feasible
        Shape (P,), bool: the planned trajectory passes the checker.
    nondominated
        Shape (P,), bool: feasible and not dominated by another feasible point's planned
        values (screening estimates a lower duration than some plans get).
    plans
        The P planned results.
    evaluations
        Placements evaluated.
    wall_time_s
        s.
    seed
        The seed.
    """

    success: bool
    status: Status
    message: str
    objectives: tuple[str, str]
    X: np.ndarray
    branch: np.ndarray
    screened: np.ndarray
    values: np.ndarray
    feasible: np.ndarray
    nondominated: np.ndarray
    plans: tuple[PlanResult, ...]
    evaluations: int
    wall_time_s: float
    seed: int


def nondominated(values: np.ndarray, feasible: np.ndarray) -> np.ndarray:
    """Feasible points that no other feasible point dominates (minimisation).

    Parameters
    ----------
    values
        Shape (P, 2).
    feasible
        Shape (P,), bool.

    Returns
    -------
    numpy.ndarray
        Shape (P,), bool.
    """
    v = np.where(feasible[:, None], values, np.inf)
    no_worse = np.all(v[None, :, :] <= v[:, None, :], axis=2)  # [i, j]: j no worse than i
    better = np.any(v[None, :, :] < v[:, None, :], axis=2)
    dominated = np.any(no_worse & better & feasible[None, :], axis=1)
    return feasible & ~dominated


class _ParetoProblem(Problem):
    """Two screened objectives and the graded violation, batched."""

    def __init__(self, fitness: PlacementFitness, space: SearchSpace, objectives: tuple[str, str]):
        super().__init__(n_var=N_VAR, n_obj=2, n_ieq_constr=1, xl=space.lower, xu=space.upper)
        self.fitness = fitness
        self.space = space
        self.objectives = tuple(
            Objective(weights=fitness.weights, kind=name) for name in objectives
        )
        self.n_evaluations = 0

    def screen(self, X: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Objectives (B, 2), violation (B,) and branch (B,) of placements."""
        n = len(X)
        F = np.full((n, 2), np.inf)
        branch = np.zeros(n, dtype=int)
        excess = self.space.reach_excess(X)
        violation = np.where(excess > 0.0, REACH_LEVEL + excess / REACH_SCALE, 0.0)
        inside = np.flatnonzero(excess == 0.0)
        if len(inside):
            values, chosen, graded, _, _ = self.fitness.screen_objectives(
                X[inside], self.objectives
            )
            F[inside] = np.where(np.isfinite(values), values, np.inf)
            violation[inside] = graded
            branch[inside] = chosen
        self.n_evaluations += n
        return F, violation, branch

    def _evaluate(self, X: np.ndarray, out: dict, *args: object, **kwargs: object) -> None:
        F, violation, _ = self.screen(np.atleast_2d(X))
        # infeasible candidates rank by G only; keep F finite for pymoo's sorting
        out["F"] = np.where(np.isfinite(F), F, 1e12)
        out["G"] = violation[:, None]


def pareto_front(
    case: Case,
    objectives: tuple[str, str],
    *,
    population: int | None = None,
    generations: int = GENERATIONS,
    seed: int | None = None,
    timing: Timing | str | None = None,
    geometry: PathGeometry | None = None,
    executor: Executor | None = None,
) -> ParetoResult:
    """NSGA-II front of two objectives over the placement, every point re-planned.

    Parameters
    ----------
    case
        The case.
    objectives
        Two registered objective names (``travel``, ``time``, ``energy``, ``copper``).
    population
        NSGA-II population; default the case's ``optimizer.population``.
    generations
        Number of generations.
    seed
        Fixes every random choice; default the case's ``optimizer.seed``.
    timing
        The time law (:class:`trackplan.choices.Timing`); default the case's ``task.timing``.
    geometry
        The case's paths when already built for this time law's path mode.
    executor
        Plans the front points concurrently (``executor.map``); None: one after the other.

    Returns
    -------
    ParetoResult

    Raises
    ------
    CaseError
        For a bad objective pair (see :func:`parse_objective_pair`).
    """
    start = time.perf_counter()
    names = parse_objective_pair(",".join(objectives), case)
    seed = case.optimizer.seed if seed is None else int(seed)
    population = population or case.optimizer.population
    law = time_law(timing or case.task.timing)
    space = SearchSpace.from_case(case)
    if geometry is None or geometry.mode != law.path_mode:
        geometry = PathGeometry.from_case(case, law.path_mode)
    timing = law.timing
    fitness = PlacementFitness(case, space, geometry, timing)
    problem = _ParetoProblem(fitness, space, names)
    algorithm = NSGA2(pop_size=population)
    result = minimize(problem, algorithm, ("n_gen", generations), seed=seed, verbose=False)
    front_X = np.zeros((0, N_VAR)) if result.X is None else np.atleast_2d(result.X)
    front_X = np.unique(front_X, axis=0)
    screened, violation, branch = problem.screen(front_X)
    keep = violation <= 0.0
    order = np.argsort(screened[keep, 0], kind="stable")
    front_X, screened, branch = front_X[keep][order], screened[keep][order], branch[keep][order]
    jobs = [(case, X, timing, int(b), geometry) for X, b in zip(front_X, branch, strict=True)]
    mapper = executor.map if executor is not None else map
    plans = tuple(mapper(plan_candidate, jobs))
    values = np.array(
        [[OBJECTIVES[name].exact(plan) for name in names] for plan in plans], dtype=float
    ).reshape(-1, 2)
    feasible = np.array([plan.feasible for plan in plans], dtype=bool)
    n_feasible = int(feasible.sum())
    front = nondominated(values, feasible)
    message = (
        f"{names[0]}–{names[1]} front of {len(plans)} placements, {n_feasible} feasible after "
        f"re-planning, {int(front.sum())} non-dominated ({problem.n_evaluations} evaluations)"
        if len(plans)
        else f"no feasible placement found in {problem.n_evaluations} evaluations"
    )
    status = (
        Status.FEASIBLE if n_feasible else Status.LIMITS_VIOLATED if plans else Status.UNREACHABLE
    )
    return ParetoResult(
        success=n_feasible > 0,
        status=status,
        message=message,
        objectives=names,
        X=front_X,
        branch=branch,
        screened=screened,
        values=values,
        feasible=feasible,
        nondominated=front,
        plans=plans,
        evaluations=problem.n_evaluations,
        wall_time_s=time.perf_counter() - start,
        seed=seed,
    )
