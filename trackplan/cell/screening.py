"""The cell compiled for one robot or machine, and batched screening distances.

:class:`CellGeometry` lays every capsule and body out as arrays for the compiled kernel
(:mod:`trackplan.cell._kernels`) and fixes which pairs are checked:

- robot link capsules against every obstacle (except the base's, which stands in the cell)
  and every workpiece body;
- tool capsules against every obstacle, and against the workpiece only where they lie
  farther than ``tool_contact`` from the TCP (the process contact is allowed);
- capsules of bodies that are not neighbours in the chain against each other;
- with a :class:`~trackplan.robots.machine.Machine` that has a positioner: the
  positioner's capsules against every arm link and tool capsule, its moving links' (not its
  base's) against every obstacle; the workpiece rides on its flange (it is clamped there:
  not checked against the positioner).

With a machine every frame is in the cell frame (the arm's base frame with the track at
0): the arm's chain frames (:meth:`Machine.arm_frames_in_cell`), then the positioner's
(:meth:`Machine.positioner_frames_in_cell`); the workpiece stands at
``T_cell_carrier(q) · T_carrier_part`` at each sample (:func:`cell_frames`,
:func:`part_placements`).

Meshes go to the kernel as boxes enclosing their triangles, so a screened distance is never larger
than the exact one; every other shape is screened exactly.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from trackplan.cell import _kernels
from trackplan.cell.model import Body, Capsules, Cell, Shape
from trackplan.cell.robot_bodies import builtin_link_capsules, self_collision_pairs
from trackplan.errors import CaseError
from trackplan.robots.kinematics import joint_frames
from trackplan.robots.machine import Machine, arm_of
from trackplan.robots.model import Robot

POSITIONER_PREFIX = "positioner "
"""Prefix of the positioner's capsule names in reports (``positioner link 1``)."""


def cell_frames(robot: Robot | Machine, q: np.ndarray) -> np.ndarray:
    """The frames the capsules move with, in the cell frame, shape (..., F, 4, 4).

    For a robot, its chain frames (:func:`~trackplan.robots.kinematics.joint_frames`):
    base, links 1..n, TCP. For a machine, the arm's chain frames moved by the track, then
    the positioner's (base, links 1..m, flange), all in the cell frame.

    Parameters
    ----------
    robot
        A robot or a machine.
    q
        Joint positions, shape (..., n): for a machine every column (arm, track,
        positioner), rad and m.
    """
    if not isinstance(robot, Machine):
        return joint_frames(robot, q)
    arm = robot.arm_frames_in_cell(q)
    if robot.positioner is None:
        return arm
    return np.concatenate([arm, robot.positioner_frames_in_cell(q)], axis=-3)


