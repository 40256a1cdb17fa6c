"""Static plots of a planned trajectory (matplotlib, Agg canvas, no pyplot state).

Each ``*_figure`` function returns a :class:`matplotlib.figure.Figure`;
:func:`write_plots` saves them as PNG files. Artists that tests and readers look for
carry a ``gid`` (``limit``, ``violation``, ``path-before``, ``reach-shell``, …).
matplotlib is imported inside the functions so that importing trackplan stays fast.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from functools import partial
from pathlib import Path
from typing import TYPE_CHECKING, Any, Literal

import numpy as np

from trackplan.case import Case
from trackplan.frames import placement_transform
from trackplan.planning.checker import RELATIVE_SLACK
from trackplan.planning.result import LIMIT_KINDS, PlanResult
from trackplan.report.scene import (
    FRAME_STYLES,
    JOINT_QUANTITIES,
    chain_points,
    equal_limits,
    frame_indices,
    joint_bounds,
    joint_series,
    path_points,
    sphere_wireframe,
    tracking_error,
    triad_lines,
    violation_samples,
)
from trackplan.robots.kinematics import forward_kinematics
from trackplan.run_files import HISTORY_KEYS

if TYPE_CHECKING:
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure
    from mpl_toolkits.mplot3d import Axes3D

DPI = 100
AXIS_COLORS = ("tab:red", "tab:green", "tab:blue")  # frame axes x, y, z
BEFORE_COLOR = "tab:purple"
AFTER_COLOR = "tab:orange"
VIOLATION_COLOR = "red"
SYMLOG_RATIO = 20.0  # data spanning more than this many limit ranges get a symlog axis
_SYMBOLS = {"position": "q", "velocity": "q̇", "acceleration": "q̈", "jerk": "d³q/dt³"}


def _new_figure(
    width: float, height: float, layout: Literal["constrained"] | None = "constrained"
) -> Figure:
    """A figure on its own Agg canvas (no pyplot, no global figure registry)."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    figure = Figure(figsize=(width, height), dpi=DPI, layout=layout)
    FigureCanvasAgg(figure)
    return figure


def _mark_violations(ax: Axes | Axes3D, coordinates: Sequence[np.ndarray], label: str) -> None:
    """Red markers (``gid="violation"``) at the given x, y (and z) coordinates."""
    ax.plot(
        *coordinates,
        ls="none",
        marker="o",
        ms=3.5,
        color=VIOLATION_COLOR,
        label=label,
        gid="violation",
    )


def _status_line(result: PlanResult) -> str:
    verdict = "feasible" if result.feasible else f"infeasible ({result.status.value})"
    return f"{result.case_name}: {verdict}"


PNG_COMPRESSION = 1
"""zlib level of the PNG files: level 1 encodes several times faster than the default 6,
for files about a third larger."""


def save_png(figure: Figure, path: Path) -> None:
    """Write ``figure`` as a PNG file at :data:`DPI`."""
    figure.savefig(path, dpi=DPI, pil_kwargs={"compress_level": PNG_COMPRESSION})


def figure_pixels(figure: Figure) -> np.ndarray:
    """``figure`` drawn at :data:`DPI`, as RGBA pixels of shape (height, width, 4), uint8."""
    figure.canvas.draw()
    return np.array(figure.canvas.buffer_rgba())  # type: ignore[attr-defined]


def save_pixels(pixels: np.ndarray, path: Path) -> None:
    """Write RGBA pixels (height, width, 4) as a PNG file as :func:`save_png` writes one."""
    from matplotlib.image import imsave

    imsave(path, pixels, dpi=DPI, pil_kwargs={"compress_level": PNG_COMPRESSION})


@dataclass(frozen=True)
class BandedFigure:
    """A plot drawn as horizontal bands, each its own figure of the same width; its image is
    the bands stacked top to bottom. The bands can be drawn in different processes
    (:func:`~trackplan.report.drawing.draw_plots`).

    Attributes
    ----------
    bands
        Builders of the band figures, top to bottom.
    """

    bands: tuple[Callable[[], Figure], ...]

    def save(self, path: Path, pixels: Sequence[np.ndarray] | None = None) -> None:
        """Write the PNG file from the bands' pixels (:func:`figure_pixels`), drawn here when
        not given."""
        if pixels is None:
            pixels = [figure_pixels(build()) for build in self.bands]
        save_pixels(np.concatenate(pixels, axis=0), path)


