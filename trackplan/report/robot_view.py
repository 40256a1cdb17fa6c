"""Interactive 3D view of the robot following the path (plotly animation).

The robot is drawn as it looks (:mod:`trackplan.report.robot_solids`: its URDF meshes, else
solids of its capsules, a thick line only without either) with a marker at each joint, on
a subsampled trajectory; the base, part and tool frames are drawn and named. A time slider
and play/pause buttons drive plotly animation frames that update only the robot, the tool
frame and the tool trail. With a work cell, obstacles and the placed workpiece are drawn as
solids, the tool's capsules follow the animation, and the closest approach is a red
segment between the nearest points.

:func:`robot_view_spec` builds the figure as plain JSON-ready data (lists, dicts, numbers),
which the report serialises directly: building plotly's validated objects for every
animation frame cost more than the rest of the report's HTML. :func:`robot_view_figure`
wraps the same data in a :class:`plotly.graph_objects.Figure`; plotly is imported there only.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import TYPE_CHECKING

import numpy as np

from trackplan.case import Case
from trackplan.frames import placement_transform
from trackplan.planning.result import PlanResult
from trackplan.report.machine_view import (
    arm_frames,
    cell_chain_points,
    frame_axis_trace,
    machine_layers,
    moves_the_part,
)
from trackplan.report.robot_solids import LINES_NOTE, SOLIDS_TRACE, RobotLook, robot_look
from trackplan.report.scene import (
    FRAME_STYLES,
    equal_limits,
    frame_indices,
    nominal_polyline,
    path_points,
    plotly_xyz,
    sphere_wireframe,
    transform_points,
    triad_lines,
)

if TYPE_CHECKING:
    import plotly.graph_objects as go

#: The id of the plotly div in report.html.
VIEW_ID = "robot-view"
#: Names of the traces the animation updates.
ROBOT_TRACE = "robot joints"
TRAIL_TRACE = "tool trail"
PATH_TRACE = "planned path"
NOMINAL_TRACE = "nominal path"
TOOL_FRAME = "tool frame"
CAPSULES_TRACE = SOLIDS_TRACE  # a robot without meshes: the solids of the capsules checked
CLOSEST_TRACE = "closest approach"
DECIMALS = 5  # 10 µm: keeps the page small, far below anything visible


def _xyz(points: np.ndarray, decimals: int = DECIMALS) -> dict[str, list[float | None]]:
    """Plotly coordinates from points (M, 3), NaN rows as gaps (None)."""
    return plotly_xyz(points, decimals)


def frame_name(k: int) -> str:
    """Name of animation frame k (0-based)."""
    return f"frame-{k:04d}"


def _cell_traces(result: PlanResult, case: Case) -> tuple[list, np.ndarray]:
    """Static traces of the cell (obstacles, workpiece, closest approach) and the vertices
    of its bodies but planes, shape (M, 3), m (for the view's limits)."""
    from trackplan.cell.model import Shape
    from trackplan.cell.screening import CellGeometry
    from trackplan.report.cell_scene import body_mesh, closest_approach, merge

    assert case.cell is not None
    geometry = CellGeometry.from_cell(case.cell, case.robot)
    T_base_part = placement_transform(result.placement)
    traces: list = []
    drawn: list[np.ndarray] = [np.zeros((0, 3))]
    # with a positioner the workpiece moves with it (machine_view)
    workpiece = () if moves_the_part(case) else case.cell.workpiece
    for label, bodies, T, color, opacity in (
        ("obstacles", case.cell.obstacles, np.eye(4), "#8c8c8c", 0.35),
        ("workpiece", workpiece, T_base_part, "#c49a6c", 0.6),
    ):
        if not bodies:
            continue
        vertices, faces = merge([body_mesh(body, T) for body in bodies])
        traces.append(_mesh_trace(vertices, faces, label, color, opacity))
        solid = [body for body in bodies if body.shape is not Shape.PLANE]
        drawn += [body_mesh(body, T)[0] for body in solid]
    closest = closest_approach(geometry, case.machine, result)
    if closest is not None:
        points, label = closest
        traces.append(
            {
                "type": "scatter3d",
                **_xyz(points),
                "mode": "lines+markers",
                "name": CLOSEST_TRACE,
                "line": {"color": "red", "width": 6},
                "marker": {"size": 4, "color": "red"},
                "hovertext": [label, label],
                "hoverinfo": "text",
            }
        )
    return traces, np.vstack(drawn)


def _mesh_trace(
    vertices: np.ndarray, faces: np.ndarray, name: str, color: str, opacity: float
) -> dict:
    return {
        "type": "mesh3d",
        **_xyz(vertices),
        "i": faces[:, 0].tolist(),
        "j": faces[:, 1].tolist(),
        "k": faces[:, 2].tolist(),
        "name": name,
        "showlegend": True,
        "color": color,
        "opacity": opacity,
        "flatshading": True,
        "hoverinfo": "name",
    }


def robot_view_figure(result: PlanResult, case: Case, n_frames: int = 150) -> go.Figure:
    """The robot following the placed path, as a plotly figure with animation frames.

    The figure of :func:`robot_view_spec`, validated by plotly.

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

    return go.Figure(robot_view_spec(result, case, n_frames))


def robot_view_spec(result: PlanResult, case: Case, n_frames: int = 150) -> dict:
    """The robot following the placed path, as plotly figure data (plain JSON-ready values).

    Static traces: the nominal path placed in the base frame (dashed), the planned tool
    path, base and part frame axes and names, and the outer reach shell of the placement
    origin. Animated traces: the robot's joints (:data:`ROBOT_TRACE`, first), its meshes or
    solids (:func:`~trackplan.report.robot_solids.robot_look`), the tool frame's axes and the
    tool trail. The axes are fixed with equal scale, fitted to everything drawn (the cell's
    bodies too), so the scene does not jump between frames.
    Coordinates are rounded to 10 µm; gaps are ``None``.

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
    dict
        ``{"data": [trace, ...], "layout": {...}, "frames": [frame, ...]}`` as plotly.js
        takes them (no template: plotly's default applies), with ``frames`` named
        :func:`frame_name`, a slider with one step per frame and play/pause buttons.

    Raises
    ------
    ValueError
        When the trajectory is empty.
    """
    trajectory = result.trajectory
    if trajectory.n_samples == 0:
        raise ValueError("no trajectory to animate")
    robot = case.robot
    idx = frame_indices(trajectory.n_samples, n_frames)
    chains = cell_chain_points(case, trajectory.q[idx])  # (F, n + 2, 3), cell frame
    tool = trajectory.tool_position[idx]
    _, points_base = path_points(result, case)
    T_base_part = placement_transform(result.placement)
    nominal = transform_points(T_base_part, nominal_polyline(case))
    reach = case.bounds.reach[1]
    shell = sphere_wireframe(reach, n_meridians=8, n_parallels=5)
    axis_length = 0.15 * reach

    joint_sizes = [8] + [6] * robot.n_dof + [4]
    joint_colors = ["#444444"] + ["#1f3b73"] * robot.n_dof + ["#ff7f0e"]

    trail = _xyz(tool)

    frames = arm_frames(case, trajectory.q[idx])  # (F, n + 2, 4, 4), cell frame
    look = robot_look(case, frames)

    def robot_trace(k: int) -> dict:
        return _robot_trace(chains[k], look, joint_sizes, joint_colors, robot.joint_names)

    tool_frames = _tool_frame_lines(frames[:, -1], 0.5 * axis_length)

    def tool_axis(axis: int) -> Callable[[int], dict]:
        def build(k: int) -> dict:
            return frame_axis_trace(tool_frames[k, axis], TOOL_FRAME, axis)

        return build

    def trail_trace(k: int) -> dict:
        return {
            "type": "scatter3d",
            **{axis: values[: k + 1] for axis, values in trail.items()},
            "mode": "lines",
            "name": TRAIL_TRACE,
            "line": {"color": "#ff7f0e", "width": 6},
            "hoverinfo": "skip",
        }

    static: list[dict] = [
        {
            "type": "scatter3d",
            **_xyz(shell),
            "mode": "lines",
            "name": f"reach shell {reach:.3g} m",
            "line": {"color": "rgba(120,120,120,0.25)", "width": 1},
            "hoverinfo": "skip",
            "visible": "legendonly",
        },
    ]
    fixed_part: list[dict] = [
        {
            "type": "scatter3d",
            **_xyz(nominal),
            "mode": "lines",
            "name": NOMINAL_TRACE,
            "line": {"color": "#7f7f7f", "width": 3, "dash": "dash"},
            "hoverinfo": "skip",
        },
        {
            "type": "scatter3d",
            **_xyz(points_base[:: max(1, len(points_base) // 2000)]),
            "mode": "lines",
            "name": PATH_TRACE,
            "line": {"color": "#9467bd", "width": 3},
            "hoverinfo": "skip",
        },
    ]
    for label, T in (("base frame", np.eye(4)), ("part frame", T_base_part)):
        lines = triad_lines(T, axis_length if label == "base frame" else 0.6 * axis_length)
        colors, dash = FRAME_STYLES[label]
        for axis, color in enumerate(colors):
            (static if label == "base frame" else fixed_part).append(
                {
                    "type": "scatter3d",
                    **_xyz(lines[axis]),
                    "mode": "lines",
                    "name": f"{label} (x, y, z)",
                    "legendgroup": label,
                    "showlegend": axis == 0,
                    "line": {"color": color, "width": 5, "dash": dash},
                    "hovertext": f"{label} {'xyz'[axis]}",
                    "hoverinfo": "text",
                }
            )
    # the external axes: the track's rail, the positioner and, with one, the part moving on
    # its flange in place of the fixed part's path, trail and frame
    layers = machine_layers(
        result,
        case,
        idx,
        {"nominal": NOMINAL_TRACE, "path": PATH_TRACE, "trail": TRAIL_TRACE},
        0.6 * axis_length,
    )
    static += layers.static
    # the joints' trace first: the browser tests read it as each frame's data[0]
    builders: list[Callable[[int], dict]] = [robot_trace, *look.builders]
    builders += [tool_axis(axis) for axis in range(3)]
    if moves_the_part(case):
        builders += layers.builders
    else:
        static += fixed_part
        builders.append(trail_trace)
    cell_points = np.zeros((0, 3))
    if case.cell is not None:
        cell_static, cell_points = _cell_traces(result, case)
        static += cell_static
    animated = [build(0) for build in builders]
    first_animated = len(static)
    animated_ids = [first_animated + i for i in range(len(builders))]

    animation = [
        {
            "name": frame_name(k),
            "data": [build(k) for build in builders],
            "traces": animated_ids,
        }
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
    fixed = [] if moves_the_part(case) else [points_base, nominal]
    limits = equal_limits(
        np.vstack(
            [
                chains.reshape(-1, 3),
                *fixed,
                layers.points,
                look.points,
                cell_points,
                [[0.0, 0.0, 0.0]],
            ]
        )
    )
    scene_axes = {
        f"{axis}axis": {
            "range": limits[i].tolist(),
            "title": {"text": f"{axis} [m]"},
            "autorange": False,
        }
        for i, axis in enumerate("xyz")
    }
    layout = {
        "title": {
            "text": f"{robot.name} following the placed path "
            f"({len(idx)} frames of {trajectory.n_samples} samples)"
        },
        "height": 720,
        "margin": {"l": 0, "r": 0, "t": 40, "b": 10},
        "scene": {
            **scene_axes,
            "aspectmode": "cube",
            "domain": {"x": [0.0, 1.0], "y": [0.14, 1.0]},
            "camera": {"eye": {"x": 1.6, "y": -1.6, "z": 1.0}},
            "annotations": frame_names(T_base_part, moves_the_part(case)),
        },
        "uirevision": "robot-view",
        "legend": {"x": 0.0, "y": 1.0},
        "sliders": [slider],
        "updatemenus": [buttons],
    }
    return {"data": [*static, *animated], "layout": layout, "frames": animation}


def _robot_trace(
    chain: np.ndarray,
    look: RobotLook,
    sizes: list[int],
    colors: list[str],
    joint_names: tuple[str, ...],
) -> dict:
    """The robot's joints (markers) over its meshes or solids; without either, a thick line
    through its frames, the legend saying why."""
    trace = {
        "type": "scatter3d",
        **_xyz(chain),
        "mode": "markers",
        "name": ROBOT_TRACE,
        "marker": {"size": sizes, "color": colors, "line": {"color": "white", "width": 1}},
        "hovertext": ["base", *joint_names, "tool"],
        "hoverinfo": "text",
    }
    if look.kind == "lines":
        trace |= {
            "mode": "lines+markers",
            "line": {"color": "#5a6b8c", "width": 14},
            "legendgroup": "robot",
            "legendgrouptitle": {"text": LINES_NOTE},
        }
    return trace


def _tool_frame_lines(T_tool: np.ndarray, length: float) -> np.ndarray:
    """The tool frame's axes at each animation frame, shape (F, 3, 3, 3)."""
    return np.stack([triad_lines(T, max(length, 1e-3)) for T in T_tool])


def frame_names(T_base_part: np.ndarray, part_moves: bool) -> list[dict]:
    """The base and part frames' names written at their origins, as the scene's annotations.

    Annotations are drawn as page text over the WebGL scene; a scatter3d text trace would
    have plotly.js trace every glyph's outline into triangles when the page opens, which
    cost about as much as the rest of the 3D view's first drawing in headless Chromium.
    Without a positioner the part frame is named too (a moving part has no fixed place).
    """
    points = [np.zeros(3)] if part_moves else [np.zeros(3), T_base_part[:3, 3]]
    names = ["base frame", "part frame"]
    return [
        {
            "x": round(float(p[0]), DECIMALS),
            "y": round(float(p[1]), DECIMALS),
            "z": round(float(p[2]), DECIMALS),
            "text": name,
            "showarrow": False,
            "yshift": -12,
            "font": {"size": 11, "color": "#333"},
        }
        for p, name in zip(points, names, strict=False)
    ]
