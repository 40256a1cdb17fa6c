"""Running a study's jobs on Dask distributed and collecting their rows as they complete.

:func:`run_study` submits one task per job (:func:`~trackplan.study.jobs.run_job`) to a
``dask.distributed`` client: one passed in (an existing cluster), or a ``LocalCluster``
it starts with one single-threaded worker process per core. Rows stream into
``summary.csv`` as jobs complete; at the end ``summary.csv`` is rewritten in job order and
``summary.html`` written. Faults: a job that raises comes back as a failed row; a task
whose worker dies is retried on another worker at most :data:`MAX_RETRIES` times, then
failed; Ctrl-C cancels the pending jobs and still writes the summary of what finished.
"""

from __future__ import annotations

import asyncio
import math
import os
import shutil
import time
import uuid
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

from trackplan.errors import CaseError
from trackplan.status import Status
from trackplan.study.jobs import (
    JOBS_DIR,
    PARTIAL_SUFFIX,
    Job,
    Study,
    complete_run,
    run_job,
)
from trackplan.study.summary import (
    SUMMARY_CSV,
    JobRow,
    SummaryWriter,
    failed_row,
    row_from_run,
    write_summary_csv,
)

if TYPE_CHECKING:
    from dask.typing import Key
    from distributed import Client, Future

MAX_RETRIES = 2
"""Times a job whose worker died is run again elsewhere before it is marked failed."""

CONNECT_TIMEOUT_S = 5.0
"""How long :func:`connect` waits for a scheduler, s."""

POLL_S = 0.2
"""How often the progress is refreshed while no job completes, s."""

CLOSE_TIMEOUT_S = 30.0
"""How long a local cluster's worker process may take to exit when the cluster closes, s.

Dask's nanny allows 4 s, then kills the process with a warning ("Worker process still
alive after 4.0 seconds, killing"): a worker that has imported numba, scipy and trackplan
spends seconds tearing its interpreter down, more than 4 s on a loaded machine (measured
with a load average of 7 on 2 cores).
"""

PRELOAD = "trackplan.study.preload"
"""Module every worker of a local cluster runs at start (allocator, numba warm-up)."""

LOCAL_CLUSTER_CONFIG = {"distributed.admin.tick.interval": "500ms"}
"""Dask settings of the local clusters started here.

Every Dask server (the scheduler, each nanny, each worker) checks its event loop's health
every 20 ms by default, to log a warning when a task holds the loop for more than 3 s. In a
worker that check takes the GIL from the running search 50 times a second; over the whole
local cluster it cost about as much CPU time as everything else the engine does (measured
under load: 0.6 s of 1.0 s in the scheduler process per 2-job batch). Every 500 ms still
catches a 3 s stall.
"""


@dataclass(frozen=True)
class StudyProgress:
    """The state of a batch, passed to the progress callback.

    Attributes
    ----------
    total
        Jobs in the study.
    done
        Jobs with a row (skipped ones included), failed ones included.
    failed
        Jobs failed so far.
    running
        Jobs a worker is running now.
    skipped
        Jobs a resumed batch found complete.
    elapsed_s
        Wall time since the jobs were submitted, s.
    last
        The row of the job that just completed, None on a refresh.
    """

    total: int
    done: int
    failed: int
    running: int
    skipped: int
    elapsed_s: float
    last: JobRow | None = None


ProgressCallback = Callable[[StudyProgress], None]


