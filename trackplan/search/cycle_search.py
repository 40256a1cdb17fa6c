"""One placement for every seam of a workpiece: the batched fitness and the search.

The decision vector holds the 6 placement variables, then each seam's spin variables in the
order written (:meth:`trackplan.tool.ToolSpec.spin_bounds` of the seam's tool: one for
``spin: free``, the profile's for ``free-varying``, none for ``fixed``;
:func:`cycle_space`). The fitness of a batch of B candidates screens every seam on its own
screening grid with the single-path screening
(:meth:`trackplan.search.fitness.PlacementFitness.screen_branches`, each call batched over
the whole population and every IK branch, on the placement and the seam's own slice of spin
variables), keeps per seam and candidate the branch clear of the cell with the least J, and
adds the moves between the seams: per candidate the best sequence
(:func:`trackplan.planning.sequence.best_sequence`) on the estimated air moves between the
seams' end configurations on the screening grid
(:func:`trackplan.timing.airmove.air_time_estimate`; a reversed seam on the same branch
swaps its ends). A candidate is feasible only if every seam is.

Fitness (minimised)
-------------------
- feasible: ``Σ_seams (J + w·T_low) + air``, ``J`` Eq. 8 on each seam's screening grid,
  ``T_low`` the duration bound of :mod:`trackplan.search.fitness`, ``w`` the time weight,
  and ``air`` the sequence's estimated moves, each costing ``Σ C_i |Δq_i| + w·T_air``;
- infeasible: ``M + v`` (graded) or ``M`` (flat), ``v`` the largest graded violation over
  the seams (the scale of :mod:`trackplan.search.fitness`).

The search runs the case's method on this fitness (:class:`PlacementProblem`, the same
algorithms, stopping rules and archive as a single path), then plans the archive's
candidates best first with :func:`trackplan.planning.cycle.plan_cycle` until one passes the
checker, each seam with its screened branch and its chosen spin (a profile reversed with
the seam when the sequence welds it end to start, :func:`trackplan.planning.cycle.seam_spin`).
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from trackplan.case import Case
from trackplan.choices import Method, choose
from trackplan.errors import CaseError
from trackplan.planning.plan import plan as plan_cycle
from trackplan.planning.result import PlanResult as CycleResult
from trackplan.planning.seams import SeamGeometries, SeamSpin, seam_geometries
from trackplan.planning.sequence import best_sequence
from trackplan.search.algorithms import DEFAULT_RESTARTS, make_algorithm
from trackplan.search.fitness import (
    REACH_LEVEL,
    REACH_SCALE,
    Finding,
    PlacementFitness,
    Screening,
)
from trackplan.search.optimize import GenerationRecord, SearchHistory, run_search, run_seeds
from trackplan.search.problem import PlacementProblem
from trackplan.search.space import N_VAR, BoundHit, SearchSpace
from trackplan.status import Status
from trackplan.timing import time_law
from trackplan.timing.airmove import air_time_estimate

FINAL_TRIES = 4
"""Archive candidates planned in full, best first, before the search gives up on them."""
POSE_SPACING = 0.005
"""Screening grid spacing along each seam, m (about that of a single 0.8 m path's 150
poses); short seams need far fewer poses than :data:`~trackplan.search.fitness.SCREEN_POSES`."""
MIN_POSES = 20
"""Fewest poses of a seam's screening grid."""


def spin_slices(case: Case) -> tuple[slice, ...]:
    """Where each seam's spin variables lie in the decision vector (as written; an empty
    slice for a fixed spin)."""
    slices = []
    first = N_VAR
    for seam in case.seams:
        slices.append(slice(first, first + seam.task.tool.n_spin))
        first += seam.task.tool.n_spin
    return tuple(slices)