PlotBuilder = Callable[[], "Figure"] | BandedFigure
"""How a plot of a run is drawn: one figure, or bands stacked into one image."""


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


def _inside_ticks(locator: object, low: float, high: float) -> np.ndarray:
    """The ticks ``locator`` (a matplotlib tick locator) places from ``low`` to ``high``,
    without those it adds beyond them: matplotlib makes a tick (two marks, a grid line, two
    labels) for every location its locator gives, drawn or not, a third more in the joint
    grid."""
    ticks = np.asarray(locator.tick_values(low, high))  # type: ignore[attr-defined]
    tolerance = 1e-10 * (high - low)
    return ticks[(ticks >= low - tolerance) & (ticks <= high + tolerance)]


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


def _joints_canvas(n: int, rows: Sequence[int]) -> Canvas:
    """The figure of :func:`joints_figure` for ``n`` joints and ``rows`` (consecutive) with
    its grid of axes, shape (len(rows), n), before anything is drawn on them."""
    from matplotlib.ticker import MaxNLocator

    top, bottom, height = _joints_height(rows)
    width = (230 * n + 100) / DPI
    figure = _new_figure(width, height / DPI, layout=None)
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
    A panel whose data exceed the limits by more than 20 times gets a symmetric-log axis
    (linear within ±limit).

    Parameters
    ----------
    result
        The planned placement; time in s, joint data in rad, rad/s, rad/s², rad/s³.
    case
        The case (robot limits).
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
    robot = case.robot
    n = robot.n_dof
    rows = list(range(len(LIMIT_KINDS)) if rows is None else rows)
    if not rows or rows != list(range(rows[0], rows[0] + len(rows))):
        raise ValueError(f"joints_figure draws consecutive rows, not {rows}")
    first = rows[0] == 0
    height = _joints_height(rows)[2]
    figure, axes = canvas or _joints_canvas(n, rows)
    if trajectory.n_samples:
        t_margin = 0.02 * (trajectory.t[-1] - trajectory.t[0])
        t_limits = (trajectory.t[0] - t_margin, trajectory.t[-1] + t_margin)
        axes[0, 0].set_xlim(*t_limits)
        axes[0, 0].set_xticks(_inside_ticks(MaxNLocator(nbins=5), *t_limits))
    half = 0.5 * trajectory.sample_time
    for band_row, row in enumerate(rows):
        kind = LIMIT_KINDS[row]
        values = joint_series(trajectory, kind)
        lower, upper = joint_bounds(robot, kind)
        margins = result.check.joint_margins.get(kind)
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
            ax.set_yticks(_inside_ticks(y_locator, *y_limits))
            ax.plot(
                *envelope(trajectory.t, series), color=f"C{j}", lw=1.0, label=robot.joint_names[j]
            )
            for bound in (lower[j], upper[j]):
                ax.axhline(bound, ls="--", lw=0.9, color="0.3", label="limit", gid="limit")
            slack = RELATIVE_SLACK * np.abs([lower[j], upper[j]])  # the checker's round-off
            beyond = (series < lower[j] - slack[0]) | (series > upper[j] + slack[1])
            if beyond.any():
                _mark_violations(ax, (trajectory.t[beyond], series[beyond]), "beyond the limit")
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
            if margins is not None and np.isfinite(margins[j]):
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
            if row == 0:
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
            f"{_status_line(result)}: joint trajectories and limits{note}",
            fontsize=10,
            y=1 - 18 / height,
        )
    return figure


def _plot_triads(
    ax: Axes3D,
    lines: np.ndarray,
    gid: str,
    label: str,
    lw: float = 1.2,
    colors: Sequence[str] = AXIS_COLORS,
    ls: str = "-",
) -> None:
    """Draw the output of :func:`triad_lines` in ``colors`` (x, y, z; red, green, blue by
    default)."""
    for axis, color in enumerate(colors):
        ax.plot(
            *lines[axis].T,
            color=color,
            lw=lw,
            ls=ls,
            gid=gid,
            label=label if axis == 0 else None,
        )


