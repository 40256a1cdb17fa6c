"""Everything a run writes into its folder: result files, plots and the HTML report."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

from trackplan.case import Case
from trackplan.io.results import write_plan_files
from trackplan.planning.result import PlanResult
from trackplan.robots.describe import robot_info

if TYPE_CHECKING:  # the search (pymoo) is not needed to write a plan
    from trackplan.search import OptimizeResult


def write_run(
    out_dir: Path,
    result: PlanResult,
    case: Case,
    *,
    history: dict | None = None,
    extra: dict | None = None,
    report: bool = True,
) -> dict:
    """Write trajectory.csv, result.json and, with ``report``, the plots and report.html.

    Parameters
    ----------
    out_dir
        Output folder (created).
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

    Returns
    -------
    dict
        The ``result.json`` content.
    """
    out_dir = Path(out_dir)
    extra = {"robot": robot_info(case.robot), **(extra or {})}
    summary = write_plan_files(result, case.robot.joint_names, out_dir, extra)
    if report:
        from trackplan.report import write_plots, write_report

        plots = write_plots(result, case, out_dir, history)
        write_report(result, case, out_dir, plots, history=history, optimizer_info=extra)
    return summary


def write_search_run(out_dir: Path, result: OptimizeResult, case: Case, *, report: bool) -> dict:
    """Write a placement search's run folder: :func:`write_run` for the final plan, with the
    ``optimizer`` and ``initial`` blocks in ``result.json``, and ``history.csv``.

    Parameters
    ----------
    out_dir
        Output folder (created).
    result
        The search.
    case
        Its case.
    report
        Also write the plots and the HTML report.

    Returns
    -------
    dict
        The ``result.json`` content.
    """
    from trackplan.io.history import optimizer_summary, write_history

    history = {result.method: result.history.as_columns()} if len(result.history) else None
    extra = optimizer_summary(result, case.robot.joint_names)
    summary = write_run(out_dir, result.final, case, history=history, extra=extra, report=report)
    write_history(result, Path(out_dir))
    return summary
