"""Work beside the caller in a forked process, where forking is available and safe.

A forked process starts with everything the caller has already imported and computed, so
that nothing is imported twice; it runs on the machine's second core while the caller goes
on. :func:`can_fork` says when that is possible, :func:`forked_pool` gives a one-process
executor (:class:`concurrent.futures.ProcessPoolExecutor` with the ``fork`` start method)
for :func:`~trackplan.search.optimize`'s ``background`` argument.
"""

from __future__ import annotations

import contextlib
import multiprocessing
import os
import signal
import sys
import threading
from collections.abc import Iterator
from typing import TYPE_CHECKING

if TYPE_CHECKING:  # imported by the command line before its search: stays light
    from concurrent.futures import ProcessPoolExecutor


def can_fork() -> bool:
    """Whether work may go to a forked process: Linux, at least two usable cores, not a
    daemonic process (which may not have children) and no other Python thread (a fork
    copies only the calling thread, whatever locks the others hold)."""
    return (
        sys.platform == "linux"
        and len(os.sched_getaffinity(0)) > 1
        and not multiprocessing.current_process().daemon
        and threading.active_count() == 1
    )


def _leave_signals() -> None:
    """The forked worker's start: Ctrl-C is the caller's to handle (it still needs the
    worker's answers), SIGTERM ends the worker (the caller then does its work itself)."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    signal.signal(signal.SIGTERM, signal.SIG_DFL)


@contextlib.contextmanager
def forked_pool() -> Iterator[ProcessPoolExecutor | None]:
    """A one-process pool whose process is forked at its first ``submit`` (None where
    :func:`can_fork` says no), shut down on leaving the block.

    The worker ignores SIGINT and dies of SIGTERM: a caller handling either keeps its
    answers or, once the pool is broken
    (:class:`concurrent.futures.process.BrokenProcessPool`), does the work itself. The fork
    happens at the first ``submit``: no other thread may run then (a progress bar's
    refresh thread, for example). The pool's own threads end on leaving the block, before
    anything else forks.
    """
    if not can_fork():
        yield None
        return
    from concurrent.futures import ProcessPoolExecutor

    pool = ProcessPoolExecutor(
        max_workers=1, mp_context=multiprocessing.get_context("fork"), initializer=_leave_signals
    )
    try:
        yield pool
    finally:
        pool.shutdown(wait=True, cancel_futures=True)