def cycle_space(case: Case) -> SearchSpace:
    """The search space of a case with several seams: the placement (its bounds and reach
    shell), then each seam's spin variables (their box, :meth:`ToolSpec.spin_bounds`)."""
    space = SearchSpace.from_bounds(case.bounds, case.source)
    tools = [seam.task.tool for seam in case.seams if seam.task.tool.n_spin]
    if not tools:
        return space
    bounds = [tool.spin_bounds() for tool in tools]
    return SearchSpace(
        np.concatenate([space.lower, *(lower for lower, _ in bounds)]),
        np.concatenate([space.upper, *(upper for _, upper in bounds)]),
        space.reach,
        np.concatenate([space.anchor, *(tool.default_variables() for tool in tools)]),
    )


@dataclass(frozen=True, eq=False)
class SeamScreen:
    """Every seam of B candidates on its chosen branch.

    Attributes
    ----------
    ok
        Shape (m, B), bool: the seam has a feasible branch clear of the cell.
    objective
        J of each seam on its branch, shape (m, B) (inf where not ``ok``).
    bound
        Duration bound of each seam, shape (m, B), s.
    branch
        Chosen branch, shape (m, B), int.
    violation, finding
        Graded violation and :class:`Finding` per seam, shape (m, B).
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


class CycleFitness:
    """The batched fitness of one placement for every seam (see the module docstring).

    Parameters
    ----------
    case
        The case (with ``cycle``).
    space
        Its search space (:func:`cycle_space`: the placement, then each seam's spin).
    geometries
        The seams' paths (:func:`trackplan.planning.cycle.seam_geometries`).
    timing
        The time law.

    Attributes
    ----------
    feasible_count
        How many evaluated candidates reach each seam feasibly, shape (m,), int.
    slices
        Each seam's spin variables in the decision vector (:func:`spin_slices`).
    """

    def __init__(self, case: Case, space: SearchSpace, geometries: SeamGeometries, timing: str):
        self.case = case
        self.space = space
        self.seams = [
            PlacementFitness(
                case.seam_case(i),
                space,
                geometries[i, False],
                timing,
                n_poses=max(
                    MIN_POSES,
                    int(np.ceil(geometries[i, False].planned.length / POSE_SPACING)) + 1,
                ),
            )
            for i in range(len(case.seams))
        ]
        self.penalty = float(case.objective.flat_penalty)
        self.flat = self.seams[0].flat
        self.time_weight = float(case.objective.time_weight)
        self.weights = np.asarray(case.objective.weights, dtype=float)
        self.reversible = np.array([seam.reversible for seam in case.seams])
        self.home = case.sequencing.home
        self.feasible_count = np.zeros(len(case.seams), dtype=int)
        self.slices = spin_slices(case)
        if space.n_var != self.slices[-1].stop:
            raise ValueError(
                f"the search space has {space.n_var} variables, the seams need "
                f"{self.slices[-1].stop} (use cycle_space)"
            )

    def full(self, X: np.ndarray) -> np.ndarray:
        """Candidates (B, n_var); placements alone (B, 6) get every free spin in the middle
        of its range."""
        X = np.atleast_2d(np.asarray(X, dtype=float))
        if X.shape[1] == N_VAR and self.space.n_var > N_VAR:
            X = np.hstack([X, np.tile(self.space.anchor[N_VAR:], (len(X), 1))])
        return X

    def seam_spins(self, X: np.ndarray) -> tuple[SeamSpin, ...]:
        """Each seam's spin variables of one candidate X (n_var,), None for a fixed spin."""
        X = self.full(X)[0]
        return tuple(X[part] if part.stop > part.start else None for part in self.slices)

    def screen_seams(self, X: np.ndarray) -> SeamScreen:
        """Screen every seam of candidates inside the reach interval.

        Parameters
        ----------
        X
            Candidates, shape (B, n_var): placements (metres and radians), then the
            seams' spin variables.

        Returns
        -------
        SeamScreen
        """
        X = self.full(X)
        rows = np.arange(len(X))
        parts = []
        for fitness, part in zip(self.seams, self.slices, strict=True):
            screen = fitness.screen_branches(np.hstack([X[:, :N_VAR], X[:, part]]))
            values = screen.values(fitness.case.objective)
            violation = screen.violation
            finding = screen.finding
            if fitness.cell is not None:
                values, violation = fitness._screen_cell(
                    X[:, :N_VAR], screen.grid.q, values, violation
                )
                blocked = np.isinf(values) & screen.ok
                finding = np.where(blocked, int(Finding.COLLISION), finding)
            ok = np.isfinite(values).any(axis=1)
            choice = np.where(ok, np.argmin(values, axis=1), np.argmin(violation, axis=1))
            q = screen.grid.q[rows, choice]  # (B, M, n)
            parts.append(
                (
                    ok,
                    np.where(ok, values[rows, choice], np.inf),
                    screen.grid.dt[rows, choice].sum(axis=1),
                    screen.branches[choice],
                    np.where(ok, 0.0, violation[rows, choice]),
                    np.where(ok, int(Finding.FEASIBLE), finding[rows, choice]),
                    q[:, 0],
                    q[:, -1],
                )
            )
        return SeamScreen(*(np.stack(column) for column in zip(*parts, strict=True)))

    def air_cost(self, seams: SeamScreen, b: int) -> float:
        """Estimated cost of the moves of candidate ``b`` in its best sequence: per move
        ``Σ C_i |Δq_i| + w · T``, plus each seam's own cost."""
        ends = np.stack([seams.q_first[:, b], seams.q_last[:, b]], axis=1)  # (m, 2, n)
        q_in = ends  # forward starts at the first end, reversed at the last
        q_out = ends[:, ::-1]
        air = self._move(q_out[:, :, None, None], q_in[None, None])
        m = len(self.seams)
        seam_cost = np.zeros((m, 2))
        if self.home is None:
            start = np.zeros((m, 2))
            end = np.zeros((m, 2))
        else:
            start = self._move(self.home, q_in)
            end = self._move(q_out, self.home)
        return best_sequence(seam_cost, air, start, end, self.reversible).cost

    def _move(self, q_from: np.ndarray, q_to: np.ndarray) -> np.ndarray:
        robot = self.case.robot
        travel = np.sum(self.weights * np.abs(q_to - q_from), axis=-1)
        if self.time_weight == 0.0:
            return np.asarray(travel)
        duration = air_time_estimate(q_from, q_to, robot.v_max, robot.a_max, robot.j_max)
        return np.asarray(travel + self.time_weight * duration)

    def evaluate(self, X: np.ndarray, incumbent: float = np.inf) -> Screening:
        """Fitness of a batch of candidates.

        Parameters
        ----------
        X
            Candidates, shape (B, n_var) (placements alone, (B, 6): every free spin in the
            middle of its range).
        incumbent
            Unused (every feasible candidate is ranked by its screening figures).

        Returns
        -------
        Screening
            ``objective`` is Σ J of the seams on their screening grids, ``duration_bound``
            the sum of their bounds; ``branch`` the first seam's branch.
        """
        X = self.full(X)
        n = len(X)
        fitness = np.full(n, np.nan)
        objective = np.full(n, np.nan)
        bound = np.full(n, np.nan)
        branch = np.zeros(n, dtype=int)
        excess = self.space.reach_excess(X)
        violation = REACH_LEVEL + excess / REACH_SCALE
        finding = np.full(n, int(Finding.REACH))
        inside = np.flatnonzero(excess == 0.0)
        if len(inside):
            seams = self.screen_seams(X[inside])
            self.feasible_count += seams.ok.sum(axis=1)
            all_ok = seams.ok.all(axis=0)
            worst = np.argmax(seams.violation, axis=0)
            violation[inside] = seams.violation.max(axis=0)
            finding[inside] = seams.finding[worst, np.arange(len(inside))]
            branch[inside] = seams.branch[0]
            for k in np.flatnonzero(all_ok):
                b = inside[k]
                air = self.air_cost(seams, int(k))
                bound[b] = seams.bound[:, k].sum()
                objective[b] = seams.objective[:, k].sum()
                fitness[b] = objective[b] + self.time_weight * bound[b] + air
            finding[inside[all_ok]] = int(Finding.FEASIBLE)
        feasible = finding == Finding.FEASIBLE
        violation[feasible] = 0.0
        fitness[~feasible] = self.penalty + (0.0 if self.flat else violation[~feasible])
        return Screening(
            X,
            fitness,
            objective,
            np.full(n, np.nan),
            bound,
            feasible,
            branch,
            violation,
            finding,
        )

    def branches(self, X: np.ndarray) -> tuple[int, ...]:
        """The branch the screening chooses for each seam at one candidate X (n_var,)."""
        seams = self.screen_seams(np.asarray(X, dtype=float)[None])
        return tuple(int(b) for b in seams.branch[:, 0])

    def unreachable_seams(self) -> tuple[str, ...]:
        """Seams that no evaluated candidate reached feasibly, by name."""
        names = self.case.seams
        return tuple(names[i].name for i in np.flatnonzero(self.feasible_count == 0))


@dataclass(frozen=True, eq=False)
class CycleSearchResult:
    """Outcome of :func:`optimize_cycle`.

    Attributes
    ----------
    success, status, message
        As for :class:`~trackplan.search.optimize.OptimizeResult`; the message names the
        seam that decides when nothing feasible was found.
    X
        Best placement, shape (6,).
    spins
        The spin variables chosen for each seam (as written), None for a fixed spin; the
        final cycle's seam plans hold the profiles.
    fitness
        Its screened fitness.
    objective
        J of the final cycle (Eq. 8 over every sample).
    final
        The cycle planned at X (:class:`~trackplan.planning.cycle.CycleResult`).
    history, evaluations, generations, stop_reason, wall_time_s, method, seed, runs
        As for a single path.
    unreachable
        Seams no evaluated placement reached, by name.
    rejected
        Candidates screened feasible whose full cycle failed the check, shape (R, 6).
    on_bounds
        The variables of X on a bound of the search box
        (:meth:`~trackplan.search.space.SearchSpace.bound_hits`).
    """

    success: bool
    status: Status
    message: str
    X: np.ndarray
    fitness: float
    objective: float
    final: CycleResult
    history: SearchHistory
    evaluations: int
    generations: int
    stop_reason: str
    wall_time_s: float
    method: str
    seed: int
    runs: int = 1
    unreachable: tuple[str, ...] = ()
    rejected: np.ndarray = field(default_factory=lambda: np.zeros((0, 6)))
    on_bounds: tuple[BoundHit, ...] = ()
    spins: tuple[SeamSpin, ...] = ()


def optimize_cycle(
    case: Case,
    *,
    method: str | Method | None = None,
    seed: int | None = None,
    budget: int | None = None,
    progress: Callable[[GenerationRecord], None] | None = None,
    timing: str | None = None,
    restarts: int | None = None,
) -> CycleSearchResult:
    """Search one placement X for every seam of the case, with the best sequence.

    Parameters
    ----------
    case
        A case with several seams (``paths:``).
    method, seed, budget, progress, timing, restarts
        As for :func:`trackplan.search.optimize.optimize_placement`.

    Returns
    -------
    CycleSearchResult

    Raises
    ------
    CaseError
        For an unknown method or timing, a negative budget or seed, or bounds with no
        placement inside the reach interval.
    """
    start = time.perf_counter()
    method = choose(Method, method or case.optimizer.method, "method")
    seed = case.optimizer.seed if seed is None else int(seed)
    budget = case.optimizer.budget if budget is None else int(budget)
    restarts = case.optimizer.restarts if restarts is None else restarts
    restarts = int(DEFAULT_RESTARTS[method] if restarts is None else restarts)
    if seed < 0:
        raise CaseError(f"seed must be ≥ 0, got {seed}", key="seed")
    if budget is not None and budget < 1:
        raise CaseError(f"budget must be ≥ 1 evaluation, got {budget}", key="budget")
    law = time_law(timing or case.task.timing)
    space = cycle_space(case)
    geometries = seam_geometries(case, law.timing)
    fitness = CycleFitness(case, space, geometries, law.timing)
    problem = PlacementProblem(space, fitness)
    records: list[GenerationRecord] = []
    stop_reason = ""
    runs = 0
    for run_seed in run_seeds(seed, restarts):
        search = make_algorithm(method, space, case.optimizer.population)
        driver = (budget, progress, start, records)
        stop_reason = run_search(search, problem, None, method, run_seed, driver)
        runs += 1
        if stop_reason in ("budget", "interrupted"):
            break
    final, chosen, rejected, fitness_value = _final_cycle(
        case, problem, fitness, law.timing, geometries
    )
    unreachable = fitness.unreachable_seams()
    status = Status.INTERRUPTED if stop_reason == "interrupted" else final.status
    return CycleSearchResult(
        success=status is Status.FEASIBLE,
        status=status,
        message=_message(final, problem.n_evaluations, unreachable, rejected),
        X=final.placement,
        fitness=fitness_value,
        objective=float(final.objective),
        final=final,
        history=SearchHistory.from_records(records),
        evaluations=problem.n_evaluations,
        generations=len(records),
        stop_reason=stop_reason,
        wall_time_s=time.perf_counter() - start,
        method=str(method),
        seed=seed,
        runs=runs,
        unreachable=unreachable,
        rejected=np.asarray(rejected, dtype=float).reshape(-1, 6),
        spins=fitness.seam_spins(chosen),
        on_bounds=space.bound_hits(final.placement),
    )


def _final_cycle(
    case: Case,
    problem: PlacementProblem,
    fitness: CycleFitness,
    timing: str,
    geometries: SeamGeometries,
) -> tuple[CycleResult, np.ndarray, list[np.ndarray], float]:
    """Plan the archive's candidates best first until a cycle passes the checker (at most
    :data:`FINAL_TRIES` screened feasible ones); the cycle, its candidate (n_var,), the
    rejected placements and the chosen candidate's screened fitness."""
    archive = problem.archive
    if not len(archive.X):
        raise CaseError("the search evaluated no placement (budget 0?)", key="budget")
    rejected: list[np.ndarray] = []
    first: tuple[CycleResult, np.ndarray, float] | None = None
    for X, feasible, value in zip(archive.X, archive.feasible, archive.fitness, strict=True):
        if first is not None and (not feasible or len(rejected) >= FINAL_TRIES):
            break
        cycle = plan_cycle(
            case,
            X[:N_VAR],
            timing=timing,
            geometries=geometries,
            branches=fitness.branches(X),
            spins=fitness.seam_spins(X),
        )
        if cycle.success:
            return cycle, X, rejected, float(value)
        first = first or (cycle, X, float(value))
        if feasible:
            rejected.append(X[:N_VAR])
    assert first is not None
    return first[0], first[1], rejected, first[2]


def _message(
    final: CycleResult, evaluations: int, unreachable: tuple[str, ...], rejected: list
) -> str:
    """One line on the outcome."""
    if final.success:
        note = (
            f" ({len(rejected)} better screened candidates failed the full check)"
            if rejected
            else ""
        )
        return (
            f"feasible placement for all {len(final.seams)} seams found in {evaluations} "
            f"evaluations: cycle time {final.duration:.3f} s (air {final.air_time:.3f} s), "
            f"J = {final.objective:.4f}{note}"
        )
    if unreachable:
        return (
            f"seam {unreachable[0]} is feasible at none of the {evaluations} placements "
            f"evaluated; at the closest: {final.message}"
        )
    return f"no feasible placement for every seam in {evaluations} evaluations: {final.message}"
