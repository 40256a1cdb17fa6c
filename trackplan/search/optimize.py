"""Where to place the workpiece: the one search of a case (Problem + Algorithm + Termination).

:func:`optimize` searches one placement for every seam of a case (one seam is a set of
one): it wires the case's fitness (:class:`~trackplan.search.case_fitness.CaseFitness`:
each seam's screening summed, plus the moves between seams), a
:class:`~trackplan.search.problem.PlacementProblem`, an algorithm of
:mod:`trackplan.search.algorithms` and the shared termination, and runs them through
:func:`~trackplan.search.driver.run_search`, which reports each generation, honours the
evaluation budget exactly and stops cleanly on Ctrl-C. The best screened candidate is then
planned at the full sample time (every seam, sequenced, checked:
:func:`~trackplan.search.plan_calls.plan_case`); should that check fail, the next best
distinct candidate of the archive is planned instead. Given a ``background`` executor,
the plans are made there: the "before" plan while the search runs, then the final
candidates.
"""

from __future__ import annotations

import copy
import functools
import time
from concurrent.futures import BrokenExecutor, Executor, Future
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import numpy as np

from trackplan.case import Case
from trackplan.choices import Method, choose
from trackplan.errors import CaseError
from trackplan.paths.path_geometry import PathGeometry
from trackplan.planning.result import PlanResult
from trackplan.search.algorithms import DEFAULT_RESTARTS, make_algorithm
from trackplan.search.case_fitness import CaseFitness, SeamSpin, pose_slice
from trackplan.search.driver import (
    GenerationRecord,
    ProgressCallback,
    SearchHistory,
    StopReason,
    run_search,
    run_seeds,
)
from trackplan.search.plan_calls import SeamGeometries, plan_case, seam_geometries
from trackplan.search.positioner_pose import positioned
from trackplan.search.problem import PlacementProblem
from trackplan.search.space import N_VAR, BoundHit, SearchSpace
from trackplan.status import Status
from trackplan.timing import time_law

if TYPE_CHECKING:  # pymoo's Algorithm is imported by the methods that run as one only
    from pymoo.core.algorithm import Algorithm
    from pymoo.core.termination import Termination

__all__ = ["GenerationRecord", "SearchHistory", "SearchResult", "optimize"]


@dataclass(frozen=True, eq=False)
class SearchResult:
    """Outcome of :func:`optimize`.

    Attributes
    ----------
    success
        True when the final plan is feasible.
    status
        :class:`trackplan.status.Status`: ``FEASIBLE``, ``INTERRUPTED`` when a signal
        stopped the search (the best placement found is still planned and checked), else
        the final plan's status.
    message
        One line: what was found, or why nothing feasible was (naming the seam that
        decides, for a case with several seams).
    X
        Best placement (x, y, z, roll, pitch, yaw), shape (6,), metres and radians.
    branch
        The first seam's IK branch.
    fitness
        Its fitness (Eq. 30) as the search ranked it (screening grids).
    objective
        J (Eq. 8) of the final plan at the full sample time (NaN without a trajectory).
    final
        The plan at X, re-planned at the full sample time and re-checked (every seam,
        sequenced).
    initial
        The plan at the centre of the bounds, or the admissible point nearest to it:
        the "before" of the paper's Fig. 6b/7b.
    history
        Per-generation figures.
    evaluations
        Placements evaluated.
    generations
        Generations run (the initial population is generation 1).
    stop_reason
        Why the last run stopped: ``stall``, ``max_generations``, ``budget``,
        ``converged`` (CMA-ES, multistart) or ``interrupted`` (Ctrl-C).
    wall_time_s
        Wall time of the whole call, s.
    method
        The search method (the class name of a pymoo ``Algorithm`` passed in).
    seed
        The seed.
    runs
        Independent runs made (``optimizer.restarts``, fewer when the budget or Ctrl-C
        stopped the search).
    rejected
        Candidates screened feasible that the final check rejected, best first, shape (R, 6).
    on_bounds
        The variables of X that lie on a bound of the search box
        (:meth:`~trackplan.search.space.SearchSpace.bound_hits`): the optimum may lie
        beyond it.
    unreachable
        Seams that no evaluated placement reached feasibly, by name.
    spins
        The spin variables chosen for each seam (as written), None for a fixed spin.
    positioner_pose
        The positioner's pose the final plan stands it at, (x, y, z, roll, pitch, yaw),
        shape (6,), m and rad (searched where the case gives bounds); None without a
        positioner.
    """

    success: bool
    status: Status
    message: str
    X: np.ndarray
    branch: int
    fitness: float
    objective: float
    final: PlanResult
    initial: PlanResult
    history: SearchHistory
    evaluations: int
    generations: int
    stop_reason: StopReason
    wall_time_s: float
    method: str
    seed: int
    runs: int = 1
    rejected: np.ndarray = field(default_factory=lambda: np.zeros((0, 6)))
    on_bounds: tuple[BoundHit, ...] = ()
    unreachable: tuple[str, ...] = ()
    spins: tuple[SeamSpin, ...] = ()
    positioner_pose: np.ndarray | None = None


