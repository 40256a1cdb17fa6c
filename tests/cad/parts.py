"""Small analytic part models (the PartModel protocol) for the seam derivation's tests.

Each face is a surface with a closed-form outward normal and distance; each edge a
parametric curve. Independent of any CAD file reader.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from trackplan.cad.part import Circle, Edge, Face, Tessellation

Curve = Callable[[np.ndarray], np.ndarray]
"""Points (M, 3) at parameters t (M,) in [0, 1]."""


@dataclass
class AnalyticFace:
    kind: str
    normal: Callable[[np.ndarray], np.ndarray]  # outward normals (M, 3) at points (M, 3)
    distance: Callable[[np.ndarray], float]  # distance of a point (3,) from the face
    centroid: tuple[float, float, float] = (0.0, 0.0, 0.0)


@dataclass
class AnalyticEdge:
    kind: str
    curve: Curve
    faces: tuple[int, ...]
    circle: Circle | None = None


@dataclass
class AnalyticPart:
    """A part made of analytic faces and edges (ids from 1 in list order)."""

    face_list: list[AnalyticFace]
    edge_list: list[AnalyticEdge]
    is_exact: bool = True
    name: str = "analytic.step"
    queried: list[float] = field(default_factory=list)  # chord errors asked for
    cached: tuple[tuple[int, ...], tuple[Edge, ...]] | None = None  # edges by edge_list

    @property
    def source(self) -> str:
        return self.name

    @property
    def exact(self) -> bool:
        return self.is_exact

    @property
    def faces(self) -> tuple[Face, ...]:
        return tuple(
            Face(i + 1, f.kind, 1.0, np.array(f.centroid)) for i, f in enumerate(self.face_list)
        )

    @property
    def edges(self) -> tuple[Edge, ...]:
        key = tuple(id(e) for e in self.edge_list)
        if self.cached is not None and self.cached[0] == key:
            return self.cached[1]
        result = []
        for i, e in enumerate(self.edge_list):
            ends = e.curve(np.array([0.0, 1.0]))
            fine = e.curve(np.linspace(0.0, 1.0, 2001 if e.kind != "line" else 2))
            length = float(np.linalg.norm(np.diff(fine, axis=0), axis=1).sum())
            result.append(Edge(i + 1, e.kind, length, ends[0], ends[1], e.faces))
        self.cached = (key, tuple(result))
        return self.cached[1]

    def edge_points(self, edge: int, max_chord_error: float) -> np.ndarray:
        self.queried.append(max_chord_error)
        e = self.edge_list[edge - 1]
        if e.kind == "line":
            return e.curve(np.array([0.0, 1.0]))
        # dense enough for these smooth test curves: refine until the midpoints are close
        count = 8
        while True:
            t = np.linspace(0.0, 1.0, count + 1)
            points = e.curve(t)
            middle = e.curve(0.5 * (t[1:] + t[:-1]))
            chord = 0.5 * (points[1:] + points[:-1])
            if np.linalg.norm(middle - chord, axis=1).max() <= max_chord_error:
                return points
            count *= 2

    def edge_circle(self, edge: int) -> Circle | None:
        return self.edge_list[edge - 1].circle

    def face_normals(self, face: int, points: np.ndarray) -> np.ndarray:
        return self.face_list[face - 1].normal(np.atleast_2d(points))

    def nearest_face(self, point: np.ndarray) -> tuple[int, float]:
        distances = [f.distance(np.asarray(point, dtype=float)) for f in self.face_list]
        k = int(np.argmin(distances))
        return k + 1, float(distances[k])

    def shared_edges(self, a: int, b: int) -> tuple[int, ...]:
        return tuple(i + 1 for i, e in enumerate(self.edge_list) if {a, b} <= set(e.faces))

    def tessellation(self, chord_error: float) -> Tessellation:
        vertices = np.array([[0, 0, 0], [0.1, 0, 0], [0, 0.1, 0], [0, 0, 0.1]], dtype=float)
        triangles = np.array([[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]])
        return Tessellation(vertices, triangles, chord_error, np.ones(4, dtype=int))


def _constant(normal: tuple[float, float, float]) -> Callable[[np.ndarray], np.ndarray]:
    unit = np.asarray(normal, dtype=float) / np.linalg.norm(normal)
    return lambda points: np.repeat(unit[None], len(points), axis=0)


def _radial(points: np.ndarray) -> np.ndarray:
    r = points.copy()
    r[:, 2] = 0.0
    return np.asarray(r / np.linalg.norm(r, axis=1, keepdims=True), dtype=float)


RADIUS = 0.06
HEIGHT = 0.1


def pipe_on_plate() -> AnalyticPart:
    """A pipe (radius 60 mm, height 100 mm, axis z) standing on a plate (top z = 0).

    Faces: 1 plate top (+z), 2 pipe wall (radial), 3 pipe top (+z). Edges: 1 the foot
    circle (faces 1, 2, from (R, 0, 0) turning positively about +z), 2 the top circle
    (faces 2, 3).
    """

    def circle(z: float) -> Curve:
        return lambda t: np.stack(
            [RADIUS * np.cos(2 * np.pi * t), RADIUS * np.sin(2 * np.pi * t), np.full_like(t, z)],
            axis=1,
        )

    def wall_distance(p: np.ndarray) -> float:
        radial = abs(np.hypot(p[0], p[1]) - RADIUS)
        below = max(0.0, -p[2], p[2] - HEIGHT)
        return float(np.hypot(radial, below))

    def plate_distance(p: np.ndarray) -> float:
        outside = max(0.0, max(abs(p[0]), abs(p[1])) - 0.2)
        return float(np.hypot(p[2], outside))

    def top_distance(p: np.ndarray) -> float:
        outside = max(0.0, np.hypot(p[0], p[1]) - RADIUS)
        return float(np.hypot(p[2] - HEIGHT, outside))

    faces = [
        AnalyticFace("plane", _constant((0, 0, 1)), plate_distance),
        AnalyticFace("cylinder", _radial, wall_distance),
        AnalyticFace("plane", _constant((0, 0, 1)), top_distance),
    ]
    edges = [
        AnalyticEdge(
            "circle",
            circle(0.0),
            (1, 2),
            Circle(np.zeros(3), np.array([0.0, 0, 1]), RADIUS, 2 * np.pi, np.array([RADIUS, 0, 0])),
        ),
        AnalyticEdge(
            "circle",
            circle(HEIGHT),
            (2, 3),
            Circle(
                np.array([0.0, 0, HEIGHT]),
                np.array([0.0, 0, 1]),
                RADIUS,
                2 * np.pi,
                np.array([RADIUS, 0, HEIGHT]),
            ),
        ),
    ]
    return AnalyticPart(faces, edges)


THICKNESS = 0.01
LENGTH = 0.2


def _segment(a: tuple[float, float, float], b: tuple[float, float, float]) -> Curve:
    pa, pb = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
    return lambda t: pa + np.outer(t, pb - pa)


def t_joint() -> AnalyticPart:
    """A web plate (x = ±5 mm, z from 0 to 100 mm, y from 0 to 200 mm) on a base plate.

    Faces: 1 base top (+z), 2 web left (−x), 3 web right (+x). Edges: 1 the right fillet
    line (faces 1, 3) from (t/2, 0, 0) to (t/2, L, 0), 2 the left one (faces 1, 2) from
    (−t/2, L, 0) to (−t/2, 0, 0).
    """
    h = THICKNESS / 2

    def plane_distance(axis: int, value: float) -> Callable[[np.ndarray], float]:
        return lambda p: float(abs(p[axis] - value))

    faces = [
        AnalyticFace("plane", _constant((0, 0, 1)), plane_distance(2, 0.0)),
        AnalyticFace("plane", _constant((-1, 0, 0)), plane_distance(0, -h)),
        AnalyticFace("plane", _constant((1, 0, 0)), plane_distance(0, h)),
    ]
    edges = [
        AnalyticEdge("line", _segment((h, 0, 0), (h, LENGTH, 0)), (1, 3)),
        AnalyticEdge("line", _segment((-h, LENGTH, 0), (-h, 0, 0)), (1, 2)),
    ]
    return AnalyticPart(faces, edges)


CURVATURE = 8.0  # 1/m: the wall follows y = CURVATURE x²


def curved_wall() -> AnalyticPart:
    """A wall along y = a x² (x in ±50 mm) standing on a plate (z = 0).

    Faces: 1 plate top (+z), 2 the wall's convex side (normal (2ax, −1, 0) normalised).
    Edge 1: their shared curve (bspline), from x = −50 mm to x = 50 mm.
    """

    def wall_normal(points: np.ndarray) -> np.ndarray:
        n = np.stack([2 * CURVATURE * points[:, 0], -np.ones(len(points)), 0 * points[:, 0]], 1)
        return np.asarray(n / np.linalg.norm(n, axis=1, keepdims=True), dtype=float)

    def curve(t: np.ndarray) -> np.ndarray:
        x = -0.05 + 0.1 * t
        return np.stack([x, CURVATURE * x**2, 0 * x], axis=1)

    def wall_distance(p: np.ndarray) -> float:
        x = np.linspace(-0.05, 0.05, 2001)
        return float(np.hypot(x - p[0], CURVATURE * x**2 - p[1]).min())

    faces = [
        AnalyticFace("plane", _constant((0, 0, 1)), lambda p: float(abs(p[2]))),
        AnalyticFace("bspline", wall_normal, wall_distance),
    ]
    return AnalyticPart(faces, [AnalyticEdge("bspline", curve, (1, 2))])


def line_edges(
    *segments: tuple[tuple[float, float, float], tuple[float, float, float]],
) -> AnalyticPart:
    """A part of line edges only (between faces 1 and 2: +z and +x planes), for chaining."""
    faces = [
        AnalyticFace("plane", _constant((0, 0, 1)), lambda p: float(abs(p[2]))),
        AnalyticFace("plane", _constant((1, 0, 0)), lambda p: float(abs(p[0]))),
    ]
    edges = [AnalyticEdge("line", _segment(a, b), (1, 2)) for a, b in segments]
    return AnalyticPart(faces, edges)
