"""The plots and ``report.html`` of one run, on two cores when the machine has them.

Drawing the PNG plots is most of a report's cost, and the joint-trajectory grid alone is as
much as the other plots together. :func:`write_run_report` therefore splits the plots into
drawing tasks (the joint grid into its two bands, :data:`~trackplan.report.figures.JOINT_BANDS`,
the others one task each) and draws them in two processes: a forked one and this one each
take the next task left until none is, then this one builds the 3D view, stacks the bands
and embeds everything. The fork shares everything already imported and computed
(matplotlib, the result), so nothing is pickled or imported twice; it hands its bands over
as pixel files in a temporary folder. Without a second core, where ``fork`` is unavailable
or unsafe (not Linux, a daemonic process such as a Dask worker, other Python threads
running), or with ``parallel=False``, this process draws every task in turn. The files are
the same either way.
"""

from __future__ import annotations

import multiprocessing
import os
import sys
import tempfile
import threading
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from trackplan.case import Case
from trackplan.planning.result import PlanResult
from trackplan.report.figures import BandedFigure, figure_pixels, plot_figures, save_png
from trackplan.report.html import report_page, view_section
from trackplan.run_files import REPORT_FILE

if TYPE_CHECKING:
    from matplotlib.figure import Figure


def can_fork() -> bool:
    """Whether plots may be drawn in a forked process: Linux, at least two usable cores,
    not a daemonic process (which may not have children) and no other Python thread (a
    fork copies only the calling thread, whatever locks the others hold)."""
    return (
        sys.platform == "linux"
        and len(os.sched_getaffinity(0)) > 1
        and not multiprocessing.current_process().daemon
        and threading.active_count() == 1
    )


@dataclass(frozen=True)
class _Task:
    """One drawing task: a whole plot written to ``path``, or band ``band`` of a banded
    plot, whose pixels the caller stacks."""

    path: Path
    build: Callable[[], Figure]
    band: int | None = None

    def run(self, band_dir: Path | None) -> np.ndarray | None:
        """Draw; a band's pixels are returned, or saved into ``band_dir`` when given."""
        if self.band is None:
            save_png(self.build(), self.path)
            return None
        pixels = figure_pixels(self.build())
        if band_dir is None:
            return pixels
        np.save(band_dir / _band_file(self.path, self.band), pixels)
        return None


def _band_file(path: Path, band: int) -> str:
    return f"{path.stem}.band{band}.npy"


def _tasks(builders: Sequence[tuple[Path, Any]]) -> list[_Task]:
    """The drawing tasks of the plots, bands first (the largest plot), then in report
    order."""
    bands = [
        _Task(path, build, k)
        for path, plot in builders
        if isinstance(plot, BandedFigure)
        for k, build in enumerate(plot.bands)
    ]
    whole = [_Task(path, plot) for path, plot in builders if not isinstance(plot, BandedFigure)]
    return bands + whole


class _Queue:
    """The tasks left: each process takes the next one and marks it done when drawn. A
    ``shared`` queue lives in shared memory, for the processes forked after it was made."""

    def __init__(self, n_tasks: int, shared: bool) -> None:
        self.n_tasks = n_tasks
        self._next: Any
        self.done: Any
        if shared:
            context = multiprocessing.get_context("fork")
            self._next = context.Value("i", 0)
            self.done = context.Array("b", n_tasks, lock=False)
        else:
            self._next, self.done = None, [0] * n_tasks
        self._taken = 0

    def take(self) -> int | None:
        """The index of the next task, or None when every task is taken."""
        if self._next is None:
            k, self._taken = self._taken, self._taken + 1
        else:
            with self._next.get_lock():
                k = self._next.value
                self._next.value = k + 1
        return k if k < self.n_tasks else None


def _draw_in_child(tasks: Sequence[_Task], queue: _Queue, band_dir: Path) -> None:
    """The forked process: draw tasks until none is left. A failure only sets the exit code:
    the caller draws the task again and raises the error itself, with its traceback."""
    try:
        while (k := queue.take()) is not None:
            tasks[k].run(band_dir)
            queue.done[k] = 1
    except Exception:
        sys.exit(1)


def write_run_report(
    result: PlanResult,
    case: Case,
    out_dir: Path,
    history: Mapping[str, Mapping[str, np.ndarray]] | None = None,
    optimizer_info: Mapping[str, object] | None = None,
    *,
    parallel: bool = True,
    n_frames: int = 150,
) -> tuple[list[Path], Path]:
    """Write the plots (:func:`~trackplan.report.figures.write_plots`) and ``report.html``
    (:func:`~trackplan.report.html.write_report`) of a run.

    Parameters
    ----------
    result
        The planned placement.
    case
        The case it was planned for.
    out_dir
        Directory to write into (created when missing).
    history
        Optimizer history per method (``convergence.png``), or None.
    optimizer_info
        Figures of the search shown as a table, or None.
    parallel
        Share the drawing with a forked process when :func:`can_fork`; the files are the
        same either way.
    n_frames
        Number of animation frames of the 3D view.

    Returns
    -------
    tuple of (list of pathlib.Path, pathlib.Path)
        The PNG files in report order, and the report file.
    """
    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    plots = plot_figures(result, case, history)
    builders = [(out_dir / name, plot) for name, plot in plots.items()]
    tasks = _tasks(builders)
    pixels: dict[tuple[Path, int], np.ndarray] = {}
    fork = parallel and len(tasks) > 1 and can_fork()
    queue = _Queue(len(tasks), shared=fork)
    with tempfile.TemporaryDirectory(prefix="trackplan-plots-") as scratch:
        band_dir = Path(scratch)
        child = None
        if fork:
            import matplotlib.figure  # noqa: F401  once, before the fork, for both processes

            child = multiprocessing.get_context("fork").Process(
                target=_draw_in_child, args=(tasks, queue, band_dir), name="trackplan-plots"
            )
            child.start()
        try:
            while (k := queue.take()) is not None:
                drawn = tasks[k].run(None)
                if drawn is not None:
                    pixels[tasks[k].path, tasks[k].band] = drawn  # type: ignore[index]
                queue.done[k] = 1
            view = view_section(result, case, n_frames)
        finally:
            if child is not None:
                child.join()
        for k, task in enumerate(tasks):
            if task.band is None:
                if not queue.done[k]:  # the forked process failed on it
                    task.run(None)
                continue
            key = (task.path, task.band)
            if key not in pixels:
                file = band_dir / _band_file(task.path, task.band)
                pixels[key] = np.load(file) if queue.done[k] else task.run(None)  # type: ignore[assignment]
    for path, plot in builders:
        if isinstance(plot, BandedFigure):
            plot.save(path, [pixels[path, band] for band in range(len(plot.bands))])
    paths = [path for path, _ in builders]
    report = out_dir / REPORT_FILE
    page = report_page(result, case, paths, view, history, optimizer_info)
    report.write_text(page, encoding="utf-8")
    return paths, report
