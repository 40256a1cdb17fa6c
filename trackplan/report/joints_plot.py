"""``joints.png``: joint positions and their three derivatives against every joint limit.

The plot is the largest of a run; it is drawn as horizontal bands (:data:`JOINT_BANDS`),
which can be drawn in different processes and are stacked into one image.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING

import numpy as np

from trackplan.case import Case
from trackplan.planning.checker import RELATIVE_SLACK
from trackplan.planning.result import LIMIT_KINDS, MOVE_KINDS, PlanResult
from trackplan.report.figure_style import (
    DPI,
    SYMLOG_RATIO,
    VIOLATION_COLOR,
    Canvas,
    inside_ticks,
    mark_violations,
    new_figure,
    status_line,
)
from trackplan.report.scene import JOINT_QUANTITIES, column_units, joint_bounds, joint_series

if TYPE_CHECKING:
    from matplotlib.figure import Figure

_SYMBOLS = {"position": "q", "velocity": "q̇", "acceleration": "q̈", "jerk": "d³q/dt³"}


ENVELOPE_POINTS = 2000
"""Most points drawn per series: longer series are drawn as their min/max envelope."""


def envelope(t: np.ndarray, y: np.ndarray, n_points: int = ENVELOPE_POINTS) -> tuple:
    """A long series reduced to the minimum and maximum of each of n_points/2 bins, in time
    order, so that every peak (and every limit excess) stays visible at a fraction of the
    drawing cost. Short series come back unchanged.

    Parameters
    ----------
    t, y
        Shape (N,).

    Returns
    -------
    tuple of numpy.ndarray
        ``(t, y)`` with at most about ``n_points`` samples.
    """
    n_bins = n_points // 2
    if len(t) <= n_points:
        return t, y
    edges = np.linspace(0, len(t), n_bins + 1).astype(int)
    rows = np.arange(len(t))
    bin_of = np.searchsorted(edges, rows, side="right") - 1
    order = np.lexsort((y, bin_of))
    first = np.searchsorted(bin_of[order], np.arange(n_bins))
    last = np.searchsorted(bin_of[order], np.arange(n_bins), side="right") - 1
    picks = np.sort(np.unique(np.concatenate([order[first], order[last]])))
    return t[picks], y[picks]


JOINT_BANDS = ((0, 1), (2, 3))
"""Rows of ``joints.png`` drawn as separate figures (bands) and stacked: the plot is the
largest of a run, and its two bands are drawn in two processes."""
# joints.png in pixels at DPI: title space, axes height, space between rows, x-axis space
# and where a band ends below a row (under its tick marks, above the next row's title)
_JOINT_TOP, _JOINT_ROW, _JOINT_GAP, _JOINT_BOTTOM, _JOINT_CUT = 63, 166, 28, 90, 8


def _joints_height(rows: Sequence[int]) -> tuple[int, int, int]:
    """Space above and below the axes of ``joints.png``'s ``rows`` and the height of their
    figure, pixels: a fixed grid in pixels (constrained layout over 4 × n panels took
    longer than the drawing, and fixed pixels let a band of rows be drawn on its own)."""
    first, last = rows[0] == 0, rows[-1] == len(LIMIT_KINDS) - 1
    top = _JOINT_TOP if first else _JOINT_GAP - _JOINT_CUT
    bottom = _JOINT_BOTTOM if last else _JOINT_CUT
    return top, bottom, top + len(rows) * _JOINT_ROW + (len(rows) - 1) * _JOINT_GAP + bottom


def joints_canvas(n: int, rows: Sequence[int]) -> Canvas:
    """The figure of :func:`joints_figure` for ``n`` joints and ``rows`` (consecutive) with
    its grid of axes, shape (len(rows), n), before anything is drawn on them."""
    from matplotlib.ticker import MaxNLocator

    top, bottom, height = _joints_height(rows)
    width = (230 * n + 100) / DPI
    figure = new_figure(width, height / DPI, layout=None)
    figure.subplots_adjust(
        left=0.06,
        right=0.99,
        bottom=bottom / height,
        top=1 - top / height,
        wspace=0.35,
        hspace=_JOINT_GAP / _JOINT_ROW,
    )
    axes = figure.subplots(len(rows), n, sharex=True, squeeze=False)
    axes[0, 0].xaxis.set_major_locator(MaxNLocator(nbins=5))
    return figure, axes


def move_samples(result: PlanResult) -> np.ndarray:
    """Which samples lie on an approach, retract or air move (``result.spans``), shape (N,),
    bool; all False for one seam alone."""
    moving = np.zeros(result.trajectory.n_samples, dtype=bool)
    for span in result.spans:
        if span.kind in MOVE_KINDS:
            moving[span.first : span.last + 1] = True
    return moving


def joints_figure(
    result: PlanResult,
    case: Case,
    rows: Sequence[int] | None = None,
    canvas: Canvas | None = None,
) -> Figure:
    """Joint positions and their three derivatives against every joint limit.

    A grid of 4 rows (q, q̇, q̈, q⃛) by one column per joint, so that each panel holds
    one signal and its own limits: the limits differ per joint and would clutter a
    shared panel. Limits are dashed lines (``gid="limit"``): ±limit, and q_min/q_max for
    positions. Samples beyond a limit are red markers (``gid="violation"``) and every
    violation window the checker reported is a red band (``gid="violation-window"``).
    Each panel states its margin (unused fraction of the limit) above its right corner.
    The approach, retract and air moves between seams are grey bands (``gid="move"``).
    A panel whose data exceed the limits by more than 20 times gets a symmetric-log axis
    (linear within ±limit).

    Parameters
    ----------
    result
        The planned placement; time in s, joint data in rad, rad/s, rad/s², rad/s³ (a
        track's column in m, m/s, m/s², m/s³).
    case
        The case (the limits of its machine: :attr:`~trackplan.case.Case.machine`, the
        robot's joints, then a track and a positioner's axes, each column titled with its
        name and unit).
    rows
        Consecutive rows (indices into ``LIMIT_KINDS``) to draw, all by default. The
        figure of some rows is the horizontal band of the full figure that holds them, to
        the pixel: the bands of :data:`JOINT_BANDS` stacked make the full figure
        (:class:`BandedFigure`).
    canvas
        The blank figure of these rows (:func:`blank_canvases`), made here when not given.

    Returns
    -------
    matplotlib.figure.Figure
        ``len(rows)`` × n axes.
    """
    from matplotlib.ticker import MaxNLocator

    trajectory = result.trajectory
    robot = case.machine
    n = robot.n_dof
    n_arm = case.robot.n_dof
    rows = list(range(len(LIMIT_KINDS)) if rows is None else rows)
    if not rows or rows != list(range(rows[0], rows[0] + len(rows))):
        raise ValueError(f"joints_figure draws consecutive rows, not {rows}")
    first = rows[0] == 0
    height = _joints_height(rows)[2]
    figure, axes = canvas or joints_canvas(n, rows)
    if trajectory.n_samples:
        t_margin = 0.02 * (trajectory.t[-1] - trajectory.t[0])
        t_limits = (trajectory.t[0] - t_margin, trajectory.t[-1] + t_margin)
        axes[0, 0].set_xlim(*t_limits)
        axes[0, 0].set_xticks(inside_ticks(MaxNLocator(nbins=5), *t_limits))
    half = 0.5 * trajectory.sample_time
    moving = move_samples(result)
    for band_row, row in enumerate(rows):
        kind = LIMIT_KINDS[row]
        values = joint_series(trajectory, kind)
        lower, upper = joint_bounds(robot, kind)
        margins = result.check.joint_margins.get(kind)
        units = column_units(robot, kind)
        for j in range(n):
            ax = axes[band_row, j]
            series = values[:, j]
            # limits first: every artist added to an axes with autoscaling on recomputes
            # the view limits of all the axes sharing its time axis
            low = float(np.min(series, initial=lower[j]))
            high = float(np.max(series, initial=upper[j]))
            limit = max(abs(lower[j]), abs(upper[j]))
            if high - low > SYMLOG_RATIO * 2 * limit:
                # linear inside ±limit, logarithmic beyond: the limits stay visible next
                # to violations that exceed them by orders of magnitude
                ax.set_yscale("symlog", linthresh=limit)
                y_limits = (1.5 * low, 1.5 * high)
            else:
                pad = 0.08 * (high - low)
                y_limits = (low - pad, high + pad)
            ax.set_ylim(*y_limits)
            y_locator = MaxNLocator(nbins=4, steps=[1, 2, 2.5, 5, 10])
            ax.set_yticks(inside_ticks(y_locator, *y_limits))
            ax.plot(
                *envelope(trajectory.t, series), color=f"C{j}", lw=1.0, label=robot.joint_names[j]
            )
            for bound in (lower[j], upper[j]):
                ax.axhline(bound, ls="--", lw=0.9, color="0.3", label="limit", gid="limit")
            slack = RELATIVE_SLACK * np.abs([lower[j], upper[j]])  # the checker's round-off
            beyond = (series < lower[j] - slack[0]) | (series > upper[j] + slack[1])
            if beyond.any():
                mark_violations(ax, (trajectory.t[beyond], series[beyond]), "beyond the limit")
            for v in result.check.violations:
                if v.limit == kind and v.joint == j + 1:
                    ax.axvspan(
                        v.t_first - half,
                        v.t_last + half,
                        color=VIOLATION_COLOR,
                        alpha=0.12,
                        lw=0,
                        label="violation window",
                        gid="violation-window",
                    )
            if moving.any():  # the moves between seams, one grey polygon per panel
                ax.fill_between(
                    trajectory.t,
                    0.0,
                    1.0,
                    where=moving,
                    transform=ax.get_xaxis_transform(),
                    color="0.5",
                    alpha=0.12,
                    lw=0,
                    gid="move",
                )
            if margins is not None and j < len(margins) and np.isfinite(margins[j]):
                # above the panel, clear of the data (a boxed label inside cost a tenth
                # of the figure)
                ax.set_title(
                    f"margin {100 * margins[j]:.0f} %",
                    loc="right",
                    fontsize=7,
                    color=VIOLATION_COLOR if margins[j] < 0 else "0.35",
                    y=1.0,
                    pad=2.0,
                )
            ax.tick_params(labelsize=7)
            ax.grid(alpha=0.3, lw=0.5)
            if j >= n_arm:  # an external axis: its name and its own unit on every row
                title = f"{robot.joint_names[j]} [{units[j]}]" if row == 0 else f"[{units[j]}]"
                ax.set_title(title, loc="left", fontsize=9 if row == 0 else 7, y=1.0, pad=2.0)
            elif row == 0:
                ax.set_title(f"joint {j + 1}", loc="left", fontsize=9, y=1.0)
            if j == 0:
                name, unit = JOINT_QUANTITIES[kind]
                ax.set_ylabel(f"{name} {_SYMBOLS[kind]} [{unit}]", fontsize=8)
                ax.yaxis.set_label_coords(-0.3, 0.5)
            if row == len(LIMIT_KINDS) - 1:
                ax.set_xlabel("time [s]", fontsize=8)
                ax.xaxis.set_label_coords(0.5, -0.14)
            else:  # the last row of a band that is not the last row of the figure
                ax.tick_params(labelbottom=False)
    if first:
        note = "" if trajectory.n_samples else f" — no trajectory: {result.message}"
        figure.suptitle(
            f"{status_line(result)}: joint trajectories and limits{note}",
            fontsize=10,
            y=1 - 18 / height,
        )
    return figure
