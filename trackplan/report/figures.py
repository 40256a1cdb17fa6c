"""Static plots of a planned trajectory (matplotlib, Agg canvas, no pyplot state).

The plots of a run, each drawn by its own module (``joints_plot``, ``path_plots``,
``speed_plot``, ``convergence_plot``, ``cell_figures``); each ``*_figure`` function returns
a :class:`matplotlib.figure.Figure`. :func:`plot_figures` lists a run's plots and
:func:`write_plots` saves them as PNG files. Artists that tests and readers look for
carry a ``gid`` (``limit``, ``violation``, ``path-before``, ``reach-shell``, …).
matplotlib is imported inside the functions so that importing trackplan stays fast.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from functools import partial
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from trackplan.case import Case
from trackplan.planning.result import PlanResult
from trackplan.report.convergence_plot import convergence_canvas, convergence_figure
from trackplan.report.cycle import CYCLE_PLOT, cycle_figure, has_moves
from trackplan.report.figure_style import BandedFigure, Canvas, PlotBuilder, new_figure, save_png
from trackplan.report.joints_plot import JOINT_BANDS, joints_canvas, joints_figure
from trackplan.report.path_plots import (
    PlotKinematics,
    path_canvas,
    path_figure,
    plot_kinematics,
    shows_tool,
    tool_figure,
)
from trackplan.report.speed_plot import speed_canvas, speed_figure

if TYPE_CHECKING:
    from matplotlib.figure import Figure

_new_figure = new_figure  # moved to figure_style; importers outside this package keep working


def blank_canvases(n_dof: int) -> dict[str, Canvas]:
    """The figures of a run's ``joints.png`` (one per band: ``joints.png/0``, …),
    ``path.png``, ``speed.png`` and ``convergence.png`` with their axes, before anything is
    drawn: what they cost does not depend on the run, and a plot worker makes them while
    the run is computed (:func:`plot_figures` takes them). Their ticks are left to the first
    draw: made beforehand, they cost the worker more than they save the drawing.

    Parameters
    ----------
    n_dof
        Number of joints of the robot.

    Returns
    -------
    dict
        ``{key: (figure, axes)}``.
    """
    canvases = {f"joints.png/{k}": joints_canvas(n_dof, rows) for k, rows in enumerate(JOINT_BANDS)}
    canvases["path.png"] = path_canvas()
    canvases["speed.png"] = speed_canvas()
    canvases["convergence.png"] = convergence_canvas()
    return canvases


def plot_figures(
    result: PlanResult,
    case: Case,
    history: Mapping[str, Mapping[str, np.ndarray]] | None = None,
    kinematics: PlotKinematics | None = None,
    canvases: dict[str, Canvas] | None = None,
) -> dict[str, PlotBuilder]:
    """The plots of a run as ``{file name: figure builder or banded figure}``, in report
    order; the builders draw with ``kinematics`` (:func:`plot_kinematics`, computed here
    when not given) and start no compiled kernel, each on its blank figure from
    ``canvases`` (:func:`blank_canvases`, which it takes out of the dict) when there is one.

    A plan whose seams are joined by moves (:func:`~trackplan.report.cycle.has_moves`)
    gets ``cycle.png`` first, and neither ``path.png`` nor ``tool.png`` (they show one
    seam's path; the 3D view shows every seam and move).
    """
    if kinematics is None:
        kinematics = plot_kinematics(result, case)
    blank = (canvases if canvases is not None else {}).pop

    def joints_band(k: int, rows: Sequence[int]) -> Figure:
        return joints_figure(result, case, rows, blank(f"joints.png/{k}", None))

    cycle = has_moves(result, case)
    builders: dict[str, PlotBuilder] = {}
    if cycle and result.trajectory.n_samples:  # seams joined by moves: the cycle first
        builders[CYCLE_PLOT] = lambda: cycle_figure(result, case)
    builders["joints.png"] = BandedFigure(
        tuple(partial(joints_band, k, rows) for k, rows in enumerate(JOINT_BANDS))
    )
    if not cycle:  # one seam's path and placement: the 3D view shows a cycle's
        builders["path.png"] = lambda: path_figure(
            result, case, kinematics=kinematics, canvas=blank("path.png", None)
        )
    builders["speed.png"] = lambda: speed_figure(result, case, kinematics, blank("speed.png", None))
    if result.check.cell is not None and result.trajectory.n_samples:
        from trackplan.report.cell_figures import clearance_figure

        builders["clearance.png"] = lambda: clearance_figure(result)
    if shows_tool(case) and not cycle:
        builders["tool.png"] = lambda: tool_figure(result, case, kinematics=kinematics)
    if history:
        builders["convergence.png"] = lambda: convergence_figure(
            history, blank("convergence.png", None)
        )
    return builders


def write_plots(
    result: PlanResult,
    case: Case,
    out_dir: Path,
    history: Mapping[str, Mapping[str, np.ndarray]] | None = None,
) -> list[Path]:
    """Write ``joints.png``, ``path.png``, ``speed.png`` (``tool.png``, ``convergence.png``).

    Parameters
    ----------
    result
        The planned placement.
    case
        The case it was planned for.
    out_dir
        Directory to write into (created when missing).
    history
        Optimizer history per method (see :func:`convergence_figure`); when given,
        ``convergence.png`` is written too. ``tool.png`` is written for a seam frame or a
        spin that is not fixed (:func:`shows_tool`).

    Returns
    -------
    list of pathlib.Path
        The files written, in report order.
    """
    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    written = []
    for name, build in plot_figures(result, case, history).items():
        path = out_dir / name
        if isinstance(build, BandedFigure):
            build.save(path)
        else:
            save_png(build(), path)
        written.append(path)
    return written
