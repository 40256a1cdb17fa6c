"""Drawing a run's plots on two cores when the machine has them.

The plots are split into drawing tasks: a banded plot (``joints.png``,
:class:`~trackplan.report.figure_style.BandedFigure`) gives one task per band, every other plot
one task. :func:`draw_plots` forks a process, and the two take the next task left until none
is; the fork shares everything already imported and computed (matplotlib, the result), so
nothing is pickled or imported twice, and it hands its bands over as pixel files in a
temporary folder. Without a second core, where ``fork`` is unavailable or unsafe (not Linux,
a daemonic process such as a Dask worker, other Python threads running), or with
``parallel=False``, the caller draws every task in turn. The files are the same either way.
"""

from __future__ import annotations

import multiprocessing
import sys
import tempfile
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any, TypeVar

import numpy as np

from trackplan.forking import can_fork
from trackplan.report.figure_style import BandedFigure, PlotBuilder, figure_pixels, save_png

if TYPE_CHECKING:
    from matplotlib.figure import Figure

T = TypeVar("T")


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
        np.save(band_dir / self.band_file, pixels)
        return None

    @property
    def band_file(self) -> str:
        return f"{self.path.stem}.band{self.band}.npy"


def _tasks(plots: Sequence[tuple[Path, PlotBuilder]]) -> list[_Task]:
    """The drawing tasks of the plots: the bands first (of the largest plot), then the
    others in report order."""
    bands = [
        _Task(path, build, k)
        for path, plot in plots
        if isinstance(plot, BandedFigure)
        for k, build in enumerate(plot.bands)
    ]
    whole = [_Task(path, plot) for path, plot in plots if not isinstance(plot, BandedFigure)]
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


def draw_plots(
    plots: Sequence[tuple[Path, PlotBuilder]],
    *,
    parallel: bool = True,
    meanwhile: Callable[[], T],
) -> T:
    """Write the PNG files of ``plots``, in two processes when ``parallel`` and
    :func:`can_fork`.

    Parameters
    ----------
    plots
        ``(file, figure builder or banded figure)`` pairs.
    parallel
        Share the drawing with a forked process when :func:`can_fork`.
    meanwhile
        Run by the caller once no task is left, while the forked process draws its last.

    Returns
    -------
    object
        What ``meanwhile`` returned.

    Raises
    ------
    Exception
        What drawing a plot raised (drawn again here when it failed in the forked process).
    """
    tasks = _tasks(plots)
    fork = parallel and len(tasks) > 1 and can_fork()
    queue = _Queue(len(tasks), shared=fork)
    pixels: dict[tuple[Path, int | None], np.ndarray | None] = {}
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
                pixels[tasks[k].path, tasks[k].band] = tasks[k].run(None)
                queue.done[k] = 1
            result = meanwhile()
        finally:
            if child is not None:
                child.join()
        for k, task in enumerate(tasks):
            if not queue.done[k]:  # the forked process failed on it
                pixels[task.path, task.band] = task.run(None)
            elif task.band is not None and (task.path, task.band) not in pixels:
                pixels[task.path, task.band] = np.load(band_dir / task.band_file)
    for path, plot in plots:
        if isinstance(plot, BandedFigure):
            plot.save(path, [pixels[path, band] for band in range(len(plot.bands))])  # type: ignore[misc]
    return result
