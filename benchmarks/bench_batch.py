"""Batch studies on Dask: speed-up with two workers, and the engine's overhead per job.

Run with ``python -m benchmarks batch``. One 8-job study (the paper's three cases and the
bracket weld, seeds 0 and 1, two restarts per search: jobs of about 5 s on an idle core,
no per-run report) runs three ways, in one process and one run:

- in a plain loop of :func:`trackplan.study.run_job` in this process (the reference);
- by :func:`trackplan.run_study` on a local cluster of 1 worker, and of 2 workers.

The three take turns for :data:`ROUNDS` rounds (the order rotates each round), so that a
change of the machine's load hits all three alike; each is reported as the median over
the rounds with its spread (max − min over the median). Every run starts warm: this
process does what the workers' preload does (allocator, numba warm-up) before the loop,
and each cluster's start (worker processes, preload, warm-up) is timed apart.

Besides wall times it prints CPU times, which other processes on the machine move much
less: the CPU time of the processes running the jobs (this process for the loop, the
worker processes for the batch, every thread of theirs) and the CPU time the engine spends
elsewhere during a batch (this process: a local cluster's scheduler and nannies run in it,
besides the client).

Prints the speed-up of 2 workers over 1 (target ≥ 1.7× on 2 cores) and the overhead of
the 1-worker batch against the plain loop (target < 5 %), in wall time and in CPU time.
"""

from __future__ import annotations

import os
import statistics
import tempfile
import time
from dataclasses import dataclass
from pathlib import Path

import psutil
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
  optimizer.restarts: [2]
"""
ROUNDS = 3
TARGET_SPEEDUP = 1.7
TARGET_OVERHEAD = 0.05
LOOP = 0
"""Key of the plain loop among the runs (the others are keyed by their worker count)."""


@dataclass(frozen=True)
class Run:
    """One run of the study's jobs.

    Attributes
    ----------
    start_s
        Cluster start (workers, preload, warm-up), s; 0 for the loop.
    wall_s
        Wall time from submitting the first job to the last result (summary files
        included), s.
    jobs_cpu_s
        CPU time of the processes running the jobs, s.
    engine_cpu_s
        CPU time of this process during the batch (a local cluster's scheduler and
        nannies run in it, besides the client), s.
    """

    start_s: float
    wall_s: float
    jobs_cpu_s: float
    engine_cpu_s: float


def _cpu(process: psutil.Process) -> float:
    """User and system CPU time of a process, s."""
    times = process.cpu_times()
    return times.user + times.system


def _loop(study: Study, out: Path) -> Run:
    """The jobs one after the other in this process."""
    wall, cpu = time.perf_counter(), time.process_time()
    for job in study.jobs:
        if run_job(job, out, report=False).failed:
            raise RuntimeError(f"{job.key} failed in the plain loop")
    return Run(0.0, time.perf_counter() - wall, time.process_time() - cpu, 0.0)


def _dask(study: Study, out: Path, workers: int) -> Run:
    """The jobs by ``run_study`` on a fresh local cluster of ``workers`` workers."""
    start = time.perf_counter()
    with local_cluster(workers) as cluster, Client(cluster) as client:
        started = time.perf_counter() - start
        processes = [psutil.Process(pid) for pid in client.run(os.getpid).values()]
        jobs_before = sum(_cpu(process) for process in processes)
        wall, engine = time.perf_counter(), time.process_time()
        result = run_study(study, out, client, report=False)
        wall, engine = time.perf_counter() - wall, time.process_time() - engine
        jobs = sum(_cpu(process) for process in processes) - jobs_before
    if result.n_failed:
        raise RuntimeError(result.message)
    return Run(started, wall, jobs, engine)


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


def _median(values: list[float]) -> str:
    """``median (spread %)``: the spread is max − min over the median."""
    middle = statistics.median(values)
    spread = (max(values) - min(values)) / middle if middle else 0.0
    return f"{middle:.2f} ({100 * spread:.0f} %)"


def main() -> None:
    """Run the benchmark and print its tables."""
    keep_freed_memory()  # as in the workers (their preload)
    warm_up()
    load_start = os.getloadavg()[0]
    kinds = (LOOP, 1, 2)
    runs: dict[int, list[Run]] = {kind: [] for kind in kinds}
    with tempfile.TemporaryDirectory(prefix="bench-batch-") as folder:
        root = Path(folder)
        cases = ", ".join(f"'{CASES / name}.yaml'" for name in CASE_NAMES)
        (root / "study.yaml").write_text(STUDY.format(cases=cases))
        study = load_study(root / "study.yaml")
        for round_ in range(ROUNDS):
            for kind in kinds[round_ % 3 :] + kinds[: round_ % 3]:
                out = root / f"{kind}-{round_}"
                runs[kind].append(_loop(study, out) if kind == LOOP else _dask(study, out, kind))
    n = len(study.jobs)
    labels = {LOOP: "plain loop", 1: "dask, 1 worker", 2: "dask, 2 workers"}
    print(
        f"{n} jobs on {os.cpu_count()} cores, {ROUNDS} rounds taking turns; load average "
        f"{load_start:.1f} at the start, {os.getloadavg()[0]:.1f} at the end{_autogroup()}"
    )
    print("each round in order: wall time s, and job CPU s per job")
    for kind in kinds:
        walls = "  ".join(f"{run.wall_s:7.2f} {run.jobs_cpu_s / n:5.2f}" for run in runs[kind])
        print(f"  {labels[kind]:<17}{walls}")
    print("median over the rounds (spread: max − min over the median):")
    header = ("cluster start s", "batch s", "per job s", "job CPU s/job", "engine CPU s/job")
    print(f"  {'run':<17}" + "".join(f"{title:>21}" for title in header))
    for kind in kinds:
        cells = (
            "–" if kind == LOOP else _median([run.start_s for run in runs[kind]]),
            _median([run.wall_s for run in runs[kind]]),
            _median([run.wall_s / n for run in runs[kind]]),
            _median([run.jobs_cpu_s / n for run in runs[kind]]),
            "–" if kind == LOOP else _median([run.engine_cpu_s / n for run in runs[kind]]),
        )
        print(f"  {labels[kind]:<17}" + "".join(f"{cell:>21}" for cell in cells))
    speedups = [one.wall_s / two.wall_s for one, two in zip(runs[1], runs[2], strict=True)]
    speedup = statistics.median(speedups)
    print(
        f"speed-up, 2 workers over 1 (median of the rounds): {speedup:.2f}× "
        f"(rounds {', '.join(f'{value:.2f}' for value in speedups)}; "
        f"target ≥ {TARGET_SPEEDUP}×: {_verdict(speedup >= TARGET_SPEEDUP)})"
    )
    pairs = list(zip(runs[LOOP], runs[1], strict=True))
    wall = [(batch.wall_s - loop.wall_s) / loop.wall_s for loop, batch in pairs]
    cpu = [
        (batch.jobs_cpu_s + batch.engine_cpu_s - loop.jobs_cpu_s) / loop.jobs_cpu_s
        for loop, batch in pairs
    ]
    for label, values in (("wall time", wall), ("CPU time, engine included", cpu)):
        middle = statistics.median(values)
        print(
            f"overhead of the 1-worker batch against the plain loop, {label}: "
            f"{100 * middle:+.1f} % (rounds {', '.join(f'{100 * v:+.1f}' for v in values)} %; "
            f"target < {100 * TARGET_OVERHEAD:.0f} %: {_verdict(middle < TARGET_OVERHEAD)})"
        )
