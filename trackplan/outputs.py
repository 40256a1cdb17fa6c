"""Everything a run writes into its folder: result files, plots and the HTML report."""

from __future__ import annotations

from pathlib import Path

from trackplan.case import Case
from trackplan.io.results import write_plan_files
from trackplan.planning.result import PlanResult
from trackplan.robots.describe import robot_info


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