def _set_equal(ax: Axes3D, points: np.ndarray) -> None:
    from matplotlib.ticker import MaxNLocator

    limits = equal_limits(points)
    ax.set_xlim(*limits[0])
    ax.set_ylim(*limits[1])
    ax.set_zlim(*limits[2])
    for axis, (low, high) in zip((ax.xaxis, ax.yaxis, ax.zaxis), limits, strict=True):
        axis.set_ticks(_inside_ticks(MaxNLocator(nbins=5), low, high))
    ax.set_box_aspect((1.0, 1.0, 1.0))
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")
    ax.set_zlabel("z [m]")


Canvas = tuple["Figure", Any]
"""A figure with its axes (as :meth:`matplotlib.figure.Figure.subplots` returns them) on
which nothing is drawn yet."""


def _path_canvas() -> Canvas:
    """The figure of :func:`path_figure` with its two 3D axes."""
    figure = _new_figure(13.0, 6.8, layout=None)
    figure.subplots_adjust(left=0.0, right=0.97, bottom=0.12, top=0.92, wspace=0.08)
    ax_cell = figure.add_subplot(1, 2, 1, projection="3d")
    ax_path = figure.add_subplot(1, 2, 2, projection="3d")
    return figure, (ax_cell, ax_path)


def _speed_canvas() -> Canvas:
    """The figure of :func:`speed_figure` with its two axes sharing the time axis."""
    figure = _new_figure(11.0, 6.5, layout=None)
    figure.subplots_adjust(left=0.07, right=0.76, bottom=0.08, top=0.94, hspace=0.08)
    return figure, figure.subplots(2, 1, sharex=True)


def _convergence_canvas() -> Canvas:
    """The figure of :func:`convergence_figure` with its three axes."""
    figure = _new_figure(9.0, 8.0, layout=None)
    figure.subplots_adjust(left=0.1, right=0.98, bottom=0.07, top=0.95, hspace=0.08)
    return figure, figure.subplots(3, 1, sharex=True)


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
    canvases = {
        f"joints.png/{k}": _joints_canvas(n_dof, rows) for k, rows in enumerate(JOINT_BANDS)
    }
    canvases["path.png"] = _path_canvas()
    canvases["speed.png"] = _speed_canvas()
    canvases["convergence.png"] = _convergence_canvas()
    return canvases


PATH_FRAMES = 7
"""Tool frames drawn along the placed path in ``path.png``."""

TOOL_FRAMES = 16
"""Tool frames drawn along the path in ``tool.png``."""


@dataclass(frozen=True)
class PlotKinematics:
    """What the plots of a run take from the robot's kinematics and from the nominal path:
    numba's compiled kernels compute them, so that a process drawing the plots
    (:class:`~trackplan.report.plot_worker.PlotWorker`) is given them and never starts numba.

    Attributes
    ----------
    chain_start
        The robot at the first sample (:func:`~trackplan.report.scene.chain_points`),
        shape (n + 2, 3), m, base frame; (0, 3) without a trajectory.
    path_frames
        ``T_base_tool`` at the samples :func:`~trackplan.report.scene.frame_indices` picks
        for ``path.png``, shape (F, 4, 4); (0, 4, 4) without a trajectory.
    tool_frames
        The same for ``tool.png``, shape (G, 4, 4); (0, 4, 4) without a trajectory or when
        the run has no ``tool.png`` (:func:`shows_tool`).
    tracking_error
        :func:`~trackplan.report.scene.tracking_error`, shape (N,), m.
    """

    chain_start: np.ndarray
    path_frames: np.ndarray
    tool_frames: np.ndarray
    tracking_error: np.ndarray


def plot_kinematics(
    result: PlanResult,
    case: Case,
    n_path_frames: int = PATH_FRAMES,
    n_tool_frames: int = TOOL_FRAMES,
) -> PlotKinematics:
    """The :class:`PlotKinematics` of a run: ``n_path_frames`` tool frames for
    ``path.png``, ``n_tool_frames`` for ``tool.png``."""
    q = result.trajectory.q
    n_samples = result.trajectory.n_samples
    none = np.zeros((0, 4, 4))
    if n_samples == 0:
        return PlotKinematics(np.zeros((0, 3)), none, none, np.zeros(0))
    robot = case.robot
    path_frames = forward_kinematics(robot, q[frame_indices(n_samples, n_path_frames)])
    tool_frames = none
    if shows_tool(case):
        tool_frames = forward_kinematics(robot, q[frame_indices(n_samples, n_tool_frames)])
    return PlotKinematics(
        chain_points(robot, q[0]), path_frames, tool_frames, tracking_error(result, case)
    )