def part_placements(
    robot: Robot | Machine,
    q: np.ndarray,
    T_carrier_part: np.ndarray,
    group: np.ndarray | None = None,
) -> tuple[np.ndarray, np.ndarray]:
    """The workpiece's placement at each sample in the cell, and the group of each sample.

    For a robot, or a machine without a positioner, the carrier is the cell (base) frame:
    the placements are ``T_carrier_part`` and the groups ``group`` as given. With a
    positioner the part rides on its flange: one placement per sample,
    ``T_cell_carrier(q_s) · T_carrier_part[group_s]``.

    Parameters
    ----------
    robot
        A robot or a machine.
    q
        Joint positions, shape (N, n).
    T_carrier_part
        Placements of the definition frame in the carrier frame, shape (4, 4) or (G, 4, 4).
    group
        The placement of each sample, shape (N,), int; default all 0.

    Returns
    -------
    tuple of numpy.ndarray
        Placements in the cell frame (G', 4, 4) and the group of each sample (N,), int.
    """
    q = np.asarray(q, dtype=float)
    T = np.asarray(T_carrier_part, dtype=float).reshape(-1, 4, 4)
    n_samples = len(q)
    group = np.zeros(n_samples, np.int64) if group is None else np.asarray(group, np.int64)
    if not isinstance(robot, Machine) or robot.positioner is None:
        return T, group
    placed: np.ndarray = robot.T_cell_carrier(q) @ T[group]
    return placed, np.arange(n_samples, dtype=np.int64)


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
        Link capsules, then a machine's positioner capsules, then tool capsules, then the
        tool capsules clipped for the workpiece.
    bodies
        Obstacles, then workpiece bodies.
    n_obstacles
        How many of ``bodies`` are obstacles.
    kind, size
        Shape code (S,) and parameters (S, 3) of each screened shape: a primitive body as
        itself, a mesh as the boxes of :meth:`~trackplan.cell.model.Body.screening_boxes`;
        the obstacles' first.
    T_frame_screen
        Pose of each screened shape in its body's frame, shape (S, 4, 4).
    screen_owner
        The body of each screened shape, shape (S,), int.
    pair_capsule, pair_body
        The capsule–body pairs checked, shape (P,) each.
    screen_pair_capsule, screen_pair_body, screen_pair_start
        The pairs the kernel screens, capsule and screened shape, shape (P',) each: those of
        pair p from ``screen_pair_start[p]`` (shape (P,)) on, its distance their least.
    self_pairs
        The capsule–capsule pairs checked, shape (Q, 2): the arm's own pairs, then the
        positioner's capsules against the arm's.
    n_frames
        Frames of the arm's chain (base, links, TCP): the TCP is frame ``n_frames − 1``.
    n_positioner_frames
        Frames of a machine's positioner chain (base, links, flange), 0 without one: they
        follow the arm's in :func:`cell_frames`, frames ``n_frames`` onwards.
    """

    cell: Cell
    capsules: Capsules
    bodies: tuple[Body, ...]
    n_obstacles: int
    kind: np.ndarray
    size: np.ndarray
    T_frame_screen: np.ndarray
    screen_owner: np.ndarray
    pair_capsule: np.ndarray
    pair_body: np.ndarray
    screen_pair_capsule: np.ndarray
    screen_pair_body: np.ndarray
    screen_pair_start: np.ndarray
    self_pairs: np.ndarray
    n_frames: int
    n_positioner_frames: int = 0

    @classmethod
    def from_cell(cls, cell: Cell, robot: Robot | Machine) -> CellGeometry:
        """Lay out ``cell`` for a robot, or a machine (the arm's built-in capsules unless
        ``cell.links``; a positioner's own capsules).

        Raises
        ------
        CaseError
            When the arm, or the machine's positioner, has no link capsules.
        """
        arm = arm_of(robot)
        links = cell.links if cell.links is not None else builtin_link_capsules(arm)
        tcp = arm.n_dof + 1
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
        positioner = _positioner_capsules(robot)
        capsules = links + positioner + tool + clipped
        bodies = (*cell.obstacles, *cell.workpiece)
        n_obstacles = len(cell.obstacles)
        screened: list[tuple[np.ndarray, np.ndarray, int, int]] = []
        for o, body in enumerate(bodies):
            if body.shape is Shape.MESH:
                screened += [(T, half, Shape.BOX, o) for T, half in body.screening_boxes()]
            else:
                screened.append((body.T_frame_body, body.size, int(body.shape), o))
        T_screen = np.array([entry[0] for entry in screened]).reshape(-1, 4, 4)
        size = np.array([entry[1] for entry in screened]).reshape(-1, 3)
        kind = np.array([entry[2] for entry in screened], dtype=np.int64)
        owner = np.array([entry[3] for entry in screened], dtype=np.int64)
        n_links = len(links)
        moving_links = np.flatnonzero(links.frame > 0)  # the base stands in the cell
        link_index = np.arange(n_links)
        positioner_index = n_links + np.arange(len(positioner))
        tool_index = n_links + len(positioner) + np.arange(n_tool)
        clipped_index = n_links + len(positioner) + n_tool + np.arange(len(kept))
        # the positioner's base stands in the cell: only its moving links meet obstacles
        positioner_moving = positioner_index[positioner.frame > tcp + 1]
        obstacles = np.arange(n_obstacles)
        workpiece = n_obstacles + np.arange(len(cell.workpiece))
        pairs = [
            np.stack(np.meshgrid(moving_links, obstacles, indexing="ij"), -1),
            np.stack(np.meshgrid(link_index, workpiece, indexing="ij"), -1),
            np.stack(np.meshgrid(tool_index, obstacles, indexing="ij"), -1),
            np.stack(np.meshgrid(clipped_index, workpiece, indexing="ij"), -1),
            np.stack(np.meshgrid(positioner_moving, obstacles, indexing="ij"), -1),
        ]
        pair = np.concatenate([p.reshape(-1, 2) for p in pairs]).astype(np.int64)
        # every pair with a body, once per screened shape of that body
        shapes = [np.flatnonzero(owner == o) for o in range(len(bodies))]
        counts = np.array([len(shapes[o]) for o in pair[:, 1]], dtype=np.int64)
        screen_capsule = np.repeat(pair[:, 0], counts)
        screen_body = (
            np.concatenate([shapes[o] for o in pair[:, 1]]).astype(np.int64)
            if len(pair)
            else np.zeros(0, dtype=np.int64)
        )
        screen_start = (np.cumsum(counts) - counts).astype(np.int64)
        moving = np.concatenate([links.frame, tool.frame])
        arm_index = np.concatenate([link_index, tool_index])
        self_pairs = np.concatenate(
            [
                arm_index[self_collision_pairs(moving)].reshape(-1, 2),
                np.stack(np.meshgrid(arm_index, positioner_index, indexing="ij"), -1).reshape(
                    -1, 2
                ),
            ]
        ).astype(np.int64)
        return cls(
            cell=cell,
            capsules=capsules,
            bodies=bodies,
            n_obstacles=n_obstacles,
            kind=kind,
            size=size,
            T_frame_screen=T_screen,
            screen_owner=owner,
            pair_capsule=np.ascontiguousarray(pair[:, 0]),
            pair_body=np.ascontiguousarray(pair[:, 1]),
            screen_pair_capsule=np.ascontiguousarray(screen_capsule),
            screen_pair_body=np.ascontiguousarray(screen_body),
            screen_pair_start=np.ascontiguousarray(screen_start),
            self_pairs=np.ascontiguousarray(self_pairs),
            n_frames=arm.n_dof + 2,
            n_positioner_frames=_n_positioner_frames(robot),
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
        """World → screened-shape transforms for placements, shape (G, S, 3, 4).

        Parameters
        ----------
        T_base_part
            Placements of the definition frame, shape (G, 4, 4).
        """
        T_base_part = np.asarray(T_base_part, dtype=float).reshape(-1, 4, 4)
        n_groups = len(T_base_part)
        n_shapes = len(self.T_frame_screen)
        T_world_body = np.broadcast_to(self.T_frame_screen, (n_groups, n_shapes, 4, 4)).copy()
        on_part = self.screen_owner >= self.n_obstacles  # the workpiece's shapes
        if on_part.any():
            T_world_body[:, on_part] = T_base_part[:, None] @ self.T_frame_screen[on_part]
        R = np.swapaxes(T_world_body[..., :3, :3], -1, -2)
        out = np.empty((n_groups, n_shapes, 3, 4))
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
            The frames the capsules move with (:func:`cell_frames`; a robot's chain frames,
            :func:`trackplan.robots.kinematics.joint_frames`), shape (N, F, 4, 4).
        T_base_part
            Placements in the frame of the obstacles (a robot's base, a machine's cell),
            shape (G, 4, 4) (or (4, 4) for one).
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
        shapes, own = _kernels.screen_pairs(
            frames,
            self.capsules.frame,
            self.capsules.segment,
            self.capsules.radius,
            self.kind,
            self.size,
            self.world_to_body(T_base_part),
            group,
            self.screen_pair_capsule,
            self.screen_pair_body,
            self.self_pairs,
        )
        if len(self.screen_pair_capsule) == len(self.pair_capsule):  # one shape per body
            return shapes, own
        # a pair's distance: the least over its body's screened shapes
        return np.minimum.reduceat(shapes, self.screen_pair_start, axis=1), own

    def screen_joints(
        self,
        robot: Robot | Machine,
        q: np.ndarray,
        T_carrier_part: np.ndarray,
        group: np.ndarray | None = None,
    ) -> tuple[np.ndarray, np.ndarray]:
        """:meth:`screen` of joint positions.

        Parameters
        ----------
        robot
            The robot or machine the geometry was laid out for.
        q
            Joint positions, shape (N, n): for a machine every column, rad and m.
        T_carrier_part
            Placements of the definition frame in the carrier frame (the base frame of a
            robot, the positioner's flange or the cell frame of a machine), shape (4, 4) or
            (G, 4, 4).
        group
            The placement of each sample, shape (N,), int; default all 0.
        """
        frames = cell_frames(robot, q)
        self.check_frames(frames)
        T_part, group = part_placements(robot, q, T_carrier_part, group)
        return self.screen(frames, T_part, group)

    def check_frames(self, frames: np.ndarray) -> None:
        """Raise ValueError when ``frames`` (..., F, 4, 4) are not the F frames laid out."""
        expected = self.n_frames + self.n_positioner_frames
        if frames.shape[-3] != expected:
            raise ValueError(
                f"the cell was laid out for {expected} frames, got {frames.shape[-3]}: "
                "lay it out (CellGeometry.from_cell) for the same robot or machine"
            )


def _positioner_capsules(robot: Robot | Machine) -> Capsules:
    """A machine's positioner capsules on the frames after the arm's, named
    ``positioner …``; none for a robot or a machine without a positioner."""
    if not isinstance(robot, Machine) or robot.positioner is None:
        return Capsules.empty()
    chain = robot.positioner.chain
    if chain.collision is None:
        raise CaseError(
            f"positioner {robot.positioner.model or chain.name!r} has no link capsules, so "
            "the cell cannot check it: give collision in its file (docs/cell.md)",
            key="positioner",
        )
    own = chain.collision
    return Capsules(
        own.frame + robot.n_arm + 2,
        own.segment,
        own.radius,
        tuple(POSITIONER_PREFIX + name for name in own.name),
    )


def _n_positioner_frames(robot: Robot | Machine) -> int:
    """Frames of a machine's positioner chain (base, links, flange); 0 without one."""
    if not isinstance(robot, Machine) or robot.positioner is None:
        return 0
    return robot.positioner.n_dof + 2
