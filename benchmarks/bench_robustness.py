"""Robustness: random placements, hostile inputs, and a large sampled path.

Run with ``python -m benchmarks robustness``. Three sections:

1. The smooth time law on random placements: for each shipped case, 150 placements drawn
   uniformly in the case's bounds and reach shell (seeded) are planned at full Ts. Prints
   how many were unreachable or left the joint ranges (geometry: no time law can help), how
   many planned feasibly, and how long they took against the path length at the rated
   speed; any reachable placement that fails the checker is listed (target: none).
2. Fuzzing (``tests/fuzzing.py``, seeded): mutants of the shipped case and robot files
   validated, and those that validate planned. Prints the exit codes, exit-1s, tracebacks,
   runs over 10 s and exit-2 messages that do not name the key (targets: 0 each).
3. A 20,000-point smooth helix (a points file): wall time and peak memory of ``validate``,
   ``plan`` and ``check``, each a fresh process (targets: 10 s and 1 GB each).
"""

from __future__ import annotations

import subprocess
import sys
import tempfile
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


FUZZ_MUTANTS = 400
FUZZ_PLANS = 60
FUZZ_SEED = 7
HELIX_POINTS = 20_000
HELIX_PLACEMENT = ("0.5", "0", "0", "0", "0", "0")
COMMAND_TIMEOUT_S = 300.0


def main() -> None:
    """Print the three sections."""
    placements()
    fuzzing()
    helix()


def fuzzing() -> None:
    """Section 2: counts over a seeded fuzz run."""
    from tests.fuzzing import RUN_LIMIT_S, fuzz

    with tempfile.TemporaryDirectory() as folder:
        counts = fuzz(Path(folder), FUZZ_MUTANTS, FUZZ_PLANS, FUZZ_SEED)
    codes = ", ".join(f"exit {code}: {n}" for code, n in sorted(counts.exit_codes.items()))
    print(f"\nfuzzing: {FUZZ_MUTANTS} mutants (seed {FUZZ_SEED}), {counts.runs} runs ({codes})")
    print(
        f"  exit 1: {len(counts.internal_errors)}  tracebacks: {counts.tracebacks}  "
        f"runs over {RUN_LIMIT_S:g} s: {counts.hangs}  exit-2 messages not naming the key: "
        f"{len(counts.bad_messages)}  slowest run {counts.slowest_s:.1f} s  (targets 0)"
    )
    for line in counts.internal_errors + counts.bad_messages:
        print(f"  {line}")


HELIX_CASE = """name: helix-20k
robot: puma560
path:
  start: [0, 0, -0.001]
  segments:
    - points: {file: helix.csv}
task:
  rated_speed: 0.05
  tolerance: 0.001
  sample_time: 0.001
  tool_rpy: [3.141592653589793, 0, 0]
"""

PEAK_MEMORY = (
    "import resource, sys\n"
    "from trackplan.cli import main\n"
    "code = main(sys.argv[1:])\n"
    "print('peak-kib', resource.getrusage(resource.RUSAGE_SELF).ru_maxrss, file=sys.stderr)\n"
    "sys.exit(code)\n"
)


def helix() -> None:
    """Section 3: validate, plan and check a 20,000-point helix, each in a fresh process."""
    print(f"\n{HELIX_POINTS}-point helix (r = 0.1 m, 3 turns, 0.3 m rise), fresh processes:")
    with tempfile.TemporaryDirectory() as name:
        folder = Path(name)
        turns = np.linspace(0.0, 6.0 * np.pi, HELIX_POINTS)
        points = np.column_stack(
            [0.1 * np.cos(turns) - 0.1, 0.1 * np.sin(turns), 0.3 * turns / (6.0 * np.pi)]
        )
        np.savetxt(folder / "helix.csv", points, delimiter=",", header="x,y,z", comments="")
        (folder / "helix.yaml").write_text(HELIX_CASE)
        case, run = str(folder / "helix.yaml"), str(folder / "run")
        for command in (
            ["validate", case],
            ["plan", case, "--out", run, "--no-report", "--placement", *HELIX_PLACEMENT],
            ["check", case, run, "--placement", *HELIX_PLACEMENT],
        ):
            seconds, peak, code = _measure(command)
            shown = f"{seconds:6.1f} s" if code is not None else f"> {COMMAND_TIMEOUT_S:g} s"
            print(
                f"  {command[0]:<9}{shown}  peak {peak / 2**30:6.2f} GiB  exit {code}"
                "  (targets 10 s, 1 GB)"
            )


def _measure(command: list[str]) -> tuple[float, float, int | None]:
    """Wall time (s), peak resident memory (bytes) and exit code of ``trackplan command``."""
    start = time.perf_counter()
    try:
        done = subprocess.run(
            [sys.executable, "-c", PEAK_MEMORY, *command],
            capture_output=True,
            text=True,
            timeout=COMMAND_TIMEOUT_S,
        )
    except subprocess.TimeoutExpired:
        return COMMAND_TIMEOUT_S, float("nan"), None
    seconds = time.perf_counter() - start
    peaks = [line.split()[1] for line in done.stderr.splitlines() if line.startswith("peak-kib")]
    return seconds, float(peaks[-1]) * 1024 if peaks else float("nan"), done.returncode


def placements() -> None:
    """Section 1: one row per case."""
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