def path_figure(
    result: PlanResult,
    case: Case,
    n_tool_frames: int = PATH_FRAMES,
    kinematics: PlotKinematics | None = None,
    canvas: Canvas | None = None,
) -> Figure:
    """The path before and after placement, in the robot's work cell (3D, equal aspect).

    Left: the work cell in the base frame: the path in its definition frame (dashed,
    ``gid="path-before"``), the placed path (solid, ``gid="path-after"``), base and part
    frame axes, the reach shell of the placement origin (wireframe spheres of radius
    ``case.bounds.reach``, ``gid="reach-shell"``) and the robot at the first sample.
    Right: the placed path close up, with tool frames at a few samples
    (``gid="tool-frames"``) and the samples inside violation windows in red.

    Parameters
    ----------
    result
        The planned placement (tool positions in m, base frame).
    case
        The case (robot, reach bounds, nominal path as fallback).
    n_tool_frames
        Number of tool frames drawn along the path.
    kinematics
        The run's :func:`plot_kinematics` with ``n_path_frames=n_tool_frames``; without
        it the robot at t = 0 and the tool frames are computed here.
    canvas
        The blank figure (:func:`blank_canvases`), made here when not given.

    Returns
    -------
    matplotlib.figure.Figure
        Two 3D axes.
    """
    trajectory = result.trajectory
    points_part, points_base = path_points(result, case)
    T_base_part = placement_transform(result.placement)
    figure, (ax_cell, ax_path) = canvas or _path_canvas()

    r_min, r_max = case.bounds.reach
    shell = sphere_wireframe(r_max)
    for radius, which in ((r_min, "min"), (r_max, "max")):
        ax_cell.plot(
            *sphere_wireframe(radius).T,
            color="0.55" if which == "max" else "0.35",
            lw=0.4,
            alpha=0.45,
            gid="reach-shell",
            label=f"reach shell of the placement origin ({r_min:.3g}–{r_max:.3g} m)"
            if which == "max"
            else None,
        )
    triad_length = 0.25 * r_max
    for name, T, length, width in (
        ("base frame", np.eye(4), triad_length, 2.0),
        ("part frame", T_base_part, 0.5 * triad_length, 1.6),
    ):
        colors, style = FRAME_STYLES[name]
        _plot_triads(
            ax_cell,
            triad_lines(T, length),
            name.replace(" ", "-"),
            f"{name} (x, y, z)",
            width,
            colors,
            "--" if style == "dash" else "-",
        )
    ax_cell.plot(
        *points_part.T,
        ls="--",
        color=BEFORE_COLOR,
        lw=1.4,
        gid="path-before",
        label="path before placement (definition frame)",
    )
    ax_cell.plot(
        *points_base.T, color=AFTER_COLOR, lw=2.0, gid="path-after", label="path after placement"
    )
    scene = [shell, points_part, points_base]
    if trajectory.n_samples:
        if kinematics is None:
            chain = chain_points(case.robot, trajectory.q[0])
        else:
            chain = kinematics.chain_start
        ax_cell.plot(*chain.T, "o-", color="0.2", lw=3.0, ms=4, gid="robot", label="robot at t = 0")
        scene.append(chain)
    _set_equal(ax_cell, np.vstack(scene))
    ax_cell.set_title("work cell (robot base frame)", fontsize=10, y=1.0)

    ax_path.plot(*points_base.T, color=AFTER_COLOR, lw=2.0, gid="path-zoom")
    ax_path.plot(*points_base[0], "o", color="tab:green", ms=6, label="start", gid="start")
    ax_path.plot(*points_base[-1], "s", color="0.2", ms=6, label="end", gid="end")
    extent = float(np.max(np.ptp(points_base, axis=0))) if len(points_base) > 1 else 0.1
    if trajectory.n_samples:
        if kinematics is None:
            idx = frame_indices(trajectory.n_samples, n_tool_frames)
            T_tool = forward_kinematics(case.robot, trajectory.q[idx])
        else:
            T_tool = kinematics.path_frames
        _plot_triads(ax_path, triad_lines(T_tool, 0.08 * extent), "tool-frames", "tool frames")
        bad = violation_samples(trajectory, result.check.violations)
        if bad.any():
            _mark_violations(ax_path, points_base[bad].T, "samples inside a violation window")
    _set_equal(ax_path, points_base)
    ax_path.set_title("placed path (close-up)", fontsize=10, y=1.0)

    handles, labels = [], []
    for ax in (ax_cell, ax_path):
        for handle, label in zip(*ax.get_legend_handles_labels(), strict=True):
            if label not in labels:
                handles.append(handle)
                labels.append(label)
    figure.legend(handles, labels, loc="lower center", ncol=4, fontsize=8, frameon=False)
    figure.suptitle(
        f"{_status_line(result)}: placement X = {_format_placement(result)}", fontsize=10
    )
    return figure


