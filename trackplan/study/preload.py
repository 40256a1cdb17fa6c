"""Dask worker preload: allocator settings and the numba kernels, before the first job.

``dask worker tcp://HOST:8786 --nthreads 1 --preload trackplan.study.preload`` (and every
local cluster :func:`trackplan.run_study` starts) runs :func:`dask_setup` in each worker
process when it starts: it leaves Ctrl-C to the client, turns off the worker's statistical
profiler (:func:`stop_profiler`), sets glibc's allocator as the CLI does
(:func:`trackplan.allocator.keep_freed_memory`) and runs two tiny searches, one per IK
family (closed form, numeric), so that numba compiles its kernels into its on-disk cache
(or loads them from it) before any job is timed.
"""

from __future__ import annotations

import signal
import threading
from typing import Any

from trackplan.allocator import keep_freed_memory

WARM_UP_CASE = """
name: warm-up
robot: {robot}
path:
  start: [0, 0, 0]
  segments:
    - line: {{to: [0.05, 0, 0]}}
    - line: {{to: [0.05, 0.05, 0]}}
task: {{rated_speed: 0.1, tolerance: 0.002, sample_time: 0.004}}
optimizer: {{population: 4, budget: 8, restarts: 1}}
"""
"""A 10 cm corner: every kernel of a search runs, in well under a second once compiled."""

WARM_UP_ROBOTS = ("puma560", "ur5")
"""One robot per IK family."""

PROFILER_CALLBACKS = ("profile", "profile-cycle")
"""The worker's periodic callbacks that sample and collect its statistical profile."""


def warm_up() -> None:
    """Run a tiny placement search per IK family (compiles or loads the numba kernels)."""
    from trackplan.io.case_file import load_case_text
    from trackplan.search.optimize import optimize

    for robot in WARM_UP_ROBOTS:
        optimize(load_case_text(WARM_UP_CASE.format(robot=robot), file="warm-up"))


def stop_profiler(worker: Any) -> None:
    """Turn off a Dask worker's statistical profiler before it starts.

    Every 10 ms (``distributed.worker.profile.interval``) the worker's event loop takes the
    GIL from the running task to walk its Python stack. A placement search is one long task
    with deep stacks (pymoo, numpy): measured 0.4 s of the event loop's CPU time per 4 s
    search, during which the search waits for the GIL. The profile is only a dashboard
    page; nothing in a batch reads it. Called from :func:`dask_setup`, which Dask runs
    before it starts the worker's periodic callbacks.
    """
    for name in PROFILER_CALLBACKS:
        callback = worker.periodic_callbacks.pop(name, None)
        if callback is not None:
            callback.stop()


def dask_setup(worker: Any) -> None:
    """Dask's preload hook: called once in each worker process as it starts.

    The worker also ignores Ctrl-C (SIGINT), which a terminal sends to every process of
    the batch: the client cancels the jobs, and the cluster or the worker's nanny stops
    the worker.
    """
    if threading.current_thread() is threading.main_thread():
        signal.signal(signal.SIGINT, signal.SIG_IGN)
    stop_profiler(worker)
    keep_freed_memory()
    warm_up()
