"""Multi-start local search, the default method: uniform samples, then local CMA-ES runs.

:class:`MultiStartSearch` asks for arrays and is told fitness arrays (no pymoo); each
local run (:class:`LocalRun`) is CMA-ES of the ``cmaes`` package, loaded without its
package ``__init__`` (:func:`cmaes_cma`). ``docs/search.md`` describes the method.
"""

from __future__ import annotations

import functools
import importlib.util
import math
import sys
from collections import deque
from pathlib import Path

import numpy as np

from trackplan.search.space import N_VAR, SearchSpace

MULTISTART_SAMPLES = 2000
"""Uniform admissible samples before the local runs of ``multistart``."""
MULTISTART_BATCH = 100
"""Samples evaluated per generation of ``multistart``'s sampling phase."""
MULTISTART_STARTS = 6
"""Local runs of ``multistart``, from the best mutually distant samples."""
MULTISTART_DISTANCE = 0.1
"""Least distance between two starts, as a share of each variable's range (max norm)."""
LOCAL_SIGMA = 0.05
"""Initial step of a local CMA-ES run, as a share of each variable's range."""
LOCAL_POPULATION = 12
"""λ of a local CMA-ES run."""
LOCAL_EVALUATIONS = 600
"""Evaluations a local run may use at most."""
RACE_GENERATIONS = 5
"""Generations every local run makes before the race may stop it."""
RACE_MARGIN = 0.03
"""A local run stops when its best fitness lies more than this share above the best of all
runs: it is descending a worse valley (the paper cases' valleys differ by 1 % to 12 %)."""
LOCAL_TOLERANCE = 1e-7
"""A local run has converged when its fitness spans less than this over cma's ``tolfun``
window of generations (:class:`LocalRun`)."""


@functools.cache
def cmaes_cma() -> type:
    """The ``cmaes`` package's ``CMA`` class, loaded without the package's ``__init__``.

    That ``__init__`` also imports the package's mixed-integer and multi-objective variants,
    and through them scipy.stats: 0.6 s of CPU under load, a tenth of a whole ``trackplan
    optimize``. ``CMA`` lives in a module of its own that needs numpy only, so that module
    is loaded by itself (under its own name, so a later ``import cmaes`` reuses it); when
    the package is already imported, or its layout differs, the package is imported.
    """
    found = None if "cmaes" in sys.modules else importlib.util.find_spec("cmaes")
    if found is not None and found.submodule_search_locations:
        file = Path(found.submodule_search_locations[0]) / "_cma.py"
        spec = importlib.util.spec_from_file_location("cmaes._cma", file)
        if file.is_file() and spec is not None and spec.loader is not None:
            module = importlib.util.module_from_spec(spec)
            try:
                spec.loader.exec_module(module)
            except ImportError:  # a later cmaes whose module needs the package after all
                pass
            else:
                sys.modules.setdefault("cmaes._cma", module)
                return module.CMA
    from cmaes import CMA

    return CMA


class LocalRun:
    """One local CMA-ES run of :class:`MultiStartSearch` (the ``cmaes`` package), on [0, 1]ⁿ.

    It stops when cmaes' own criteria fire, after :data:`LOCAL_EVALUATIONS`, or when the
    fitness has flattened: the best and worst values of each of its last ``10 + ⌈30 n/λ⌉``
    generations (cma's ``tolfun`` window) span less than :data:`LOCAL_TOLERANCE`.

    Parameters
    ----------
    start
        The start, scaled to [0, 1], shape (n,).
    seed
        Seeds the run's normal samples.
    """

    def __init__(self, start: np.ndarray, seed: int):
        n = len(start)
        self.es = cmaes_cma()(
            mean=np.asarray(start, dtype=float),
            sigma=LOCAL_SIGMA,
            bounds=np.tile([0.0, 1.0], (n, 1)),
            seed=seed,
            population_size=LOCAL_POPULATION,
        )
        self.evaluations = 0
        self.generations = 0
        self.best = math.inf
        self.dropped = False
        self.window: deque[float] = deque(maxlen=2 * (10 + math.ceil(30 * n / LOCAL_POPULATION)))
        self.asked = np.zeros((0, n))

    @property
    def stopped(self) -> bool:
        """Whether the run has stopped."""
        flat = (
            len(self.window) == self.window.maxlen
            and max(self.window) - min(self.window) < LOCAL_TOLERANCE
        )
        return (
            self.dropped or flat or self.evaluations >= LOCAL_EVALUATIONS or self.es.should_stop()
        )

    def ask(self) -> np.ndarray:
        """The next generation, shape (λ, n), in [0, 1]."""
        self.asked = np.array([self.es.ask() for _ in range(LOCAL_POPULATION)])
        return self.asked

    def tell(self, fitness: np.ndarray) -> None:
        """Tell the fitness (λ,) of the generation last asked."""
        self.es.tell(list(zip(self.asked, fitness.tolist(), strict=True)))
        self.evaluations += len(fitness)
        self.generations += 1
        self.best = min(self.best, float(fitness.min()))
        self.window.extend((float(fitness.min()), float(fitness.max())))


