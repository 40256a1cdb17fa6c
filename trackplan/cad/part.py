"""A part's CAD model as the seam derivation reads it: faces, edges and their geometry.

A :class:`PartModel` is what a STEP file (an exact B-rep, read with OpenCascade) or a mesh
(triangles, read with trimesh) becomes: numbered faces and edges with their kinds, sizes and
neighbours, and the geometric queries the seams need: points along an edge, a face's outward
normal at points on it, the face nearest a point, the edges two faces share, and a
tessellation for the cell and the report. Lengths are metres in the path's definition frame
(the file's unit converted); ids are stable for a given file.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Protocol

import numpy as np

FACE_KINDS = ("plane", "cylinder", "cone", "sphere", "torus", "bspline", "other", "region")
"""Kinds of faces: a STEP face's surface type; ``region`` a mesh's smooth region."""
EDGE_KINDS = ("line", "circle", "ellipse", "bspline", "other", "boundary")
"""Kinds of edges: a STEP edge's curve type; ``boundary`` the border between two regions of
a mesh (a polyline)."""


@dataclass(frozen=True, eq=False)
class Face:
    """One face of the part.

    Attributes
    ----------
    id
        Its number, from 1, stable for a given file.
    kind
        One of :data:`FACE_KINDS`.
    area
        m².
    centroid
        Shape (3,), m.
    normal
        The outward unit normal of a plane (or a mesh region's mean), shape (3,); None else.
    axis
        The unit axis of a cylinder, cone or torus, shape (3,); None else.
    """

    id: int
    kind: str
    area: float
    centroid: np.ndarray
    normal: np.ndarray | None = None
    axis: np.ndarray | None = None


@dataclass(frozen=True, eq=False)
class Edge:
    """One edge of the part.

    Attributes
    ----------
    id
        Its number, from 1, stable for a given file.
    kind
        One of :data:`EDGE_KINDS`.
    length
        m.
    start, end
        Its end points in its own direction, shape (3,) each, m (equal for a closed edge).
    faces
        The ids of the faces it bounds (two for an edge between two faces).
    """

    id: int
    kind: str
    length: float
    start: np.ndarray
    end: np.ndarray
    faces: tuple[int, ...] = ()

    @property
    def closed(self) -> bool:
        """True for a closed edge (a full circle)."""
        return bool(np.linalg.norm(self.end - self.start) < 1e-9)


@dataclass(frozen=True, eq=False)
class Circle:
    """The exact geometry of a circular edge, in its own direction.

    Attributes
    ----------
    center
        Shape (3,), m.
    axis
        Unit axis, shape (3,): the edge turns positively about it (right hand).
    radius
        m.
    angle
        The angle it spans, rad, in (0, 2π].
    start
        Its start point, shape (3,), m.
    """

    center: np.ndarray
    axis: np.ndarray
    radius: float
    angle: float
    start: np.ndarray


@dataclass(frozen=True, eq=False)
class Tessellation:
    """The part's triangles, for the cell's clearance and the report.

    Attributes
    ----------
    vertices
        Shape (V, 3), m.
    triangles
        Vertex indices, shape (T, 3), int, outward by the right-hand rule.
    chord_error
        The largest distance of the triangles from the exact surface, m (0 for a mesh).
    face
        The face id of every triangle, shape (T,), int.
    """

    vertices: np.ndarray
    triangles: np.ndarray
    chord_error: float
    face: np.ndarray = field(default_factory=lambda: np.zeros(0, dtype=int))


class PartModel(Protocol):
    """A part read from a CAD file: the seam derivation's only view of it."""

    @property
    def source(self) -> str:
        """The file it was read from."""
        ...

    @property
    def exact(self) -> bool:
        """True for an exact B-rep (STEP); False for a mesh, whose positions and normals are
        as good as its tessellation."""
        ...

    @property
    def faces(self) -> tuple[Face, ...]:
        """Every face, by id order."""
        ...

    @property
    def edges(self) -> tuple[Edge, ...]:
        """Every edge, by id order."""
        ...

    def edge_points(self, edge: int, max_chord_error: float) -> np.ndarray:
        """Points along an edge from its start to its end, shape (K, 3), m: its vertices for
        a line (K = 2), else close enough that the polyline stays within
        ``max_chord_error`` (m) of the curve."""
        ...

    def edge_circle(self, edge: int) -> Circle | None:
        """The exact circle of a circular edge, else None."""
        ...

    def face_normals(self, face: int, points: np.ndarray) -> np.ndarray:
        """The face's outward unit normal at the points of it nearest ``points`` (M, 3),
        shape (M, 3)."""
        ...

    def nearest_face(self, point: np.ndarray) -> tuple[int, float]:
        """The face nearest a point (3,), and its distance, m."""
        ...

    def shared_edges(self, a: int, b: int) -> tuple[int, ...]:
        """The edges that faces a and b share, by id (none when they do not meet)."""
        ...

    def tessellation(self, chord_error: float) -> Tessellation:
        """The part's triangles within ``chord_error`` (m) of the surface."""
        ...
