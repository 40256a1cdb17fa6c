"""The plots and ``report.html`` of one run, on two cores when the machine has them.

Every run gets the same report; a plan whose seams are joined by moves (approach, retract,
air) gets the cycle's plot and sequence too (:mod:`trackplan.report.cycle`).

Drawing the PNG plots is most of a report's cost: :func:`write_run_report` draws them in
two processes (:func:`~trackplan.report.drawing.draw_plots`) and builds the 3D view while
the other process draws its last plot, or, given a
:class:`~trackplan.report.plot_worker.PlotWorker` started before the run was computed, has
the worker draw them while it builds the 3D view. The files are the same either way.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from trackplan.case import Case
from trackplan.planning.result import PlanResult
from trackplan.report.drawing import can_fork, draw_plots
from trackplan.report.figures import plot_figures, plot_kinematics
from trackplan.report.html import report_page, view_section
from trackplan.run_files import REPORT_FILE

if TYPE_CHECKING:
    from trackplan.report.plot_worker import PlotWorker

__all__ = ["can_fork", "write_run_report"]


def write_run_report(
    result: PlanResult,
    case: Case,
    out_dir: Path,
    history: Mapping[str, Mapping[str, np.ndarray]] | None = None,
    optimizer_info: Mapping[str, object] | None = None,
    *,
    parallel: bool = True,
    n_frames: int = 150,
    worker: PlotWorker | None = None,
    meanwhile: Callable[[], object] | None = None,
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
        Share the drawing with a forked process when
        :func:`~trackplan.report.drawing.can_fork`; the files are the same either way.
    n_frames
        Number of animation frames of the 3D view.
    worker
        A plot worker started before the run was computed, which draws the plots
        (and ends); when it is gone or fails, the plots are drawn here.
    meanwhile
        More work of the caller (the run's other files), done while the other process
        draws, after the 3D view.

    Returns
    -------
    tuple of (list of pathlib.Path, pathlib.Path)
        The PNG files in report order, and the report file.
    """
    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    kinematics = plot_kinematics(result, case)  # numba's kernels run here, not in the worker
    builders = plot_figures(result, case, history, kinematics)
    plots = [(out_dir / name, plot) for name, plot in builders.items()]

    def view_and_more() -> str:
        view = view_section(result, case, n_frames)
        if meanwhile is not None:
            meanwhile()
        return view

    if worker is not None and worker.draw(result, case, history, out_dir, kinematics):
        view = view_and_more()
        if not worker.wait():
            draw_plots(plots, parallel=parallel, meanwhile=lambda: None)
    else:
        view = draw_plots(plots, parallel=parallel, meanwhile=view_and_more)
    paths = [path for path, _ in plots]
    report = out_dir / REPORT_FILE
    page = report_page(result, case, paths, view, history, optimizer_info)
    report.write_text(page, encoding="utf-8")
    return paths, report