class MultiStartSearch:
    """Multi-start local search: uniform samples, then local CMA-ES runs, asked for arrays.

    Phase 1 evaluates :data:`MULTISTART_SAMPLES` uniform admissible placements in batches
    of :data:`MULTISTART_BATCH`. Phase 2 takes the best of them that lie at least
    :data:`MULTISTART_DISTANCE` apart (scaled max norm) as starts, at most
    :data:`MULTISTART_STARTS`, and runs a local CMA-ES (:class:`LocalRun`: step
    :data:`LOCAL_SIGMA`, λ = :data:`LOCAL_POPULATION`) from each. The local runs advance
    side by side: one generation asks λ placements of every run still going, so that one
    batched screening call serves them all. Every run draws from its own generator,
    seeded from the search's, so a seed reproduces the search exactly.

    It follows ask/tell with arrays (:meth:`ask`, :meth:`tell`), not pymoo's populations:
    the driver (:func:`trackplan.search.optimize.optimize`) evaluates what it
    asks; :class:`~trackplan.search.pymoo_algorithms.AskTellAlgorithm` runs it as a pymoo
    Algorithm where a pymoo termination is given.

    Parameters
    ----------
    space
        The admissible placements.

    Attributes
    ----------
    converged
        Non-empty once the last local run has stopped.
    n_gen
        Generations told so far.
    """

    def __init__(self, space: SearchSpace):
        self.space = space
        self.setup(0)

    def setup(self, seed: int | None) -> None:
        """Start afresh, every random draw from ``numpy.random.default_rng(seed)`` (the
        generator a pymoo Algorithm's ``setup`` makes of its seed)."""
        self.random_state = np.random.default_rng(seed)
        self.converged: dict = {}
        self.n_gen = 0
        self.samples: list[np.ndarray] = []
        self.sample_fitness: list[np.ndarray] = []
        self.runs: list[LocalRun] | None = None
        self._asking: list[LocalRun] = []
        self._asked = np.zeros((0, N_VAR))

    def ask(self) -> np.ndarray | None:
        """The next generation's placements, shape (B, 6); None once every run has stopped."""
        done = sum(len(x) for x in self.samples)
        if done < MULTISTART_SAMPLES:
            n = min(MULTISTART_BATCH, MULTISTART_SAMPLES - done)
            self._asked = self.space.sample(self.random_state, n)
            return self._asked
        if self.runs is None:
            starts = self._distinct_starts()
            seeds = self.random_state.integers(2**31, size=len(starts))
            self.runs = [LocalRun(z, int(s)) for z, s in zip(starts, seeds, strict=True)]
        self._asking = [run for run in self.runs if not run.stopped]
        if not self._asking:
            self.converged = {"local runs": len(self.runs)}
            return None
        Z = np.concatenate([run.ask() for run in self._asking])
        return self.space.from_unit(Z)

    def tell(self, fitness: np.ndarray) -> None:
        """Tell the fitness (B,) of the generation last asked."""
        if self.runs is None:
            self.samples.append(self._asked)
            self.sample_fitness.append(fitness)
        else:
            for i, run in enumerate(self._asking):
                run.tell(fitness[i * LOCAL_POPULATION : (i + 1) * LOCAL_POPULATION])
            self._race()
        self.n_gen += 1

    def _race(self) -> None:
        """Stop the local runs that have fallen behind: after :data:`RACE_GENERATIONS`, a run
        whose best lies more than :data:`RACE_MARGIN` (relative) above the best of all runs."""
        assert self.runs is not None
        leader = min(run.best for run in self.runs)
        for run in self._asking:
            behind = run.best - leader > RACE_MARGIN * abs(leader)
            run.dropped |= run.generations >= RACE_GENERATIONS and behind

    def _distinct_starts(self) -> list[np.ndarray]:
        """The best samples at least MULTISTART_DISTANCE apart, best first, scaled to [0, 1]."""
        X = np.concatenate(self.samples)
        fitness = np.concatenate(self.sample_fitness)
        Z = self.space.to_unit(X)
        starts: list[np.ndarray] = []
        for i in np.argsort(fitness, kind="stable"):
            if all(np.max(np.abs(Z[i] - z)) >= MULTISTART_DISTANCE for z in starts):
                starts.append(Z[i])
                if len(starts) == MULTISTART_STARTS:
                    break
        return starts
