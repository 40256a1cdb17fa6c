"""pymoo operators that reproduce the paper's MATLAB GA (Section 4) and keep X admissible.

MATLAB's ``ga`` with the paper's options, step by step (``stepGA``), and where it lives here:

- fitness scaling ``fitscalingrank``: expectation ∝ 1/√rank, scaled to the number of
  parents (:func:`rank_scaled_expectation`);
- selection ``selectionstochunif``: stochastic uniform sampling on that expectation
  (:func:`stochastic_uniform`, :class:`StochasticUniformSelection`);
- elite count ``ceil(0.05 · population)``, crossover fraction 0.8 of the other children,
  parents shuffled, crossover children from consecutive pairs and mutation children from
  the remaining parents (:class:`MatlabMating`); the next generation is the elites plus
  the children (:class:`EliteSurvival`);
- crossover ``crossoverscattered``: each gene from either parent with probability ½
  (:class:`ScatteredCrossover`);
- mutation ``mutationadaptfeasible`` (the default for bounded problems):
  :class:`AdaptiveFeasibleMutation`, an adaptive step along a random direction,
  shortened until the child is admissible;
- stopping: ``MaxStallGenerations = 50`` with ``FunctionTolerance = 1e-3`` (MATLAB's
  ``totalChange`` stall test, :class:`StallTermination`), ``MaxGenerations = 100 · n``.

The reach constraint (Eq. 32) is kept by construction: the initial population is sampled
by rejection (:class:`AdmissibleSampling`), mutation only makes admissible children and
crossover children are repaired (:class:`ReachRepair`).
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from pymoo.core.crossover import Crossover
from pymoo.core.infill import InfillCriterion
from pymoo.core.mutation import Mutation
from pymoo.core.population import Population
from pymoo.core.problem import Problem
from pymoo.core.repair import Repair
from pymoo.core.sampling import Sampling
from pymoo.core.selection import Selection
from pymoo.core.survival import Survival
from pymoo.core.termination import Termination

from trackplan.search.space import SearchSpace

MIN_STEP = math.sqrt(np.finfo(float).eps)
"""Smallest mutation step, as a share of each variable's range (MATLAB: sqrt(eps))."""
STEP_FACTOR = 4.0
"""Mutation step growth after an improving generation and shrink after a stalled one."""
_SHORTENINGS = 30
"""Halvings of a mutation step before the parent is kept unchanged."""


def _generator(random_state: np.random.Generator | None) -> np.random.Generator:
    """The generator pymoo passes (the algorithm's seeded ``random_state``)."""
    if random_state is None:
        raise ValueError("the operators draw from the algorithm's seeded random_state, got None")
    return random_state


def rank_scaled_expectation(fitness: np.ndarray, n_parents: int) -> np.ndarray:
    """MATLAB's ``fitscalingrank``: expected number of selections per individual.

    The individual of rank r (1 = best, ties in order of appearance) gets an expectation
    proportional to ``1/√r``; the expectations sum to ``n_parents``.

    Parameters
    ----------
    fitness
        Shape (N,), lower is better.
    n_parents
        Number of parents to be selected.

    Returns
    -------
    numpy.ndarray
        Shape (N,).
    """
    order = np.argsort(fitness, kind="stable")
    rank = np.empty(len(fitness))
    rank[order] = np.arange(1, len(fitness) + 1)
    raw = 1.0 / np.sqrt(rank)
    return n_parents * raw / raw.sum()


def stochastic_uniform(
    expectation: np.ndarray, n_select: int, rng: np.random.Generator
) -> np.ndarray:
    """MATLAB's ``selectionstochunif``: one random offset, then equal steps along the wheel.

    The individuals are laid out on a line in order, each with a section as long as its
    expectation; ``n_select`` equally spaced pointers, the first at a uniform random
    position within the first step, select the individuals whose sections they hit. Each
    individual is selected ⌊e⌋ or ⌈e⌉ times for an expectation e summing to ``n_select``.

    Parameters
    ----------
    expectation
        Shape (N,), non-negative.
    n_select
        Number of selections.
    rng
        The random generator.

    Returns
    -------
    numpy.ndarray
        Selected indices in wheel order, shape (n_select,), int.
    """
    wheel = np.cumsum(expectation) / np.sum(expectation)
    step = 1.0 / n_select
    pointers = rng.random() * step + step * np.arange(n_select)
    return np.minimum(np.searchsorted(wheel, pointers, side="right"), len(expectation) - 1)


