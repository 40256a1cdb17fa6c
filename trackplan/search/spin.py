"""The spin about the tool axis at a fixed placement: a fast inner search.

With ``spin: free`` or ``free-varying`` (:mod:`trackplan.tool`) a plan at a given placement
still has the spin to choose. Only the k spin variables vary, so one batched screening
(:class:`~trackplan.search.fitness.PlacementFitness`) evaluates many profiles at once:
profiles that counter-rotate a share of the tool's own turn about its axis (the turn a
fixed spin would force on the wrist), random ones, then a few rounds of perturbations
around the best. The best is planned and checked by
:func:`~trackplan.planning.plan.plan`.
"""

from __future__ import annotations

import numpy as np

from trackplan.case import Case
from trackplan.frames import as_placement
from trackplan.paths.path_geometry import PathGeometry
from trackplan.planning.plan import plan
from trackplan.planning.result import PlanResult
from trackplan.search.fitness import PlacementFitness
from trackplan.search.space import SearchSpace
from trackplan.timing import time_law
from trackplan.tool import SPIN_DEGREE, spin_knots, tool_axis_twist

COUNTER_SHARES = (0.0, 0.25, 0.5, 0.75, 1.0)
"""Shares of the tool's own turn about its axis that the seed profiles counter-rotate."""
RANDOM_PROFILES = 48
"""Random spin variables screened besides the seeds."""
REFINE_ROUNDS = 3
"""Rounds of perturbation around the best profile."""
REFINE_PROFILES = 24
"""Perturbed profiles per round."""
REFINE_SCALE = 0.1
"""Perturbation, as a share of each spin variable's range."""


def spin_seeds(fitness: PlacementFitness) -> np.ndarray:
    """Spin variables that counter-rotate shares of the tool's turn, shape (S, k).

    The zero-spin orientation turns by ``τ(s)`` about the tool axis along the path
    (:func:`trackplan.tool.tool_axis_twist`); the seed of share α is the profile nearest to
    ``c − α τ(s)`` (least squares on the screening grid), shifted to the middle of the
    spin range and kept within range and rate by :meth:`ToolSpec.spin_variables`.
    """
    tool = fitness.case.task.tool
    length = fitness.geometry.planned.length
    twist = tool_axis_twist(fitness.R_base)
    middle = 0.5 * sum(tool.spin_range)
    if tool.n_spin == 1:
        return np.array([[middle]])
    from scipy.interpolate import BSpline  # only free-spin tools need scipy's splines

    basis = BSpline.design_matrix(
        fitness.s_grid, spin_knots(tool.n_spin, length), SPIN_DEGREE
    ).toarray()
    seeds = []
    for share in COUNTER_SHARES:
        target = -share * twist
        target += middle - 0.5 * (target.max() + target.min())
        coefficients = np.linalg.lstsq(basis, target, rcond=None)[0]
        seeds.append(tool.spin_variables(coefficients[None], length)[0])
    return np.array(seeds)


def optimize_spin(
    case: Case,
    X: np.ndarray,
    *,
    timing: str | None = None,
    geometry: PathGeometry | None = None,
    seed: int | None = None,
) -> PlanResult:
    """Plan the case at placement X with the spin that gives the least joint travel.

    Parameters
    ----------
    case
        The case; its tool spin must be ``free`` or ``free-varying`` (else X is planned
        as it is).
    X
        Placement, shape (6,), metres and radians.
    timing
        The time law; default the case's.
    geometry
        The case's paths when already built in the law's path mode.
    seed
        Seed of the random profiles; default the case's ``optimizer.seed``.

    Returns
    -------
    PlanResult
        The plan of the best screened spin (feasible or, failing that, the least violating).
    """
    X = as_placement(X)
    law = time_law(timing or case.task.timing)
    if geometry is None or geometry.mode != law.path_mode:
        geometry = PathGeometry.from_case(case, law.path_mode)
    if not case.task.tool.n_spin:
        return plan(case, X, timing=law.timing, geometries={(0, False): geometry})
    space = SearchSpace.from_case(case)
    fitness = PlacementFitness(case, space, geometry, law.timing)
    rng = np.random.default_rng(case.optimizer.seed if seed is None else seed)
    lower, upper = space.lower[6:], space.upper[6:]
    spins = np.vstack(
        [spin_seeds(fitness), rng.uniform(lower, upper, (RANDOM_PROFILES, len(lower)))]
    )
    best, best_fitness = _best(fitness, X, spins)
    for _ in range(REFINE_ROUNDS):
        step = rng.normal(0.0, REFINE_SCALE, (REFINE_PROFILES, len(lower))) * (upper - lower)
        trial = np.clip(best + step, lower, upper)
        candidate, value = _best(fitness, X, trial)
        if value < best_fitness:
            best, best_fitness = candidate, value
    return plan(case, X, timing=law.timing, geometries={(0, False): geometry}, spin=best)


def _best(fitness: PlacementFitness, X: np.ndarray, spins: np.ndarray) -> tuple[np.ndarray, float]:
    """The spin variables of smallest fitness among (S, k) at placement X, and that fitness."""
    screening = fitness.evaluate(np.hstack([np.tile(X, (len(spins), 1)), spins]))
    i = int(np.argmin(screening.fitness))
    return spins[i], float(screening.fitness[i])
