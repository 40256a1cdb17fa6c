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
   ``plan`` and ``check``, each a fresh process (targets: 10 s and 1 GB each), and the CPU
   time of writing the plan's trajectory.csv against ``numpy.savetxt`` (``%.17g``).
"""

from __future__ import annotations

import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from trackplan.io.case_file import load_case
from trackplan.io.csv_table import write_csv_table
from trackplan.paths.path_geometry import PathGeometry
from trackplan.planning.plan import plan
from trackplan.run_files import TRAJECTORY_FILE
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
LARGE_POINTS = 1_000_000
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


PEAK_MEMORY = (
    "import resource, sys\n"
    "from trackplan.cli import main\n"
    "code = main(sys.argv[1:])\n"
    "use = resource.getrusage(resource.RUSAGE_SELF)\n"
    "print('peak-kib', use.ru_maxrss, use.ru_utime + use.ru_stime, file=sys.stderr)\n"
    "sys.exit(code)\n"
)


def helix() -> None:
    """Section 3: the helix and the large points file, each command in a fresh process."""
    from tests.large_paths import HELIX_PLACEMENT, write_helix_case

    placement = [str(value) for value in HELIX_PLACEMENT]
    print(
        f"\n{HELIX_POINTS}-point helix (r = 0.1 m, 3 turns, 0.3 m rise) and a "
        f"{LARGE_POINTS:,}-point file of the same helix, fresh processes "
        "(wall time, CPU time, peak resident memory; targets 10 s and 1 GB each):"
    )
    with tempfile.TemporaryDirectory() as name:
        folder = Path(name)
        case, run = str(write_helix_case(folder, HELIX_POINTS)), str(folder / "run")
        large = str(write_helix_case(folder, LARGE_POINTS))
        for label, command in (
            ("validate", ["validate", case]),
            ("plan", ["plan", case, "--out", run, "--no-report", "--placement", *placement]),
            ("check", ["check", case, run, "--placement", *placement]),
            (f"validate {LARGE_POINTS // 1000}k", ["validate", large]),
        ):
            seconds, cpu, peak, code = _measure(command)
            shown = f"{seconds:6.1f} s" if code is not None else f"> {COMMAND_TIMEOUT_S:g} s"
            print(
                f"  {label:<14}{shown}  CPU {cpu:6.1f} s  peak {peak / 2**30:5.2f} GiB  exit {code}"
            )
        _csv_writer(folder / "run" / TRAJECTORY_FILE)


def _csv_writer(trajectory: Path) -> None:
    """CPU time of writing the plan's trajectory.csv: the exact writer against numpy.savetxt."""
    if not trajectory.is_file():
        print("  no trajectory.csv to time the CSV writer on")
        return
    table = np.loadtxt(trajectory, delimiter=",", skiprows=1, ndmin=2)
    header = [f"c{i}" for i in range(table.shape[1])]
    out = trajectory.with_name("again.csv")
    write_csv_table(out, table[:2], header)  # the kernel loaded, as in a plan
    start = time.process_time()
    write_csv_table(out, table, header)
    exact = time.process_time() - start
    same = np.array_equal(np.loadtxt(out, delimiter=",", skiprows=1, ndmin=2), table)
    size = out.stat().st_size
    start = time.process_time()
    np.savetxt(out, table, delimiter=",", header=",".join(header), comments="", fmt="%.17g")
    reference = time.process_time() - start
    print(
        f"  writing its trajectory.csv ({table.size:,} values): {exact:.2f} s CPU, "
        f"{size / 1e6:.0f} MB, read back bit for bit: {same}; numpy.savetxt %.17g "
        f"{reference:.2f} s, {out.stat().st_size / 1e6:.0f} MB ({reference / exact:.1f} times)"
    )


def _measure(command: list[str]) -> tuple[float, float, float, int | None]:
    """Wall time (s), CPU time (s), peak resident memory (bytes), exit code of ``trackplan``."""
    start = time.perf_counter()
    try:
        done = subprocess.run(
            [sys.executable, "-c", PEAK_MEMORY, *command],
            capture_output=True,
            text=True,
            timeout=COMMAND_TIMEOUT_S,
        )
    except subprocess.TimeoutExpired:
        return COMMAND_TIMEOUT_S, float("nan"), float("nan"), None
    seconds = time.perf_counter() - start
    usage = [line.split() for line in done.stderr.splitlines() if line.startswith("peak-kib")]
    if not usage:
        return seconds, float("nan"), float("nan"), done.returncode
    return seconds, float(usage[-1][2]), float(usage[-1][1]) * 1024, done.returncode


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
            result = plan(case, X, geometries={(0, False): geometry})
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