def _format_placement(result: PlanResult) -> str:
    x = result.placement
    return f"({x[0]:.4f}, {x[1]:.4f}, {x[2]:.4f}) m, rpy ({x[3]:.4f}, {x[4]:.4f}, {x[5]:.4f}) rad"


def speed_figure(
    result: PlanResult,
    case: Case,
    kinematics: PlotKinematics | None = None,
    canvas: Canvas | None = None,
) -> Figure:
    """Tool speed against v_r and v_t^max, and the tracking error against ρ, over time.

    Top (``gid="speed"``): Cartesian speed of the tool point with the rated speed
    (``gid="rated-speed"``) and the corner speed cap (``gid="corner-speed"``); slow-downs on
    straight pieces shaded. Bottom (``gid="tracking-error"``): distance of the tool point
    from the nominal path (sharp corners kept) with the tolerance ρ (``gid="tolerance"``).
    Samples inside a speed or tracking violation window the checker reported are red
    markers (``gid="violation"``).

    Parameters
    ----------
    result
        The planned placement (speed in m/s, shown in mm/s).
    case
        The case (task bounds, nominal path).
    kinematics
        The run's :func:`plot_kinematics` (for the tracking error), computed here when not
        given.
    canvas
        The blank figure (:func:`blank_canvases`), made here when not given.

    Returns
    -------
    matplotlib.figure.Figure
        Two axes sharing the time axis.
    """
    trajectory = result.trajectory
    task = case.task
    t = trajectory.t
    figure, (ax_speed, ax_error) = canvas or _speed_canvas()

    ax_speed.plot(
        t, 1e3 * trajectory.speed, color="tab:blue", lw=1.2, label="tool speed", gid="speed"
    )
    ax_speed.axhline(
        1e3 * task.rated_speed,
        ls="--",
        color="tab:green",
        label=f"rated speed vᵣ = {1e3 * task.rated_speed:.4g} mm/s",
        gid="rated-speed",
    )
    ax_speed.axhline(
        1e3 * task.corner_speed,
        ls=":",
        color="tab:orange",
        lw=1.5,
        label=f"corner speed cap vₜᵐᵃˣ = {1e3 * task.corner_speed:.4g} mm/s",
        gid="corner-speed",
    )
    ax_speed.set_ylabel("tool speed [mm/s]")
    top = max(task.rated_speed, task.corner_speed, float(np.max(trajectory.speed, initial=0.0)))
    ax_speed.set_ylim(0.0, 1.15e3 * top)
    if trajectory.n_samples and result.slowdowns:
        _mark_slowdowns(ax_speed, result, t)

    error = tracking_error(result, case) if kinematics is None else kinematics.tracking_error
    ax_error.plot(
        t, 1e3 * error, color="tab:purple", lw=1.2, label="tracking error", gid="tracking-error"
    )
    ax_error.axhline(
        1e3 * task.tolerance,
        ls="--",
        color="0.3",
        label=f"tolerance ρ = {1e3 * task.tolerance:.4g} mm",
        gid="tolerance",
    )
    ax_error.set_ylabel("tracking error [mm]")
    ax_error.set_xlabel("time [s]")
    ax_error.set_ylim(0.0, 1.15e3 * max(task.tolerance, float(np.max(error, initial=0.0))))

    # the speed cap depends on where the tool is (corner or straight): mark what the
    # checker reported rather than guess the cap here
    for ax, values, kind in ((ax_speed, trajectory.speed, "speed"), (ax_error, error, "tracking")):
        reported = [v for v in result.check.violations if v.limit == kind]
        inside = violation_samples(trajectory, reported)
        if inside.any():
            _mark_violations(ax, (t[inside], 1e3 * values[inside]), f"{kind} violation")
        ax.grid(alpha=0.3, lw=0.5)
        ax.legend(fontsize=8, loc="upper left", bbox_to_anchor=(1.01, 1.0), frameon=False)
    note = "" if trajectory.n_samples else f" — no trajectory: {result.message}"
    figure.suptitle(f"{_status_line(result)}: tool speed and tracking error{note}", fontsize=10)
    return figure


