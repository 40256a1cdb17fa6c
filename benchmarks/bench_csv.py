"""Writing trajectory.csv: the compiled shortest-float printer against the standard library.

Run with ``python -m benchmarks csv``. For two real runs, the longest shipped case
(:data:`CASE`, at its example placement) and a 10-minute cycle at Ts = 4 ms (the helix of
``tests/large_paths.py`` at 3.2 mm/s: about 149,000 rows of 30 columns), it prints, in one
run:

- ``trackplan plan CASE --no-report`` as a fresh process: wall and CPU time (median of
  :data:`PROCESS_RUNS` after one that fills numba's cache);
- the CPU time of turning that run's trajectory.csv table into its text (best of
  :data:`REPEATS`, warm): by the compiled kernel
  (:func:`trackplan.io.csv_table.format_table`), by the standard library in two ways
  (``csv.writer`` on the rows as Python floats, which writes each as ``repr`` does, and
  ``float.__repr__`` mapped over every value and joined: the same bytes, checked) and by
  ``numpy.savetxt`` with ``%.17g`` (the reference: exact, but not the shortest text);
  each as a ratio against the reference and as a share of the whole process's CPU time,
  the standard library's share counted with the extra time it would add to the process;
  and that extra time as a share of the process's CPU time and of its wall time.

The rule is stated on CPU time: ``trackplan plan --no-report`` runs in one process, so on an
idle machine its wall time is about its CPU time, while on a shared machine the wall time
measures the other load as much as the run.

The kernel stays while the standard library would add more than :data:`THRESHOLD` of a
real run's CPU time (issue 27's rule); the figures are on docs/benchmarks.md.
"""

from __future__ import annotations

import csv
import io
import os
import resource
import statistics
import subprocess
import sys
import tempfile
import time
from collections.abc import Callable
from pathlib import Path

import numpy as np

from trackplan.io.csv_table import format_table
from trackplan.run_files import TRAJECTORY_FILE

CASES = Path(__file__).resolve().parent.parent / "cases"
CASE = "bracket-weld"
"""The shipped case with an example placement that has the most samples (9,676)."""
CYCLE_SPEED = 0.0032
"""m/s: the helix (1.91 m) in about 600 s."""
CYCLE_SAMPLE_TIME = 0.004
"""s."""
PROCESS_RUNS = 3
REPEATS = 3
THRESHOLD = 0.10
"""Share of a run's CPU time under which the standard library replaces the kernel."""


def stdlib_table(table: np.ndarray) -> bytes:
    """The standard library's text of ``table`` (n_rows, n_columns): ``csv`` writes each
    Python float as ``repr`` does (shortest round trip), so the bytes equal the kernel's."""
    text = io.StringIO()
    csv.writer(text, lineterminator="\n").writerows(np.asarray(table, dtype=float).tolist())
    return text.getvalue().encode("ascii")


def repr_table(table: np.ndarray) -> bytes:
    """The standard library's text of ``table`` (n_rows, n_columns) by ``float.__repr__``
    mapped over all values and joined (no Python loop of ours): the same bytes again."""
    table = np.asarray(table, dtype=float)
    words = map(float.__repr__, table.ravel().tolist())
    rows = zip(*[words] * table.shape[1], strict=False)
    return ("\n".join(map(",".join, rows)) + "\n").encode("ascii")


def savetxt_table(table: np.ndarray) -> bytes:
    """``numpy.savetxt`` with ``%.17g``: exact, not the shortest text (the reference)."""
    text = io.BytesIO()
    np.savetxt(text, table, delimiter=",", fmt="%.17g")
    return text.getvalue()


def _best_cpu(function: Callable[[], bytes]) -> tuple[float, bytes]:
    """Shortest CPU time over :data:`REPEATS` calls after a warm-up one, s, and the text."""
    text = function()
    times = []
    for _ in range(REPEATS):
        start = time.process_time()
        function()
        times.append(time.process_time() - start)
    return min(times), text


def _children_cpu() -> float:
    usage = resource.getrusage(resource.RUSAGE_CHILDREN)
    return usage.ru_utime + usage.ru_stime