def optimize(
    case: Case,
    *,
    method: str | Method | Algorithm | None = None,
    termination: Termination | tuple | None = None,
    seed: int | None = None,
    budget: int | None = None,
    progress: ProgressCallback | None = None,
    geometry: PathGeometry | None = None,
    geometries: SeamGeometries | None = None,
    timing: str | None = None,
    executor: Executor | None = None,
    restarts: int | None = None,
    background: Executor | None = None,
) -> SearchResult:
    """Search the placement X of the workpiece with the least joint travel (Eq. 8, 30)
    for every seam of the case, with the best sequence between them.

    Parameters
    ----------
    case
        The case: robot, seams, task, bounds (Eq. 28, 29), objective and optimizer settings.
    method
        A :class:`trackplan.choices.Method` (``multistart``, ``ga``: the paper's
        configuration, ``cmaes``, ``de``, ``random``), or any single-objective pymoo
        ``Algorithm`` instance, as pymoo's ``minimize`` takes it (each restart runs a fresh
        copy); default the case's ``optimizer.method``.
    termination
        A pymoo ``Termination`` (or a tuple such as ``("n_gen", 50)``, as ``minimize``
        takes it) replacing the default stall and generation rules; the budget still
        applies.
    seed
        Fixes every random choice; default the case's ``optimizer.seed``. The same seed
        gives the same history and result.
    budget
        Largest number of placement evaluations; default the case's ``optimizer.budget``
        (None: the method's own stopping rules only).
    progress
        Called with a :class:`GenerationRecord` after every generation. A
        KeyboardInterrupt raised there (or anywhere in the search) stops the search; the
        best placement found so far is still planned and returned (``stop_reason``
        ``interrupted``).
    geometry
        The path of a case of one seam when already built for this timing.
    geometries
        The seams' paths when already built for this timing
        (:func:`~trackplan.search.plan_calls.seam_geometries`).
    timing
        ``smooth`` or ``paper``; default the case's ``task.timing``. Paper timing plans
        every screened candidate with Section 3.1's time law: slow.
    executor
        Plans several candidates concurrently when the time law runs during the search
        (paper timing, or ``objective.time_weight > 0``); None: one after the other.
    restarts
        Independent runs of the method, each from a fresh initial population, the best of
        all kept; default the case's ``optimizer.restarts``, else the method's own
        (:data:`trackplan.search.algorithms.DEFAULT_RESTARTS`; 1 for a pymoo Algorithm).
        The first run uses ``seed`` itself, so ``restarts=1`` is one run exactly as
        configured (the paper's GA).
    background
        Makes the plans at full Ts there: the "before" plan (``initial``) while the search
        runs, then the final candidates, e.g. on the second core in a process forked before
        the search (:func:`trackplan.forking.forked_pool`), whose warm-up (the time law's
        first calls) the search then does not wait for. The results are the same; when the
        executor breaks (its process killed), the plans are made here. None: here, after
        the search.

    Returns
    -------
    SearchResult

    Raises
    ------
    CaseError
        For an unknown method or timing, a negative seed, a budget or restarts below 1,
        or bounds with no placement inside the reach interval.
    """
    start = time.perf_counter()
    custom = None if method is None or isinstance(method, str) else method  # a pymoo Algorithm
    chosen = None if custom else choose(Method, method or case.optimizer.method, "method")
    seed = case.optimizer.seed if seed is None else int(seed)
    budget = case.optimizer.budget if budget is None else int(budget)
    if restarts is None:
        restarts = case.optimizer.restarts
    if restarts is None:
        restarts = 1 if chosen is None else DEFAULT_RESTARTS[chosen]
    restarts = int(restarts)
    law = time_law(timing or case.task.timing)
    if seed < 0:
        raise CaseError(f"seed must be ≥ 0, got {seed}", key="seed")
    if budget is not None and budget < 1:
        raise CaseError(f"budget must be ≥ 1 evaluation, got {budget}", key="budget")
    if restarts < 1:
        raise CaseError(f"restarts must be ≥ 1, got {restarts}", key="restarts")
    space = SearchSpace.from_case(case)
    geometries = _geometries(case, law.timing, law.path_mode, geometry, geometries)
    fitness = CaseFitness(case, space, geometries, law.timing, executor=executor)
    problem = PlacementProblem(space, fitness)
    planner = _Planner(case, law.timing, geometries, background)
    before = planner.submit(space.anchor, None, fitness.seam_spins(space.anchor))
    records: list[GenerationRecord] = []
    stop_reason = StopReason.BUDGET
    runs = 0
    for run_seed in run_seeds(seed, restarts):
        if chosen is None:
            search = copy.deepcopy(custom)
        else:
            search = make_algorithm(chosen, space, case.optimizer.population)
        driver = (budget, progress, start, records)
        stop_reason = run_search(search, problem, termination, chosen, run_seed, driver)
        runs += 1
        if stop_reason in (StopReason.BUDGET, StopReason.INTERRUPTED):
            break
    initial = planner.result(before, space.anchor, None, fitness.seam_spins(space.anchor))
    final, kept, branches, rejected = _final_plan(problem, fitness, planner)
    unreachable = fitness.unreachable_seams()
    status = Status.INTERRUPTED if stop_reason is StopReason.INTERRUPTED else final.status
    return SearchResult(
        success=status is Status.FEASIBLE,
        status=status,
        message=_message(case, final, problem, rejected, space, unreachable, branches[0]),
        X=final.placement,
        branch=branches[0],
        fitness=float(problem.archive.fitness[kept]),
        objective=float(final.objective),
        final=final,
        initial=initial,
        history=SearchHistory.from_records(records),
        evaluations=problem.n_evaluations,
        generations=len(records),
        stop_reason=stop_reason,
        wall_time_s=time.perf_counter() - start,
        method=type(custom).__name__ if chosen is None else str(chosen),
        seed=seed,
        runs=runs,
        rejected=np.asarray(rejected, dtype=float).reshape(-1, 6),
        on_bounds=space.bound_hits(final.placement),
        unreachable=unreachable,
        spins=fitness.seam_spins(problem.archive.X[kept]),
        positioner_pose=_positioner_pose(case, problem.archive.X[kept]),
    )


