"""The external axes in the 3D view: the track's rail, the positioner, the part on it.

With a track or a positioner the case's :attr:`~trackplan.case.Case.machine` is a
:class:`~trackplan.robots.machine.Machine` and the joint vector holds the robot's joints,
the track (m) and the positioner's axes (rad). The 3D view is drawn in the cell frame: the
robot's base moves along the track, the positioner's links follow its axes
(:meth:`~trackplan.robots.machine.Machine.positioner_frames_in_cell`), and the part (the
nominal seam, the planned path, the part frame and the workpiece bodies) rides on the
positioner's flange: a point p of the part's definition frame is at
``T_cell_carrier(q) · T(X) · p`` (:meth:`~trackplan.robots.machine.Machine.T_cell_carrier`,
:func:`~trackplan.frames.placement_transform`) in the frame of joint vector q.

Pure numpy and plain plotly trace dicts, as :mod:`trackplan.report.robot_view` builds them.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from trackplan.case import Case
from trackplan.frames import placement_transform
from trackplan.planning.result import PlanResult
from trackplan.report.scene import (
    FRAME_STYLES,
    chain_points,
    nominal_polyline,
    plotly_xyz,
    transform_points,
    triad_lines,
)
from trackplan.robots.collision import Capsules
from trackplan.robots.machine import Machine

#: Names of the traces of the external axes.
RAIL_TRACE = "track rail"
POSITIONER_TRACE = "positioner"
POSITIONER_CAPSULES_TRACE = "positioner capsules"
WORKPIECE_TRACE = "workpiece"
#: Most points of the part's polylines drawn in each animation frame.
PART_POINTS = 150
#: Decimals of the moving part's coordinates, m (0.1 mm: they are sent in every frame).
PART_DECIMALS = 4

TraceBuilder = Callable[[int], dict]


_xyz = plotly_xyz


def thin_polyline(points: np.ndarray, n_points: int = PART_POINTS) -> np.ndarray:
    """Every k-th point of a polyline (the last kept), at most about ``n_points``."""
    if len(points) <= n_points:
        return points
    step = -(-len(points) // n_points)
    return np.vstack([points[::step], points[-1:]])


def cell_chain_points(case: Case, q: np.ndarray) -> np.ndarray:
    """The robot drawn as links (:func:`~trackplan.report.scene.chain_points`) in the cell
    frame: its base moved by the track. Shape (..., n_arm + 2, 3), m."""
    machine = case.machine
    if isinstance(machine, Machine):
        return machine.arm_frames_in_cell(q)[..., :3, 3]
    return chain_points(machine, q)


def arm_frames(case: Case, q: np.ndarray) -> np.ndarray:
    """The robot's chain frames in the cell frame, shape (..., n_arm + 2, 4, 4)."""
    from trackplan.robots.kinematics import joint_frames

    machine = case.machine
    if isinstance(machine, Machine):
        return machine.arm_frames_in_cell(q)
    return joint_frames(machine, q)


def part_transforms(result: PlanResult, case: Case, q: np.ndarray) -> np.ndarray:
    """Where the part's definition frame is in the cell: ``T_cell_carrier(q) · T(X)``,
    shape (..., 4, 4) for q (..., n); the placement alone for a robot without a
    positioner."""
    T_X = placement_transform(result.placement)
    machine = case.machine
    if not isinstance(machine, Machine) or machine.positioner is None:
        return np.broadcast_to(T_X, (*np.shape(q)[:-1], 4, 4)).copy()
    T: np.ndarray = machine.T_cell_carrier(q) @ T_X
    return T


def moves_the_part(case: Case) -> bool:
    """Whether the case has a positioner: the part moves in the 3D view."""
    machine = case.machine
    return isinstance(machine, Machine) and machine.positioner is not None


@dataclass
class MachineLayers:
    """The traces of the external axes in the 3D view.

    Attributes
    ----------
    static
        Traces drawn once (the track's rail).
    builders
        Builders of the animated traces, each taking the animation frame's index.
    points
        Every point drawn over all frames, shape (M, 3), m (for the view's limits).
    """

    static: list[dict] = field(default_factory=list)
    builders: list[TraceBuilder] = field(default_factory=list)
    points: np.ndarray = field(default_factory=lambda: np.zeros((0, 3)))