@dataclass(frozen=True, eq=False)
class StudyResult:
    """Outcome of :func:`run_study`.

    Attributes
    ----------
    success
        True when every job ran and found a feasible placement.
    status
        The first that applies: ``INTERRUPTED`` (Ctrl-C), ``FAILED`` (a job raised or lost
        its workers), the status of the first job without a feasible placement, else
        ``FEASIBLE``.
    message
        One line: how many jobs were feasible, infeasible, failed, skipped, cancelled.
    rows
        One row per job that has one (cancelled jobs have none), in the study's order.
    n_jobs
        Jobs in the study.
    n_skipped
        Jobs found complete by a resumed batch.
    n_cancelled
        Jobs cancelled by Ctrl-C.
    wall_time_s
        Wall time of the batch, s.
    out_dir
        The output folder.
    """

    success: bool
    status: Status
    message: str
    rows: tuple[JobRow, ...]
    n_jobs: int
    n_skipped: int
    n_cancelled: int
    wall_time_s: float
    out_dir: Path

    @property
    def n_failed(self) -> int:
        """Jobs that raised or lost their workers."""
        return sum(row.failed for row in self.rows)

    @property
    def n_feasible(self) -> int:
        """Jobs whose final plan passed the checker."""
        return sum(row.success for row in self.rows)


def run_study(
    study: Study | str | Path,
    out: str | Path,
    client: Client | None = None,
    *,
    workers: int | None = None,
    resume: bool = False,
    report: bool = True,
    progress: ProgressCallback | None = None,
) -> StudyResult:
    """Run every job of a study on Dask; write the run folders and the summary.

    Parameters
    ----------
    study
        The study, or its file (:func:`trackplan.io.study_file.load_study`).
    out
        Output folder: ``jobs/<key>/`` per job, ``summary.csv``, ``summary.html``,
        ``errors/<key>.txt`` per failed job.
    client
        A ``dask.distributed.Client`` to run the jobs on; None starts a local cluster
        of ``workers`` single-threaded worker processes for the call.
    workers
        Worker processes of the local cluster; default one per core.
    resume
        Skip the jobs whose run folder holds a complete result. Without it, an output
        folder that holds results of this study is refused.
    report
        Write each run's plots and ``report.html`` (``summary.html`` is always written).
    progress
        Called with a :class:`StudyProgress` when a job completes and about every
        :data:`POLL_S` seconds in between.

    Returns
    -------
    StudyResult

    Raises
    ------
    CaseError
        A bad study file, an output folder holding results without ``resume``, or
        ``workers`` < 1.
    """
    if not isinstance(study, Study):
        from trackplan.io.study_file import load_study

        study = load_study(study)
    if workers is not None and workers < 1:
        raise CaseError(f"expected at least 1 worker, got {workers}", key="--workers")
    start = time.perf_counter()
    out = Path(out)
    done = [job for job in study.jobs if complete_run(out, job)]
    if done and not resume:
        raise CaseError(
            f"holds complete results of {len(done)} of this study's jobs: add --resume to keep "
            "them and run the rest, or choose another output folder",
            file=str(out),
        )
    (out / JOBS_DIR).mkdir(parents=True, exist_ok=True)
    _remove_partial_runs(out)
    skipped = {job.key: row_from_run(out / JOBS_DIR / job.key) for job in done}
    pending = [job for job in study.jobs if job.key not in skipped]
    rows = dict(skipped)
    writer = SummaryWriter(out / SUMMARY_CSV)
    try:
        for row in skipped.values():
            writer.add(row)
        with _client(client, workers) as active:
            interrupted = _run_jobs(
                active,
                pending,
                out,
                report,
                writer,
                rows,
                len(study.jobs),
                len(skipped),
                progress,
            )
        for job in study.jobs:  # finished on disk, not yet collected when Ctrl-C came
            if job.key not in rows and complete_run(out, job):
                rows[job.key] = row_from_run(out / JOBS_DIR / job.key)
    finally:
        writer.close()
    ordered = tuple(rows[job.key] for job in study.jobs if job.key in rows)
    write_summary_csv(ordered, out / SUMMARY_CSV)
    from trackplan.study.report import write_study_report

    write_study_report(study, ordered, out)
    n_cancelled = len(study.jobs) - len(ordered)
    status = _status(ordered, interrupted)
    return StudyResult(
        success=status.success,
        status=status,
        message=_message(ordered, len(study.jobs), len(skipped), n_cancelled),
        rows=ordered,
        n_jobs=len(study.jobs),
        n_skipped=len(skipped),
        n_cancelled=n_cancelled,
        wall_time_s=time.perf_counter() - start,
        out_dir=out,
    )