def _plan_process(case: Path, out: Path, placement: list[str]) -> tuple[float, float]:
    """Median wall and CPU time of ``trackplan plan CASE --no-report`` in a fresh process, s."""
    command = [sys.executable, "-m", "trackplan", "plan", str(case), "--no-report"]
    command += ["--out", str(out)]
    if placement:
        command += ["--placement", *placement]
    subprocess.run(command, check=True, capture_output=True)  # fills numba's cache
    walls, cpus = [], []
    for _ in range(PROCESS_RUNS):
        before, start = _children_cpu(), time.perf_counter()
        subprocess.run(command, check=True, capture_output=True)
        walls.append(time.perf_counter() - start)
        cpus.append(_children_cpu() - before)
    return statistics.median(walls), statistics.median(cpus)


def _measure(label: str, case: Path, out: Path, placement: list[str]) -> float:
    """Print one run's figures; return the standard library's extra CPU time as a share of
    the run's."""
    wall, cpu = _plan_process(case, out, placement)
    table = np.loadtxt(out / TRAJECTORY_FILE, delimiter=",", skiprows=1, ndmin=2)
    kernel, text = _best_cpu(lambda: format_table(table))
    csv_module, csv_text = _best_cpu(lambda: stdlib_table(table))
    stdlib, stdlib_text = _best_cpu(lambda: repr_table(table))
    reference, _ = _best_cpu(lambda: savetxt_table(table))
    rows, columns = table.shape
    print(f"\n{label}: {rows:,} rows × {columns} columns, {len(text) / 1e6:.1f} MB")
    print(f"  trackplan plan --no-report, fresh process: {wall:.2f} s wall, {cpu:.2f} s CPU")
    print(f"  {'text of trajectory.csv':<34}{'CPU s':>8}{'/ savetxt':>11}{'share of run':>14}")
    extra = stdlib - kernel
    for name, seconds, share in (
        ("numpy.savetxt %.17g (reference)", reference, None),
        ("compiled kernel (format_table)", kernel, kernel / cpu),
        ("standard library: csv.writer", csv_module, csv_module / (cpu + csv_module - kernel)),
        ("standard library: repr, joined", stdlib, stdlib / (cpu + extra)),
    ):
        shown = f"{100 * share:>13.1f}%" if share is not None else f"{'':>14}"
        print(f"  {name:<34}{seconds:>8.3f}{seconds / reference:>10.2f}×{shown}")
    verdict = "over" if extra > THRESHOLD * cpu else "within"
    print(
        f"  the faster library way adds {extra:.2f} s CPU = {100 * extra / cpu:.0f} % of the "
        f"run's CPU time, {verdict} the {100 * THRESHOLD:.0f} % threshold; same bytes: "
        f"{stdlib_text == text and csv_text == text}"
    )
    print(
        f"  ({100 * extra / wall:.0f} % of its wall time here, at a load average of "
        f"{os.getloadavg()[0]:.1f}: a serial run's wall time on an idle machine is its CPU time)"
    )
    return extra / cpu


def main() -> None:
    """Print both runs."""
    from tests.large_paths import HELIX_PLACEMENT, write_helix_case

    with tempfile.TemporaryDirectory() as name:
        folder = Path(name)
        shares = [
            _measure(f"{CASE} (longest shipped case)", CASES / f"{CASE}.yaml", folder / "case", [])
        ]
        helix = write_helix_case(folder)
        text = helix.read_text()
        text = text.replace("rated_speed: 0.05", f"rated_speed: {CYCLE_SPEED}")
        helix.write_text(text.replace("sample_time: 0.001", f"sample_time: {CYCLE_SAMPLE_TIME}"))
        placement = [str(value) for value in HELIX_PLACEMENT]
        shares.append(
            _measure("10-minute cycle at Ts = 4 ms (helix)", helix, folder / "cycle", placement)
        )
    worst = max(shares)
    keep = worst > THRESHOLD
    print(
        f"\nthe standard library would add up to {100 * worst:.0f} % of a real run's CPU time: "
        + ("keep the compiled kernel" if keep else "the standard library suffices")
    )


if __name__ == "__main__":
    main()