def machine_layers(
    result: PlanResult,
    case: Case,
    idx: np.ndarray,
    names: dict[str, str],
    axis_length: float,
) -> MachineLayers:
    """The rail, the positioner and the part moving with it, at the samples ``idx``.

    Parameters
    ----------
    result
        The planned placement (its trajectory's q holds every axis).
    case
        The case; without external axes nothing is drawn.
    idx
        Sample indices of the animation frames, shape (F,).
    names
        Trace names of the view's nominal path, planned path and tool trail
        (``{"nominal": …, "path": …, "trail": …}``), reused for the part's moving copies.
    axis_length
        Drawn length of the part frame's axes, m.

    Returns
    -------
    MachineLayers
    """
    machine = case.machine
    layers = MachineLayers()
    if not isinstance(machine, Machine):
        return layers
    q = result.trajectory.q[idx]
    drawn: list[np.ndarray] = []
    if machine.track is not None:
        track = machine.track
        rail = np.outer([track.lower, track.upper], track.axis)
        drawn.append(rail)
        layers.static.append(
            {
                "type": "scatter3d",
                **_xyz(rail),
                "mode": "lines+markers",
                "name": RAIL_TRACE,
                "line": {"color": "#6b6b47", "width": 10},
                "marker": {"size": 4, "color": "#6b6b47"},
                "hovertext": [f"track {track.lower:.3g} m", f"track {track.upper:.3g} m"],
                "hoverinfo": "text",
            }
        )
    if machine.positioner is None:
        layers.points = np.vstack([np.zeros((0, 3)), *drawn])
        return layers
    frames = machine.positioner_frames_in_cell(q)  # (F, m + 2, 4, 4)
    links = frames[..., :3, 3]
    drawn.append(links.reshape(-1, 3))
    chain = machine.positioner.chain
    hover = ["positioner base", *chain.joint_names, "flange"]

    def positioner_trace(k: int) -> dict:
        return {
            "type": "scatter3d",
            **_xyz(links[k]),
            "mode": "lines+markers",
            "name": POSITIONER_TRACE,
            "line": {"color": "#2f7f5f", "width": 10},
            "marker": {"size": 5, "color": "#1b4d39"},
            "hovertext": hover,
            "hoverinfo": "text",
        }

    layers.builders.append(positioner_trace)
    if chain.collision is not None and len(chain.collision.radius):
        layers.builders.append(_capsules_builder(chain.collision, frames))
    T_part = part_transforms(result, case, q)  # (F, 4, 4)
    nominal = thin_polyline(nominal_polyline(case))
    T_carrier = machine.T_cell_carrier(q)
    planned = thin_polyline(result.trajectory.tool_position)
    trail = result.trajectory.tool_position[idx]  # the TCP relative to the carrier
    moving_nominal = moving_points(T_part, nominal)
    moving_path = moving_points(T_carrier, planned)
    drawn += [moving_nominal.reshape(-1, 3), moving_path.reshape(-1, 3)]
    nominal_style = {
        "name": names["nominal"],
        "line": {"color": "#7f7f7f", "width": 3, "dash": "dash"},
    }
    path_style = {"name": names["path"], "line": {"color": "#9467bd", "width": 3}}

    def trail_trace(k: int) -> dict:
        # the weld so far, carried by the part: the TCP's samples up to frame k relative
        # to the carrier, placed with the carrier of frame k
        done = transform_points(T_carrier[k], trail[: k + 1])
        return {
            "type": "scatter3d",
            **_xyz(done, PART_DECIMALS),
            "mode": "lines",
            "name": names["trail"],
            "line": {"color": "#ff7f0e", "width": 6},
            "hoverinfo": "skip",
        }

    layers.builders += [
        moving_line_builder(moving_nominal, {**nominal_style, "hoverinfo": "skip"}),
        moving_line_builder(moving_path, {**path_style, "hoverinfo": "skip"}),
        trail_trace,
    ]
    layers.builders += _part_frame_builders(T_part, axis_length)
    if case.cell is not None and case.cell.workpiece:
        from trackplan.report.cell_scene import body_mesh, merge

        vertices, faces = merge([body_mesh(body, np.eye(4)) for body in case.cell.workpiece])
        moving = moving_points(T_part, vertices)
        drawn.append(moving.reshape(-1, 3))
        layers.builders.append(_mesh_builder(moving, faces, WORKPIECE_TRACE, "#c49a6c", 0.6))
    layers.points = np.vstack(drawn)
    return layers