study = run_study
"""The front door's name for :func:`run_study`: ``trackplan.study(study, out, ...)``."""


def _run_jobs(
    client: Client,
    jobs: list[Job],
    out: Path,
    report: bool,
    writer: SummaryWriter,
    rows: dict[str, JobRow],
    total: int,
    n_skipped: int,
    progress: ProgressCallback | None,
) -> bool:
    """Submit the jobs, collect their rows as they complete; True when Ctrl-C stopped it."""
    from distributed import as_completed

    client.run_on_scheduler(limit_retries, MAX_RETRIES)  # type: ignore[no-untyped-call]  # distributed is unannotated
    token = uuid.uuid4().hex[:8]
    futures: dict[Future[JobRow], Job] = {
        client.submit(run_job, job, str(out), report, key=f"{job.key}-{token}", pure=False): job
        for job in jobs
    }
    keys = {future.key for future in futures}
    start = time.perf_counter()
    running, last_poll = 0, -math.inf

    def state(last: JobRow | None = None) -> StudyProgress:
        return StudyProgress(
            total=total,
            done=len(rows),
            failed=sum(row.failed for row in rows.values()),
            running=running,
            skipped=n_skipped,
            elapsed_s=time.perf_counter() - start,
            last=last,
        )

    completed = as_completed(futures)  # type: ignore[no-untyped-call]  # distributed is unannotated
    try:
        while not completed.is_empty():  # type: ignore[no-untyped-call]  # distributed is unannotated
            if not completed.has_ready():  # type: ignore[no-untyped-call]  # distributed is unannotated
                if time.perf_counter() - last_poll > 1.0:
                    running = _count_running(client, keys)
                    last_poll = time.perf_counter()
                if progress is not None:
                    progress(state())
                time.sleep(POLL_S)
                continue
            for future in completed.next_batch(block=False):  # type: ignore[no-untyped-call]  # distributed is unannotated
                row = _row(future, futures[future])
                rows[row.job] = row
                writer.add(row)
                running = max(running - 1, 0)
                if progress is not None:
                    progress(state(row))
    except KeyboardInterrupt:
        pending = [future for future in futures if not future.done()]  # type: ignore[no-untyped-call]  # distributed is unannotated
        client.cancel(pending)  # type: ignore[no-untyped-call]  # distributed is unannotated
        return True
    return False


def _row(future: Future[JobRow], job: Job) -> JobRow:
    """The row a finished task returned, or a failed row when the task itself failed.

    A task whose worker died after it finished, before its result was fetched, is pending
    again when it gets here (Dask recomputes it elsewhere): ``exception`` waits for that.
    """
    if future.cancelled():  # type: ignore[no-untyped-call]  # distributed is unannotated
        return failed_row(job.describe(), "cancelled", math.nan, "")
    exc = future.exception()  # type: ignore[no-untyped-call]  # distributed is unannotated
    if exc is None:
        row: JobRow = future.result()
        return row
    reason = f"{type(exc).__name__}: {exc}".replace("\n", " ")
    return failed_row(job.describe(), reason, math.nan, "")


def _count_running(client: Client, keys: set[Key]) -> int:
    """Tasks of this batch that a worker is running now.

    Workers hold a few more tasks than threads (Dask's queueing); at most one task per
    thread runs.
    """
    processing = client.processing()  # type: ignore[no-untyped-call]  # distributed is unannotated
    threads = client.nthreads()  # type: ignore[no-untyped-call]  # distributed is unannotated
    return sum(
        min(sum(key in keys for key in tasks), threads.get(worker, 1))
        for worker, tasks in processing.items()
    )


def limit_retries(retries: int, dask_scheduler=None) -> None:  # type: ignore[no-untyped-def]
    """Let the scheduler rerun a task whose worker died at most ``retries`` times.

    Run on the scheduler (``client.run_on_scheduler``): Dask's ``allowed-failures``.
    """
    dask_scheduler.allowed_failures = retries