SLOWDOWN_COLOR = "tab:orange"
SLOWDOWN_REASONS = 6
"""Most distinct slow-down reasons listed in the legend of ``speed.png``; the rest are in
the report's slow-down table."""


def _mark_slowdowns(ax: Axes, result: PlanResult, t: np.ndarray) -> None:
    """Shade the slow-downs of ``result`` on the speed axes ``ax`` and number them (1, 2, …
    in the order of ``result.slowdowns``, as the report's table and the summary list them).

    The numbers stand in one row at the top of the axes, each at the start of its slow-down
    (``gid="slowdown-label"``); slow-downs too close to be labelled apart share a label
    ("3–5"). The reason of each slow-down is given once per distinct reason in the legend,
    after the numbers it applies to. Labels are laid out from their measured widths, so
    none overlaps another or leaves the axes.
    """
    from matplotlib.patches import Patch
    from matplotlib.transforms import blended_transform_factory

    trajectory = result.trajectory
    spans = [
        np.interp([slowdown.s_start, slowdown.s_end], trajectory.s, t)
        for slowdown in result.slowdowns
    ]
    for k, (t0, t1) in enumerate(spans):
        ax.axvspan(
            t0,
            t1,
            color=SLOWDOWN_COLOR,
            alpha=0.15,
            lw=0,
            gid="slowdown",
            label="slow-down below vᵣ (numbered)" if k == 0 else None,
        )
    figure = ax.figure
    renderer = figure.canvas.get_renderer()  # type: ignore[attr-defined]
    ax.get_xlim()  # settles the autoscaled time axis before positions are measured
    to_pixels = ax.transData.transform
    box = ax.get_window_extent(renderer)
    gap = 4.0 * figure.dpi / 72.0  # 4 pt between labels

    def label_text(first: int, last: int) -> str:
        return str(first + 1) if first == last else f"{first + 1}–{last + 1}"

    def width(text: str) -> float:
        probe = ax.text(0.0, 0.0, text, fontsize=7)
        extent = probe.get_window_extent(renderer).width
        probe.remove()
        return float(extent)

    # left to right: a label starts at its first slow-down unless the previous label
    # reaches there, which then takes this slow-down too
    labels: list[list] = []  # [first, last, left px, width px]
    for k, (t0, _) in enumerate(spans):
        x = float(to_pixels((t0, 0.0))[0])
        if labels and x < labels[-1][2] + labels[-1][3] + gap:
            labels[-1][1] = k
            labels[-1][3] = width(label_text(labels[-1][0], k))
        else:
            labels.append([k, k, max(x, box.x0), width(label_text(k, k))])
    # right to left: labels that would leave the axes move left, and push their
    # neighbours left as far as needed
    limit = box.x1
    for label in reversed(labels):
        label[2] = min(label[2], limit - label[3])
        limit = label[2] - gap
    transform = blended_transform_factory(figure.dpi_scale_trans, ax.transAxes)
    for first, last, left, _ in labels:
        ax.text(
            left / figure.dpi,
            0.97,
            label_text(first, last),
            transform=transform,
            ha="left",
            va="top",
            fontsize=7,
            color="0.15",
            gid="slowdown-label",
        )
    reasons: dict[str, list[int]] = {}
    for k, slowdown in enumerate(result.slowdowns):
        reasons.setdefault(slowdown.limit, []).append(k + 1)
    listed = list(reasons.items())[:SLOWDOWN_REASONS]
    for reason, numbers in listed:
        ax.add_artist(Patch(visible=False, label=_wrap(f"{_ranges(numbers)}: {reason}")))
    if len(reasons) > len(listed):
        ax.add_artist(
            Patch(visible=False, label=f"{len(reasons) - len(listed)} more reasons: see report")
        )


def _ranges(numbers: Sequence[int]) -> str:
    """Sorted integers as runs: 1, 2, 3, 5 → "1–3, 5"."""
    runs: list[list[int]] = []
    for n in numbers:
        if runs and n == runs[-1][1] + 1:
            runs[-1][1] = n
        else:
            runs.append([n, n])
    return ", ".join(str(a) if a == b else f"{a}–{b}" for a, b in runs)


