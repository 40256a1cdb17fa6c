"""``path.png`` and ``tool.png``: the path before and after placement, and the tool frames.

Also what the plots take from the robot's kinematics (:class:`PlotKinematics`), computed
by numba's kernels before a plot worker draws them.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from trackplan.case import Case
from trackplan.frames import placement_transform
from trackplan.planning.result import PlanResult
from trackplan.report.figure_style import (
    AFTER_COLOR,
    AXIS_COLORS,
    BEFORE_COLOR,
    Canvas,
    inside_ticks,
    mark_violations,
    new_figure,
    status_line,
)
from trackplan.report.scene import (
    FRAME_STYLES,
    carrier_chain_points,
    carrier_tool_frames,
    equal_limits,
    frame_indices,
    path_points,
    sphere_wireframe,
    tracking_error,
    triad_lines,
    violation_samples,
)
from trackplan.tool import SpinMode, ToolFrame

if TYPE_CHECKING:
    from matplotlib.figure import Figure
    from mpl_toolkits.mplot3d import Axes3D

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
    path_frames = carrier_tool_frames(case, q[frame_indices(n_samples, n_path_frames)])
    tool_frames = none
    if shows_tool(case):
        tool_frames = carrier_tool_frames(case, q[frame_indices(n_samples, n_tool_frames)])
    return PlotKinematics(
        carrier_chain_points(case, q[0]), path_frames, tool_frames, tracking_error(result, case)
    )


def shows_tool(case: Case) -> bool:
    """Whether a run of this case gets ``tool.png``: a seam frame or a spin not fixed."""
    tool = case.task.tool
    return tool.frame == ToolFrame.SEAM or tool.spin != SpinMode.FIXED


def path_canvas() -> Canvas:
    """The figure of :func:`path_figure` with its two 3D axes."""
    figure = new_figure(13.0, 6.8, layout=None)
    figure.subplots_adjust(left=0.0, right=0.97, bottom=0.12, top=0.92, wspace=0.08)
    ax_cell = figure.add_subplot(1, 2, 1, projection="3d")
    ax_path = figure.add_subplot(1, 2, 2, projection="3d")
    return figure, (ax_cell, ax_path)


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
    figure, (ax_cell, ax_path) = canvas or path_canvas()

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
            chain = carrier_chain_points(case, trajectory.q[0])
        else:
            chain = kinematics.chain_start
        ax_cell.plot(*chain.T, "o-", color="0.2", lw=3.0, ms=4, gid="robot", label="robot at t = 0")
        scene.append(chain)
    _set_equal(ax_cell, np.vstack(scene))
    # with a positioner the path is drawn relative to its flange (trajectory.tool_position)
    where = "positioner flange" if case.positioner is not None else "robot base frame"
    ax_cell.set_title(f"work cell ({where})", fontsize=10, y=1.0)

    ax_path.plot(*points_base.T, color=AFTER_COLOR, lw=2.0, gid="path-zoom")
    ax_path.plot(*points_base[0], "o", color="tab:green", ms=6, label="start", gid="start")
    ax_path.plot(*points_base[-1], "s", color="0.2", ms=6, label="end", gid="end")
    extent = float(np.max(np.ptp(points_base, axis=0))) if len(points_base) > 1 else 0.1
    if trajectory.n_samples:
        if kinematics is None:
            idx = frame_indices(trajectory.n_samples, n_tool_frames)
            T_tool = carrier_tool_frames(case, trajectory.q[idx])
        else:
            T_tool = kinematics.path_frames
        _plot_triads(ax_path, triad_lines(T_tool, 0.08 * extent), "tool-frames", "tool frames")
        bad = violation_samples(trajectory, result.check.violations)
        if bad.any():
            mark_violations(ax_path, points_base[bad].T, "samples inside a violation window")
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
        f"{status_line(result)}: placement X = {_format_placement(result)}", fontsize=10
    )
    return figure


def _format_placement(result: PlanResult) -> str:
    x = result.placement
    return f"({x[0]:.4f}, {x[1]:.4f}, {x[2]:.4f}) m, rpy ({x[3]:.4f}, {x[4]:.4f}, {x[5]:.4f}) rad"


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
    figure = new_figure(13.0, 5.6, layout=None)
    figure.subplots_adjust(left=0.06, right=0.98, bottom=0.1, top=0.88, wspace=0.12)
    ax_spin = figure.add_subplot(1, 2, 1)
    ax_frames = figure.add_subplot(1, 2, 2, projection="3d")
    if trajectory.n_samples and len(trajectory.spin) == trajectory.n_samples:
        ax_spin.plot(trajectory.s, trajectory.spin, color=AFTER_COLOR, lw=1.8, gid="spin")
    if tool.spin != SpinMode.FIXED:
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
            T_tool = carrier_tool_frames(case, trajectory.q[idx])
        else:
            T_tool = kinematics.tool_frames
        _plot_triads(ax_frames, triad_lines(T_tool, 0.06 * extent), "tool-frames", "tool frames")
    _set_equal(ax_frames, points_base)
    ax_frames.set_title(f"tool frames ({tool.frame} frame)", fontsize=10, y=1.0)
    figure.suptitle(status_line(result), fontsize=10)
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
        axis.set_ticks(inside_ticks(MaxNLocator(nbins=5), low, high))
    ax.set_box_aspect((1.0, 1.0, 1.0))
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")
    ax.set_zlabel("z [m]")