def _positioner_pose(case: Case, X: np.ndarray) -> np.ndarray | None:
    """The positioner pose of a candidate X (n_var,), shape (6,), or None without one."""
    placed = positioned(case, X[pose_slice(case)])
    return None if placed.positioner is None else np.array(placed.positioner.pose)


def _geometries(
    case: Case,
    timing: str,
    mode: str,
    geometry: PathGeometry | None,
    geometries: SeamGeometries | None,
) -> SeamGeometries:
    """The seams' paths in the law's path mode: those given when they are in that mode,
    else built."""
    if geometries is not None and all(g.mode == mode for g in geometries.values()):
        return geometries
    if geometry is not None and geometry.mode == mode and len(case.seams) == 1:
        return {(0, False): geometry}
    return seam_geometries(case, timing)


class _Planner:
    """:func:`~trackplan.search.plan_calls.plan_case` of the case's candidates at full Ts,
    on ``background`` while it works, else here."""

    def __init__(
        self,
        case: Case,
        timing: str,
        geometries: SeamGeometries,
        background: Executor | None,
    ) -> None:
        self.case, self.timing, self.geometries = case, timing, geometries
        self.background = background

    def submit(
        self, X: np.ndarray, branches: tuple[int, ...] | None, spins: tuple[SeamSpin, ...]
    ) -> Future[PlanResult] | None:
        """Start planning ``X`` in the background; None without one (or a broken one)."""
        if self.background is None:
            return None
        try:
            return self.background.submit(self._job(X, branches, spins))
        except BrokenExecutor:
            self.background = None
            return None

    def result(
        self,
        job: Future[PlanResult] | None,
        X: np.ndarray,
        branches: tuple[int, ...] | None,
        spins: tuple[SeamSpin, ...],
    ) -> PlanResult:
        """The plan of ``X`` submitted as ``job``, made here when the background broke."""
        if job is not None:
            try:
                return job.result()
            except BrokenExecutor:
                self.background = None
        return self._job(X, branches, spins)()

    def plan(
        self, X: np.ndarray, branches: tuple[int, ...], spins: tuple[SeamSpin, ...]
    ) -> PlanResult:
        """The plan of ``X``, waited for."""
        return self.result(self.submit(X, branches, spins), X, branches, spins)

    def _job(
        self, X: np.ndarray, branches: tuple[int, ...] | None, spins: tuple[SeamSpin, ...]
    ) -> functools.partial[PlanResult]:
        return functools.partial(
            plan_case,
            positioned(self.case, X[pose_slice(self.case)]),
            X[:N_VAR],
            timing=self.timing,
            geometries=self.geometries,
            branches=branches,
            spins=spins,
        )