def _wrap(text: str, width: int = 36) -> str:
    """``text`` in lines of at most ``width`` characters (the legend column of
    ``speed.png`` holds about 40)."""
    import textwrap

    return "\n".join(textwrap.wrap(text, width)) or text


def history_columns(
    history: Mapping[str, Mapping[str, np.ndarray]],
) -> dict[str, dict[str, np.ndarray]]:
    """Check a history table and return it as float arrays of equal length per method."""
    columns: dict[str, dict[str, np.ndarray]] = {}
    for method, table in history.items():
        missing = [key for key in HISTORY_KEYS if key not in table]
        if missing:
            raise ValueError(f"history of {method!r} lacks {', '.join(missing)}")
        arrays = {key: np.asarray(table[key], dtype=float).ravel() for key in HISTORY_KEYS}
        lengths = {len(a) for a in arrays.values()}
        if len(lengths) != 1:
            raise ValueError(
                f"history of {method!r} has columns of different lengths {sorted(lengths)}"
            )
        columns[method] = arrays
    return columns


MINOR_DECADES = 2.0
"""Log fitness axes spanning more decades than this get no minor ticks."""

LOG_RATIO = 10.0
"""Fitness axes whose largest value is less than this times their smallest are linear."""


def convergence_figure(
    history: Mapping[str, Mapping[str, np.ndarray]], canvas: Canvas | None = None
) -> Figure:
    """Best and mean fitness and feasible share per generation, one colour per method.

    Each generation is drawn at its cumulative number of placement evaluations, the
    budget all methods share (their population sizes differ). Fitness axes are
    logarithmic when every value is positive and they span a decade or more (penalised
    candidates sit decades above feasible ones), with labelled minor ticks when they span
    at most :data:`MINOR_DECADES` decades and a tick per decade otherwise; within a decade
    (:data:`LOG_RATIO`) they are linear, labelled with as many digits as the ticks need.

    Parameters
    ----------
    history
        ``{method: {"generation", "evaluations", "best", "mean", "feasible_share",
        "wall_time"}}``, arrays of shape (G,) per method; fitness unitless, share in [0, 1],
        wall time in s.
    canvas
        The blank figure (:func:`blank_canvases`), made here when not given.

    Returns
    -------
    matplotlib.figure.Figure
        Three axes (best, mean, feasible share), one line per method in each
        (``gid=method``).
    """
    from matplotlib.ticker import LogFormatter, MaxNLocator, NullLocator, ScalarFormatter

    columns = history_columns(history)
    figure, (ax_best, ax_mean, ax_share) = canvas or _convergence_canvas()
    for k, (method, c) in enumerate(columns.items()):
        color = f"C{k}"
        final = f"{method}: best {c['best'][-1]:.4g} after {c['evaluations'][-1]:.0f} evaluations"
        final += f", {c['wall_time'][-1]:.3g} s"
        ax_best.plot(
            c["evaluations"], c["best"], "-", color=color, marker=".", gid=method, label=final
        )
        ax_mean.plot(
            c["evaluations"], c["mean"], "--", color=color, marker=".", gid=method, label=method
        )
        ax_share.plot(
            c["evaluations"],
            100 * c["feasible_share"],
            "-",
            color=color,
            marker=".",
            gid=method,
            label=method,
        )
    for ax, key, label in (
        (ax_best, "best", "best fitness"),
        (ax_mean, "mean", "mean fitness"),
    ):
        values = np.concatenate([c[key] for c in columns.values()])
        if values.size and np.all(values > 0) and values.max() < LOG_RATIO * values.min():
            # within a decade a log axis has no decade to label and its minor labels all
            # round to the same digit ("7e−01"): a linear axis with plain numbers, as many
            # digits as the ticks need to differ
            ax.yaxis.set_major_locator(MaxNLocator(nbins=5))
            ax.yaxis.set_major_formatter(ScalarFormatter(useOffset=False))
        elif values.size and np.all(values > 0):
            ax.set_yscale("log")
            # plain-text labels: the default ones are mathtext, whose parser costs more
            # than the rest of the figure
            ax.yaxis.set_major_formatter(LogFormatter())
            if np.log10(values.max() / values.min()) > MINOR_DECADES:
                # a labelled tick per decade is enough; eight minor ticks per decade
                # cost more than the rest of the figure
                ax.yaxis.set_minor_locator(NullLocator())
            else:
                ax.yaxis.set_minor_formatter(LogFormatter(labelOnlyBase=False))
        ax.set_ylabel(f"{label} [–]")
    ax_share.set_ylabel("feasible share [%]")
    ax_share.set_ylim(-2, 102)
    ax_share.set_xlabel("placement evaluations (one marker per generation)")
    for ax in (ax_best, ax_mean, ax_share):
        ax.grid(alpha=0.3, lw=0.5, which="both")
    ax_best.legend(fontsize=8)
    figure.suptitle("placement search: convergence per method", fontsize=10)
    return figure


