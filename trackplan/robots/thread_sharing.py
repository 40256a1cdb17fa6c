"""Whether the closed-form path IK on all branches shares its work among threads.

The caller that makes the repeated calls (the search's fitness) owns a
:class:`ThreadSharing` and passes it to :func:`trackplan.robots.path_ik.solve_path_ik`
and :func:`~trackplan.robots.path_ik.solve_path_ik_branches`; a call without one uses
:func:`path_threads` threads and remembers nothing.
"""

from __future__ import annotations

import os

EFFICIENT = 0.7
"""Parallel efficiency (the threads' CPU time over threads × wall time) of a shared call of
the path IK below which sharing does not pay: a thread waited for a core. Measured on two
cores: about 0.95 with the second core free, about 0.3–0.4 at a load of 4."""

FIRST_PAUSE = 4
"""Calls of the path IK run on one thread after a shared call that did not pay; the pause
doubles while sharing keeps not paying, up to :data:`LAST_PAUSE`."""
LAST_PAUSE = 64


def path_threads() -> int:
    """The cores this process may run on (``os.sched_getaffinity``): the threads the
    closed-form path IK on all branches shares its work among while that pays."""
    if hasattr(os, "sched_getaffinity"):
        return len(os.sched_getaffinity(0))
    return os.cpu_count() or 1


class ThreadSharing:
    """Whether the path IK shares its work among threads: while sharing pays.

    Threads help only where a core is free. On a busy machine a thread waits for a core
    and the caller waits for the thread: the call then takes longer than on one thread
    (the corner case's search took 1.5× its one-thread wall time at a load of 4 on two
    cores). So each shared call measures its parallel efficiency; below
    :data:`EFFICIENT`, the next calls run on one thread (:data:`FIRST_PAUSE` calls, twice
    as many after each further shared call that does not pay, at most
    :data:`LAST_PAUSE`). The results are the same on any number of threads. One object
    serves one caller's sequence of calls (it is not locked).
    """

    def __init__(self) -> None:
        self.pause = 0  # the last pause, calls
        self.left = 0  # calls still to run on one thread

    def threads(self) -> int:
        """Threads for the next call: one during a pause, else :func:`path_threads`."""
        if self.left > 0:
            self.left -= 1
            return 1
        return path_threads()

    def note(self, efficiency: float) -> None:
        """Record a shared call's parallel efficiency (in (0, 1])."""
        if efficiency >= EFFICIENT:
            self.pause = 0
        else:
            self.pause = min(LAST_PAUSE, 2 * self.pause if self.pause else FIRST_PAUSE)
            self.left = self.pause
