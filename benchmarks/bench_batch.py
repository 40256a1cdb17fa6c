"""Batch studies on Dask: speed-up with two workers, and the engine's per-job overhead.

Run with ``python -m benchmarks batch``. One 8-job study (the paper's three cases and the
bracket weld, seeds 0 and 1, ten restarts per search: jobs of about 5 s on an idle core,
no per-run report) is run, in one process and one run:

- in a plain loop of :func:`trackplan.study.run_job` in this process (the reference),
  once before and once after the Dask runs (their mean is the reference, their spread
  shows how much the machine's load moves the timings);
- by :func:`trackplan.run_study` on a local cluster of 1 worker, then of 2 workers.

Every run starts warm (kernels compiled, glibc's allocator set: this process does what
the workers' preload does) and the cluster start is timed apart. Prints the wall times,
the speed-up of 2 workers over 1 (target ≥ 1.7× on 2 cores) and the engine's overhead per
job with 1 worker (target < 5 %): against the plain loop, and as the time the batch took
beyond the jobs' own wall times on the worker (submission, scheduling, results, summary
files), which the machine's load moves much less.
"""

from __future__ import annotations

import os
import tempfile
import time
from pathlib import Path

from distributed import Client

from trackplan.allocator import keep_freed_memory
from trackplan.io.study_file import load_study
from trackplan.study import Study, local_cluster, run_job, run_study
from trackplan.study.preload import warm_up

CASES = Path(__file__).resolve().parent.parent / "cases"
CASE_NAMES = ("paper-line", "paper-circle", "paper-corner", "bracket-weld")
STUDY = """
name: batch-benchmark
cases: [{cases}]
seeds: [0, 1]
set:
  optimizer.restarts: [10]
"""
TARGET_SPEEDUP = 1.7
TARGET_OVERHEAD = 0.05


def _loop(study: Study, out: Path) -> tuple[float, float]:
    """Wall time of the jobs in a plain loop, and the sum of their own wall times, s."""
    start = time.perf_counter()
    rows = [run_job(job, out, report=False) for job in study.jobs]
    return time.perf_counter() - start, sum(row.wall_time_s for row in rows)


def _dask(study: Study, out: Path, workers: int) -> tuple[float, float, float]:
    """Cluster start, batch wall time and the sum of the jobs' own wall times, s."""
    start = time.perf_counter()
    with local_cluster(workers) as cluster, Client(cluster) as client:
        started = time.perf_counter() - start
        start = time.perf_counter()
        result = run_study(study, out, client, report=False)
        batch = time.perf_counter() - start
    if result.n_failed:
        raise RuntimeError(result.message)
    return started, batch, sum(row.wall_time_s for row in result.rows)


def _autogroup() -> str:
    """A note when the kernel shares the CPU between sessions, not processes."""
    flag = Path("/proc/sys/kernel/sched_autogroup_enabled")
    if flag.is_file() and flag.read_text().strip() == "1":
        return (
            "; the kernel's autogroup scheduling is on: under load, this session's processes "
            "share one session's CPU share, however many workers run"
        )
    return ""


def _verdict(ok: bool) -> str:
    return "met" if ok else "NOT met"


def main() -> None:
    """Run the benchmark and print its table."""
    keep_freed_memory()  # as in the workers (their preload)
    warm_up()
    load_start = os.getloadavg()[0]
    with tempfile.TemporaryDirectory(prefix="bench-batch-") as folder:
        root = Path(folder)
        cases = ", ".join(f"'{CASES / name}.yaml'" for name in CASE_NAMES)
        (root / "study.yaml").write_text(STUDY.format(cases=cases))
        study = load_study(root / "study.yaml")
        n = len(study.jobs)
        before, _ = _loop(study, root / "loop-before")
        runs = {workers: _dask(study, root / f"dask-{workers}", workers) for workers in (1, 2)}
        after, _ = _loop(study, root / "loop-after")
    loop = (before + after) / 2
    print(
        f"{n} jobs on {os.cpu_count()} cores; load average {load_start:.1f} at the start, "
        f"{os.getloadavg()[0]:.1f} at the end{_autogroup()}"
    )
    print(f"{'run':<22}{'cluster start s':>16}{'batch s':>10}{'per job s':>11}")
    for label, wall in (("plain loop, before", before), ("plain loop, after", after)):
        print(f"{label:<22}{'–':>16}{wall:>10.2f}{wall / n:>11.2f}")
    for workers, (started, batch, _) in runs.items():
        label = f"dask, {workers} worker{'s' if workers > 1 else ''}"
        print(f"{label:<22}{started:>16.2f}{batch:>10.2f}{batch / n:>11.2f}")
    speedup = runs[1][1] / runs[2][1]
    print(
        f"speed-up, 2 workers over 1: {speedup:.2f}× "
        f"(target ≥ {TARGET_SPEEDUP}×: {_verdict(speedup >= TARGET_SPEEDUP)})"
    )
    _, batch, jobs = runs[1]
    against_loop = (batch - loop) / loop
    engine = (batch - jobs) / jobs
    print(
        f"engine overhead, 1 worker: against the plain loop (mean of before and after) "
        f"{(batch - loop) / n * 1e3:+.0f} ms per job, {100 * against_loop:+.1f} % "
        f"(target < {100 * TARGET_OVERHEAD:.0f} %: {_verdict(against_loop < TARGET_OVERHEAD)})"
    )
    print(
        f"engine overhead, 1 worker: batch beyond the jobs' own wall times "
        f"{(batch - jobs) / n * 1e3:+.0f} ms per job, {100 * engine:+.1f} % "
        f"(target < {100 * TARGET_OVERHEAD:.0f} %: {_verdict(engine < TARGET_OVERHEAD)})"
    )
