"""Welding cells: how long ``optimize`` takes with a positioner, a track and a weave.

Run with ``python -m benchmarks cells``. For each shipped welding-cell case (a pipe flange
and a pipe saddle on the two-axis positioner, a 3 m seam on a 4 m track, a weaving fillet)
it runs ``trackplan.optimize`` with the case's own settings and prints the wall time, its
ratio against the issue's bound of 30 s, and its ratio against optimizing the arm-only
``bracket-weld`` case (the README's walk-through) in the same run (the reference); then the
final plan's verdict, J and its downhand figures. The kernels are compiled before the
first row; the whole table is timed :data:`REPEATS` times and the median and the worst
time per case printed.
"""

from __future__ import annotations

import time
from pathlib import Path

import numpy as np

import trackplan

CASES = Path(__file__).resolve().parent.parent / "cases"
CELLS = (
    "positioner-pipe-flange",
    "positioner-pipe-saddle",
    "track-long-seam",
    "kuka-weld-weave",
)
REFERENCE = "bracket-weld"
BOUND = 30.0
"""s: the issue's bound on one optimize of each case on 2 cores."""
REPEATS = 3


def _optimize(name: str) -> tuple[float, trackplan.SearchResult]:
    """Wall time of one optimize of the case, s, and its result."""
    case = trackplan.load_case(CASES / f"{name}.yaml")
    start = time.perf_counter()
    result = trackplan.optimize(case)
    return time.perf_counter() - start, result


def main() -> None:
    """Print the table."""
    _optimize(REFERENCE)  # compile the kernels once
    times: dict[str, list[float]] = {name: [] for name in (REFERENCE, *CELLS)}
    results: dict[str, trackplan.SearchResult] = {}
    for _ in range(REPEATS):
        for name in (REFERENCE, *CELLS):
            seconds, results[name] = _optimize(name)
            times[name].append(seconds)
    reference = float(np.median(times[REFERENCE]))
    print(f"reference: optimize {REFERENCE} median {reference:.2f} s over {REPEATS} runs")
    print(
        f"{'case':<26} {'median s':>9} {'worst s':>8} {'/ 30 s':>7} {'/ ref':>6} "
        f"{'verdict':<10} {'J':>8} {'slope°':>7} {'rot.°':>6}"
    )
    for name in CELLS:
        median, worst = float(np.median(times[name])), float(np.max(times[name]))
        final = results[name].final
        figures = final.check.downhand
        slope = "-" if figures is None else f"{np.degrees(figures.max_slope):.2f}"
        rotation = "-" if figures is None else f"{np.degrees(figures.max_rotation):.2f}"
        print(
            f"{name:<26} {median:>9.2f} {worst:>8.2f} {worst / BOUND:>7.2f} "
            f"{median / reference:>6.2f} {final.status.value:<10} {final.objective:>8.4f} "
            f"{slope:>7} {rotation:>6}"
        )
    downhand_over_draws()


DRAWS = 20
"""Random placements per positioner case for the downhand table (seed :data:`SEED`)."""
SEED = 29


def downhand_over_draws() -> None:
    """Plan each positioner case at :data:`DRAWS` placements drawn uniformly in its search
    box (seed :data:`SEED`) and print how many are feasible, and over the feasible ones the
    median and the worst largest slope and rotation and the least share of samples
    downhand."""
    rng = np.random.default_rng(SEED)
    print(
        f"\n{'case':<26} {'feasible':>9} {'slope° med':>11} {'worst':>6} "
        f"{'rot.° med':>10} {'worst':>6} {'least share':>12}"
    )
    for name in CELLS[:2]:
        case = trackplan.load_case(CASES / f"{name}.yaml")
        lower, upper = case.bounds.lower, case.bounds.upper
        slopes, rotations, shares = [], [], []
        for _ in range(DRAWS):
            result = trackplan.plan(case, rng.uniform(lower, upper))
            figures = result.check.downhand
            if result.success and figures is not None:
                slopes.append(np.degrees(figures.max_slope))
                rotations.append(np.degrees(figures.max_rotation))
                shares.append(figures.share)
        if not slopes:
            print(f"{name:<26} {0:>6}/{DRAWS}")
            continue
        print(
            f"{name:<26} {len(slopes):>6}/{DRAWS} {np.median(slopes):>11.2f} "
            f"{np.max(slopes):>6.2f} {np.median(rotations):>10.2f} {np.max(rotations):>6.2f} "
            f"{np.min(shares):>12.3f}"
        )
