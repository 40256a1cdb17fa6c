"""Where to place the workpiece: the search facade (Problem + Algorithm + Termination).

:func:`optimize_placement` wires a :class:`~trackplan.search.problem.PlacementProblem`,
an algorithm of :mod:`trackplan.search.algorithms` and the shared termination, and runs
them through pymoo's ask/tell interface so that it can report each generation, honour
the evaluation budget exactly and stop cleanly on Ctrl-C. The best screened candidate is
then planned at the full sample time by :func:`~trackplan.planning.plan.plan_placement`
and checked by the checker; should that check fail, the next best distinct candidate of
the archive is planned instead. Given a ``background`` executor, the plans are made there:
the "before" plan while the search runs, then the final candidates.
"""

from __future__ import annotations

import copy
import time
from collections.abc import Callable
from concurrent.futures import BrokenExecutor, Executor, Future
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import numpy as np

from trackplan.case import Case
from trackplan.choices import Method, choose
from trackplan.errors import CaseError
from trackplan.paths.path_geometry import PathGeometry
from trackplan.planning.plan import plan
from trackplan.planning.result import PlanResult
from trackplan.run_files import HISTORY_KEYS
from trackplan.search.algorithms import (
    DEFAULT_RESTARTS,
    MAX_GENERATIONS,
    MultiStartSearch,
    make_algorithm,
    make_termination,
)
from trackplan.search.fitness import PlacementFitness
from trackplan.search.problem import PlacementProblem
from trackplan.search.space import BoundHit, SearchSpace
from trackplan.status import Status
from trackplan.timing import time_law

if TYPE_CHECKING:  # pymoo's Algorithm is imported by the methods that run as one only
    from pymoo.core.algorithm import Algorithm
    from pymoo.core.termination import Termination


@dataclass(frozen=True)
class GenerationRecord:
    """One generation of a search, as passed to the progress callback.

    Attributes
    ----------
    generation
        1 for the initial population.
    evaluations
        Placements evaluated so far.
    best
        Best fitness found so far (Eq. 30).
    mean
        Mean fitness of the candidates evaluated in this generation.
    feasible_share
        Share of this generation's candidates screened feasible, in [0, 1].
    wall_time
        Seconds since the search started.
    best_objective
        J of the best candidate so far on the screening grid (NaN while none is feasible).
    """

    generation: int
    evaluations: int
    best: float
    mean: float
    feasible_share: float
    wall_time: float
    best_objective: float


@dataclass(frozen=True, eq=False)
class SearchHistory:
    """Per-generation figures of a search, arrays of shape (G,).

    Attributes
    ----------
    generation, evaluations, best, mean, feasible_share, wall_time
        See :class:`GenerationRecord` (wall time in s).
    """

    generation: np.ndarray = field(default_factory=lambda: np.zeros(0, int))
    evaluations: np.ndarray = field(default_factory=lambda: np.zeros(0, int))
    best: np.ndarray = field(default_factory=lambda: np.zeros(0))
    mean: np.ndarray = field(default_factory=lambda: np.zeros(0))
    feasible_share: np.ndarray = field(default_factory=lambda: np.zeros(0))
    wall_time: np.ndarray = field(default_factory=lambda: np.zeros(0))

    @classmethod
    def from_records(cls, records: list[GenerationRecord]) -> SearchHistory:
        """The history of a list of generation records."""
        return cls(
            **{
                key: np.array([getattr(r, key) for r in records], dtype=float)
                if key not in ("generation", "evaluations")
                else np.array([getattr(r, key) for r in records], dtype=int)
                for key in HISTORY_KEYS
            }
        )

    def as_columns(self) -> dict[str, np.ndarray]:
        """``{column: array}`` in :data:`HISTORY_KEYS` order (the report's history format)."""
        return {key: getattr(self, key) for key in HISTORY_KEYS}

    def __len__(self) -> int:
        return len(self.generation)