class StochasticUniformSelection(Selection):
    """Stochastic uniform selection on rank-scaled fitness (``F`` of the population)."""

    def _do(
        self,
        problem: Problem,
        pop: Population,
        n_select: int,
        n_parents: int,
        *args: object,
        random_state: np.random.Generator | None = None,
        **kwargs: object,
    ) -> np.ndarray:
        """Indices, shape (n_select, n_parents), in wheel order."""
        total = n_select * n_parents
        expectation = rank_scaled_expectation(pop.get("F")[:, 0], total)
        chosen = stochastic_uniform(expectation, total, _generator(random_state))
        return chosen.reshape(n_select, n_parents)


class ScatteredCrossover(Crossover):
    """MATLAB's ``crossoverscattered``: one child per pair, each gene from either parent."""

    def __init__(self) -> None:
        super().__init__(n_parents=2, n_offsprings=1, prob=1.0)

    def _do(
        self,
        problem: Problem,
        X: np.ndarray,
        *args: object,
        random_state: np.random.Generator | None = None,
        **kwargs: object,
    ) -> np.ndarray:
        """Children, shape (1, n_matings, n_var), from parents X (2, n_matings, n_var)."""
        take_first = _generator(random_state).random(X.shape[1:]) < 0.5
        return np.where(take_first, X[0], X[1])[None]


class AdaptiveFeasibleMutation(Mutation):
    """A step along a random direction, adapted per generation and kept admissible.

    After MATLAB's ``mutationadaptfeasible``: the step size σ (a share of each variable's
    range) is 1 in the first generations, grows ×4 (up to 1) after a generation that
    improved the best fitness and shrinks ÷4 (down to √eps) after one that did not. Each
    child is ``parent + σ · span ⊙ d`` with d a uniformly random unit direction; the step
    is halved until the child lies in the bounds and the reach shell (after 30 halvings
    the parent is kept). MATLAB chooses among the generators of the bounds' tangent cone;
    a random direction serves the same purpose for a box.

    Parameters
    ----------
    space
        The admissible set.
    """

    def __init__(self, space: SearchSpace):
        super().__init__(prob=1.0)
        self.space = space
        self.step = 1.0
        self._best: list[float] = []

    def adapt(self, best: float) -> float:
        """Update the step with the current best fitness (once per generation); return it."""
        self._best.append(best)
        if len(self._best) <= 2:
            self.step = 1.0
        elif self._best[-1] < self._best[-2]:
            self.step = min(1.0, self.step * STEP_FACTOR)
        else:
            self.step = max(MIN_STEP, self.step / STEP_FACTOR)
        return self.step

    def _do(
        self,
        problem: Problem,
        X: np.ndarray,
        *args: object,
        random_state: np.random.Generator | None = None,
        algorithm: Any = None,
        **kwargs: object,
    ) -> np.ndarray:
        """Mutated children, shape (N, 6), from parents X (N, 6)."""
        population = getattr(algorithm, "pop", None)
        if population is not None and len(population):
            self.adapt(float(np.min(population.get("F"))))
        direction = _generator(random_state).standard_normal(X.shape)
        direction /= np.linalg.norm(direction, axis=1, keepdims=True)
        children = np.array(X, dtype=float)
        pending = np.arange(len(X))
        length = np.full(len(X), self.step)
        for _ in range(_SHORTENINGS):
            trial = X[pending] + (length[pending, None] * direction[pending]) * self.space.span
            ok = self.space.contains(trial)
            children[pending[ok]] = trial[ok]
            pending = pending[~ok]
            if not len(pending):
                break
            length[pending] *= 0.5
        return children


class AdmissibleSampling(Sampling):
    """Uniform in the bounds and inside the reach shell (rejection sampling)."""

    def __init__(self, space: SearchSpace):
        super().__init__()
        self.space = space

    def _do(
        self,
        problem: Problem,
        n_samples: int,
        *args: object,
        random_state: np.random.Generator | None = None,
        **kwargs: object,
    ) -> np.ndarray:
        """Placements, shape (n_samples, 6)."""
        return self.space.sample(_generator(random_state), n_samples)


class ReachRepair(Repair):
    """Moves placements into the bounds and the reach shell (:meth:`SearchSpace.repair`)."""

    def __init__(self, space: SearchSpace):
        super().__init__()
        self.space = space

    def _do(self, problem: Problem, X: np.ndarray, **kwargs: object) -> np.ndarray:
        """Admissible placements, shape (N, 6)."""
        return self.space.repair(X)


