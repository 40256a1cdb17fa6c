"""The placement optimisers: the search of each method and the stopping rules they share.

- ``multistart`` (the default): uniform admissible samples, then local CMA-ES runs (the
  ``cmaes`` package) from the best mutually distant ones, side by side in one batch per
  generation, the runs that fall behind the leader stopped early (a race). The fitness has
  a few valleys (IK branches, placements mirrored about the base); sampling finds them all
  and short local runs descend each, which reaches the best known J on every shipped case
  and seed where a single global run stops in whichever valley it first entered
  (``docs/search.md``). It imports neither ``cma`` nor matplotlib (``import cma`` alone
  takes about 2 s), nor pymoo's ``Algorithm`` (:class:`MultiStartSearch` asks for arrays
  and is told fitness arrays; the driver evaluates them without pymoo's populations);
- ``ga``: the paper's MATLAB GA configuration through pymoo's GeneticAlgorithm with the
  operators of :mod:`trackplan.search.operators`;
- ``cmaes``: CMA-ES of the ``cma`` package (Hansen's reference implementation) behind
  pymoo's ask/tell interface, on the bounds scaled to [0, 1]; cma's BoundTransform keeps
  samples in the box and the graded penalty of the fitness handles the reach constraint
  (:class:`~trackplan.search.pymoo_algorithms.CMAESearch`);
- ``de``: pymoo's differential evolution, DE/rand/1/bin, with the reach repair;
- ``random``: uniform admissible sampling in batches (pymoo's RandomSearch), the baseline.

Every method but ``multistart`` evaluates ``population`` candidates per generation and
stops on the same rules: the MATLAB stall test, 100 × 6 generations, or the evaluation
budget (the driver); CMA-ES also stops when cma's own criteria say it has converged.
``multistart`` stops when its last local run has converged, after 100 × 6 generations or
on the budget. pymoo's ``Algorithm`` and terminations are imported by the methods that
use them only (0.1 s of an ``optimize`` run's start).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from trackplan.choices import Method
from trackplan.errors import CaseError
from trackplan.search.multistart import MultiStartSearch
from trackplan.search.space import N_VAR, SearchSpace

if TYPE_CHECKING:  # pymoo's Algorithm is imported by the methods that run as one only
    from pymoo.core.algorithm import Algorithm
    from pymoo.core.termination import Termination

CROSSOVER_FRACTION = 0.8
"""MATLAB's CrossoverFraction as the paper sets it."""
STALL_GENERATIONS = 50
"""MATLAB's MaxStallGenerations (default, as in the paper)."""
FUNCTION_TOLERANCE = 1e-3
"""MATLAB's FunctionTolerance as the paper sets it."""
MAX_GENERATIONS = 100 * N_VAR
"""MATLAB's default MaxGenerations, 100 × number of variables."""
DE_CR = 0.7
"""DE crossover rate."""
DE_F = 0.8
"""DE differential weight."""
DEFAULT_RESTARTS = {
    Method.MULTISTART: 1,
    Method.GA: 6,
    Method.CMAES: 6,
    Method.DE: 6,
    Method.RANDOM: 1,
}
"""Independent runs per method when the case does not say (GA: what the paper cases need
to land within 2 % of the best known J on every seed)."""


def make_algorithm(
    method: str, space: SearchSpace, population: int
) -> MultiStartSearch | Algorithm:
    """The search of a method: :class:`MultiStartSearch` (seeded by ``setup(seed)``) or a
    pymoo Algorithm (seeded by ``setup(problem, seed=...)``).

    Parameters
    ----------
    method
        A :class:`trackplan.choices.Method`.
    space
        The admissible placements.
    population
        Candidates per generation.

    Raises
    ------
    CaseError
        For an unknown method or a population below 2.
    """
    if population < 2:
        raise CaseError(f"population must be ≥ 2, got {population}", key="optimizer.population")
    if method == "cmaes":
        from trackplan.search.pymoo_algorithms import CMAESearch

        return CMAESearch(space, population)
    if method == "multistart":
        return MultiStartSearch(space)
    # the population methods' operators and pymoo classes, imported for them only
    from pymoo.algorithms.base.genetic import GeneticAlgorithm
    from pymoo.algorithms.soo.nonconvex.de import DE
    from pymoo.algorithms.soo.nonconvex.random_search import RandomSearch

    from trackplan.search.operators import (
        AdaptiveFeasibleMutation,
        AdmissibleSampling,
        EliteSurvival,
        MatlabMating,
        ReachRepair,
        ScatteredCrossover,
        StochasticUniformSelection,
        elite_count,
    )

    sampling = AdmissibleSampling(space)
    if method == "ga":
        n_elite = elite_count(population)
        return GeneticAlgorithm(
            pop_size=population,
            sampling=sampling,
            mating=MatlabMating(
                StochasticUniformSelection(),
                ScatteredCrossover(),
                AdaptiveFeasibleMutation(space),
                CROSSOVER_FRACTION,
                ReachRepair(space),
            ),
            survival=EliteSurvival(n_elite),
            n_offsprings=population - n_elite,
            eliminate_duplicates=False,
        )
    if method == "de":
        return DE(
            pop_size=population,
            sampling=sampling,
            variant="DE/rand/1/bin",
            CR=DE_CR,
            F=DE_F,
            repair=ReachRepair(space),
        )
    if method == "random":
        return RandomSearch(n_points_per_iteration=population, sampling=sampling)
    raise CaseError(f"unknown method {method!r}", key="method")


def make_termination(
    termination: Termination | tuple | None = None, method: Method | None = None
) -> tuple[Termination, dict[str, Termination]]:
    """The stopping rules every method shares (the budget is the driver's).

    Parameters
    ----------
    termination
        A pymoo ``Termination`` or a ``get_termination`` tuple (``("n_gen", 50)``) to use
        instead of the default stall and generation rules; it is reported as ``custom``.
    method
        The method; ``multistart`` has no stall rule (its local runs stop themselves).

    Returns
    -------
    tuple
        The combined termination, and its parts by stop reason (``stall``,
        ``max_generations``) to tell which one fired.
    """
    from pymoo.core.termination import TerminateIfAny
    from pymoo.termination.max_gen import MaximumGenerationTermination

    if termination is not None:
        if isinstance(termination, tuple):
            from pymoo.termination import get_termination

            termination = get_termination(*termination)
        return termination, {"custom": termination}
    parts: dict[str, Termination] = {
        "max_generations": MaximumGenerationTermination(MAX_GENERATIONS),
    }
    if method is not Method.MULTISTART:
        from trackplan.search.operators import StallTermination

        parts["stall"] = StallTermination(STALL_GENERATIONS, FUNCTION_TOLERANCE)
    return TerminateIfAny(*parts.values()), parts
