"""A process forked at a command's start that gets matplotlib ready to draw its plots.

Importing matplotlib and the report's modules and drawing the first figure of a process
(fonts, text layout, 3D axes, the PNG encoder) cost about as much as drawing half the
plots. A :class:`PlotWorker` forked when ``trackplan optimize`` starts does that on the
second core while the command imports its planner, loads the case and starts numba's
kernels on the first (the second core is idle then: the search and the plans beside it
start later). :func:`~trackplan.report.run_report.write_run_report` then sends it the run's
result with what the plots need from the compiled kernels
(:class:`~trackplan.report.path_plots.PlotKinematics`), so that the worker never starts
numba, and it draws the plots (in two processes,
:func:`~trackplan.report.drawing.draw_plots`) while the caller builds the 3D view. When the
worker is gone or fails, the caller draws the plots itself, and raises any error.

Given the robot's number of joints early (:meth:`PlotWorker.prepare`), it also makes the
plots' figures and axes (:func:`~trackplan.report.figures.blank_canvases`) before the
result comes. The worker ignores SIGINT (the caller decides what an interruption means and
still writes its report) and ends when its connection closes: after one run's plots, at
:meth:`PlotWorker.close` (which terminates a worker that has not answered), or when the
caller's process ends.
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
    from trackplan.report.path_plots import PlotKinematics


_READY = "ready"
"""What the worker sends once it has warmed up."""


class PlotWorker:
    """A forked process ready to draw one run's plots (:meth:`start`)."""

    def __init__(self, pid: int, connection: Connection) -> None:
        self.pid = pid
        self._connection: Connection | None = connection
        self._answered = False
        self._ready = False

    @classmethod
    def start(cls) -> PlotWorker | None:
        """Fork the worker, which imports matplotlib and the report's modules and draws a
        small figure; None where :func:`~trackplan.forking.can_fork` says no."""
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
                _serve(theirs)
                code = 0
            finally:
                os._exit(code)
        signal.pthread_sigmask(signal.SIG_SETMASK, blocked)
        theirs.close()
        return cls(pid, ours)

    def prepare(self, n_dof: int) -> None:
        """Have the worker make the blank figures of the plots of a robot with ``n_dof``
        joints (:func:`~trackplan.report.figures.blank_canvases`) once it is ready, while
        the run is computed; a run of another robot gets figures made when it is drawn."""
        if self._connection is None:
            return
        try:
            self._connection.send(("canvases", n_dof))
        except (OSError, EOFError):
            self.close()

    def draw(
        self,
        result: PlanResult,
        case: Case,
        history: Mapping[str, Mapping[str, np.ndarray]] | None,
        out_dir: Path,
        kinematics: PlotKinematics,
    ) -> bool:
        """Send the run to draw the plots of
        (:func:`~trackplan.report.figures.plot_figures`, with the run's ``kinematics``)
        into ``out_dir``; False when the worker is gone."""
        if self._connection is None:
            return False
        try:
            self._connection.send(("draw", (result, case, history, Path(out_dir), kinematics)))
        except (OSError, EOFError):
            self.close()
            return False
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
                self._answered = True
            except (OSError, EOFError):
                written = False
        self.close()
        return written

    def close(self) -> None:
        """End the worker and collect its exit: one that has not answered (still getting
        ready, or drawing when the caller stopped waiting, on an error or a signal) is
        terminated."""
        if self._connection is None:
            return
        self._connection.close()
        self._connection = None
        if not self._answered:
            with contextlib.suppress(ProcessLookupError):
                os.kill(self.pid, signal.SIGTERM)
        with contextlib.suppress(ChildProcessError):
            os.waitpid(self.pid, 0)


@contextlib.contextmanager
def plot_worker() -> Iterator[PlotWorker | None]:
    """A :class:`PlotWorker` (None where there is none) that is closed on leaving the
    block."""
    worker = PlotWorker.start()
    try:
        yield worker
    finally:
        if worker is not None:
            worker.close()


def _warm_up() -> None:
    """Load what the first figure of a process loads: the report's modules, matplotlib, its
    fonts and text layout, its 3D axes and the PNG encoder. No compiled kernel runs here."""
    import io

    import trackplan.report.drawing  # noqa: F401  (what draw_plots and the result need)
    from trackplan.report.figure_style import DPI, PNG_COMPRESSION, new_figure

    figure = new_figure(2.0, 2.0, layout=None)
    ax = figure.add_subplot(1, 2, 1)
    ax.plot([0.0, 1.0], [0.0, 1.0], marker="o", label="x [m]")
    ax.set_title("warm-up", fontsize=7)
    ax.legend(fontsize=7)
    figure.add_subplot(1, 2, 2, projection="3d").plot([0.0, 1.0], [0.0, 1.0], [0.0, 1.0])
    figure.savefig(
        io.BytesIO(), format="png", dpi=DPI, pil_kwargs={"compress_level": PNG_COMPRESSION}
    )


def _serve(connection: Connection) -> None:
    """The worker: get ready, then draw the plots of the one run it is sent, and answer
    whether they were all written."""
    _warm_up()
    from trackplan.report.drawing import draw_plots
    from trackplan.report.figures import blank_canvases, plot_figures

    connection.send(_READY)
    canvases, n_dof = {}, None
    try:
        while (message := connection.recv())[0] == "canvases":
            n_dof = message[1]
            canvases = blank_canvases(n_dof)
    except (EOFError, OSError):
        return
    result, run_case, history, out_dir, kinematics = message[1]
    if run_case.machine.n_dof != n_dof:
        canvases = {}
    try:
        plots = plot_figures(result, run_case, history, kinematics, canvases)
        draw_plots([(out_dir / name, plot) for name, plot in plots.items()], meanwhile=lambda: None)
    except Exception:
        connection.send(False)
        return
    connection.send(True)
