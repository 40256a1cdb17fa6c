"""Exact distances through coal (the maintained successor of hpp-fcl).

Signed: positive when apart, negative (the penetration depth) when overlapping. Meshes are
triangle meshes (a BVH) and their distance is to the surface: a capsule wholly inside a
closed mesh, touching no triangle, is not reported as overlapping (model solid parts
that can swallow a link as primitives, or as meshes of their outer surfaces).
"""

from __future__ import annotations

import math

import coal
import numpy as np

from trackplan.cell.model import Body, Shape

GJK_TOLERANCE = 1e-10
"""Convergence tolerance of coal's GJK, m (its default 1e-6 is too coarse for the 1e-6 m test)."""


def _request() -> coal.DistanceRequest:
    request = coal.DistanceRequest()
    request.gjk_tolerance = GJK_TOLERANCE
    request.enable_signed_distance = True
    return request


def body_geometry(body: Body) -> tuple[coal.CollisionGeometry, np.ndarray]:
    """The coal geometry of a body and its pose in the body's frame, shape (4, 4)."""
    size = body.size
    if body.shape is Shape.PLANE:
        return coal.Halfspace(np.array([0.0, 0.0, 1.0]), 0.0), body.T_frame_body
    if body.shape is Shape.BOX:
        return coal.Box(*(2.0 * size)), body.T_frame_body
    if body.shape is Shape.CYLINDER:
        return coal.Cylinder(size[0], 2.0 * size[1]), body.T_frame_body
    if body.shape is Shape.SPHERE:
        return coal.Sphere(size[0]), body.T_frame_body
    if body.shape is Shape.CAPSULE:
        return coal.Capsule(size[0], 2.0 * size[1]), body.T_frame_body
    mesh = coal.BVHModelOBBRSS()
    mesh.beginModel(len(body.faces), len(body.vertices))
    mesh.addVertices(np.asarray(body.vertices, dtype=float))
    mesh.addTriangles(np.asarray(body.faces, dtype=np.int64))
    mesh.endModel()
    return mesh, body.T_frame_body


def capsule_pose(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Pose of a capsule whose axis runs from a to b: origin at the middle, z along b − a.

    Parameters
    ----------
    a, b
        End points, shape (3,), m.

    Returns
    -------
    numpy.ndarray
        Shape (4, 4).
    """
    ax, ay, az = float(a[0]), float(a[1]), float(a[2])
    zx, zy, zz = float(b[0]) - ax, float(b[1]) - ay, float(b[2]) - az
    length = math.sqrt(zx * zx + zy * zy + zz * zz)
    if length > 0.0:
        zx, zy, zz = zx / length, zy / length, zz / length
    else:
        zx, zy, zz = 0.0, 0.0, 1.0
    # x = helper × z with a helper axis not parallel to z, then y = z × x
    if abs(zx) < 0.9:  # helper (1, 0, 0)
        xx, xy, xz = 0.0, -zz, zy
    else:  # helper (0, 1, 0)
        xx, xy, xz = zz, 0.0, -zx
    norm = math.sqrt(xx * xx + xy * xy + xz * xz)
    xx, xy, xz = xx / norm, xy / norm, xz / norm
    yx, yy, yz = zy * xz - zz * xy, zz * xx - zx * xz, zx * xy - zy * xx
    return np.array(
        [
            [xx, yx, zx, ax + 0.5 * length * zx],
            [xy, yy, zy, ay + 0.5 * length * zy],
            [xz, yz, zz, az + 0.5 * length * zz],
            [0.0, 0.0, 0.0, 1.0],
        ]
    )


def _transform(T: np.ndarray) -> coal.Transform3s:
    return coal.Transform3s(np.ascontiguousarray(T[:3, :3]), np.ascontiguousarray(T[:3, 3]))


class ExactDistance:
    """Exact capsule–body and capsule–capsule distances, with coal objects built once."""

    def __init__(self) -> None:
        self._request = _request()
        self._last_points = np.zeros((2, 3))
        # keyed by id; the body is kept so that its id cannot be reused while cached
        self._bodies: dict[int, tuple[Body, coal.CollisionGeometry, np.ndarray]] = {}

    def capsule_body(
        self, a: np.ndarray, b: np.ndarray, radius: float, body: Body, T_world_frame: np.ndarray
    ) -> float:
        """Signed distance between a capsule (world end points a, b, m; radius, m) and a body.

        Parameters
        ----------
        a, b
            Capsule axis end points in the world, shape (3,), m.
        radius
            m.
        body
            The body.
        T_world_frame
            Pose of the body's frame in the world, shape (4, 4).
        """
        key = id(body)
        if key not in self._bodies:
            self._bodies[key] = (body, *body_geometry(body))
        _, geometry, T_frame_body = self._bodies[key]
        return self._distance(
            a, b, radius, geometry, np.asarray(T_world_frame, dtype=float) @ T_frame_body
        )

    def capsule_capsule(
        self, a0: np.ndarray, b0: np.ndarray, r0: float, a1: np.ndarray, b1: np.ndarray, r1: float
    ) -> float:
        """Signed distance between two capsules given by world end points and radii, m."""
        length = float(np.linalg.norm(np.asarray(b1) - np.asarray(a1)))
        return self._distance(a0, b0, r0, _capsule(r1, length), capsule_pose(a1, b1))

    @property
    def last_points(self) -> np.ndarray:
        """Nearest points of the last distance computed (capsule first), shape (2, 3), m."""
        return self._last_points

    def nearest_points_body(
        self, a: np.ndarray, b: np.ndarray, radius: float, body: Body, T_world_frame: np.ndarray
    ) -> np.ndarray:
        """Nearest points of a capsule and a body (as :meth:`capsule_body`), shape (2, 3), m."""
        self.capsule_body(a, b, radius, body, T_world_frame)
        return self._last_points

    def nearest_points_capsules(
        self, a0: np.ndarray, b0: np.ndarray, r0: float, a1: np.ndarray, b1: np.ndarray, r1: float
    ) -> np.ndarray:
        """Nearest points of two capsules (as :meth:`capsule_capsule`), shape (2, 3), m."""
        self.capsule_capsule(a0, b0, r0, a1, b1, r1)
        return self._last_points

    def _distance(
        self,
        a: np.ndarray,
        b: np.ndarray,
        radius: float,
        geometry: coal.CollisionGeometry,
        T_world_body: np.ndarray,
    ) -> float:
        length = float(np.linalg.norm(np.asarray(b) - np.asarray(a)))
        result = coal.DistanceResult()
        distance = coal.distance(
            _capsule(radius, length),
            _transform(capsule_pose(a, b)),
            geometry,
            _transform(T_world_body),
            self._request,
            result,
        )
        self._last_points = np.array([result.getNearestPoint1(), result.getNearestPoint2()])
        return float(distance)


def _capsule(radius: float, length: float) -> coal.CollisionGeometry:
    """A coal capsule (a sphere when the axis has no length)."""
    if length <= 1e-12:
        return coal.Sphere(radius)
    return coal.Capsule(radius, length)
