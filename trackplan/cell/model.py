"""The work cell as pure data: bodies (primitive shapes and meshes) and capsules.

Frames (docs/cell.md): obstacles are fixed in the robot base frame, workpiece bodies in the
path's definition frame (they move with the placement X), robot link capsules in their link
frames and tool capsules in the TCP frame.
"""

from __future__ import annotations

import enum
from dataclasses import dataclass, field

import numpy as np

from trackplan.robots.collision import Capsules

DEFAULT_CLEARANCE = 0.005
"""Least allowed distance between the robot and the cell when the case gives none, m."""


class Shape(enum.IntEnum):
    """Kinds of bodies (the codes the screening kernel dispatches on)."""

    PLANE = 0  # half-space z <= 0 of the body frame: the normal (z) points to the free side
    BOX = 1  # centred box, half extents (hx, hy, hz)
    CYLINDER = 2  # axis z, radius, half length
    SPHERE = 3  # centre at the origin, radius
    CAPSULE = 4  # axis z, radius, half length
    MESH = 5  # triangle mesh; screened as the boxes that enclose its triangles


MAX_SCREENING_BOXES = 64
"""Most boxes a mesh body is screened as (:meth:`Body.screening_boxes`)."""


@dataclass(frozen=True, eq=False)
class Body:
    """One rigid body of the cell.

    Attributes
    ----------
    name
        Name used in reports.
    shape
        Its :class:`Shape`.
    T_frame_body
        Pose of the body in its frame (base frame for obstacles, definition frame for
        the workpiece), shape (4, 4).
    size
        Shape parameters, shape (3,), m: box half extents; cylinder and capsule
        (radius, half length, 0); sphere (radius, 0, 0); plane and mesh zeros.
    vertices, faces
        Mesh only: vertices in the body frame, shape (V, 3), m, and triangles, shape
        (F, 3), int; empty otherwise.
    """

    name: str
    shape: Shape
    T_frame_body: np.ndarray
    size: np.ndarray = field(default_factory=lambda: np.zeros(3))
    vertices: np.ndarray = field(default_factory=lambda: np.zeros((0, 3)))
    faces: np.ndarray = field(default_factory=lambda: np.zeros((0, 3), dtype=np.int64))

    def __post_init__(self) -> None:
        for key, dtype in (
            ("T_frame_body", float),
            ("size", float),
            ("vertices", float),
            ("faces", np.int64),
        ):
            value = np.array(getattr(self, key), dtype=dtype)
            value.flags.writeable = False
            object.__setattr__(self, key, value)

    def screening_box(self) -> tuple[np.ndarray, np.ndarray]:
        """A mesh's axis-aligned bounding box in its body frame, as (T_frame_box, half extents).

        It encloses the mesh: a distance to it is never larger than to the mesh.
        """
        return self._box(self.vertices)

    def screening_boxes(
        self, max_boxes: int = MAX_SCREENING_BOXES
    ) -> list[tuple[np.ndarray, np.ndarray]]:
        """A mesh as at most ``max_boxes`` axis-aligned boxes that enclose its triangles, as
        (T_frame_box, half extents) each: the leaves of a median split of the triangles'
        centroids along the longest side, every leaf's box around its own triangles. The
        screening kernel sees a mesh as these boxes: a screened distance is never larger than
        the exact one, and, unlike one bounding box around the whole mesh, a tool working
        in a corner of a large part is not inside them."""
        triangles = self.vertices[self.faces]  # (F, 3, 3)
        if not len(triangles):
            return [self.screening_box()]
        leaves = [np.arange(len(triangles))]
        centroids = triangles.mean(axis=1)
        while len(leaves) < max_boxes:
            sizes = [len(leaf) for leaf in leaves]
            k = int(np.argmax(sizes))
            if sizes[k] <= 1:
                break
            leaf = leaves.pop(k)
            points = centroids[leaf]
            axis = int(np.argmax(np.ptp(points, axis=0)))
            order = leaf[np.argsort(points[:, axis], kind="stable")]
            half = len(order) // 2
            leaves += [order[:half], order[half:]]
        return [self._box(triangles[leaf].reshape(-1, 3)) for leaf in leaves]

    def _box(self, points: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The axis-aligned box (body frame) around points (K, 3), placed in its frame."""
        low, high = points.min(axis=0), points.max(axis=0)
        T_body_box = np.eye(4)
        T_body_box[:3, 3] = 0.5 * (low + high)
        return self.T_frame_body @ T_body_box, 0.5 * (high - low)


@dataclass(frozen=True, eq=False)
class Cell:
    """The work cell of a case.

    Attributes
    ----------
    obstacles
        Bodies fixed in the robot base frame (a machine's cell frame: the base with the
        track at 0).
    workpiece
        Bodies in the path's definition frame (they move with the placement, and with a
        machine's positioner flange).
    tool
        Tool capsules in the TCP frame (their ``frame`` is ignored: always the TCP).
    links
        Robot link capsules, or None for the robot's own model
        (:func:`trackplan.cell.robot_bodies.builtin_link_capsules`).
    clearance
        Least allowed distance between the robot (links and tool) and the cell, and
        between non-adjacent links, m.
    tool_contact
        Length of the tool from the TCP back along its axis (−z of the TCP frame) that may
        touch the workpiece, m.
    """

    obstacles: tuple[Body, ...] = ()
    workpiece: tuple[Body, ...] = ()
    tool: Capsules = field(default_factory=Capsules.empty)
    links: Capsules | None = None
    clearance: float = DEFAULT_CLEARANCE
    tool_contact: float = 0.0


__all__ = ["DEFAULT_CLEARANCE", "Body", "Capsules", "Cell", "Shape"]
