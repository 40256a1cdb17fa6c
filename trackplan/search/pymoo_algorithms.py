"""The searches that run as pymoo Algorithms of their own, imported by the methods that use
them only (pymoo's ``Algorithm`` brings its default terminations and their indicators:
about 0.1 s of a start).

- :class:`CMAESearch`: the ``cmaes`` method, CMA-ES of the ``cma`` package;
- :class:`AskTellAlgorithm`: :class:`~trackplan.search.multistart.MultiStartSearch`, which
  asks for arrays, as a pymoo Algorithm, for a search given a pymoo termination.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from pymoo.core.algorithm import Algorithm
from pymoo.core.population import Population

from trackplan.search.multistart import MultiStartSearch
from trackplan.search.space import SearchSpace

CMA_SIGMA = 0.3
"""Initial CMA-ES step size, as a share of each variable's range."""


class CMAESearch(Algorithm):
    """CMA-ES (the ``cma`` package) on the bounds scaled to [0, 1], behind ask/tell.

    The start is a uniform admissible sample, the step size
    :data:`CMA_SIGMA`; cma draws
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
        x0 = self.space.to_unit(self.space.sample(rng, 1)[0])
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
        return Population.new("X", self.space.from_unit(np.asarray(self._asked)))

    def _initialize_advance(self, infills: Population | None = None, **kwargs: object) -> None:
        self._advance(infills)

    def _advance(self, infills: Population | None = None, **kwargs: object) -> None:
        if infills is None:
            raise ValueError("CMAESearch follows ask/tell: tell it the evaluated infills")
        self.es.tell(self._asked, infills.get("F")[:, 0].tolist())
        self.pop = infills
        self.converged = dict(self.es.stop())


class AskTellAlgorithm(Algorithm):
    """A :class:`~trackplan.search.multistart.MultiStartSearch` behind pymoo's ask/tell: what
    it asks as a population, the population's fitness told back; its draws from the seed
    of ``setup(problem, seed=...)``, as without pymoo.

    Parameters
    ----------
    search
        The search (started afresh by ``setup``).

    Attributes
    ----------
    converged
        The search's: non-empty once it has stopped.
    """

    def __init__(self, search: MultiStartSearch, **kwargs: object):
        super().__init__(**kwargs)
        self.search = search

    @property
    def converged(self) -> dict:
        """Non-empty once the search has stopped."""
        return self.search.converged

    def _setup(self, problem: object, **kwargs: object) -> None:
        self.search.setup(self.seed)

    def _initialize_infill(self) -> Population | None:
        return self._infill()

    def _infill(self) -> Population | None:
        X = self.search.ask()
        return None if X is None else Population.new("X", X)

    def _initialize_advance(self, infills: Population | None = None, **kwargs: object) -> None:
        self._advance(infills)

    def _advance(self, infills: Population | None = None, **kwargs: object) -> None:
        if infills is None:
            raise ValueError("AskTellAlgorithm follows ask/tell: tell it the evaluated infills")
        self.search.tell(infills.get("F")[:, 0])
        self.pop = infills

    def _set_optimum(self) -> None:
        """The best of the latest generation (the search's own best is the problem's
        archive); cheaper than pymoo's filter over the whole population."""
        self.opt = self.pop[[int(np.argmin(self.pop.get("F")[:, 0]))]]
