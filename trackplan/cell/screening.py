"""The cell compiled for one robot, and batched screening distances.

:class:`CellGeometry` lays every capsule and body out as arrays for the compiled kernel
(:mod:`trackplan.cell._kernels`) and fixes which pairs are checked:

- robot link capsules against every obstacle (except the base's, which stands in the cell)
  and every workpiece body;
- tool capsules against every obstacle, and against the workpiece only where they lie
  farther than ``tool_contact`` from the TCP (the process contact is allowed);
- capsules of bodies that are not neighbours in the chain against each other.

Meshes go to the kernel as their bounding boxes, so a screened distance is never larger
than the exact one; every other shape is screened exactly.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from trackplan.cell import _kernels
from trackplan.cell.model import Body, Capsules, Cell, Shape
from trackplan.cell.robot_bodies import builtin_link_capsules, self_collision_pairs
from trackplan.robots.kinematics import joint_frames
from trackplan.robots.model import Robot


def clip_tool_segment(segment: np.ndarray, contact: float) -> np.ndarray | None:
    """The part of a tool capsule's axis farther than ``contact`` behind the TCP.

    Parameters
    ----------
    segment
        Axis end points in the TCP frame, shape (2, 3), m.
    contact
        ``tool_contact``, m: points with ``z > −contact`` may touch the workpiece.

    Returns
    -------
    numpy.ndarray or None
        The clipped end points, shape (2, 3), or None when nothing is left.
    """
    a, b = np.asarray(segment, dtype=float)
    limit = -contact
    a_in, b_in = a[2] <= limit, b[2] <= limit
    if a_in and b_in:
        return np.array([a, b])
    if not a_in and not b_in:
        return None
    t = (limit - a[2]) / (b[2] - a[2])
    cut = a + t * (b - a)
    return np.array([a, cut]) if a_in else np.array([cut, b])


@dataclass(frozen=True, eq=False)
class CellGeometry:
    """A cell laid out for the kernel, for one robot.

    Attributes
    ----------
    cell
        The cell.
    capsules
        Link capsules, then tool capsules, then the tool capsules clipped for the workpiece.
    bodies
        Obstacles, then workpiece bodies.
    n_obstacles
        How many of ``bodies`` are obstacles.
    kind, size
        Shape code (O,) and parameters (O, 3) of each body as screened (meshes as boxes).
    T_frame_screen
        Pose of each screened body in its frame, shape (O, 4, 4).
    pair_capsule, pair_body
        The capsule–body pairs checked, shape (P,) each.
    self_pairs
        The capsule–capsule pairs checked, shape (Q, 2).
    n_frames
        Frames of the chain (base, links, TCP).
    """

    cell: Cell
    capsules: Capsules
    bodies: tuple[Body, ...]
    n_obstacles: int
    kind: np.ndarray
    size: np.ndarray
    T_frame_screen: np.ndarray
    pair_capsule: np.ndarray
    pair_body: np.ndarray
    self_pairs: np.ndarray
    n_frames: int

    @classmethod
    def from_cell(cls, cell: Cell, robot: Robot) -> CellGeometry:
        """Lay out ``cell`` for ``robot`` (its built-in capsules unless ``cell.links``)."""
        links = cell.links if cell.links is not None else builtin_link_capsules(robot)
        tcp = robot.n_dof + 1
        n_tool = len(cell.tool)
        tool = Capsules(np.full(n_tool, tcp), cell.tool.segment, cell.tool.radius, cell.tool.name)
        clipped_rows = [
            (k, clip_tool_segment(cell.tool.segment[k], cell.tool_contact)) for k in range(n_tool)
        ]
        kept = [(k, seg) for k, seg in clipped_rows if seg is not None]
        clipped = Capsules(
            np.full(len(kept), tcp),
            np.array([seg for _, seg in kept]).reshape(-1, 2, 3),
            np.array([cell.tool.radius[k] for k, _ in kept]),
            tuple(cell.tool.name[k] for k, _ in kept),
        )
        capsules = links + tool + clipped
        bodies = (*cell.obstacles, *cell.workpiece)
        n_obstacles = len(cell.obstacles)
        kind = np.empty(len(bodies), dtype=np.int64)
        size = np.zeros((len(bodies), 3))
        T_screen = np.empty((len(bodies), 4, 4))
        for o, body in enumerate(bodies):
            if body.shape is Shape.MESH:
                T_screen[o], size[o] = body.screening_box()
                kind[o] = Shape.BOX
            else:
                T_screen[o], size[o], kind[o] = body.T_frame_body, body.size, body.shape
        n_links = len(links)
        moving_links = np.flatnonzero(links.frame > 0)  # the base stands in the cell
        link_index = np.arange(n_links)
        tool_index = n_links + np.arange(n_tool)
        clipped_index = n_links + n_tool + np.arange(len(kept))
        obstacles = np.arange(n_obstacles)
        workpiece = n_obstacles + np.arange(len(cell.workpiece))
        pairs = [
            np.stack(np.meshgrid(moving_links, obstacles, indexing="ij"), -1),
            np.stack(np.meshgrid(link_index, workpiece, indexing="ij"), -1),
            np.stack(np.meshgrid(tool_index, obstacles, indexing="ij"), -1),
            np.stack(np.meshgrid(clipped_index, workpiece, indexing="ij"), -1),
        ]
        pair = np.concatenate([p.reshape(-1, 2) for p in pairs]).astype(np.int64)
        moving = np.concatenate([links.frame, tool.frame])
        return cls(
            cell=cell,
            capsules=capsules,
            bodies=bodies,
            n_obstacles=n_obstacles,
            kind=kind,
            size=size,
            T_frame_screen=T_screen,
            pair_capsule=np.ascontiguousarray(pair[:, 0]),
            pair_body=np.ascontiguousarray(pair[:, 1]),
            self_pairs=np.ascontiguousarray(self_collision_pairs(moving)),
            n_frames=robot.n_dof + 2,
        )

    @property
    def n_pairs(self) -> int:
        """Capsule–body pairs plus self pairs checked per sample."""
        return len(self.pair_capsule) + len(self.self_pairs)

    def pair_names(self) -> list[tuple[str, str]]:
        """(capsule, body) names of every pair: capsule–body pairs, then self pairs."""
        names = self.capsules.name
        out = [
            (names[k], self.bodies[o].name)
            for k, o in zip(self.pair_capsule, self.pair_body, strict=True)
        ]
        out += [(names[i], names[j]) for i, j in self.self_pairs]
        return out

    def world_to_body(self, T_base_part: np.ndarray) -> np.ndarray:
        """World → screened-body transforms for placements, shape (G, O, 3, 4).

        Parameters
        ----------
        T_base_part
            Placements of the definition frame, shape (G, 4, 4).
        """
        T_base_part = np.asarray(T_base_part, dtype=float).reshape(-1, 4, 4)
        n_groups = len(T_base_part)
        T_world_body = np.broadcast_to(
            self.T_frame_screen, (n_groups, len(self.bodies), 4, 4)
        ).copy()
        if len(self.bodies) > self.n_obstacles:
            T_world_body[:, self.n_obstacles :] = (
                T_base_part[:, None] @ self.T_frame_screen[self.n_obstacles :]
            )
        R = np.swapaxes(T_world_body[..., :3, :3], -1, -2)
        out = np.empty((n_groups, len(self.bodies), 3, 4))
        out[..., :3] = R
        out[..., 3] = -np.einsum("...ij,...j->...i", R, T_world_body[..., :3, 3])
        return out

    def screen(
        self, frames: np.ndarray, T_base_part: np.ndarray, group: np.ndarray | None = None
    ) -> tuple[np.ndarray, np.ndarray]:
        """Screened signed distances of every pair at every sample.

        Parameters
        ----------
        frames
            Chain frames (:func:`trackplan.robots.kinematics.joint_frames`), shape
            (N, n + 2, 4, 4).
        T_base_part
            Placements, shape (G, 4, 4) (or (4, 4) for one).
        group
            The placement of each sample, shape (N,), int; default all 0.

        Returns
        -------
        tuple of numpy.ndarray
            Capsule–body distances (N, P) and self distances (N, Q), m.
        """
        frames = np.ascontiguousarray(np.asarray(frames, dtype=float)[..., :3, :])
        n_samples = len(frames)
        group = np.zeros(n_samples, np.int64) if group is None else np.asarray(group, np.int64)
        return _kernels.screen_pairs(
            frames,
            self.capsules.frame,
            self.capsules.segment,
            self.capsules.radius,
            self.kind,
            self.size,
            self.world_to_body(T_base_part),
            group,
            self.pair_capsule,
            self.pair_body,
            self.self_pairs,
        )

    def screen_joints(
        self, robot: Robot, q: np.ndarray, T_base_part: np.ndarray, group: np.ndarray | None = None
    ) -> tuple[np.ndarray, np.ndarray]:
        """:meth:`screen` of joint positions q, shape (N, n), rad."""
        return self.screen(joint_frames(robot, q), T_base_part, group)
