"""One summary row per job, read from its run folder, and ``summary.csv``.

A row is built from the files a job wrote (``result.json`` and ``job.json``), both for a
job that just finished and for one a resumed batch skips, so the summary always says
what the run folders hold.
"""

from __future__ import annotations

import csv
import json
import math
from collections.abc import Iterable
from dataclasses import astuple, dataclass, fields
from pathlib import Path
from typing import Any, TextIO

from trackplan.check_report import IGNORED_UNLESS_BROKEN
from trackplan.errors import CaseError
from trackplan.io.csv_cells import neutralised, restored
from trackplan.run_files import RESULT_FILE
from trackplan.status import Status

JOB_FILE = "job.json"
"""The job's keys, wall time and worker, written last into a run folder."""

SUMMARY_CSV = "summary.csv"


@dataclass(frozen=True)
class JobRow:
    """The summary of one job (a row of ``summary.csv``).

    Attributes
    ----------
    job
        The job's key (its run folder's name).
    case, robot, sweep, seed
        The job's keys (see :class:`~trackplan.study.jobs.Job`).
    status
        The final plan's status (:class:`~trackplan.status.Status`: ``FEASIBLE``,
        ``LIMITS_VIOLATED``, ``UNREACHABLE``, …), or ``FAILED`` when the job raised or lost
        its workers; written as its value (``feasible``, ``failed``, …).
    success
        True when the final plan passed the checker.
    J
        Joint travel of the final plan (Eq. 8), rad (NaN without a trajectory).
    duration_s
        Duration of the path motion, s.
    cycle_time_s
        Time from the first to the last sample of the written trajectory (rest to rest), s.
    tracking_error_m
        Largest distance of the tool point from the nominal path, m.
    worst_margin
        Smallest unused fraction over every limit (negative: a limit is broken; see
        :func:`worst_margin`).
    wall_time_s
        Wall time of the job on its worker, s.
    worker
        The Dask worker's address (``host:pid`` outside Dask).
    message
        The plan's one-line outcome, or why the job failed.
    """

    job: str
    case: str
    robot: str
    sweep: str
    seed: int
    status: Status
    success: bool
    J: float
    duration_s: float
    cycle_time_s: float
    tracking_error_m: float
    worst_margin: float
    wall_time_s: float
    worker: str
    message: str

    @property
    def failed(self) -> bool:
        """True when the job produced no result."""
        return self.status is Status.FAILED


COLUMNS = tuple(field.name for field in fields(JobRow))
"""Columns of ``summary.csv``."""


def row_from_run(folder: str | Path) -> JobRow:
    """The summary row of a complete run folder (its ``job.json`` and ``result.json``).

    A run without a trajectory (an unreachable placement, say) is a row with its verdict:
    its ``result.json`` holds ``null`` for the figures a trajectory would give, which are
    NaN in the row.
    """
    folder = Path(folder)
    job = json.loads((folder / JOB_FILE).read_text(encoding="utf-8"))
    result = json.loads((folder / RESULT_FILE).read_text(encoding="utf-8"))
    n_samples = int(result.get("n_samples") or 0)
    sample_time = _number(result.get("sample_time"))
    return JobRow(
        job=job["job"],
        case=job["case"],
        robot=job["robot"],
        sweep=job["sweep"],
        seed=int(job["seed"]),
        status=_status(result.get("status"), folder / RESULT_FILE),
        success=bool(result["feasible"]),
        J=_number(result.get("objective")),
        duration_s=_number(result.get("duration")),
        cycle_time_s=(n_samples - 1) * sample_time if n_samples else math.nan,
        tracking_error_m=_number(result.get("max_tracking_error")),
        worst_margin=worst_margin(result.get("margins") or {}),
        wall_time_s=_number(job.get("wall_time_s")),
        worker=str(job["worker"]),
        message=str(result["message"]),
    )


def _status(word: Any, file: Path) -> Status:
    """The :class:`~trackplan.status.Status` whose value ``word`` is (the ``status`` of a
    ``result.json`` or a ``summary.csv`` row).

    Raises
    ------
    CaseError
        When ``word`` is none of the Status values.
    """
    try:
        return Status(word)
    except ValueError:
        words = ", ".join(status.value for status in Status)
        raise CaseError(
            f"unknown status {word!r}: expected one of {words} (not written by trackplan? "
            "remove its run folder to run the job again)",
            file=str(file),
            key="status",
        ) from None


