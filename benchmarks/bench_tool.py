"""Tool orientation: fixed against free spin on the seam weld, and the screening's cost.

Run with ``python -m benchmarks tool``. Prints, in one run:

- the welding case ``seam-weld-fixed`` against ``seam-weld-free`` (frame seam, work angle
  45°, travel angle −10°; the spin fixed at 0 against chosen by the search), optimised
  with the same method and seed: J, duration, feasibility, evaluations;
- placements screened per second by the batched screening of the search on the paper's
  circle with the seam frame, ``spin: fixed`` against ``spin: free-varying`` (the six
  B-spline coefficients as extra variables), on the same placements; target: free-varying
  no more than 3× slower per candidate.
"""

from __future__ import annotations

import time
from pathlib import Path

import numpy as np

from trackplan.io.case_file import load_case
from trackplan.paths.path_geometry import PathGeometry
from trackplan.search.fitness import PlacementFitness
from trackplan.search.optimize import optimize
from trackplan.search.space import SearchSpace

CASES = Path(__file__).resolve().parent.parent / "cases"
PLACEMENTS = 300
"""Placements screened per variant (one batch of the search's size, repeated)."""
BATCH = 30
"""Candidates per screening call (the GA's population)."""
TARGET_RATIO = 3.0


def compare_spin() -> None:
    """J, duration and feasibility of the weld with the spin fixed and free, same seed."""
    print(f"{'case':<18} {'spin':<6} {'feasible':<9} {'J':>8} {'duration s':>11} {'evals':>6}")
    for name in ("seam-weld-fixed", "seam-weld-free"):
        case = load_case(CASES / f"{name}.yaml")
        result = optimize(case)
        final = result.final
        print(
            f"{name:<18} {case.task.tool.spin:<6} {result.success!s:<9} "
            f"{final.objective:>8.4f} {final.duration:>11.3f} {result.evaluations:>6}"
            f"   seed {case.optimizer.seed}, {case.optimizer.method}"
        )
        if not result.success:
            print(f"  {result.message}")


def screening_rate() -> None:
    """Placements per second of the batched screening, spin fixed against free-varying."""
    fixed = load_case(CASES / "paper-circle-seam-fixed.yaml")
    free = load_case(CASES / "paper-circle-seam-free.yaml")
    geometry = PathGeometry.from_case(fixed)
    rng = np.random.default_rng(0)
    rates = {}
    placements = SearchSpace.from_case(fixed).sample(rng, PLACEMENTS)
    for label, case in (("fixed", fixed), ("free-varying", free)):
        space = SearchSpace.from_case(case)
        spins = space.sample(rng, PLACEMENTS)[:, 6:]
        X = np.hstack([placements, spins])
        fitness = PlacementFitness(case, space, geometry, "smooth")
        fitness.evaluate(X[:BATCH])  # warm-up (numba)
        start = time.perf_counter()
        for first in range(0, PLACEMENTS, BATCH):
            fitness.evaluate(X[first : first + BATCH])
        rates[label] = PLACEMENTS / (time.perf_counter() - start)
        print(
            f"screening, spin {label:<13} {rates[label]:8.1f} placements/s "
            f"({space.n_var} variables)"
        )
    ratio = rates["fixed"] / rates["free-varying"]
    verdict = "met" if ratio <= TARGET_RATIO else "MISSED"
    print(f"free-varying costs {ratio:.2f}x per candidate (target <= {TARGET_RATIO:g}x: {verdict})")


def main() -> None:
    """Print both comparisons."""
    screening_rate()
    compare_spin()


if __name__ == "__main__":
    main()