def elite_count(population: int) -> int:
    """MATLAB's default elite count, ``ceil(0.05 · population)``."""
    return math.ceil(0.05 * population)


class MatlabMating(InfillCriterion):
    """One generation's children as MATLAB's ``stepGA`` makes them (without the elites).

    Of the ``n`` children asked for, ``round(crossover_fraction · n)`` are crossover children
    and the rest mutation children; ``2 · n_crossover + n_mutation`` parents are selected,
    shuffled, then consumed in order: pairs for crossover, singles for mutation.

    Parameters
    ----------
    selection, crossover, mutation
        The operators (:class:`StochasticUniformSelection`, :class:`ScatteredCrossover`,
        :class:`AdaptiveFeasibleMutation`).
    crossover_fraction
        Share of crossover children among the non-elite children.
    repair
        Applied to every child (crossover children may leave the reach shell).
    """

    def __init__(
        self,
        selection: Selection,
        crossover: Crossover,
        mutation: Mutation,
        crossover_fraction: float,
        repair: Repair,
    ):
        super().__init__(repair=repair)
        self.selection = selection
        self.crossover = crossover
        self.mutation = mutation
        self.crossover_fraction = crossover_fraction

    def _do(
        self,
        problem: Problem,
        pop: Population,
        n_offsprings: int,
        random_state: np.random.Generator | None = None,
        **kwargs: object,
    ) -> Population:
        """``n_offsprings`` children: crossover children first, then mutation children."""
        n_crossover = math.floor(self.crossover_fraction * n_offsprings + 0.5)  # MATLAB round
        n_mutation = n_offsprings - n_crossover
        n_parents = 2 * n_crossover + n_mutation
        parents = self.selection.do(
            problem, pop, n_parents, 1, to_pop=False, random_state=random_state, **kwargs
        )[:, 0]
        parents = _generator(random_state).permutation(parents)
        pairs = parents[: 2 * n_crossover].reshape(n_crossover, 2)
        crossed = self.crossover.do(problem, pop, pairs, random_state=random_state, **kwargs)
        singles = Population.new("X", pop.get("X")[parents[2 * n_crossover :]])
        mutated = self.mutation.do(problem, singles, random_state=random_state, **kwargs)
        return Population.merge(crossed, mutated)


class EliteSurvival(Survival):
    """Generational replacement keeping the elites: the next population is the
    ``n_elite`` best of the current one followed by all the children.

    pymoo hands the survival the current population followed by the children; the
    current population is the algorithm's ``pop`` at that moment.
    """

    def __init__(self, n_elite: int):
        super().__init__(filter_infeasible=False)
        self.n_elite = n_elite

    def _do(
        self,
        problem: Problem,
        pop: Population,
        *args: object,
        n_survive: int | None = None,
        algorithm: Any = None,
        **kwargs: object,
    ) -> Population:
        """Elites of the parents, then the children (at most ``n_survive``)."""
        n_parents = len(algorithm.pop)
        parents, children = pop[:n_parents], pop[n_parents:]
        elites = parents[np.argsort(parents.get("F")[:, 0], kind="stable")[: self.n_elite]]
        return Population.merge(elites, children)[:n_survive]


class StallTermination(Termination):
    """MATLAB's stall test (``StallTest = 'totalChange'``, the default since R2014a).

    With ``b_g`` the best fitness found up to generation g, the search stops at the first
    generation G > W with ``|b_{G−W} − b_G| / (W · max(1, |b_G|)) ≤ tol``: the average
    relative change of the best fitness over the last W generations is at most tol.

    Parameters
    ----------
    window
        W, MATLAB's ``MaxStallGenerations``.
    tolerance
        tol, MATLAB's ``FunctionTolerance``.
    """

    def __init__(self, window: int = 50, tolerance: float = 1e-3):
        super().__init__()
        self.window = window
        self.tolerance = tolerance
        self.best: list[float] = []

    def _update(self, algorithm: Any) -> float:
        """Record the generation's best; 1.0 once the stall test passes."""
        current = float(np.min(algorithm.pop.get("F")))
        self.best.append(min(current, self.best[-1]) if self.best else current)
        if len(self.best) <= self.window:
            return 0.0
        change = abs(self.best[-1 - self.window] - self.best[-1])
        change /= self.window * max(1.0, abs(self.best[-1]))
        return 1.0 if change <= self.tolerance else 0.0
