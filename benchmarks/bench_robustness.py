"""The smooth time law on random placements: every reachable one must pass the checker.

Run with ``python -m benchmarks robustness``. For each shipped case, 150 placements drawn
uniformly in the case's bounds and reach shell (seeded) are planned at full Ts. Prints how
many were unreachable or left the joint ranges (geometry: no time law can help), how many
planned feasibly, and how long they took against the path length at the rated speed; any
reachable placement that fails the checker is listed (target: none).
"""

from __future__ import annotations

import time
from pathlib import Path

import numpy as np

from trackplan.io.case_file import load_case
from trackplan.paths.path_geometry import PathGeometry
from trackplan.planning.plan import plan_placement
from trackplan.status import Status

CASES = Path(__file__).resolve().parent.parent / "cases"
CASE_NAMES = ("paper-line", "paper-circle", "paper-corner", "ur5-bead", "bracket-weld")
PLACEMENTS = 150
SEED = 11
GEOMETRIC = (Status.UNREACHABLE, Status.POSITION_LIMITS, Status.BRANCH_SWITCH)


def main() -> None:
    """Print one row per case."""
    header = (
        f"{'case':<14}{'planned':>8}{'geometry':>10}{'feasible':>10}{'failed':>8}"
        f"{'T/(L/v_r) median':>18}{'max':>7}{'ms each':>9}"
    )
    print(header + "\n" + "-" * len(header))
    failures = []
    for name in CASE_NAMES:
        case = load_case(CASES / f"{name}.yaml")
        geometry = PathGeometry.from_case(case)
        rng = np.random.default_rng(SEED)
        counts = {"geometry": 0, "feasible": 0, "failed": 0}
        ratios = []
        start = time.perf_counter()
        planned = 0
        while planned < PLACEMENTS:
            X = rng.uniform(case.bounds.lower, case.bounds.upper)
            if not case.bounds.reach[0] <= np.linalg.norm(X[:3]) <= case.bounds.reach[1]:
                continue
            planned += 1
            result = plan_placement(case, X, geometry=geometry)
            if result.status in GEOMETRIC:
                counts["geometry"] += 1
            elif result.feasible:
                counts["feasible"] += 1
                ratios.append(result.duration * case.task.rated_speed / result.path_length)
            else:
                counts["failed"] += 1
                failures.append((name, X, result.message))
        seconds = time.perf_counter() - start
        median = f"{np.median(ratios):.3f}" if ratios else "—"
        worst = f"{np.max(ratios):.3f}" if ratios else "—"
        print(
            f"{name:<14}{planned:>8}{counts['geometry']:>10}{counts['feasible']:>10}"
            f"{counts['failed']:>8}{median:>18}{worst:>7}{1e3 * seconds / planned:>9.1f}"
        )
    for name, X, message in failures:
        print(f"FAILED {name} at X = {np.round(X, 4).tolist()}: {message}")
    print(f"reachable placements failing the checker: {len(failures)} (target 0)")


if __name__ == "__main__":
    main()