@dataclass(frozen=True, eq=False)
class OptimizeResult:
    """Outcome of :func:`optimize_placement`.

    Attributes
    ----------
    success
        True when the final plan is feasible.
    status
        :class:`trackplan.status.Status`: ``FEASIBLE``, ``INTERRUPTED`` when a signal
        stopped the search (the best placement found is still planned and checked), else
        the final plan's status.
    message
        One line: what was found, or why nothing feasible was.
    X
        Best placement (x, y, z, roll, pitch, yaw), shape (6,), metres and radians.
    branch
        Its IK branch.
    fitness
        Its fitness (Eq. 30) as the search ranked it (screening grid).
    objective
        J (Eq. 8) of the final plan at the full sample time (NaN without a trajectory).
    final
        The plan at X, re-planned at the full sample time and re-checked.
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
        ``converged`` (CMA-ES) or ``interrupted`` (Ctrl-C).
    runs
        Independent runs made (``optimizer.restarts``, fewer when the budget or Ctrl-C
        stopped the search).
    wall_time_s
        Wall time of the whole call, s.
    method
        The search method (the class name of a pymoo ``Algorithm`` passed in).
    seed
        The seed.
    rejected
        Candidates screened feasible that the final check rejected, best first, shape (R, 6).
    on_bounds
        The variables of X that lie on a bound of the search box
        (:meth:`~trackplan.search.space.SearchSpace.bound_hits`): the optimum may lie
        beyond it.
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
    stop_reason: str
    wall_time_s: float
    method: str
    seed: int
    runs: int = 1
    rejected: np.ndarray = field(default_factory=lambda: np.zeros((0, 6)))
    on_bounds: tuple[BoundHit, ...] = ()


ProgressCallback = Callable[[GenerationRecord], None]
"""Called after every generation; raising KeyboardInterrupt stops the search."""


def optimize_placement(
    case: Case,
    *,
    method: str | Method | Algorithm | None = None,
    termination: Termination | tuple | None = None,
    seed: int | None = None,
    budget: int | None = None,
    progress: ProgressCallback | None = None,
    geometry: PathGeometry | None = None,
    timing: str | None = None,
    executor: Executor | None = None,
    restarts: int | None = None,
    background: Executor | None = None,
) -> OptimizeResult:
    """Search the placement X of the workpiece with the least joint travel (Eq. 8, 30).

    Parameters
    ----------
    case
        The case: robot, path, task, bounds (Eq. 28, 29), objective and optimizer settings.
    method
        A :class:`trackplan.choices.Method` (``ga``: the paper's configuration,
        ``cmaes``, ``de``, ``random``), or any single-objective pymoo ``Algorithm``
        instance, as pymoo's ``minimize`` takes it (each restart runs a fresh copy);
        default the case's ``optimizer.method``.
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
        The case's paths when already built for this timing.
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
    OptimizeResult

    Raises
    ------
    CaseError
        For an unknown method or timing, a negative budget, bounds with no placement
        inside the reach interval, or a case with several seams
        (:func:`trackplan.search.cycle_search.optimize_cycle` searches those).
    """
    sequencing = case.sequencing  # adapter until the one search (issue 27)
    if len(case.seams) > 1 or sequencing.approach > 0 or sequencing.home is not None:
        raise CaseError(
            f"case {case.name} has several seams (paths): search it with "
            "trackplan.search.cycle_search.optimize_cycle (docs/seams.md)",
            key="paths",
        )
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
    if geometry is None or geometry.mode != law.path_mode:
        geometry = PathGeometry.from_case(case, law.path_mode)
    timing = law.timing
    fitness = PlacementFitness(case, space, geometry, timing, executor=executor)
    problem = PlacementProblem(space, fitness)
    planner = _Planner(case, timing, geometry, background)
    before = planner.submit(space.anchor)
    records: list[GenerationRecord] = []
    stop_reason = ""
    runs = 0
    for run_seed in run_seeds(seed, restarts):
        if chosen is None:
            search = copy.deepcopy(custom)
        else:
            search = make_algorithm(chosen, space, case.optimizer.population)
        driver = (budget, progress, start, records)
        stop_reason = run_search(search, problem, termination, chosen, run_seed, driver)
        runs += 1
        if stop_reason in ("budget", "interrupted"):
            break
    initial = planner.result(before, space.anchor)
    final, rejected = _final_plan(problem, planner)
    archive = problem.archive
    kept = int(np.flatnonzero(np.all(archive.X[:, :6] == final.placement, axis=1))[0])
    if stop_reason == "interrupted":
        status = Status.INTERRUPTED
    else:
        status = final.status
    return OptimizeResult(
        success=status is Status.FEASIBLE,
        status=status,
        message=_message(final, problem, rejected, space),
        X=final.placement,
        branch=int(final.branch),
        fitness=float(archive.fitness[kept]),
        objective=float(final.objective),
        final=final,
        initial=initial,
        history=SearchHistory.from_records(records),
        evaluations=problem.n_evaluations,
        generations=len(records),
        stop_reason=stop_reason,
        wall_time_s=time.perf_counter() - start,
        method=type(custom).__name__ if chosen is None else chosen,
        seed=seed,
        runs=runs,
        rejected=np.asarray(rejected, dtype=float).reshape(-1, 6),
        on_bounds=space.bound_hits(final.placement),
    )


def run_seeds(seed: int, restarts: int) -> list[int]:
    """Seeds of the independent runs: ``seed`` itself, then children of it."""
    children = np.random.SeedSequence(seed).spawn(restarts - 1)
    return [seed] + [int(child.generate_state(1)[0]) for child in children]


def run_search(
    search: MultiStartSearch | Algorithm,
    problem: PlacementProblem,
    termination: Termination | tuple | None,
    method: Method | None,
    seed: int,
    driver: tuple[int | None, ProgressCallback | None, float, list[GenerationRecord]],
) -> str:
    """One run of a search from ``seed`` on ``problem``; the stop reason.

    A :class:`~trackplan.search.algorithms.MultiStartSearch` asks for arrays and is told
    fitness arrays, without pymoo (:func:`_run_arrays`), unless a pymoo ``termination``
    is given (it then runs as a pymoo Algorithm:
    :class:`~trackplan.search.pymoo_algorithms.AskTellAlgorithm`, the same draws); a pymoo
    Algorithm runs with ``termination`` or the method's stopping rules
    (:func:`~trackplan.search.algorithms.make_termination`). ``driver`` is the budget,
    the progress callback, the search's start (``time.perf_counter``) and the records,
    appended to one per generation.
    """
    if isinstance(search, MultiStartSearch):
        if termination is None:
            search.setup(seed)
            return _run_arrays(search, problem, *driver)
        from trackplan.search.pymoo_algorithms import AskTellAlgorithm

        search = AskTellAlgorithm(search)
    rules, parts = make_termination(termination, method)
    search.setup(problem, termination=rules, seed=seed)
    return _run(search, problem, parts, *driver)


def _run_arrays(
    search: MultiStartSearch,
    problem: PlacementProblem,
    budget: int | None,
    progress: ProgressCallback | None,
    start: float,
    records: list[GenerationRecord],
) -> str:
    """:func:`_run` of a search that asks for arrays: the same stopping rules (the budget,
    the search's convergence, :data:`~trackplan.search.algorithms.MAX_GENERATIONS`), the
    same records."""
    try:
        while True:
            X = search.ask()
            if X is None or len(X) == 0:
                return "converged"
            remaining = None if budget is None else budget - problem.n_evaluations
            truncated = remaining is not None and len(X) > remaining
            if truncated:
                X = X[:remaining]
            fitness = problem.screen(X)
            if not truncated:
                search.tell(fitness)
            records.append(_record(len(records) + 1, problem, fitness, start))
            if progress is not None:
                progress(records[-1])
            if budget is not None and problem.n_evaluations >= budget:
                return "budget"
            if search.converged:
                return "converged"
            if search.n_gen >= MAX_GENERATIONS:
                return "max_generations"
    except KeyboardInterrupt:
        return _interrupted(problem, start, records)


def _run(
    algorithm: Algorithm,
    problem: PlacementProblem,
    parts: dict,
    budget: int | None,
    progress: ProgressCallback | None,
    start: float,
    records: list[GenerationRecord],
) -> str:
    """Ask, evaluate, tell until a stopping rule fires, appending one record per generation
    to ``records`` (numbered on from earlier runs); the stop reason."""
    try:
        while True:
            infills = algorithm.ask()
            if infills is None or len(infills) == 0:  # the algorithm has nothing left to try
                return "converged"
            remaining = None if budget is None else budget - problem.n_evaluations
            truncated = remaining is not None and len(infills) > remaining
            if truncated:
                infills = infills[:remaining]
            algorithm.evaluator.eval(problem, infills, algorithm=algorithm)
            if not truncated:
                algorithm.tell(infills=infills)
            records.append(_record(len(records) + 1, problem, infills.get("F")[:, 0], start))
            if progress is not None:
                progress(records[-1])
            if budget is not None and problem.n_evaluations >= budget:
                return "budget"
            if getattr(algorithm, "converged", None):
                return "converged"
            if algorithm.termination.has_terminated():
                fired = [name for name, part in parts.items() if part.has_terminated()]
                return fired[0] if fired else "stall"
    except KeyboardInterrupt:
        return _interrupted(problem, start, records)


def _interrupted(problem: PlacementProblem, start: float, records: list[GenerationRecord]) -> str:
    """Inside the handler of a KeyboardInterrupt: the record of a generation evaluated but
    not yet recorded, and the stop reason ``interrupted``; re-raised before any evaluation."""
    if problem.n_evaluations == 0:
        raise
    if problem.last is not None and (
        not records or records[-1].evaluations < problem.n_evaluations
    ):
        records.append(_record(len(records) + 1, problem, problem.last.fitness, start))
    return "interrupted"


def _record(
    generation: int, problem: PlacementProblem, fitness: np.ndarray, start: float
) -> GenerationRecord:
    """The figures of the latest generation (``fitness``: its evaluated candidates', (B,))."""
    best_objective = problem.archive.objective[0] if len(problem.archive.objective) else np.nan
    return GenerationRecord(
        generation=generation,
        evaluations=problem.n_evaluations,
        best=problem.best_fitness,
        mean=float(np.mean(fitness)),
        feasible_share=float(np.mean(fitness < problem.fitness.penalty)),
        wall_time=time.perf_counter() - start,
        best_objective=float(best_objective),
    )


class _Planner:
    """:func:`plan_placement` of the case's candidates ``(x, y, z, roll, pitch, yaw[,
    spin])`` at full Ts, on ``background`` while it works, else here."""

    def __init__(
        self, case: Case, timing: str, geometry: PathGeometry, background: Executor | None
    ) -> None:
        self.case, self.timing, self.geometry = case, timing, geometry
        self.background = background

    def submit(self, X: np.ndarray, branch: int | None = None) -> Future[PlanResult] | None:
        """Start planning ``X`` in the background; None without one (or a broken one)."""
        if self.background is None:
            return None
        try:
            return self.background.submit(plan, self.case, X[:6], **self._options(X, branch))
        except BrokenExecutor:
            self.background = None
            return None

    def result(
        self, job: Future[PlanResult] | None, X: np.ndarray, branch: int | None = None
    ) -> PlanResult:
        """The plan of ``X`` submitted as ``job``, made here when the background broke."""
        if job is not None:
            try:
                return job.result()
            except BrokenExecutor:
                self.background = None
        return plan(self.case, X[:6], **self._options(X, branch))

    def plan(self, X: np.ndarray, branch: int | None = None) -> PlanResult:
        """The plan of ``X``, waited for."""
        return self.result(self.submit(X, branch), X, branch)

    def _options(self, X: np.ndarray, branch: int | None) -> dict:
        geometries = None if self.geometry is None else {(0, False): self.geometry}
        return {"timing": self.timing, "branch": branch, "geometries": geometries, "spin": X[6:]}


def _final_plan(
    problem: PlacementProblem, planner: _Planner
) -> tuple[PlanResult, list[np.ndarray]]:
    """Plan the archive's candidates best first at full Ts until one passes the checker.

    Returns the first feasible plan, or the plan of the best candidate when none passes;
    and the placements screened feasible that the check rejected.
    """
    archive = problem.archive
    rejected: list[np.ndarray] = []
    first: PlanResult | None = None
    for X, feasible, branch in zip(archive.X, archive.feasible, archive.branch, strict=True):
        if first is not None and not feasible:
            break
        plan = planner.plan(X, int(branch))
        if plan.feasible:
            return plan, rejected
        first = first or plan
        if feasible:
            rejected.append(X[:6])
    if first is None:
        raise CaseError("the search evaluated no placement (budget 0?)", key="budget")
    return first, rejected


def _message(
    final: PlanResult, problem: PlacementProblem, rejected: list, space: SearchSpace
) -> str:
    """One line on the outcome."""
    n = problem.n_evaluations
    if final.feasible:
        note = (
            f" ({len(rejected)} better screened candidates failed the final check)"
            if rejected
            else ""
        )
        return (
            f"feasible placement found in {n} evaluations: J = {final.objective:.4f}, "
            f"duration {final.duration:.3f} s, branch {final.branch}{note}"
        )
    return (
        f"no feasible placement in {n} evaluations; the closest, "
        f"{space.describe(final.placement)}: {final.message}"
    )
