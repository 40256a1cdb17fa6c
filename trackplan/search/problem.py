"""The placement search as a pymoo Problem: vectorised evaluation and a record of the best.

Every optimiser (GA, CMA-ES, DE, random) sees the same problem: six bounded placement
variables, plus the tool's spin variables when the spin is free (:mod:`trackplan.tool`),
and one objective, the fitness of Eq. 30 (:mod:`trackplan.search.fitness`). The whole
population is evaluated in one call. The problem also keeps what the search needs
whatever the algorithm does with its population: the number of evaluations, the best
fitness so far, and an archive of the best distinct candidates (the fallbacks should the
final re-check reject the best one).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Protocol

import numpy as np
from pymoo.core.problem import Problem

from trackplan.search.fitness import Screening
from trackplan.search.space import SearchSpace

ARCHIVE_SIZE = 8
"""Distinct candidates kept for the final re-check."""
DISTINCT = 1e-3
"""Two placements are distinct when they differ by more than this share of a variable's range."""


@dataclass(frozen=True, eq=False)
class Archive:
    """The best distinct candidates evaluated so far, best first.

    Attributes
    ----------
    X
        Variables (placement, then spin), shape (K, 6 + k).
    fitness
        Shape (K,).
    objective
        J on the screening grid, shape (K,) (NaN when infeasible).
    feasible
        Shape (K,), bool (as screened).
    branch
        Chosen IK branch, shape (K,), int.
    """

    X: np.ndarray
    fitness: np.ndarray
    objective: np.ndarray
    feasible: np.ndarray
    branch: np.ndarray

    @classmethod
    def empty(cls, n_var: int) -> Archive:
        """An archive with no candidate of ``n_var`` variables."""
        return cls(
            np.zeros((0, n_var)), np.zeros(0), np.zeros(0), np.zeros(0, bool), np.zeros(0, int)
        )

    def merged(self, screening: Screening, span: np.ndarray, size: int = ARCHIVE_SIZE) -> Archive:
        """This archive with a batch added: the ``size`` best, pairwise distinct.

        Parameters
        ----------
        screening
            The batch.
        span
            Ranges of the variables, shape (6 + k,), for the distinctness test.
        size
            Largest number of candidates kept.
        """
        X = np.concatenate([self.X, screening.X])
        fitness = np.concatenate([self.fitness, screening.fitness])
        objective = np.concatenate([self.objective, screening.objective])
        feasible = np.concatenate([self.feasible, screening.feasible])
        branch = np.concatenate([self.branch, screening.branch])
        keep: list[int] = []
        scale = np.where(span > 0.0, span, 1.0)
        for i in np.argsort(fitness, kind="stable"):
            if len(keep) == size:
                break
            if all(np.max(np.abs(X[i] - X[j]) / scale) > DISTINCT for j in keep):
                keep.append(int(i))
        index = np.asarray(keep, dtype=int)
        return Archive(X[index], fitness[index], objective[index], feasible[index], branch[index])


class Fitness(Protocol):
    """What the problem evaluates: :class:`~trackplan.search.fitness.PlacementFitness`, or
    the case fitness of :mod:`trackplan.search.case_fitness`."""

    penalty: float

    def evaluate(self, X: np.ndarray, incumbent: float = np.inf) -> Screening:
        """Fitness of a batch of candidates, shape (B, n_var)."""
        ...


class PlacementProblem(Problem):
    """Bounded variables X = (x, y, z, roll, pitch, yaw, spin...), one objective: Eq. 30.

    Parameters
    ----------
    space
        Bounds and reach constraint.
    fitness
        The batched fitness function.

    Attributes
    ----------
    n_evaluations
        Placements evaluated so far.
    archive
        The best distinct candidates (:class:`Archive`).
    last
        The screening of the latest batch, or None before the first.
    """

    def __init__(self, space: SearchSpace, fitness: Fitness):
        super().__init__(n_var=space.n_var, n_obj=1, xl=space.lower, xu=space.upper, vtype=float)
        self.space = space
        self.fitness = fitness
        self.n_evaluations = 0
        self.archive = Archive.empty(space.n_var)
        self.last: Screening | None = None

    @property
    def best_fitness(self) -> float:
        """Best fitness evaluated so far (inf before the first evaluation)."""
        return float(self.archive.fitness[0]) if len(self.archive.fitness) else np.inf

    def screen(self, X: np.ndarray) -> np.ndarray:
        """Evaluate a batch of candidates, shape (B, 6 + k), and record it; its fitness (B,).

        What pymoo's evaluator calls (through ``_evaluate``), and what the driver calls
        for a search that asks for arrays (:class:`~trackplan.search.multistart.MultiStartSearch`).
        """
        screening = self.fitness.evaluate(X, incumbent=self.best_fitness)
        self.n_evaluations += len(screening.X)
        self.archive = self.archive.merged(screening, self.space.span)
        self.last = screening
        return screening.fitness

    def _evaluate(self, x: np.ndarray, out: dict, *args: object, **kwargs: object) -> None:
        """Evaluate a batch, shape (B, 6 + k), into ``out["F"]`` (B, 1)."""
        out["F"] = self.screen(x)[:, None]
