"""The jobs of a study, and running one of them into its run folder.

A study is the cartesian product of case files × robots × sweeps of case keys × seeds
(see ``docs/studies.md``); each :class:`Job` carries its validated :class:`~trackplan.case.Case`
with the robot and the swept keys already applied, so a worker needs none of the input
files. :func:`run_job` is what a Dask worker executes: one placement search, its run folder
written under a temporary name and renamed when complete, so that a folder named after a
job always holds a whole result (what ``--resume`` relies on).
"""

from __future__ import annotations

import json
import os
import shutil
import socket
import time
import traceback
import uuid
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from trackplan.case import Case
from trackplan.run_files import RESULT_FILE
from trackplan.status import Status
from trackplan.study.summary import JOB_FILE, JobRow, failed_row, row_from_run

JOBS_DIR = "jobs"
"""Folder of the run folders inside a study's output folder."""

ERRORS_DIR = "errors"
"""Folder of the tracebacks of failed jobs inside a study's output folder."""

PARTIAL_SUFFIX = ".partial"
"""Ending of a run folder still being written (removed when a batch starts)."""


@dataclass(frozen=True, eq=False)
class Job:
    """One placement search of a study.

    Attributes
    ----------
    key
        ``<case>__<robot>__<sweep>__s<seed>``: the run folder's name, unique in the study.
    case_label
        The case file's name without ``.yaml``.
    case_file
        The case file.
    robot
        The robot's name (the study's override, else the case's robot).
    sweep
        The swept case keys and their values, ``((dotted.key, value), ...)``; empty
        without ``set``.
    sweep_label
        ``key=value,...`` as in the folder name, ``base`` without sweeps.
    seed
        The search's random seed.
    case
        The validated case with the robot and the swept values applied.
    """

    key: str
    case_label: str
    case_file: str
    robot: str
    sweep: tuple[tuple[str, Any], ...]
    sweep_label: str
    seed: int
    case: Case

    def describe(self) -> dict[str, Any]:
        """The job's keys as plain JSON types (the run folder's ``job.json`` block)."""
        return {
            "job": self.key,
            "case": self.case_label,
            "case_file": self.case_file,
            "robot": self.robot,
            "sweep": self.sweep_label,
            "set": dict(self.sweep),
            "seed": self.seed,
        }


@dataclass(frozen=True, eq=False)
class Study:
    """A validated study: its jobs in a fixed order (cases, robots, sweeps, seeds).

    Attributes
    ----------
    name
        Shown in the summary; the study file's name by default.
    jobs
        Every job, in the order of the product.
    cases
        Case labels, in file order.
    robots
        Robot names, in the study's order (the cases' own robots without ``robots``).
    source
        The study file, or None for a study built in code.
    """

    name: str
    jobs: tuple[Job, ...]
    cases: tuple[str, ...]
    robots: tuple[str, ...]
    source: str | None = None


def run_job(job: Job, out_dir: str | Path, report: bool = True) -> JobRow:
    """Run one job's placement search and write its run folder ``out_dir/jobs/<key>/``.

    The folder holds what ``trackplan optimize`` writes (``trajectory.csv``,
    ``result.json``, ``history.csv``, and with ``report`` the plots and ``report.html``)
    plus ``job.json`` (the job's keys, wall time and worker). It is written under a
    temporary name and renamed when complete. A job that raises leaves no run folder: it
    comes back as a failed row, its traceback in ``out_dir/errors/<key>.txt``.

    Parameters
    ----------
    job
        The job.
    out_dir
        The study's output folder.
    report
        Also write the plots and ``report.html`` of the run.

    Returns
    -------
    JobRow
        The job's summary row (read back from the files written), or a failed row.
    """
    from trackplan.outputs import write_search_run
    from trackplan.search.optimize import optimize

    start = time.perf_counter()
    jobs_dir = Path(out_dir) / JOBS_DIR
    final = jobs_dir / job.key
    partial = jobs_dir / f".{job.key}.{uuid.uuid4().hex[:8]}{PARTIAL_SUFFIX}"
    worker = worker_name()
    try:
        result = optimize(job.case, seed=job.seed)
        if result.status is Status.INTERRUPTED:
            raise KeyboardInterrupt  # a search cut short is not a result to keep
        write_search_run(partial, result, job.case, report=report)
        record = {
            **job.describe(),
            "wall_time_s": time.perf_counter() - start,
            "worker": worker,
        }
        (partial / JOB_FILE).write_text(json.dumps(record, indent=2) + "\n")
        _publish(partial, final)
        return row_from_run(final)
    except Exception as exc:
        shutil.rmtree(partial, ignore_errors=True)
        errors = Path(out_dir) / ERRORS_DIR
        errors.mkdir(parents=True, exist_ok=True)
        (errors / f"{job.key}.txt").write_text(traceback.format_exc())
        reason = f"{type(exc).__name__}: {exc}".replace("\n", " ")
        return failed_row(job.describe(), reason, time.perf_counter() - start, worker)


def _publish(partial: Path, final: Path) -> None:
    """Rename a finished run folder to its job's name.

    Should the job have run twice (Dask may rerun a task whose worker it lost touch
    with), the first complete folder is kept.
    """
    try:
        os.rename(partial, final)
    except OSError:
        if not (final / JOB_FILE).is_file():
            raise
        shutil.rmtree(partial, ignore_errors=True)


def worker_name() -> str:
    """The address of the Dask worker running this, else ``host:pid``."""
    try:
        from distributed import get_worker

        return str(get_worker().address)
    except (ImportError, ValueError):
        return f"{socket.gethostname()}:{os.getpid()}"


def complete_run(out_dir: str | Path, job: Job) -> bool:
    """True when the job's run folder holds a complete result (``--resume`` skips it)."""
    folder = Path(out_dir) / JOBS_DIR / job.key
    return (folder / JOB_FILE).is_file() and (folder / RESULT_FILE).is_file()