def _remove_partial_runs(out: Path) -> None:
    """Remove run folders left half-written by a killed batch."""
    for folder in (out / JOBS_DIR).glob(f".*{PARTIAL_SUFFIX}"):
        shutil.rmtree(folder, ignore_errors=True)


@contextmanager
def _client(client: Client | None, workers: int | None) -> Iterator[Client]:
    """The client given, or one on a local cluster started (and closed) here."""
    if client is not None:
        yield client
        return
    with local_cluster(workers) as cluster:
        from distributed import Client

        with Client(cluster) as local:  # type: ignore[no-untyped-call]  # distributed is unannotated
            yield local


@contextmanager
def local_cluster(workers: int | None = None, preload: bool = True) -> Iterator[Any]:
    """A ``LocalCluster`` of single-threaded worker processes, closed on exit.

    It runs with :data:`LOCAL_CLUSTER_CONFIG`, and gives its workers
    :data:`CLOSE_TIMEOUT_S` to exit when it closes.

    Parameters
    ----------
    workers
        Worker processes; default one per core (``os.cpu_count()``).
    preload
        Run :mod:`trackplan.study.preload` in each worker as it starts.
    """
    import dask
    from distributed import LocalCluster

    n_workers = workers or os.cpu_count() or 1
    with (
        dask.config.set(LOCAL_CLUSTER_CONFIG),
        LocalCluster(  # type: ignore[no-untyped-call]  # distributed is unannotated
            n_workers=n_workers,
            threads_per_worker=1,
            processes=True,
            dashboard_address=":0",  # a free port: never clashes with another cluster
            preload=[PRELOAD] if preload else [],
        ) as cluster,
    ):
        try:
            yield cluster
        finally:
            cluster.sync(_close_workers, cluster)


async def _close_workers(cluster: Any) -> None:
    """Close a local cluster's workers through their nannies, each within :data:`CLOSE_TIMEOUT_S`.

    Closing the cluster alone gives each worker process 4 s to exit before its nanny kills
    it; a worker still stuck after :data:`CLOSE_TIMEOUT_S` is killed with Dask's warning.
    """
    await asyncio.gather(
        *(nanny.close(timeout=CLOSE_TIMEOUT_S) for nanny in list(cluster.workers.values()))
    )


def connect(address: str, timeout: float | None = None) -> Client:
    """A client on the Dask scheduler at ``address`` (``tcp://HOST:PORT``).

    Parameters
    ----------
    address
        The scheduler's address.
    timeout
        Seconds to wait for it; default :data:`CONNECT_TIMEOUT_S`.

    Raises
    ------
    CaseError
        When no scheduler answers there within the timeout.
    """
    from distributed import Client

    timeout = CONNECT_TIMEOUT_S if timeout is None else timeout

    try:
        return Client(address, timeout=timeout)  # type: ignore[no-untyped-call]  # distributed is unannotated
    except (OSError, TimeoutError, ValueError) as exc:
        detail = str(exc).splitlines()[0] if str(exc) else type(exc).__name__
        raise CaseError(
            f"no Dask scheduler answers at {address} within {timeout:g} s ({detail})",
            key="--scheduler",
        ) from None


def _status(rows: tuple[JobRow, ...], interrupted: bool) -> Status:
    """The batch's status (see :class:`StudyResult`)."""
    if interrupted:
        return Status.INTERRUPTED
    if any(row.failed for row in rows):
        return Status.FAILED
    return next((row.status for row in rows if not row.success), Status.FEASIBLE)


def _message(rows: tuple[JobRow, ...], total: int, skipped: int, cancelled: int) -> str:
    """``8 jobs: 6 feasible, 1 infeasible, 1 failed`` (+ skipped, cancelled)."""
    feasible = sum(row.success for row in rows)
    failed = sum(row.failed for row in rows)
    parts = [
        f"{feasible} feasible",
        f"{len(rows) - feasible - failed} infeasible",
        f"{failed} failed",
    ]
    if skipped:
        parts.append(f"{skipped} skipped (already complete)")
    if cancelled:
        parts.append(f"{cancelled} cancelled")
    return f"{total} jobs: " + ", ".join(parts)
