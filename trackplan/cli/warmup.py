"""numba's kernels compiled ahead of their first use, so that a first run compiles each once.

On a fresh install numba compiles every kernel a command uses at its first call, most of a
first ``trackplan demo``'s time (docs/benchmarks.md, "First run"), and keeps it in its
on-disk cache, from which later runs load it. ``optimize`` and ``demo`` search in their own
process and plan beside it in a forked one (:func:`~trackplan.forking.forked_pool`):

- :func:`compile_shared` runs in the command's process before the search: it compiles the
  kernels that the search and the plans both start with (forward kinematics, the link
  frames, the closed-form IK of all branches), which the forked process then inherits
  instead of compiling them at the same time.
- :func:`late_compiles` forks a process that compiles a kernel only the end of the run
  needs (the CSV writer's) beside the search, long before the command writes its files, and
  hands it over through numba's on-disk cache; once that kernel is cached, it forks nothing.

Both only call the package's own functions on tiny inputs: the kernels compile with the
types a run passes them (their callers pass read-only inputs,
:func:`trackplan._kernels.read_only`), and a warm run loads what it would load anyway.
"""

from __future__ import annotations

import contextlib
import os
import signal
import sys
from collections.abc import Iterator
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from trackplan.case import Case


def compile_shared(case: Case) -> None:
    """Compile (or load) the kernels the search and the plans beside it both start with.

    Parameters
    ----------
    case
        The case to be searched: its robot's kernels are compiled.
    """
    import numpy as np

    from trackplan.robots.families import ik_family
    from trackplan.robots.families.base import FusedClosedForm
    from trackplan.robots.kinematics import forward_kinematics, joint_frames

    robot = case.robot
    q = np.zeros((1, robot.n_dof))
    T = forward_kinematics(robot, q)
    joint_frames(robot, q)
    family = ik_family(robot)
    if isinstance(family, FusedClosedForm):
        family.solve_flat(T, with_aux=False)


def _writer_cached() -> bool:
    """Whether numba's cache holds the CSV writer's kernel already (then nothing to do)."""
    from trackplan.io._kernels import format_rows

    try:
        return os.path.exists(format_rows._cache._cache_file._index_path)  # type: ignore[attr-defined]
    except AttributeError:  # another numba: compile it
        return False


def _compile_late() -> None:
    """The work of the late process: the CSV writer's kernel."""
    import numpy as np

    from trackplan.io.csv_table import format_table

    format_table(np.zeros((1, 2)))


@contextlib.contextmanager
def late_compiles() -> Iterator[None]:
    """Fork the late-compile process (where forking is possible and its kernel is not cached
    yet) for the block; on leaving, end it if it still runs, and reap it."""
    from trackplan.forking import can_fork

    if not can_fork() or _writer_cached():
        yield
        return
    sys.stdout.flush()
    sys.stderr.flush()
    blocked = signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGINT})
    pid = os.fork()
    if pid == 0:  # never returns into the caller's code
        code = 1
        try:
            signal.signal(signal.SIGINT, signal.SIG_IGN)
            signal.signal(signal.SIGTERM, signal.SIG_DFL)
            signal.pthread_sigmask(signal.SIG_SETMASK, blocked)
            _compile_late()
            code = 0
        finally:
            os._exit(code)
    signal.pthread_sigmask(signal.SIG_SETMASK, blocked)
    try:
        yield
    finally:
        with contextlib.suppress(ProcessLookupError, ChildProcessError):
            if os.waitpid(pid, os.WNOHANG) == (0, 0):
                os.kill(pid, signal.SIGTERM)
                os.waitpid(pid, 0)