def shows_tool(case: Case) -> bool:
    """Whether a run of this case gets ``tool.png``: a seam frame or a spin not fixed."""
    tool = case.task.tool
    return str(tool.frame) == "seam" or str(tool.spin) != "fixed"


def tool_figure(
    result: PlanResult,
    case: Case,
    n_frames: int = TOOL_FRAMES,
    kinematics: PlotKinematics | None = None,
) -> Figure:
    """The spin along the path and the tool frames it gives (docs/tool.md).

    Left: spin about the tool axis against the arc length s of the planned path (rad),
    with the spin range of ``free`` and ``free-varying`` (``gid="spin"``). Right: the placed
    path with the tool frames at ``n_frames`` samples (x red, y green, z blue — the z axis
    is the tool axis, the x axis turns with the spin; ``gid="tool-frames"``).

    Returns
    -------
    matplotlib.figure.Figure
        A 2D and a 3D axes.
    """
    trajectory = result.trajectory
    tool = case.task.tool
    figure = _new_figure(13.0, 5.6, layout=None)
    figure.subplots_adjust(left=0.06, right=0.98, bottom=0.1, top=0.88, wspace=0.12)
    ax_spin = figure.add_subplot(1, 2, 1)
    ax_frames = figure.add_subplot(1, 2, 2, projection="3d")
    if trajectory.n_samples and len(trajectory.spin) == trajectory.n_samples:
        ax_spin.plot(trajectory.s, trajectory.spin, color=AFTER_COLOR, lw=1.8, gid="spin")
    if str(tool.spin) != "fixed":
        for bound in tool.spin_range:
            ax_spin.axhline(bound, ls="--", color="0.4", lw=1.0)
    ax_spin.set_xlabel("s along the planned path [m]")
    ax_spin.set_ylabel("spin about the tool axis [rad]")
    ax_spin.set_title(f"spin: {tool.spin}", fontsize=10, y=1.0)
    ax_spin.grid(alpha=0.3)
    _, points_base = path_points(result, case)
    ax_frames.plot(*points_base.T, color=AFTER_COLOR, lw=1.5, gid="tool-path")
    if trajectory.n_samples:
        extent = float(np.max(np.ptp(points_base, axis=0))) if len(points_base) > 1 else 0.1
        if kinematics is None:
            idx = frame_indices(trajectory.n_samples, n_frames)
            T_tool = forward_kinematics(case.robot, trajectory.q[idx])
        else:
            T_tool = kinematics.tool_frames
        _plot_triads(ax_frames, triad_lines(T_tool, 0.06 * extent), "tool-frames", "tool frames")
    _set_equal(ax_frames, points_base)
    ax_frames.set_title(f"tool frames ({tool.frame} frame)", fontsize=10, y=1.0)
    figure.suptitle(_status_line(result), fontsize=10)
    return figure


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
    """
    if kinematics is None:
        kinematics = plot_kinematics(result, case)
    blank = (canvases if canvases is not None else {}).pop

    def joints_band(k: int, rows: Sequence[int]) -> Figure:
        return joints_figure(result, case, rows, blank(f"joints.png/{k}", None))

    builders: dict[str, PlotBuilder] = {
        "joints.png": BandedFigure(
            tuple(partial(joints_band, k, rows) for k, rows in enumerate(JOINT_BANDS))
        ),
        "path.png": lambda: path_figure(
            result, case, kinematics=kinematics, canvas=blank("path.png", None)
        ),
        "speed.png": lambda: speed_figure(result, case, kinematics, blank("speed.png", None)),
    }
    if result.check.cell is not None and result.trajectory.n_samples:
        from trackplan.report.cell_figures import clearance_figure

        builders["clearance.png"] = lambda: clearance_figure(result)
    if shows_tool(case):
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
