"""The search loop: run one search method on a problem, one record per generation.

:func:`run_search` drives a :class:`~trackplan.search.multistart.MultiStartSearch` (asked
for arrays) or a pymoo ``Algorithm`` (ask/tell) on a
:class:`~trackplan.search.problem.PlacementProblem`, honours the evaluation budget exactly,
reports each generation (:class:`GenerationRecord`) and stops cleanly on Ctrl-C.
"""

from __future__ import annotations

import enum
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import numpy as np

from trackplan.choices import Method
from trackplan.run_files import HISTORY_KEYS
from trackplan.search.algorithms import MAX_GENERATIONS, make_termination
from trackplan.search.multistart import MultiStartSearch
from trackplan.search.problem import PlacementProblem

if TYPE_CHECKING:  # pymoo's Algorithm is imported by the methods that run as one only
    from pymoo.core.algorithm import Algorithm
    from pymoo.core.termination import Termination


class StopReason(enum.StrEnum):
    """Why a run of a search stopped (the words of ``optimizer.stop_reason`` in result.json)."""

    STALL = "stall"
    """The best fitness stalled (the MATLAB stall test)."""
    MAX_GENERATIONS = "max_generations"
    """The generation limit."""
    BUDGET = "budget"
    """The evaluation budget."""
    CONVERGED = "converged"
    """The method's own convergence (CMA-ES, the local runs of multistart)."""
    INTERRUPTED = "interrupted"
    """A signal (Ctrl-C)."""
    CUSTOM = "custom"
    """A pymoo termination given by the caller."""


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


ProgressCallback = Callable[[GenerationRecord], None]
"""Called after every generation; raising KeyboardInterrupt stops the search."""


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
) -> StopReason:
    """One run of a search from ``seed`` on ``problem``; the stop reason.

    A :class:`~trackplan.search.multistart.MultiStartSearch` asks for arrays and is told
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
) -> StopReason:
    """:func:`_run` of a search that asks for arrays: the same stopping rules (the budget,
    the search's convergence, :data:`~trackplan.search.algorithms.MAX_GENERATIONS`), the
    same records."""
    try:
        while True:
            X = search.ask()
            if X is None or len(X) == 0:
                return StopReason.CONVERGED
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
                return StopReason.BUDGET
            if search.converged:
                return StopReason.CONVERGED
            if search.n_gen >= MAX_GENERATIONS:
                return StopReason.MAX_GENERATIONS
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
) -> StopReason:
    """Ask, evaluate, tell until a stopping rule fires, appending one record per generation
    to ``records`` (numbered on from earlier runs); the stop reason."""
    try:
        while True:
            infills = algorithm.ask()
            if infills is None or len(infills) == 0:  # the algorithm has nothing left to try
                return StopReason.CONVERGED
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
                return StopReason.BUDGET
            if getattr(algorithm, "converged", None):
                return StopReason.CONVERGED
            if algorithm.termination.has_terminated():
                fired = [name for name, part in parts.items() if part.has_terminated()]
                return StopReason(fired[0]) if fired else StopReason.STALL
    except KeyboardInterrupt:
        return _interrupted(problem, start, records)


def _interrupted(
    problem: PlacementProblem, start: float, records: list[GenerationRecord]
) -> StopReason:
    """Inside the handler of a KeyboardInterrupt: the record of a generation evaluated but
    not yet recorded, and the stop reason ``interrupted``; re-raised before any evaluation."""
    if problem.n_evaluations == 0:
        raise
    if problem.last is not None and (
        not records or records[-1].evaluations < problem.n_evaluations
    ):
        records.append(_record(len(records) + 1, problem, problem.last.fitness, start))
    return StopReason.INTERRUPTED


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
