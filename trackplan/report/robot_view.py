"""Interactive 3D view of the robot following the path (plotly animation).

The robot is drawn from its DH chain as links between consecutive frame origins (base,
DH frames 1..n, tool) with a marker at each joint, on a subsampled trajectory. A time
slider and play/pause buttons drive plotly animation frames that update only the robot
and the tool trail. plotly is imported inside the functions.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from trackplan.case import Case
from trackplan.frames import placement_transform
from trackplan.planning.result import PlanResult
from trackplan.report.scene import (
    chain_points,
    equal_limits,
    frame_indices,
    nominal_polyline,
    path_points,
    sphere_wireframe,
    transform_points,
    triad_lines,
)

if TYPE_CHECKING:
    import plotly.graph_objects as go

#: The id of the plotly div in report.html.
VIEW_ID = "robot-view"
#: Names of the traces the animation updates.
ROBOT_TRACE = "robot"
TRAIL_TRACE = "tool trail"
PATH_TRACE = "planned path"
NOMINAL_TRACE = "nominal path"
DECIMALS = 5  # 10 µm: keeps the page small, far below anything visible
_AXIS_COLORS = ("#d62728", "#2ca02c", "#1f77b4")


def _xyz(points: np.ndarray) -> dict[str, list[float | None]]:
    """Plotly coordinates from points (M, 3), NaN rows as gaps (None)."""
    rounded = np.round(points, DECIMALS)
    return {
        axis: [None if np.isnan(v) else float(v) for v in rounded[:, i]]
        for i, axis in enumerate("xyz")
    }


def frame_name(k: int) -> str:
    """Name of animation frame k (0-based)."""
    return f"frame-{k:04d}"


def robot_view_figure(result: PlanResult, case: Case, n_frames: int = 150) -> go.Figure:
    """The robot following the placed path, as a plotly figure with animation frames.

    Static traces: the nominal path placed in the base frame (dashed), the planned tool
    path, base and part frame axes, and the outer reach shell of the placement origin.
    Animated traces: the robot (links and joints, ``name="robot"``) and the tool trail.
    The axes are fixed with equal scale so the scene does not jump between frames.

    Parameters
    ----------
    result
        The planned placement; needs a non-empty trajectory (q in rad, positions in m).
    case
        The case (robot, nominal path, reach).
    n_frames
        Number of animation frames (evenly spread samples, first and last included);
        fewer when the trajectory has fewer samples.

    Returns
    -------
    plotly.graph_objects.Figure
        With ``frames`` named :func:`frame_name`, a slider with one step per frame and
        play/pause buttons.

    Raises
    ------
    ValueError
        When the trajectory is empty.
    """
    import plotly.graph_objects as go

    trajectory = result.trajectory
    if trajectory.n_samples == 0:
        raise ValueError("no trajectory to animate")
    robot = case.robot
    idx = frame_indices(trajectory.n_samples, n_frames)
    chains = chain_points(robot, trajectory.q[idx])  # (F, n + 2, 3)
    tool = trajectory.tool_position[idx]
    _, points_base = path_points(result, case)
    T_base_part = placement_transform(result.placement)
    nominal = transform_points(T_base_part, nominal_polyline(case))
    reach = case.bounds.reach[1]
    shell = sphere_wireframe(reach, n_meridians=8, n_parallels=5)
    axis_length = 0.15 * reach

    joint_sizes = [8] + [6] * robot.n_dof + [4]
    joint_colors = ["#444444"] + ["#1f3b73"] * robot.n_dof + ["#ff7f0e"]

    # The animated traces are plain dicts and the figure skips plotly's property validation
    # (it cost ~2 s for 150 frames); the static traces below are validated go objects.
    def robot_trace(k: int) -> dict:
        return {
            "type": "scatter3d",
            **_xyz(chains[k]),
            "mode": "lines+markers",
            "name": ROBOT_TRACE,
            "line": {"color": "#5a6b8c", "width": 8},
            "marker": {
                "size": joint_sizes,
                "color": joint_colors,
                "line": {"color": "white", "width": 1},
            },
            "hovertext": ["base", *robot.joint_names, "tool"],
            "hoverinfo": "text",
        }

    def trail_trace(k: int) -> dict:
        return {
            "type": "scatter3d",
            **_xyz(tool[: k + 1]),
            "mode": "lines",
            "name": TRAIL_TRACE,
            "line": {"color": "#ff7f0e", "width": 6},
            "hoverinfo": "skip",
        }

    static = [
        go.Scatter3d(
            **_xyz(shell),
            mode="lines",
            name=f"reach shell {reach:.3g} m",
            line={"color": "rgba(120,120,120,0.25)", "width": 1},
            hoverinfo="skip",
            visible="legendonly",
        ),
        go.Scatter3d(
            **_xyz(nominal),
            mode="lines",
            name=NOMINAL_TRACE,
            line={"color": "#7f7f7f", "width": 3, "dash": "dash"},
            hoverinfo="skip",
        ),
        go.Scatter3d(
            **_xyz(points_base[:: max(1, len(points_base) // 2000)]),
            mode="lines",
            name=PATH_TRACE,
            line={"color": "#9467bd", "width": 3},
            hoverinfo="skip",
        ),
    ]
    for label, T in (("base frame", np.eye(4)), ("part frame", T_base_part)):
        lines = triad_lines(T, axis_length if label == "base frame" else 0.6 * axis_length)
        for axis, color in enumerate(_AXIS_COLORS):
            static.append(
                go.Scatter3d(
                    **_xyz(lines[axis]),
                    mode="lines",
                    name=label,
                    legendgroup=label,
                    showlegend=axis == 0,
                    line={"color": color, "width": 5},
                    hoverinfo="skip",
                )
            )
    animated = [robot_trace(0), trail_trace(0)]
    first_animated = len(static)
    animated_ids = [first_animated, first_animated + 1]

    frames = [
        {"name": frame_name(k), "data": [robot_trace(k), trail_trace(k)], "traces": animated_ids}
        for k in range(len(idx))
    ]
    times = trajectory.t[idx]
    frame_ms = max(30, round(1000 * float(np.mean(np.diff(times)))) if len(idx) > 1 else 30)
    step_args = {
        "mode": "immediate",
        "frame": {"duration": 0, "redraw": True},
        "transition": {"duration": 0},
    }
    slider = {
        "active": 0,
        "currentvalue": {"prefix": "t = ", "suffix": " s", "font": {"color": "#222", "size": 13}},
        # one label per frame is unreadable: show the current value only
        "font": {"color": "rgba(0,0,0,0)"},
        "pad": {"t": 30},
        "len": 0.86,
        "x": 0.14,
        "steps": [
            {"label": f"{t:.2f}", "method": "animate", "args": [[frame_name(k)], step_args]}
            for k, t in enumerate(times)
        ],
    }
    buttons = {
        "type": "buttons",
        "direction": "left",
        "x": 0.0,
        "y": 0.0,
        "xanchor": "left",
        "yanchor": "top",
        "pad": {"t": 35, "r": 10},
        "showactive": False,
        "buttons": [
            {
                "label": "▶ play",
                "method": "animate",
                "args": [
                    None,
                    {
                        "mode": "immediate",
                        "fromcurrent": True,
                        "frame": {"duration": frame_ms, "redraw": True},
                        "transition": {"duration": 0},
                    },
                ],
            },
            {
                "label": "❚❚ pause",
                "method": "animate",
                "args": [[None], {**step_args, "frame": {"duration": 0, "redraw": False}}],
            },
        ],
    }
    limits = equal_limits(
        np.vstack([chains.reshape(-1, 3), points_base, nominal, [[0.0, 0.0, 0.0]]])
    )
    scene_axes = {
        f"{axis}axis": {"range": limits[i].tolist(), "title": f"{axis} [m]", "autorange": False}
        for i, axis in enumerate("xyz")
    }
    figure = go.Figure(data=[*static, *animated], frames=frames, _validate=False)
    figure.update_layout(
        title=(
            f"{robot.name} following the placed path "
            f"({len(idx)} frames of {trajectory.n_samples} samples)"
        ),
        height=720,
        margin={"l": 0, "r": 0, "t": 40, "b": 10},
        scene={
            **scene_axes,
            "aspectmode": "cube",
            "domain": {"x": [0.0, 1.0], "y": [0.14, 1.0]},
            "camera": {"eye": {"x": 1.6, "y": -1.6, "z": 1.0}},
        },
        uirevision="robot-view",
        legend={"x": 0.0, "y": 1.0},
        sliders=[slider],
        updatemenus=[buttons],
    )
    return figure
