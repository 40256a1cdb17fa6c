"""Everything a run writes into its folder: result files, plots, report and search history.

The folder is written as a whole (:func:`trackplan.io.run_folder.write_run_folder`): every
file through a staging folder and an atomic rename, ``result.json`` last, and an earlier
run's files that this run does not write are removed.
"""

from __future__ import annotations

from dataclasses import replace
from functools import partial
from pathlib import Path
from typing import TYPE_CHECKING

from trackplan.case import Case
from trackplan.io.results import write_plan_files
from trackplan.io.run_folder import write_run_folder
from trackplan.planning.result import PlanResult
from trackplan.robots.describe import robot_info

if TYPE_CHECKING:  # the search (pymoo) is not needed to write a plan
    from trackplan.report.plot_worker import PlotWorker
    from trackplan.search.optimize import SearchResult


def write_run(
    out_dir: Path,
    result: PlanResult,
    case: Case,
    *,
    history: dict | None = None,
    extra: dict | None = None,
    report: bool = True,
    search: SearchResult | None = None,
    plot_worker: PlotWorker | None = None,
) -> dict:
    """Write trajectory.csv, result.json and, with ``report``, the plots and report.html of
    any plan (one seam or several: :func:`~trackplan.io.results.write_plan_files`).

    Parameters
    ----------
    out_dir
        Output folder (created). Outputs of an earlier run there are replaced or removed.
    result
        The plan to write.
    case
        Its case.
    history
        Optimizer history per method (for ``convergence.png``), or None.
    extra
        More keys for ``result.json`` (optimizer figures, the initial plan); the ``robot``
        block (:func:`~trackplan.robots.describe.robot_info`) is always added.
    report
        Also write the plots and the HTML report (which embeds them).
    search
        The search (:class:`~trackplan.search.optimize.SearchResult`) whose
        ``history.csv`` to write, or None.
    plot_worker
        A :class:`~trackplan.report.plot_worker.PlotWorker` to draw the plots, or None.

    Returns
    -------
    dict
        The ``result.json`` content.
    """
    extra = {"robot": robot_info(case.robot), **(extra or {})}
    written: dict = {}

    def write_files(folder: Path) -> None:
        if search is not None:
            from trackplan.io.history import write_history_csv
            from trackplan.run_files import HISTORY_FILE

            write_history_csv(search.history, folder / HISTORY_FILE)
        written.update(write_plan_files(result, case, folder, extra))

    def write(folder: Path) -> None:
        if not report:
            write_files(folder)
            return
        from trackplan.report.run_report import write_run_report

        # the files written while the plots are drawn
        meanwhile = partial(write_files, folder)
        write_run_report(
            result, case, folder, history, extra, worker=plot_worker, meanwhile=meanwhile
        )

    write_run_folder(Path(out_dir), write)
    return written


def write_search_run(
    out_dir: Path,
    result: SearchResult,
    case: Case,
    *,
    report: bool,
    extra: dict | None = None,
    plot_worker: PlotWorker | None = None,
) -> dict:
    """Write a placement search's run folder: :func:`write_run` for the final plan, with the
    ``optimizer`` and ``initial`` blocks (and ``extra``) in ``result.json``, and ``history.csv``.

    Parameters
    ----------
    out_dir
        Output folder (created); written as a whole like :func:`write_run`.
    result
        The search (:class:`~trackplan.search.optimize.SearchResult`).
    case
        Its case.
    report
        Also write the plots and the HTML report.
    extra
        More keys for ``result.json`` (an interrupted search's marks).
    plot_worker
        A :class:`~trackplan.report.plot_worker.PlotWorker` to draw the plots, or None.

    Returns
    -------
    dict
        The ``result.json`` content.
    """
    from trackplan.io.history import optimizer_summary

    if result.positioner_pose is not None and case.positioner is not None:
        case = replace(case, positioner=case.positioner.at(result.positioner_pose))
    history = {result.method: result.history.as_columns()} if len(result.history) else None
    blocks = {**optimizer_summary(result, case.machine.joint_names), **(extra or {})}
    return write_run(
        out_dir,
        result.final,
        case,
        history=history,
        extra=blocks,
        report=report,
        search=result,
        plot_worker=plot_worker,
    )
