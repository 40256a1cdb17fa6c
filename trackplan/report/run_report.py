"""The plots and ``report.html`` of one run, on two cores when the machine has them.

Drawing the PNG plots is most of a report's cost, and the joint-trajectory grid alone is as
much as the other plots and the 3D view together. :func:`write_run_report` therefore draws
the first plot in a forked process while this one draws the others and builds the 3D view,
then embeds them all. The fork shares everything already imported and computed (matplotlib,
the result), so nothing is pickled or imported twice. Without a second core, where ``fork``
is unavailable or unsafe (not Linux, a daemonic process such as a Dask worker, other
Python threads running), or with ``parallel=False``, the plots are drawn in turn.
"""

from __future__ import annotations

import multiprocessing
import os
import sys
import threading
from collections.abc import Callable, Mapping
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from trackplan.case import Case
from trackplan.planning.result import PlanResult
from trackplan.report.figures import plot_figures, save_png
from trackplan.report.html import report_page, view_section
from trackplan.run_files import REPORT_FILE

if TYPE_CHECKING:
    from matplotlib.figure import Figure


def can_fork() -> bool:
    """Whether a plot may be drawn in a forked process: Linux, at least two usable cores,
    not a daemonic process (which may not have children) and no other Python thread (a
    fork copies only the calling thread, whatever locks the others hold)."""
    return (
        sys.platform == "linux"
        and len(os.sched_getaffinity(0)) > 1
        and not multiprocessing.current_process().daemon
        and threading.active_count() == 1
    )


def _save(build: Callable[[], Figure], path: Path) -> None:
    save_png(build(), path)


def _save_in_child(build: Callable[[], Figure], path: Path) -> None:
    """:func:`_save` in the forked process; a failure only sets the exit code: the parent
    draws the plot again and raises the error itself, with its traceback."""
    try:
        _save(build, path)
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
        Draw the first plot in a forked process when :func:`can_fork`; the files are the
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
    builders = list(plot_figures(result, case, history).items())
    paths = [out_dir / name for name, _ in builders]
    child, first = None, 0
    if parallel and len(builders) > 1 and can_fork():
        import matplotlib.figure  # noqa: F401  once, before the fork, for both processes

        child = multiprocessing.get_context("fork").Process(
            target=_save_in_child, args=(builders[0][1], paths[0]), name="trackplan-plot"
        )
        child.start()
        first = 1
    for (_, build), path in zip(builders[first:], paths[first:], strict=True):
        _save(build, path)
    view = view_section(result, case, n_frames)
    if child is not None:
        child.join()
        if child.exitcode != 0:
            _save(builders[0][1], paths[0])
    report = out_dir / REPORT_FILE
    page = report_page(result, case, paths, view, history, optimizer_info)
    report.write_text(page, encoding="utf-8")
    return paths, report
