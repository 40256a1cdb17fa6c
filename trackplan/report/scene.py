"""Geometry shared by the static plots and the interactive 3D view.

Pure numpy: no plotting library is imported here. Lengths in metres, angles in radians,
points as ``(..., 3)`` arrays with batch axes first. Polylines that hold several pieces
separate them with a row of NaN, which both matplotlib and plotly draw as a gap.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from trackplan.case import Case
from trackplan.frames import placement_transform
from trackplan.paths import NominalPath
from trackplan.planning.result import PlanResult, Trajectory, Violation
from trackplan.robots.kinematics import forward_kinematics, joint_frames
from trackplan.robots.machine import Machine
from trackplan.robots.model import Robot

#: Display name and unit of each joint limit kind.
JOINT_QUANTITIES = {
    "position": ("position", "rad"),
    "velocity": ("velocity", "rad/s"),
    "acceleration": ("acceleration", "rad/s²"),
    "jerk": ("jerk", "rad/s³"),
    "torque": ("torque", "N·m"),
}


LINEAR_UNITS = {
    "position": "m",
    "velocity": "m/s",
    "acceleration": "m/s²",
    "jerk": "m/s³",
}
"""Unit of each limit kind for a linear axis (a track)."""


def column_units(robot: Robot | Machine, kind: str) -> tuple[str, ...]:
    """The unit of every column of the joint vector for one limit kind: the robot's joints
    and a positioner's axes in rad, rad/s, …; a track in m, m/s, m/s², m/s³.

    Returns
    -------
    tuple of str
        Length n (the robot's or the machine's joints).
    """
    angular = JOINT_QUANTITIES[kind][1]
    units = getattr(robot, "units", ("rad",) * robot.n_dof)
    return tuple(LINEAR_UNITS[kind] if unit == "m" else angular for unit in units)


def joint_series(trajectory: Trajectory, kind: str) -> np.ndarray:
    """The trajectory's samples of one joint limit kind.

    Parameters
    ----------
    trajectory
        The trajectory.
    kind
        ``position``, ``velocity``, ``acceleration`` or ``jerk``.

    Returns
    -------
    numpy.ndarray
        Shape (N, n): q (rad), q̇ (rad/s), q̈ (rad/s²) or q⃛ (rad/s³).
    """
    return {
        "position": trajectory.q,
        "velocity": trajectory.qd,
        "acceleration": trajectory.qdd,
        "jerk": trajectory.qddd,
    }[kind]


def joint_bounds(robot: Robot | Machine, kind: str) -> tuple[np.ndarray, np.ndarray]:
    """Lower and upper bound of one joint limit kind.

    Returns
    -------
    tuple of numpy.ndarray
        ``(lower, upper)``, each shape (n,), in the unit of :func:`joint_series`:
        ``(q_min, q_max)`` for positions, ``(-limit, +limit)`` otherwise.
    """
    if kind == "position":
        return robot.q_min, robot.q_max
    limit = robot.limits(kind)
    return -limit, limit


def plotly_xyz(points: np.ndarray, decimals: int = 5) -> dict[str, list[float | None]]:
    """Plotly coordinates ``{"x": [...], "y": [...], "z": [...]}`` from points (M, 3), m,
    rounded to ``decimals`` (10 µm by default), NaN rows as gaps (None)."""
    columns = np.round(points, decimals).T.astype(object)
    columns[np.isnan(points.T.astype(float))] = None
    return {axis: columns[i].tolist() for i, axis in enumerate("xyz")}


def transform_points(T: np.ndarray, points: np.ndarray) -> np.ndarray:
    """Apply a homogeneous transform to points.

    Parameters
    ----------
    T
        Transform, shape (4, 4).
    points
        Shape (..., 3), m, in the transform's source frame.

    Returns
    -------
    numpy.ndarray
        Shape (..., 3), m, in the transform's target frame.
    """
    return points @ T[:3, :3].T + T[:3, 3]


DRAWING_STEP = 1e-3
"""Largest distance between drawn points of the nominal path, m."""


def nominal_polyline(case: Case) -> np.ndarray:
    """The path as the user gave it (sharp corners kept), points at most 1 mm apart.

    Returns
    -------
    numpy.ndarray
        Shape (K, 3), m, definition frame.
    """
    return NominalPath.from_specs(case.start, case.segments).polyline(DRAWING_STEP)


def path_points(result: PlanResult, case: Case) -> tuple[np.ndarray, np.ndarray]:
    """The tool path before and after placement.

    The points come from ``trajectory.tool_position`` (after placement, base frame) and
    ``inv(T_base_part)`` applied to them (before placement, definition frame), so they
    need no path object. Without a trajectory, the nominal path stands in for both.

    Returns
    -------
    tuple of numpy.ndarray
        ``(points_part, points_base)``, each shape (N, 3), m: definition frame, base frame.
    """
    T_base_part = placement_transform(result.placement)
    points_base = result.trajectory.tool_position
    if len(points_base) == 0:
        points_part = nominal_polyline(case)
        return points_part, transform_points(T_base_part, points_part)
    return transform_points(np.linalg.inv(T_base_part), points_base), points_base


def tracking_error(result: PlanResult, case: Case) -> np.ndarray:
    """Distance of the tool point from the nominal path (sharp corners kept) per sample;
    with several seams or moves between them, from the nominal path of the seam being
    welded, NaN on the moves.

    Returns
    -------
    numpy.ndarray
        Shape (N,), m (empty without a trajectory).
    """
    if result.trajectory.n_samples == 0:
        return np.zeros(0)
    points_part, _ = path_points(result, case)
    seams = [span for span in result.spans if span.kind == "seam"]
    if len(seams) == len(result.spans) <= 1:  # one seam alone
        return NominalPath.from_specs(case.start, case.segments).project(points_part)[1]
    error = np.full(len(points_part), np.nan)  # NaN on the moves between seams
    for span in seams:
        seam = case.seams[case.seam_names.index(span.label)]
        rows = slice(span.first, span.last + 1)
        path = NominalPath.from_specs(seam.start, seam.segments)
        error[rows] = path.project(points_part[rows])[1]
    return error


def frame_indices(n_samples: int, n_frames: int) -> np.ndarray:
    """Sample indices of ``n_frames`` evenly spread animation frames, first and last included.

    Returns
    -------
    numpy.ndarray
        Shape (min(n_frames, n_samples),), increasing int indices.
    """
    count = max(1, min(n_frames, n_samples))
    return np.unique(np.round(np.linspace(0, n_samples - 1, count)).astype(int))


def chain_points(robot: Robot, q: np.ndarray) -> np.ndarray:
    """Origins of the base, DH frames 1..n and the tool: the robot drawn as links.

    Parameters
    ----------
    q
        Joint positions, shape (..., n), rad.

    Returns
    -------
    numpy.ndarray
        Shape (..., n + 2, 3), m, base frame.
    """
    return joint_frames(robot, q)[..., :3, 3]


def carrier_tool_frames(case: Case, q: np.ndarray) -> np.ndarray:
    """The tool frames relative to the part's carrier (the positioner's flange; the cell
    without a positioner; the robot's base for a robot alone), the frame of
    ``trajectory.tool_position``.

    Parameters
    ----------
    q
        Joint vectors, shape (..., n) (the machine's joints, or the robot's).

    Returns
    -------
    numpy.ndarray
        Shape (..., 4, 4).
    """
    machine = case.machine
    if isinstance(machine, Machine):
        return machine.T_carrier_tool(q)
    return forward_kinematics(machine, q)


def carrier_chain_points(case: Case, q: np.ndarray) -> np.ndarray:
    """:func:`chain_points` of the robot (on its track) in the carrier frame
    (:func:`carrier_tool_frames`), shape (..., n_arm + 2, 3), m."""
    machine = case.machine
    if not isinstance(machine, Machine):
        return chain_points(machine, q)
    frames = np.linalg.inv(machine.T_cell_carrier(q))[..., None, :, :] @ (
        machine.arm_frames_in_cell(q)
    )
    return frames[..., :3, 3]


def sphere_wireframe(radius: float, n_meridians: int = 12, n_parallels: int = 7) -> np.ndarray:
    """A wireframe sphere about the origin as NaN-separated circles.

    Parameters
    ----------
    radius
        m.
    n_meridians, n_parallels
        Number of meridian and parallel circles.

    Returns
    -------
    numpy.ndarray
        Shape (K, 3), m.
    """
    theta = np.linspace(0.0, 2.0 * np.pi, 61)
    circles = []
    for phi in np.linspace(0.0, np.pi, n_meridians, endpoint=False):
        circles.append(
            np.stack([np.cos(theta) * np.cos(phi), np.cos(theta) * np.sin(phi), np.sin(theta)], 1)
        )
    for z in np.linspace(-1.0, 1.0, n_parallels + 2)[1:-1]:
        r = np.sqrt(1.0 - z**2)
        circles.append(np.stack([r * np.cos(theta), r * np.sin(theta), np.full_like(theta, z)], 1))
    gap = np.full((1, 3), np.nan)
    return radius * np.vstack([np.vstack([c, gap]) for c in circles])[:-1]


FRAME_STYLES = {
    "base frame": (("#8b0000", "#006400", "#00008b"), "solid"),
    "part frame": (("#ff8c69", "#66cd66", "#6ca6ff"), "dash"),
    "tool frame": (("#ff0000", "#00b000", "#0000ff"), "solid"),
}
"""Colours of the x, y and z axes (dark and light red, green, blue) and the line style of
the robot's base frame, of the part (path definition) frame and of the tool frame, in
every view: the frames are told apart by colour, style and legend entry; the tool frame
has the plain red, green and blue."""


def triad_lines(T: np.ndarray, length: float) -> np.ndarray:
    """Axes of frames as NaN-separated line pieces, one polyline per axis.

    Parameters
    ----------
    T
        Frames, shape (F, 4, 4) or (4, 4).
    length
        Drawn axis length, m.

    Returns
    -------
    numpy.ndarray
        Shape (3, 3 F, 3), m: for x, y and z, the pieces origin → origin + length · axis.
    """
    T = np.asarray(T, dtype=float).reshape(-1, 4, 4)
    origin = T[:, :3, 3]
    gap = np.full_like(origin, np.nan)
    return np.stack(
        [np.stack([origin, origin + length * T[:, :3, i], gap], 1).reshape(-1, 3) for i in range(3)]
    )


def violation_samples(trajectory: Trajectory, violations: Sequence[Violation]) -> np.ndarray:
    """Samples inside the time window of any of ``violations``.

    Returns
    -------
    numpy.ndarray
        Shape (N,), bool.
    """
    inside = np.zeros(trajectory.n_samples, dtype=bool)
    half = 0.5 * trajectory.sample_time
    for v in violations:
        inside |= (trajectory.t >= v.t_first - half) & (trajectory.t <= v.t_last + half)
    return inside


def equal_limits(points: np.ndarray, pad: float = 0.05) -> np.ndarray:
    """Axis limits of a cube holding every finite point: equal aspect in 3D.

    Parameters
    ----------
    points
        Shape (M, 3), m (NaN rows ignored).
    pad
        Margin as a fraction of the cube's side.

    Returns
    -------
    numpy.ndarray
        Shape (3, 2): (low, high) per axis, m.
    """
    finite = points[np.all(np.isfinite(points), axis=1)]
    low, high = finite.min(axis=0), finite.max(axis=0)
    half = 0.5 * max(float(np.max(high - low)), 1e-3) * (1.0 + 2.0 * pad)
    center = 0.5 * (low + high)
    return np.stack([center - half, center + half], axis=1)
