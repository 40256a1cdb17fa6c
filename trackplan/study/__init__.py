"""Batch studies: many placement searches (parts × robots × settings) on Dask distributed.

:func:`run_study` runs every job of a study file (:mod:`trackplan.io.study_file`) on a
``dask.distributed`` cluster, local or remote, and writes one run folder per job,
``summary.csv`` and ``summary.html``; ``trackplan batch`` is the same from the command
line. See ``docs/studies.md``.
"""

from trackplan.study.jobs import Job, Study, run_job
from trackplan.study.runner import (
    StudyProgress,
    StudyResult,
    connect,
    local_cluster,
    run_study,
)
from trackplan.study.summary import COLUMNS, JobRow, read_summary_csv

__all__ = [
    "COLUMNS",
    "Job",
    "JobRow",
    "Study",
    "StudyProgress",
    "StudyResult",
    "connect",
    "local_cluster",
    "read_summary_csv",
    "run_job",
    "run_study",
]