def moving_points(T: np.ndarray, points: np.ndarray) -> np.ndarray:
    """Points (M, 3) fixed in a moving frame, placed with its poses T (F, 4, 4): shape
    (F, M, 3), m (one matrix product, no loop over frames)."""
    return np.einsum("fij,kj->fki", T[:, :3, :3], points) + T[:, None, :3, 3]


def moving_line_builder(moving: np.ndarray, style: dict[str, object]) -> TraceBuilder:
    """An animated polyline: its points (F, M, 3) in each frame (NaN rows are gaps), drawn
    in ``style`` (the trace's name, line, hover and the like), coordinates rounded to
    :data:`PART_DECIMALS`."""

    def build(k: int) -> dict:
        return {"type": "scatter3d", **_xyz(moving[k], PART_DECIMALS), "mode": "lines", **style}

    return build


def _part_frame_builders(T_part: np.ndarray, length: float) -> list[TraceBuilder]:
    """The part frame's three axes, one trace each, moving with the part."""
    label = "part frame"
    lines = np.stack([triad_lines(T, max(length, 1e-3)) for T in T_part])  # (F, 3, 3, 3)

    def axis_builder(axis: int) -> TraceBuilder:
        def build(k: int) -> dict:
            return frame_axis_trace(lines[k, axis], label, axis)

        return build

    return [axis_builder(axis) for axis in range(3)]


def frame_axis_trace(line: np.ndarray, label: str, axis: int) -> dict:
    """One axis (0, 1, 2: x, y, z) of a named frame as a plotly line, in the frame's style
    (:data:`~trackplan.report.scene.FRAME_STYLES`); ``line`` its two points (2, 3), m."""
    colors, dash = FRAME_STYLES[label]
    return {
        "type": "scatter3d",
        **_xyz(line),
        "mode": "lines",
        "name": f"{label} (x, y, z)",
        "legendgroup": label,
        "showlegend": axis == 0,
        "line": {"color": colors[axis], "width": 5, "dash": dash},
        "hovertext": f"{label} {'xyz'[axis]}",
        "hoverinfo": "text",
    }


def animated_mesh(
    vertices: np.ndarray,
    faces: np.ndarray,
    k: int,
    style: dict[str, object],
    decimals: int = PART_DECIMALS,
) -> dict:
    """Frame k of an animated plotly mesh: its vertices (V, 3) with the triangles (T, 3),
    which are the same in every frame, carried by the first frame only; ``style`` holds the
    trace's name, colour, opacity and the like."""
    triangles = (
        {"i": faces[:, 0].tolist(), "j": faces[:, 1].tolist(), "k": faces[:, 2].tolist()}
        if k == 0
        else {}
    )
    return {"type": "mesh3d", **_xyz(vertices, decimals), **triangles, **style}


def _mesh_builder(
    vertices: np.ndarray, faces: np.ndarray, name: str, color: str, opacity: float
) -> TraceBuilder:
    """An animated mesh: vertices (F, V, 3) per frame, the same triangles (T, 3) in every
    frame (only the first frame carries them)."""
    style = {
        "name": name,
        "showlegend": True,
        "color": color,
        "opacity": opacity,
        "flatshading": True,
        "hoverinfo": "name",
    }

    def build(k: int) -> dict:
        return animated_mesh(vertices[k], faces, k, style)

    return build


def _capsules_builder(capsules: Capsules, frames: np.ndarray) -> TraceBuilder:
    """The positioner's link capsules (on its chain frames (F, m + 2, 4, 4)) as a mesh."""
    from trackplan.report.cell_scene import capsule_mesh, merge

    meshes = []
    for k in range(len(frames)):
        parts = []
        for c in range(len(capsules.radius)):
            T = frames[k, capsules.frame[c]]
            a, b = transform_points(T, capsules.segment[c])
            parts.append(capsule_mesh(a, b, float(capsules.radius[c])))
        meshes.append(merge(parts))
    vertices = np.stack([v for v, _ in meshes])
    return _mesh_builder(vertices, meshes[0][1], POSITIONER_CAPSULES_TRACE, "#2f7f5f", 0.35)
