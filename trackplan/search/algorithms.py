"""The placement optimisers: a pymoo Algorithm and a Termination per method.

- ``ga``: the paper's MATLAB GA configuration through pymoo's GeneticAlgorithm with the
  operators of :mod:`trackplan.search.operators`;
- ``cmaes``: CMA-ES of the ``cma`` package (Hansen's reference implementation) behind
  pymoo's ask/tell interface, on the bounds scaled to [0, 1]; cma's BoundTransform keeps
  samples in the box and the graded penalty of the fitness handles the reach constraint;
- ``de``: pymoo's differential evolution, DE/rand/1/bin, with the reach repair;
- ``random``: uniform admissible sampling in batches (pymoo's RandomSearch), the baseline.

Every method evaluates ``population`` candidates per generation and stops on the same
rules: the MATLAB stall test, 100 × 6 generations, or the evaluation budget (the driver);
CMA-ES also stops when cma's own criteria say it has converged.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from pymoo.algorithms.base.genetic import GeneticAlgorithm
from pymoo.algorithms.soo.nonconvex.de import DE
from pymoo.algorithms.soo.nonconvex.random_search import RandomSearch
from pymoo.core.algorithm import Algorithm
from pymoo.core.population import Population
from pymoo.core.termination import TerminateIfAny, Termination
from pymoo.termination import get_termination
from pymoo.termination.max_gen import MaximumGenerationTermination

from trackplan.errors import CaseError
from trackplan.search.operators import (
    AdaptiveFeasibleMutation,
    AdmissibleSampling,
    EliteSurvival,
    MatlabMating,
    ReachRepair,
    ScatteredCrossover,
    StallTermination,
    StochasticUniformSelection,
    elite_count,
)
from trackplan.search.space import N_VAR, SearchSpace

"""Placement search methods."""
CROSSOVER_FRACTION = 0.8
"""MATLAB's CrossoverFraction as the paper sets it."""
STALL_GENERATIONS = 50
"""MATLAB's MaxStallGenerations (default, as in the paper)."""
FUNCTION_TOLERANCE = 1e-3
"""MATLAB's FunctionTolerance as the paper sets it."""
MAX_GENERATIONS = 100 * N_VAR
"""MATLAB's default MaxGenerations, 100 × number of variables."""
CMA_SIGMA = 0.3
"""Initial CMA-ES step size, as a share of each variable's range."""
DE_CR = 0.7
"""DE crossover rate."""
DE_F = 0.8
"""DE differential weight."""


def make_algorithm(method: str, space: SearchSpace, population: int) -> Algorithm:
    """The pymoo Algorithm of a method (seeded by ``setup(problem, seed=...)``).

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
    if method == "cmaes":
        return CMAESearch(space, population)
    if method == "random":
        return RandomSearch(n_points_per_iteration=population, sampling=sampling)
    raise CaseError(f"unknown method {method!r}", key="method")


def make_termination(
    termination: Termination | tuple | None = None,
) -> tuple[Termination, dict[str, Termination]]:
    """The stopping rules every method shares (the budget is the driver's).

    Parameters
    ----------
    termination
        A pymoo ``Termination`` or a ``get_termination`` tuple (``("n_gen", 50)``) to use
        instead of the default stall and generation rules; it is reported as ``custom``.

    Returns
    -------
    tuple
        The combined termination, and its parts by stop reason (``stall``,
        ``max_generations``) to tell which one fired.
    """
    if termination is not None:
        if isinstance(termination, tuple):
            termination = get_termination(*termination)
        return termination, {"custom": termination}
    parts: dict[str, Termination] = {
        "stall": StallTermination(STALL_GENERATIONS, FUNCTION_TOLERANCE),
        "max_generations": MaximumGenerationTermination(MAX_GENERATIONS),
    }
    return TerminateIfAny(*parts.values()), parts


class CMAESearch(Algorithm):
    """CMA-ES (the ``cma`` package) on the bounds scaled to [0, 1], behind ask/tell.

    The start is a uniform admissible sample, the step size :data:`CMA_SIGMA`; cma draws
    its normal samples from the algorithm's seeded generator (its ``randn`` option), so no
    global random state is touched.

    Parameters
    ----------
    space
        The admissible placements.
    population
        λ, candidates per generation.

    Attributes
    ----------
    converged
        cma's stop criteria that fired (empty while it runs).
    """

    def __init__(self, space: SearchSpace, population: int, **kwargs: object):
        super().__init__(**kwargs)
        self.space = space
        self.population = population
        self.es: Any = None
        self.converged: dict = {}
        self._asked: list[np.ndarray] = []

    def _setup(self, problem: object, **kwargs: object) -> None:
        import cma

        rng = self.random_state
        x0 = (self.space.sample(rng, 1)[0] - self.space.lower) / self.space.span
        options = {
            "bounds": [0.0, 1.0],
            "popsize": self.population,
            "randn": lambda *shape: rng.standard_normal(shape),
            "seed": math.nan,
            "verbose": -9,
            "verb_log": 0,
            "verb_disp": 0,
            "maxiter": math.inf,
        }
        self.es = cma.CMAEvolutionStrategy(x0, CMA_SIGMA, options)

    def _initialize_infill(self) -> Population:
        return self._infill()

    def _infill(self) -> Population:
        self._asked = self.es.ask()
        Z = np.clip(np.asarray(self._asked), 0.0, 1.0)
        return Population.new("X", self.space.lower + Z * self.space.span)

    def _initialize_advance(self, infills: Population | None = None, **kwargs: object) -> None:
        self._advance(infills)

    def _advance(self, infills: Population | None = None, **kwargs: object) -> None:
        if infills is None:
            raise ValueError("CMAESearch follows ask/tell: tell it the evaluated infills")
        self.es.tell(self._asked, infills.get("F")[:, 0].tolist())
        self.pop = infills
        self.converged = dict(self.es.stop())