def _final_plan(
    problem: PlacementProblem, fitness: CaseFitness, planner: _Planner
) -> tuple[PlanResult, int, tuple[int, ...], list[np.ndarray]]:
    """Plan the archive's candidates best first at full Ts until one passes the checker.

    Returns the first feasible plan, or the plan of the best candidate when none passes;
    its row in the archive and its seams' branches; and the placements screened feasible
    that the check rejected.
    """
    archive = problem.archive
    rejected: list[np.ndarray] = []
    first: tuple[PlanResult, int, tuple[int, ...]] | None = None
    for row, (X, feasible) in enumerate(zip(archive.X, archive.feasible, strict=True)):
        if first is not None and not feasible:
            break
        branches = fitness.branches(X)
        plan = planner.plan(X, branches, fitness.seam_spins(X))
        if plan.success:
            return plan, row, branches, rejected
        first = first or (plan, row, branches)
        if feasible:
            rejected.append(X[:N_VAR])
    if first is None:
        raise CaseError("the search evaluated no placement (budget 0?)", key="budget")
    return *first, rejected


def _message(
    case: Case,
    final: PlanResult,
    problem: PlacementProblem,
    rejected: list[np.ndarray],
    space: SearchSpace,
    unreachable: tuple[str, ...],
    branch: int,
) -> str:
    """One line on the outcome."""
    n = problem.n_evaluations
    m = len(case.seams)
    note = f" ({len(rejected)} better screened candidates failed the final check)"
    note = note if rejected else ""
    if final.success and m == 1:
        return (
            f"feasible placement found in {n} evaluations: J = {final.objective:.4f}, "
            f"duration {final.duration:.3f} s, branch {branch}{note}"
        )
    if final.success:
        return (
            f"feasible placement for all {m} seams found in {n} evaluations: cycle time "
            f"{final.duration:.3f} s (air {getattr(final, 'air_time', 0.0):.3f} s), "
            f"J = {final.objective:.4f}{note}"
        )
    if unreachable and m > 1:
        return (
            f"seam {unreachable[0]} is feasible at none of the {n} placements "
            f"evaluated; at the closest: {final.message}"
        )
    if m > 1:
        return f"no feasible placement for every seam in {n} evaluations: {final.message}"
    return (
        f"no feasible placement in {n} evaluations; the closest, "
        f"{space.describe(final.placement)}: {final.message}"
    )
