"""A process forked before a long computation that gets matplotlib ready to draw its plots.

Importing matplotlib and drawing the first figure of a process (fonts, numba's start for the
robot's kinematics) cost about as much as drawing half the plots. A :class:`PlotWorker`
forked before the placement search does that on the second core while the search runs on
the first; :func:`~trackplan.report.run_report.write_run_report` then sends it the run's
result, and it draws the plots (in two processes,
:func:`~trackplan.report.drawing.draw_plots`) while the caller builds the 3D view. When the
worker is gone or fails, the caller draws the plots itself, and raises any error.

The worker ignores SIGINT (the caller decides what an interruption means and still writes
its report) and ends when its connection closes: after one run's plots, at
:meth:`PlotWorker.close`, or when the caller's process ends.
"""

from __future__ import annotations

import contextlib
import multiprocessing
import os
import signal
import sys
from collections.abc import Iterator, Mapping
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:  # imported by the command line before its search: stays light
    from multiprocessing.connection import Connection

    from trackplan.case import Case
    from trackplan.planning.result import PlanResult


_READY = "ready"
"""What the worker sends once it has warmed up."""


class PlotWorker:
    """A forked process ready to draw one run's plots (:meth:`start`)."""

    def __init__(self, pid: int, connection: Connection) -> None:
        self.pid = pid
        self._connection: Connection | None = connection
        self._drawing = False
        self._ready = False

    @classmethod
    def start(cls, case: Case | None = None) -> PlotWorker | None:
        """Fork the worker, which imports matplotlib, draws a small figure and, given a
        case, runs its robot's kinematics once; None where
        :func:`~trackplan.forking.can_fork` says no."""
        from trackplan.forking import can_fork

        if not can_fork():
            return None
        ours, theirs = multiprocessing.Pipe()
        sys.stdout.flush()
        sys.stderr.flush()
        # SIGINT blocked across the fork, so that the worker ignores it from its start
        blocked = signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGINT})
        pid = os.fork()
        if pid == 0:  # the worker; it never returns into the caller's code
            code = 1
            try:
                signal.signal(signal.SIGINT, signal.SIG_IGN)
                signal.pthread_sigmask(signal.SIG_SETMASK, blocked)
                ours.close()
                _serve(theirs, case)
                code = 0
            finally:
                os._exit(code)
        signal.pthread_sigmask(signal.SIG_SETMASK, blocked)
        theirs.close()
        return cls(pid, ours)

    def draw(
        self,
        result: PlanResult,
        case: Case,
        history: Mapping[str, Mapping[str, np.ndarray]] | None,
        out_dir: Path,
    ) -> bool:
        """Send the run to draw the plots of
        (:func:`~trackplan.report.figures.plot_figures`) into ``out_dir``; False when the
        worker is gone."""
        if self._connection is None:
            return False
        try:
            self._connection.send((result, case, history, Path(out_dir)))
        except (OSError, EOFError):
            self.close()
            return False
        self._drawing = True
        return True

    def ready(self) -> bool:
        """Wait until the worker is ready to draw (it has warmed up); False when it is
        gone."""
        if self._connection is None:
            return False
        if not self._ready:
            try:
                self._ready = self._connection.recv() == _READY
            except (OSError, EOFError):
                return False
        return self._ready

    def wait(self) -> bool:
        """Wait for the plots sent with :meth:`draw`; True when the worker wrote them all.
        The worker ends either way."""
        written = False
        if self._connection is not None and self.ready():
            try:
                written = self._connection.recv() is True
            except (OSError, EOFError):
                written = False
        self._drawing = False
        self.close()
        return written

    def close(self) -> None:
        """End the worker and collect its exit: one still drawing (the caller stopped
        waiting, on an error or a signal) is terminated."""
        if self._connection is None:
            return
        self._connection.close()
        self._connection = None
        if self._drawing:
            with contextlib.suppress(ProcessLookupError):
                os.kill(self.pid, signal.SIGTERM)
        with contextlib.suppress(ChildProcessError):
            os.waitpid(self.pid, 0)


@contextlib.contextmanager
def plot_worker(case: Case | None = None) -> Iterator[PlotWorker | None]:
    """A :class:`PlotWorker` (None where there is none) that is closed on leaving the
    block."""
    worker = PlotWorker.start(case)
    try:
        yield worker
    finally:
        if worker is not None:
            worker.close()


def _warm_up(case: Case | None) -> None:
    """Load what the first figure of a process loads: matplotlib, its fonts and text layout,
    its 3D axes, and numba's kernels for the robot's kinematics."""
    from trackplan.report.figures import _new_figure, figure_pixels

    figure = _new_figure(2.0, 2.0, layout=None)
    ax = figure.add_subplot(1, 2, 1)
    ax.plot([0.0, 1.0], [0.0, 1.0], marker="o", label="x [m]")
    ax.set_title("warm-up", fontsize=7)
    ax.legend(fontsize=7)
    figure.add_subplot(1, 2, 2, projection="3d").plot([0.0, 1.0], [0.0, 1.0], [0.0, 1.0])
    figure_pixels(figure)
    if case is not None:
        from trackplan.report.scene import chain_points
        from trackplan.robots.kinematics import forward_kinematics

        q = np.zeros((1, case.robot.n_dof))
        forward_kinematics(case.robot, q)
        chain_points(case.robot, q)


def _serve(connection: Connection, case: Case | None) -> None:
    """The worker: get ready, then draw the plots of the one run it is sent, and answer
    whether they were all written."""
    from trackplan.report.drawing import draw_plots
    from trackplan.report.figures import plot_figures

    _warm_up(case)
    connection.send(_READY)
    try:
        result, run_case, history, out_dir = connection.recv()
    except (EOFError, OSError):
        return
    try:
        plots = plot_figures(result, run_case, history)
        draw_plots([(out_dir / name, plot) for name, plot in plots.items()], meanwhile=lambda: None)
    except Exception:
        connection.send(False)
        return
    connection.send(True)