def _number(value: Any) -> float:
    """A number of ``result.json`` as a float: ``null`` (no such figure) is NaN."""
    return math.nan if value is None else float(value)


def failed_row(job: dict[str, Any], reason: str, wall_time_s: float, worker: str) -> JobRow:
    """The row of a job without a result.

    Parameters
    ----------
    job
        The job's keys (:meth:`~trackplan.study.jobs.Job.describe`).
    reason
        Why it failed, one line.
    wall_time_s
        Time spent before it failed, s (NaN when unknown).
    worker
        Where it failed (empty when unknown).
    """
    nan = math.nan
    return JobRow(
        job=job["job"],
        case=job["case"],
        robot=job["robot"],
        sweep=job["sweep"],
        seed=int(job["seed"]),
        status=Status.FAILED,
        success=False,
        J=nan,
        duration_s=nan,
        cycle_time_s=nan,
        tracking_error_m=nan,
        worst_margin=nan,
        wall_time_s=wall_time_s,
        worker=worker,
        message=reason,
    )


def worst_margin(margins: dict[str, Any]) -> float:
    """The smallest unused fraction of a limit in ``result.json``'s ``margins`` block.

    Every joint limit (per joint) and task limit counts, except those of
    :data:`IGNORED_UNLESS_BROKEN`, which count only when broken. ``null`` entries (a limit
    that does not apply) are skipped.

    Returns
    -------
    float
        The smallest margin (negative: a limit is broken), NaN when there is none (no
        trajectory).
    """
    values = []
    for kind, entry in margins.items():
        for value in entry.values() if isinstance(entry, dict) else (entry,):
            number = _number(value)
            if not math.isfinite(number):
                continue
            if kind not in IGNORED_UNLESS_BROKEN or number < 0:
                values.append(number)
    return min(values) if values else math.nan


class SummaryWriter:
    """``summary.csv`` written row by row as jobs complete (flushed after each row).

    Parameters
    ----------
    file
        The CSV file (replaced).
    """

    def __init__(self, file: str | Path):
        self.file = Path(file)
        self._handle: TextIO = self.file.open("w", newline="", encoding="utf-8")
        self._writer = csv.writer(self._handle)
        self._writer.writerow(COLUMNS)
        self._handle.flush()

    def add(self, row: JobRow) -> None:
        """Append one row."""
        self._writer.writerow(_cells(row))
        self._handle.flush()

    def close(self) -> None:
        """Close the file."""
        self._handle.close()


def write_summary_csv(rows: Iterable[JobRow], file: str | Path) -> None:
    """Write ``summary.csv`` with the given rows."""
    writer = SummaryWriter(file)
    try:
        for row in rows:
            writer.add(row)
    finally:
        writer.close()


def read_summary_csv(file: str | Path) -> list[JobRow]:
    """Read ``summary.csv`` back into rows.

    Raises
    ------
    CaseError
        A row whose ``status`` is none of the :class:`~trackplan.status.Status` values.
    """
    with Path(file).open(newline="", encoding="utf-8-sig") as handle:  # a spreadsheet's BOM
        return [_row(cells, Path(file)) for cells in csv.DictReader(handle)]


def _cells(row: JobRow) -> list[str]:
    """CSV cells: floats in full precision (``repr``), booleans as true/false, text that a
    spreadsheet would run as a formula with a leading ``'`` (:func:`neutralised`)."""
    cells = []
    for value in astuple(row):
        if isinstance(value, bool):
            cells.append("true" if value else "false")
        elif isinstance(value, Status):
            cells.append(value.value)
        elif isinstance(value, float):
            cells.append(repr(value))
        elif isinstance(value, str):
            cells.append(neutralised(value))
        else:
            cells.append(str(value))
    return cells


def _row(cells: dict[str, str], file: Path) -> JobRow:
    values: dict[str, Any] = {}
    for field in fields(JobRow):
        text = cells[field.name]
        if field.type == "Status":
            values[field.name] = _status(text, file)
        elif field.type == "bool":
            values[field.name] = text == "true"
        elif field.type == "int":
            values[field.name] = int(text)
        elif field.type == "float":
            values[field.name] = float(text)
        else:
            values[field.name] = restored(text)
    return JobRow(**values)
