"""Triangle meshes of the work cell for the 3D view: bodies, capsules, the closest approach.

Pure numpy; the plotly traces are built in :mod:`trackplan.report.robot_view`.
"""

from __future__ import annotations

import numpy as np

from trackplan.cell.model import Body, Shape
from trackplan.cell.screening import CellGeometry
from trackplan.planning.result import PlanResult
from trackplan.robots.kinematics import joint_frames
from trackplan.robots.machine import Machine
from trackplan.robots.model import Robot

PLANE_HALF_SIZE = 1.0
"""Half size of the square drawn for a plane, m."""
N_AROUND = 10
"""Vertices around a cylinder, capsule or sphere."""

_BOX_FACES = np.array(
    [
        [0, 1, 3], [0, 3, 2], [4, 6, 7], [4, 7, 5], [0, 4, 5], [0, 5, 1],
        [2, 3, 7], [2, 7, 6], [0, 2, 6], [0, 6, 4], [1, 5, 7], [1, 7, 3],
    ]
)  # fmt: skip


def _apply(T: np.ndarray, points: np.ndarray) -> np.ndarray:
    return points @ T[:3, :3].T + T[:3, 3]


def _revolved(profile: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """A closed surface of revolution about z from a profile of (radius, z) rows."""
    angle = np.linspace(0.0, 2 * np.pi, N_AROUND, endpoint=False)
    ring = np.stack([np.cos(angle), np.sin(angle)], axis=1)
    n_rings = len(profile)
    vertices = np.concatenate(
        [np.column_stack([r * ring, np.full(N_AROUND, z)]) for r, z in profile]
    )
    faces = []
    for i in range(n_rings - 1):
        for j in range(N_AROUND):
            a, b = i * N_AROUND + j, i * N_AROUND + (j + 1) % N_AROUND
            faces += [[a, b, b + N_AROUND], [a, b + N_AROUND, a + N_AROUND]]
    # caps: fans around the first and last rings' centres
    bottom, top = len(vertices), len(vertices) + 1
    vertices = np.vstack([vertices, [0.0, 0.0, profile[0][1]], [0.0, 0.0, profile[-1][1]]])
    last = (n_rings - 1) * N_AROUND
    for j in range(N_AROUND):
        faces.append([bottom, (j + 1) % N_AROUND, j])
        faces.append([top, last + j, last + (j + 1) % N_AROUND])
    return vertices, np.asarray(faces)


def _rounded(radius: float, half: float, n_cap: int) -> np.ndarray:
    """Profile of a capsule (n_cap rings per hemisphere) or, with n_cap = 0, a cylinder."""
    if n_cap == 0:
        return np.array([[radius, -half], [radius, half]])
    phi = np.linspace(-np.pi / 2, 0.0, n_cap + 1)[1:]
    low = [(radius * np.cos(p), -half + radius * np.sin(p)) for p in phi]
    high = [(r, -z) for r, z in reversed(low)]
    return np.array(low + high)


def body_mesh(body: Body, T_world_frame: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Vertices (V, 3) in the world, m, and triangles (F, 3) of a body."""
    T = np.asarray(T_world_frame, dtype=float) @ body.T_frame_body
    size = body.size
    if body.shape is Shape.MESH:
        return _apply(T, body.vertices), body.faces
    if body.shape is Shape.BOX:
        corners = np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)]) * size
        return _apply(T, corners), _BOX_FACES
    if body.shape is Shape.PLANE:
        h = PLANE_HALF_SIZE
        square = np.array([[-h, -h, 0.0], [h, -h, 0.0], [h, h, 0.0], [-h, h, 0.0]])
        return _apply(T, square), np.array([[0, 1, 2], [0, 2, 3]])
    if body.shape is Shape.SPHERE:
        vertices, faces = _revolved(_rounded(size[0], 0.0, 4))
    elif body.shape is Shape.CYLINDER:
        vertices, faces = _revolved(_rounded(size[0], size[1], 0))
    else:
        vertices, faces = _revolved(_rounded(size[0], size[1], 3))
    return _apply(T, vertices), faces


def capsule_mesh(a: np.ndarray, b: np.ndarray, radius: float) -> tuple[np.ndarray, np.ndarray]:
    """A capsule from its axis end points a, b (3,) and radius, m, as a triangle mesh."""
    from trackplan.cell.exact import capsule_pose

    half = 0.5 * float(np.linalg.norm(np.asarray(b) - np.asarray(a)))
    vertices, faces = _revolved(_rounded(radius, half, 3))
    return _apply(capsule_pose(a, b), vertices), faces


def merge(meshes: list[tuple[np.ndarray, np.ndarray]]) -> tuple[np.ndarray, np.ndarray]:
    """One mesh of several: vertices stacked, faces re-indexed."""
    vertices, faces, offset = [], [], 0
    for v, f in meshes:
        vertices.append(v)
        faces.append(np.asarray(f) + offset)
        offset += len(v)
    if not vertices:
        return np.zeros((0, 3)), np.zeros((0, 3), dtype=int)
    return np.vstack(vertices), np.vstack(faces)


def robot_capsules_mesh(
    geometry: CellGeometry, frames: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """Link and tool capsules at one configuration (frames (n + 2, 4, 4)) as one mesh."""
    capsules = geometry.capsules
    n_drawn = _n_links(geometry) + len(geometry.cell.tool)  # not the tool's clipped copies
    meshes = []
    for k in range(n_drawn):
        T = frames[capsules.frame[k]]
        a, b = _apply(T, capsules.segment[k])
        meshes.append(capsule_mesh(a, b, float(capsules.radius[k])))
    return merge(meshes)


def _n_links(geometry: CellGeometry) -> int:
    """Link capsules come first, then the tool's, then the tool's clipped copies."""
    tcp = geometry.n_frames - 1
    return int(np.sum(geometry.capsules.frame != tcp))


def closest_approach(
    geometry: CellGeometry, robot: Robot | Machine, result: PlanResult
) -> tuple[np.ndarray, str] | None:
    """The two nearest points (2, 3) of the closest pair at the closest sample, and a label;
    with a machine, in the cell frame (the robot on its track, the workpiece on the
    positioner's flange)."""
    from trackplan.cell.exact import ExactDistance
    from trackplan.frames import placement_transform

    cell = result.check.cell
    if cell is None or not np.isfinite(cell.min_clearance):
        return None
    names = geometry.pair_names()
    pair = names.index(cell.closest)
    q = result.trajectory.q[cell.point]
    T_part = placement_transform(result.placement)
    if isinstance(robot, Machine):
        frames = robot.arm_frames_in_cell(q)
        T_part = robot.T_cell_carrier(q) @ T_part
    else:
        frames = joint_frames(robot, q)
    capsules = geometry.capsules
    oracle = ExactDistance()
    n_body_pairs = len(geometry.pair_capsule)
    if pair < n_body_pairs:
        k, o = geometry.pair_capsule[pair], geometry.pair_body[pair]
        a, b = _apply(frames[capsules.frame[k]], capsules.segment[k])
        T = T_part if o >= geometry.n_obstacles else np.eye(4)
        points = oracle.nearest_points_body(a, b, capsules.radius[k], geometry.bodies[o], T)
    else:
        i, j = geometry.self_pairs[pair - n_body_pairs]
        a0, b0 = _apply(frames[capsules.frame[i]], capsules.segment[i])
        a1, b1 = _apply(frames[capsules.frame[j]], capsules.segment[j])
        points = oracle.nearest_points_capsules(
            a0, b0, capsules.radius[i], a1, b1, capsules.radius[j]
        )
    label = (
        f"closest approach: {cell.closest[0]} – {cell.closest[1]} "
        f"{1e3 * cell.min_clearance:.1f} mm at t = {cell.t_closest:.3f} s"
    )
    return points, label
