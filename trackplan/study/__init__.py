"""Batch studies: many placement searches (parts × robots × settings) on Dask distributed.

:func:`run_study` runs every job of a study file (:mod:`trackplan.io.study_file`) on a
``dask.distributed`` cluster, local or remote, and writes one run folder per job,
``summary.csv`` and ``summary.html``; ``trackplan batch`` is the same from the command
line. See ``docs/studies.md``.

The package itself is callable, ``trackplan.study(study, out, ...)``: the front door's
verb (:func:`trackplan.study.runner.study`) and this package share the name.
"""

import sys
from types import ModuleType
from typing import Any

from trackplan.study import runner
from trackplan.study.jobs import Job, Study, run_job
from trackplan.study.runner import (
    StudyProgress,
    StudyResult,
    connect,
    local_cluster,
    run_study,
    study,
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
    "study",
]


class _CallablePackage(ModuleType):
    """This package, which ``trackplan.study(...)`` calls: it runs :func:`runner.study`."""

    def __call__(self, *args: Any, **kwargs: Any) -> StudyResult:
        """Run a study: the arguments of :func:`trackplan.study.runner.run_study`."""
        return runner.study(*args, **kwargs)


sys.modules[__name__].__class__ = _CallablePackage
